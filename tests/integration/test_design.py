"""Where to measure next (bayesfo.design, in bayesfo.planning): the expected information against known answers.

Known answers: two structures whose posteriors are the same carry no information about which
is right (I = 0 everywhere); two whose predictions part by far more than the noise at some
frequency, with equal probabilities, give there the whole entropy of the choice, ln 2, and their
log Bayes factor moves decisively after one point there. The information of a set of points is
at most the entropy and grows with the set. The command writes what the API returns.
"""

from __future__ import annotations

import json
import math
import warnings
from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import bayesfo as bf  # noqa: E402
from bayesfo.data import FrequencyResponse  # noqa: E402
from bayesfo.errors import InputError  # noqa: E402
from bayesfo.planning import DECISIVE, design  # noqa: E402
from bayesfo.structures import get_structure  # noqa: E402

W = np.logspace(-1, 1, 15)


def _result(name, theta, rel_sd, log_z, n=400, seed=0, noise=0.01):
    """A stand-in for a structure's result: Voigt draws around ``theta`` (a1, b0, q) scattered
    by ``rel_sd``, proportional noise ``noise``."""
    rng = np.random.default_rng(seed)
    theta = np.asarray(theta, float)
    draws = theta * (1 + rel_sd * rng.standard_normal((n, 3)))
    samples = np.column_stack([draws, np.full(n, noise)])
    post = SimpleNamespace(samples=samples, noise="proportional",
                           param_names=("a1", "b0", "q", "sigma_rel"))
    return SimpleNamespace(name=name, structure=get_structure("voigt"), posterior=post,
                           log_z=log_z, criteria=SimpleNamespace(evidence=SimpleNamespace(log_z=log_z)))


class _Comparison(SimpleNamespace):
    def __getitem__(self, name):
        return self._by[name]


def _make(*results):
    data = FrequencyResponse(W, get_structure("voigt").response([[1.0, 1.0, 0.5]], W,
                                                                  "compliance")[0],
                             kind="compliance")
    return _Comparison(data=data, ranking=[r.name for r in results],
                       _by={r.name: r for r in results})


def test_identical_posteriors_carry_no_information():
    a = _result("a", [1.0, 1.0, 0.5], 0.05, 0.0, seed=1)
    b = _result("b", [1.0, 1.0, 0.5], 0.05, 0.0, seed=1)
    plan = design(_make(a, b), window=(0.01, 100.0), points=2)
    assert plan.probabilities == pytest.approx((0.5, 0.5))
    assert plan.entropy == pytest.approx(math.log(2))
    # Zero up to Monte Carlo error: each predictive is estimated from its own 160 of the
    # draws, so the two normal forms differ by their sampling error (a few thousandths of a nat).
    assert np.max(plan.information) < 0.02
    assert plan.proposed[-1]["information"] < 0.03
    assert abs(plan.expected_change["a"]) < 0.05 and abs(plan.expected_change["b"]) < 0.05
    assert plan.p_decisive == 0.0


def test_structures_that_part_far_outside_the_noise_give_the_whole_entropy():
    """q = 0.5 against q = 0.9 with a1 = b0 = 1 (J = 1/(s^q + 1)): at ω = 100 rad/s the
    magnitudes differ by a factor of about 5 and the phases by 36°, against 1 % noise and 1 %
    parameter spread; at 1e-4 rad/s both are the spring within 0.7 %."""
    a = _result("half", [1.0, 1.0, 0.5], 0.01, 0.0)
    b = _result("nine", [1.0, 1.0, 0.9], 0.01, 0.0, seed=2)
    plan = design(_make(a, b), window=(1e-4, 100.0), points=1)
    assert plan.information[-1] == pytest.approx(math.log(2), abs=0.01)
    assert np.all(plan.information <= math.log(2) + 0.01)
    assert plan.information[0] < 0.3
    assert plan.proposed[0]["information"] == pytest.approx(math.log(2), abs=0.01)
    # After that point either structure, if right, wins decisively.
    assert plan.expected_change["half"] > 10 * DECISIVE
    assert plan.expected_change["nine"] < -10 * DECISIVE
    assert plan.p_decisive == pytest.approx(1.0)


def test_the_information_of_a_set_grows_with_it_and_stays_below_the_entropy():
    a = _result("a", [1.0, 1.0, 0.5], 0.03, 0.3, seed=3)
    b = _result("b", [1.0, 1.0, 0.55], 0.03, 0.0, seed=4)
    plan = design(_make(a, b), window=(0.01, 100.0), points=4)
    totals = [p["information"] for p in plan.proposed]
    assert totals == sorted(totals) and totals[-1] <= plan.entropy + 1e-6
    assert all(p["gain"] >= 0 for p in plan.proposed)
    n = len(plan.proposed)
    assert 1 <= n <= 4 and len({p["omega"] for p in plan.proposed}) == n  # distinct
    # Fewer than asked only where a further point adds nothing measurable, and said so.
    assert n == 4 or any("adds measurable information" in t for t in plan.notes)
    assert plan.asked == 4
    for value in plan.alternatives.values():
        assert 0 <= value <= plan.entropy + 1e-6
    # The same seed gives the same design.
    again = design(_make(a, b), window=(0.01, 100.0), points=4)
    assert again.proposed == plan.proposed


def test_cost_per_second_moves_the_points_to_higher_frequencies():
    from bayesfo.planning import seconds

    assert seconds(2 * np.pi) == pytest.approx(13.0)  # 10 s + three periods of 1 s
    # Springs of 10 and 5 (b0 0.1, 0.2) behind the same springpot: the two part below
    # ω ≈ b0² and agree above, so the lowest frequency tells them apart most, and one a
    # decade or two higher almost as well in a fraction of the time.
    a = _result("a", [1.0, 0.1, 0.5], 0.01, 0.0, seed=3)
    b = _result("b", [1.0, 0.2, 0.5], 0.01, 0.0, seed=4)
    plain = design(_make(a, b), window=(1e-3, 100.0), points=1)
    cheap = design(_make(a, b), window=(1e-3, 100.0), points=1, cost="low-frequency")
    assert plain.proposed[0]["omega"] < 0.01
    assert cheap.proposed[0]["omega"] > plain.proposed[0]["omega"]
    assert cheap.proposed[0]["seconds"] < plain.proposed[0]["seconds"]


@pytest.mark.parametrize("kwargs, message", [
    ({"window": (5.0, 1.0)}, "'window' must have 0 < low < high"),
    ({"window": (0.0, 1.0)}, "'window' must have 0 < low < high"),
    ({"window": "wide"}, "'window' must be two frequencies"),
    ({"points": 0}, "'points' must be an integer from 1 to 20"),
    ({"cost": "cheap"}, "'cost' must be one of uniform, low-frequency"),
    ({"structures": ["a", "zz"]}, "no structure 'zz'"),
])
def test_bad_arguments_are_refused(kwargs, message):
    a = _result("a", [1.0, 1.0, 0.5], 0.03, 0.0)
    b = _result("b", [1.0, 1.0, 0.55], 0.03, 0.0)
    with pytest.raises(InputError, match=message):
        design(_make(a, b), **kwargs)


def test_a_settled_choice_is_refused_with_the_reason():
    a = _result("a", [1.0, 1.0, 0.5], 0.03, 0.0)
    b = _result("b", [1.0, 1.0, 0.55], 0.03, -20.0)
    with pytest.raises(InputError, match=r"could still win; a has posterior probability 1\.0000"):
        design(_make(a, b))
    with pytest.raises(InputError, match="one structure with a posterior"):
        design(_make(a))


@pytest.fixture(scope="module")
def compared(tmp_path_factory):
    """Voigt and Zener on simulated Zener data whose second plateau lies above the window."""
    rng = np.random.default_rng(0)
    w = np.logspace(-1, 1, 15)
    g = get_structure("zener").response([[1.0, 0.02, 1.0, 0.5]], w, "compliance")[0]
    sd = 0.01 * np.abs(g)
    data = FrequencyResponse(w, g + sd / np.sqrt(2) * (rng.normal(size=15) + 1j * rng.normal(size=15)),
                             sd, kind="compliance")
    out = tmp_path_factory.mktemp("design")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = bf.compare(data, "voigt,zener", seed=0, progress=False, workers=1)
        bf.write_outputs(result, out / "run", figures=False)
    return result, out


def test_the_command_prints_and_writes_what_the_api_gives(compared, run_cli, tmp_path):
    # Both structures miss these data (the fixture's Zener lies outside the prior's support:
    # 108 % in |G| at 10 rad/s), so the command plans for the best one's parameters.
    from bayesfo.planning import all_inadequate, design_parameter

    result, out = compared
    assert all_inadequate(result) == list(result.ranking)
    plan = design_parameter(result, None, structure=result.ranking[0], points=2)
    status, text, err = run_cli("design", out / "run", "--points", "2", "--json")
    assert status == 0, err
    shown = json.loads(text)
    assert [p["omega"] for p in shown["proposed"]] == [p["omega"] for p in plan.proposed]
    assert shown["sd_now"] == plan.sd_now and shown["parameter"] == "all"
    figure = tmp_path / "design.png"
    status, text, err = run_cli("design", out / "run", "--points", "2", "--figure", figure)
    assert status == 2 and "leave it out" in err
    status, text, err = run_cli("design", out / "run", "--parameter", "q", "--structures",
                                "zener", "--points", "1", "--json")
    assert status == 0, err
    from bayesfo.planning import design_parameter

    want = design_parameter(result, "q", structure="zener", points=1)
    assert json.loads(text)["proposed"][0]["omega"] == want.proposed[0]["omega"]
    status, _, err = run_cli("design", out / "run", "--parameter", "q", "--figure",
                             tmp_path / "p.png")
    assert status == 2 and "leave it out with --parameter" in err
    status, _, err = run_cli("design", out / "run", "--window", "10,1")
    assert status == 2 and "--window must have 0 < low < high" in err
    status, _, err = run_cli("design", out / "run", "--figure", tmp_path / "no" / "d.png")
    assert status == 2 and "does not exist" in err


@pytest.mark.slow
def test_the_proposed_points_settle_the_choice_faster_than_rules_of_thumb():
    """A simulation study: Zener data (the demo's frequencies, 2 % noise) whose second plateau
    begins near 10⁴ rad/s, two decades above the window, so that Voigt and Zener are not yet told
    apart. Three proposed points (window up to 1000 × the highest frequency), simulated from
    the truth and added, raise ln B of the Zener over the Voigt far more than three log-uniform
    points over the same window, or three in the decade above or below the data."""
    zener = get_structure("zener")
    truth = [1.78398201, 1.65441487e-05, 8.7e-08, 0.569527278]  # a1, b0, b1, q
    w = bf.read(__import__("pathlib").Path(__file__).parents[2] / "examples" / "data"
                / "adhesive_468mp" / "Tp020C.csv").omega

    def simulate(omega, rng):
        g = zener.response([truth], omega, "modulus")[0]
        sd = 0.02 * np.abs(g)
        return g + sd / np.sqrt(2) * (rng.normal(size=g.size) + 1j * rng.normal(size=g.size)), sd

    def log_b(omega, y, sd):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            c = bf.compare(FrequencyResponse(omega, y, sd, kind="modulus"), "voigt,zener",
                           seed=0, progress=False, workers=1)
        return c, c["zener"].criteria.evidence.log_z - c["voigt"].criteria.evidence.log_z

    y, sd = simulate(w, np.random.default_rng(0))
    first, before = log_b(w, y, sd)
    assert abs(before) < 2  # not yet told apart
    plan = design(first, points=3, window=(w.min() / 10, w.max() * 1000))
    # Where the plateau begins: above the data, the first far above.
    assert plan.proposed[0]["omega"] > 100 * w.max(), plan.proposed
    assert all(p["omega"] > w.max() for p in plan.proposed), plan.proposed
    lo, hi = w.min(), w.max()
    sets = {"proposed": np.array([p["omega"] for p in plan.proposed]),
            "log-uniform": np.logspace(np.log10(lo / 10), np.log10(hi * 1000), 5)[1:-1],
            "decade below": np.logspace(np.log10(lo / 10), np.log10(lo), 4)[:-1],
            "decade above": np.logspace(np.log10(hi), np.log10(hi * 10), 4)[1:]}
    for seed in (1, 2):
        rng = np.random.default_rng(seed)
        after = {}
        for name, extra in sets.items():
            y2, sd2 = simulate(extra, rng)
            after[name] = log_b(np.r_[w, extra], np.r_[y, y2], np.r_[sd, sd2])[1]
        assert after["proposed"] > DECISIVE
        assert after["proposed"] > 2 * max(v for k, v in after.items() if k != "proposed")


def test_a_parameter_is_best_measured_where_it_shows():
    """Voigt, J = 1/(a1 s^q + b0) with a1 = b0 = 1: b0 (the spring) shows at the lowest
    frequencies; a1 where ln|a1 s^q| does not also carry the spread of q ln ω, near ω = 1. The
    expected posterior sd after one point agrees with an independent regression of the parameter
    on measurements simulated from the draws (their residual variance)."""
    from bayesfo.planning import design_parameter

    a = _result("a", [1.0, 1.0, 0.5], 0.05, 0.0, n=2000, seed=5)
    b = _result("b", [1.0, 1.0, 0.55], 0.05, -1.0, seed=6)
    comp = _make(a, b)
    spring = design_parameter(comp, "b0", window=(1e-4, 1e4), points=1)
    springpot = design_parameter(comp, "a1", window=(1e-4, 1e4), points=1)
    assert spring.structure == "a" and spring.proposed[0]["omega"] < 1e-2
    assert 1e-2 < springpot.proposed[0]["omega"] < 1e2
    for plan, column in ((spring, 1), (springpot, 0)):
        p = plan.proposed[0]
        assert p["sd_after"] < plan.sd_now
        assert p["information"] == pytest.approx(-math.log(p["sd_after"] / plan.sd_now), rel=1e-6)
        # Independent: regress the parameter on (ln|J|, arg J) measured at that frequency.
        rng = np.random.default_rng(0)
        theta = a.posterior.samples
        j = get_structure("voigt").response(theta[:, :3], np.array([p["omega"]]),
                                            "compliance")[:, 0]
        y = np.column_stack([np.log(np.abs(j)), np.angle(j)])
        y = y + 0.01 / np.sqrt(2) * rng.standard_normal(y.shape)
        x = np.column_stack([np.ones(len(y)), y])
        coef, *_ = np.linalg.lstsq(x, theta[:, column], rcond=None)
        residual_sd = np.std(theta[:, column] - x @ coef)
        assert p["sd_after"] == pytest.approx(residual_sd, rel=0.15)
    with pytest.raises(InputError, match="has no parameter 'zz'; its parameters are a1, b0, q"):
        design_parameter(comp, "zz")


def test_proposed_points_lie_apart_by_the_width_of_the_information(monkeypatch):
    """Two structures that part most at the window's top with 10 % noise: without a spacing
    the greedy choice puts its second point on the neighbouring candidate (100 and 86 rad/s,
    0.07 decades apart, as 0.063 and 0.074 rad/s were proposed on silk data); with it the
    points lie at least half the information peak's width apart (here the cap, 0.5)."""
    import bayesfo.planning.choice as choice

    a = _result("a", [1.0, 1.0, 0.5], 0.03, 0.3, seed=3, noise=0.1)
    b = _result("b", [1.0, 1.0, 0.55], 0.03, 0.0, seed=4, noise=0.1)

    def gaps(plan):
        logs = np.log10([p["omega"] for p in plan.proposed])
        return np.abs(logs[:, None] - logs[None, :])[np.triu_indices(logs.size, 1)]

    plan = design(_make(a, b), window=(0.01, 100.0), points=5)
    step = np.log10(plan.omega[1] / plan.omega[0])
    assert 2 * step < plan.spacing <= choice.MAX_SPACING
    assert len(plan.proposed) >= 2 and gaps(plan).min() >= plan.spacing - 1e-9
    assert plan.to_dict()["min_spacing_decades"] == plan.spacing
    with monkeypatch.context() as mp:
        mp.setattr(choice, "SPACING_SHARE", 0.0)
        stacked = design(_make(a, b), window=(0.01, 100.0), points=5)
    assert gaps(stacked).min() < 0.1
    # The rule on a known curve: a peak of half-maximum width 0.6 decades gives 0.3, within
    # a step of the grid (0.1 decades).
    x = np.linspace(-3, 3, 61)
    info = np.exp(-0.5 * (x / (0.6 / 2.3548)) ** 2)
    assert choice.min_spacing(x, info) == pytest.approx(0.3, abs=0.051)


def test_a_design_among_structures_that_all_fail_the_checks_says_so():
    a = _result("a", [1.0, 1.0, 0.5], 0.03, 0.3, seed=3)
    b = _result("b", [1.0, 1.0, 0.55], 0.03, 0.0, seed=4)
    for r in (a, b):
        r.criteria.adequacy = SimpleNamespace(adequate=False)
    plan = design(_make(a, b), window=(0.01, 100.0), points=2)
    assert any("every structure considered (a, b) fails" in n for n in plan.notes)
    b.criteria.adequacy = SimpleNamespace(adequate=True)
    plan = design(_make(a, b), window=(0.01, 100.0), points=2)
    assert not any("every structure considered" in n for n in plan.notes)


def test_the_parameters_together_carry_at_least_the_information_of_each():
    """The information about the parameter vector bounds that about any one of them, and with
    one parameter the joint plan is the single one's."""
    from bayesfo.planning import all_inadequate, design_parameter

    a = _result("a", [1.0, 1.0, 0.5], 0.05, 0.0, n=2000, seed=5)
    b = _result("b", [1.0, 1.0, 0.55], 0.05, -1.0, seed=6)
    comp = _make(a, b)
    joint = design_parameter(comp, None, window=(1e-4, 1e4), points=1)
    assert joint.parameter == "all" and set(joint.sd_now) == {"a1", "b0", "q"}
    for name in ("a1", "b0", "q"):
        one = design_parameter(comp, name, window=(1e-4, 1e4), points=1)
        assert np.all(joint.information >= one.information - 1e-9)
        assert joint.proposed[0]["sd_after"][name] <= joint.sd_now[name]
    assert all_inadequate(comp) == []
    for r in (a, b):
        r.criteria.adequacy = SimpleNamespace(adequate=False)
    assert all_inadequate(comp) == ["a", "b"] and all_inadequate(comp, ["b"]) == ["b"]


def test_the_command_plans_for_the_best_ones_parameters_where_every_structure_fails(
        run_cli, tmp_path):
    """Two relaxations 2.3 decades apart (J = 1 + 2/(1 + 10 s) + 2/(1 + 0.05 s), 1 % noise, σ
    given) compared with single-relaxation structures only: both fail the checks, so design
    says so and proposes where the best one's parameters are least determined."""
    w = np.logspace(-2, 2, 20)
    s = 1j * w
    g = 1 + 2 / (1 + 10 * s) + 2 / (1 + 0.05 * s)
    rng = np.random.default_rng(0)
    sd = 0.01 * np.abs(g)
    data = FrequencyResponse(w, g + sd / np.sqrt(2) * (rng.normal(size=20)
                                                        + 1j * rng.normal(size=20)),
                             sd, kind="compliance")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = bf.compare(data, "zener-int,voigt-int", seed=0, progress=False, workers=1)
        bf.write_outputs(result, tmp_path / "run", figures=False)
    assert not any(result[n].criteria.adequacy.adequate for n in result.ranking)
    status, text, err = run_cli("design", tmp_path / "run", "--points", "2", "--json")
    assert status == 0, err
    plan = json.loads(text)
    best = result.ranking[0]
    assert plan["structure"] == best and plan["parameter"] == "all"
    assert any("every structure considered" in n and "fails" in n for n in plan["notes"])
    assert len({p["omega"] for p in plan["proposed"]}) == 2
    last = plan["proposed"][-1]["sd_after"]
    assert set(last) == set(plan["sd_now"]) and all(last[k] <= plan["sd_now"][k] for k in last)
    status, text, err = run_cli("design", tmp_path / "run", "--points", "1")
    assert status == 0 and "note: every structure considered" in text
    assert f"all parameters of {best}" in text
    status, _, err = run_cli("design", tmp_path / "run", "--figure", tmp_path / "d.png")
    assert status == 2 and "leave it out" in err
