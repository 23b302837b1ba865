"""Physical parameters and units in every output: summary.json, ranking.csv, the report, corner
and trace labels and ``bayesfo identify``.

The known answers are the closed forms of the fractional Zener solid (spring G_e parallel to a
spring G_m in series with a springpot c_q, q), whose compliance the card writes as
(b0 + b1 s^q) / (1 + a1 s^q):

    G_e = 1/b0,  G_m = (a1 b0 - b1) / (b0 b1),  c_q = (a1 b0 - b1) / b0²,  τ = (b1/b0)^(1/q),

and of the fractional Kelvin-Voigt b0 / (1 + a1 s^q): G_e = 1/b0, c_q = a1/b0.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import re
import warnings

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import bayesfo as bf  # noqa: E402
from bayesfo.comparison import RANKING_FIELDS  # noqa: E402
from bayesfo.comparison.parameters import (  # noqa: E402
    UNDETERMINED_DECADES,
    not_determined,
    summarise_draws,
)
from bayesfo.comparison.results import (  # noqa: E402
    parameter_units,
    physical_forms,
    physical_text,
)
from bayesfo.data import FrequencyResponse  # noqa: E402
from bayesfo.inference._arviz import hdi  # noqa: E402
from bayesfo.output.report import render_report, verdict  # noqa: E402
from bayesfo.plotting import plot_corner, plot_trace  # noqa: E402
from bayesfo.plotting._compute import param_symbol, unit_mathtext  # noqa: E402
from bayesfo.structures import get_structure  # noqa: E402

W = np.logspace(-2, 3, 30)
#: a1 [s^q], b0 [1/MPa], b1 [s^q/MPa], q: G_e = 1e5 MPa, G_m = 9e5 MPa, c_q = 1.8e5 MPa s^q,
#: τ = 0.04 s.
ZENER = (2.0, 1e-5, 2e-6, 0.5)


def zener_by_hand(a1, b0, b1, q):
    """The physical parameters of the fractional Zener solid from its compliance coefficients."""
    return {"G_e": 1 / b0, "G_m": (a1 * b0 - b1) / (b0 * b1), "c_q": (a1 * b0 - b1) / b0**2,
            "q": q, "tau": (b1 / b0) ** (1 / q)}


# Columns of ranking.csv before the physical parameters were added: none may move or go.
OLD_RANKING_FIELDS = (
    "rank", "structure", "parent", "n_params", "log_evidence", "log_evidence_err",
    "evidence_method", "delta_log_evidence", "bayes_factor", "posterior_probability",
    "evidence_agree", "loo", "loo_se", "delta_loo", "rank_loo", "waic", "rank_waic", "aic",
    "rank_aic", "aicc", "rank_aicc", "bic", "rank_bic", "max_log_likelihood", "rmse",
    "holdout_lpd", "holdout_rmse", "q_mean", "q_sd", "pareto_k_max", "rhat_max", "ess_min",
    "converged", "sampler", "fits", "adequate", "adequacy_p_min", "max_phase_error_deg",
    "max_log10_magnitude_error", "error")


def _noisy(g, rel_sd, seed):
    rng = np.random.default_rng(seed)
    sd = rel_sd * np.abs(g)
    return g + sd / np.sqrt(2) * (rng.normal(size=g.size) + 1j * rng.normal(size=g.size)), sd


def _compared(tmp_path_factory, data, structures: str, *, seed: int, folder: str):
    """``compare`` on ``data`` (predictive warnings ignored) and its outputs without figures in
    a new folder: (result, folder)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bf.errors.PredictiveWarning)
        result = bf.compare(data, structures, seed=seed, workers=1, progress=False)
    out = tmp_path_factory.mktemp(folder)
    bf.write_outputs(result, out, figures=False)
    return result, out


@pytest.fixture(scope="module")
def zener_run(tmp_path_factory):
    """A fractional Zener modulus in MPa, 1 % noise with σ known, run through compare."""
    g = get_structure("zener").response(np.array([ZENER]), W, "modulus")[0]
    noisy, sd = _noisy(g, 0.01, 1)
    data = FrequencyResponse(W, noisy, sd, kind="modulus", units="MPa", name="zener sim")
    return _compared(tmp_path_factory, data, "zener", seed=0, folder="zener")


@pytest.fixture(scope="module")
def voigt_compliance(tmp_path_factory):
    """A fractional Kelvin-Voigt compliance in 1/Pa (G_e = 1000 Pa, c_q = 1000 Pa s^0.5)."""
    g = get_structure("voigt").response([1.0, 1e-3, 0.5], np.logspace(-1, 2.5, 20), "compliance")
    noisy, sd = _noisy(g, 0.03, 3)
    data = FrequencyResponse(np.logspace(-1, 2.5, 20), noisy, sd, kind="compliance",
                             units="1/Pa", name="voigt sim")
    result = bf.compare(data, "voigt", seed=2, workers=1, progress=False)
    out = tmp_path_factory.mktemp("voigt")
    bf.write_outputs(result, out, figures=False)
    return result, out


def test_summary_reports_the_physical_parameters_of_a_zener_modulus(zener_run):
    result, out = zener_run
    (s,) = json.loads((out / "summary.json").read_text())["structures"]
    assert (s["natural_form"], s["picture"]) == ("physical", "fractional_zener_ss")
    phys = s["parameters_physical"]
    assert list(phys) == ["G_e", "G_m", "c_q", "q", "tau"]
    assert {n: p["unit"] for n, p in phys.items()} == {
        "G_e": "MPa", "G_m": "MPa", "c_q": "MPa s^q", "q": "", "tau": "s"}
    truth = zener_by_hand(*ZENER)
    post = result["zener"].posterior
    draws = dict(zip(post.param_names, post.samples.T))
    by_hand = zener_by_hand(draws["a1"], draws["b0"], draws["b1"], draws["q"])
    at_map = zener_by_hand(*post.map_theta)
    for name, p in phys.items():
        # The summary is that of the closed form applied to each draw ...
        assert p["mean"] == pytest.approx(np.mean(by_hand[name]), rel=1e-12)
        assert p["sd"] == pytest.approx(np.std(by_hand[name], ddof=1), rel=1e-9)
        assert p["median"] == pytest.approx(np.median(by_hand[name]), rel=1e-12)
        assert p["map"] == pytest.approx(at_map[name], rel=1e-12)
        assert p["hdi_low"] < p["median"] < p["hdi_high"]
        # ... and the posterior recovers the true material within its spread.
        assert abs(p["mean"] - truth[name]) < 4 * p["sd"] + 1e-3 * truth[name], name
        assert p["mean"] == pytest.approx(truth[name], rel=0.03), name


def test_the_parameters_block_is_unchanged_and_gains_units(zener_run):
    result, out = zener_run
    (s,) = json.loads((out / "summary.json").read_text())["structures"]
    post = result["zener"].posterior
    units = {"a1": "s^q", "b0": "1/MPa", "b1": "s^q/MPa", "q": ""}
    for name, summary in post.summary.items():
        # Keys are only ever added: whether the data determine the parameter, and for a
        # positive quantity with a unit the HDI on a log scale that this judges.
        added = {"unit": units[name], "not_determined": False, "not_determined_reason": None}
        if units[name]:
            x = post.samples[:, post.param_names.index(name)]
            lo, hi = hdi(np.log10(x), 0.94)
            added |= {"hdi_log_low": pytest.approx(10 ** lo, rel=1e-12),
                      "hdi_log_high": pytest.approx(10 ** hi, rel=1e-12)}
        assert s["parameters"][name] == summary.to_dict() | added
    # For modulus data the other form is the card's compliance coefficients, the same numbers.
    other = s["parameters_other_form"]
    assert list(other) == ["a1", "b0", "b1", "q"]
    for name, p in other.items():
        assert p["unit"] == units[name]
        for key in ("mean", "sd", "hdi_low", "hdi_high", "median", "map"):
            assert p[key] == pytest.approx(s["parameters"][name][key], rel=1e-12)


def test_ranking_csv_keeps_its_columns_and_adds_the_physical_parameters(zener_run):
    result, out = zener_run
    assert RANKING_FIELDS[: len(OLD_RANKING_FIELDS)] == OLD_RANKING_FIELDS
    assert RANKING_FIELDS[len(OLD_RANKING_FIELDS):] == (
        "physical_parameters", "delta_loo_se", "not_determined", "poorly_determined", "orders",
        "sampled", "log_evidence_bound", "delta_log_evidence_bound", "posterior_probability_bound")
    with (out / "ranking.csv").open(newline="") as fh:
        (row,) = list(csv.DictReader(fh))
    text = row["physical_parameters"]
    parts = dict(p.split("=") for p in text.split("; "))
    assert list(parts) == ["G_e", "G_m", "c_q", "q", "tau"]
    assert parts["G_e"].endswith(" MPa") and parts["c_q"].endswith(" MPa s^q")
    assert parts["tau"].endswith(" s") and " " not in parts["q"]
    phys = result["zener"].physical["physical"]
    for name, value in parts.items():
        assert float(value.split()[0]) == pytest.approx(phys[name]["median"], rel=1e-3)
    assert "," not in text  # one cell, readable without quoting
    # Every fractional order by its symbol, mean and 94 % HDI (the Zener has one, q).
    q = phys["q"]
    assert row["orders"] == f"q {q['mean']:.3f} [{q['hdi_low']:.3f}–{q['hdi_high']:.3f}]"
    assert "," not in row["orders"]


def test_units_follow_the_data_units():
    z = get_structure("zener")
    names = ("a1", "b0", "b1", "q", "sigma")
    assert parameter_units(z, names, "modulus", "Pa") == {
        "a1": "s^q", "b0": "1/Pa", "b1": "s^q/Pa", "q": "", "sigma": "Pa"}
    assert parameter_units(z, names, "modulus", "MPa")["b0"] == "1/MPa"
    # Compliance data in 1/Pa: the coefficients keep their compliance units, σ is in 1/Pa.
    assert parameter_units(z, names, "compliance", "1/Pa") == {
        "a1": "s^q", "b0": "1/Pa", "b1": "s^q/Pa", "q": "", "sigma": "1/Pa"}
    assert parameter_units(z, ("a1", "b0", "q", "sigma_rel"), "modulus", "Pa")["sigma_rel"] == ""
    # Known coefficients through the summariser: every draw equal gives the value itself.
    coef = dict(zip(("a1", "b0", "b1", "q"), ZENER))
    draws = {k: np.full(50, v) for k, v in coef.items()}
    forms = physical_forms(z, draws, coef, "modulus", "Pa")
    truth = zener_by_hand(*ZENER)
    for name, p in forms["physical"].items():
        assert p["mean"] == pytest.approx(truth[name], rel=1e-12) and p["sd"] == 0.0
        assert p["map"] == pytest.approx(truth[name], rel=1e-12)
    assert forms["physical"]["G_m"]["unit"] == "Pa" and forms["physical"]["c_q"]["unit"] == "Pa s^q"
    assert physical_text(forms["physical"]) == ("G_e=1e+05 Pa; G_m=9e+05 Pa; c_q=1.8e+05 Pa s^q; "
                                                "q=0.5; tau=0.04 s")
    # The fractional Maxwell model: c_delta has the unit of its own order beta - alpha.
    m = get_structure("maxwell")
    mcoef = {"a1": 3.0, "b1": 0.5, "alpha": 0.2, "beta": 0.7}
    mforms = physical_forms(m, {k: np.full(4, v) for k, v in mcoef.items()}, mcoef, "modulus",
                            "kPa")
    assert mforms["physical"]["c_beta"]["unit"] == "kPa s^beta"
    assert mforms["physical"]["c_delta"]["unit"] == "kPa s^(beta-alpha)"
    assert mforms["physical"]["c_delta"]["mean"] == pytest.approx(3.0 / 0.5)  # c_δ = a1/b1


def test_inverted_and_max_order_structures_report_their_own_coefficients():
    for name in ("voigt-inv", "max-n2m1"):
        s = get_structure(name)
        coef = {n: 0.5 for n in s.param_names}
        forms = physical_forms(s, {k: np.full(5, v) for k, v in coef.items()}, coef, "modulus",
                               "Pa")
        assert forms["picture"] is None and forms["other"] is None
        assert forms["natural_form"] == "coefficients"
        assert list(forms["physical"]) == list(s.param_names)
    inv = physical_forms(get_structure("voigt-inv"), {"a1": [1.0, 1.0], "b0": [2.0, 2.0],
                                                      "q": [0.5, 0.5]},
                         {"a1": 1.0, "b0": 2.0, "q": 0.5}, "modulus", "Pa")
    assert inv["physical"]["b0"]["unit"] == "Pa" and inv["physical"]["a1"]["unit"] == "s^q"


def test_compliance_data_report_stress_in_pa(voigt_compliance):
    result, out = voigt_compliance
    (s,) = json.loads((out / "summary.json").read_text())["structures"]
    assert s["natural_form"] == "coefficients" and s["picture"] == "voigt"
    assert s["parameters"]["b0"]["unit"] == "1/Pa" and s["parameters"]["a1"]["unit"] == "s^q"
    phys = s["parameters_physical"]
    assert s["parameters_other_form"] == phys  # the other form of compliance data
    assert (phys["G_e"]["unit"], phys["c_q"]["unit"], phys["tau"]["unit"]) == ("Pa", "Pa s^q",
                                                                               "s")
    # G_e = 1/b0 = 1000 Pa and c_q = a1/b0 = 1000 Pa s^0.5, τ = a1^(1/q) = 1 s.
    for name, truth in (("G_e", 1000.0), ("c_q", 1000.0), ("tau", 1.0)):
        assert abs(phys[name]["mean"] - truth) < 4 * phys[name]["sd"], name
    post = result["voigt"].posterior
    i = post.param_names.index("b0")
    assert phys["G_e"]["mean"] == pytest.approx(np.mean(1 / post.samples[:, i]), rel=1e-12)


def test_units_change_with_the_data_units_of_a_result(zener_run):
    result, _ = zener_run
    r = result["zener"]
    assert r.units == {"a1": "s^q", "b0": "1/MPa", "b1": "s^q/MPa", "q": ""}
    as_pa = dataclasses.replace(r, data_units="Pa")
    assert as_pa.units["b0"] == "1/Pa" and as_pa.physical["physical"]["G_e"]["unit"] == "Pa"
    unknown = dataclasses.replace(r, data_kind=None)
    assert unknown.units == {} and unknown.physical is None
    # Without the data's units the stress unit is an arbitrary unit (no "[G]" placeholder).
    bare = dataclasses.replace(r, data_units="")
    assert bare.units["b0"] == "1/a.u." and bare.physical["physical"]["c_q"]["unit"] == "a.u. s^q"


def test_corner_and_trace_labels_carry_units(zener_run):
    result, _ = zener_run
    r = result["zener"]
    drawn = plot_corner(r)
    ndim = len(r.posterior.param_names)
    labels = [drawn.axes[ndim * (ndim - 1) + j].get_xlabel() for j in range(ndim)]
    plt.close(drawn.figure)
    # Modulus data: the physical parameters, in the data's unit.
    assert labels[0].startswith("log$_{10}$ $G_{e}$ [MPa]")
    assert labels[1].startswith("log$_{10}$ $G_{m}$ [MPa]")
    assert labels[2].startswith("log$_{10}$ $c_{q}$ [MPa s$^{q}$]")
    assert labels[3] == "$q$"  # an order has no unit
    drawn = plot_trace(r)
    texts = [ax.get_xlabel() + ax.get_ylabel() for ax in drawn.axes]
    plt.close(drawn.figure)
    assert any("$G_{e}$ [MPa]" in t for t in texts) and any("[MPa s$^{q}$]" in t for t in texts)


def test_unit_and_symbol_mathtext():
    assert unit_mathtext("Pa s^q") == "Pa s$^{q}$"
    assert unit_mathtext("s^(beta-alpha)") == r"s$^{\beta-\alpha}$"
    assert unit_mathtext("s^(2*q)") == "s$^{2q}$"
    assert unit_mathtext("1/(µm/N)") == "1/(µm/N)"
    assert param_symbol("c_alpha") == r"$c_{\alpha}$" and param_symbol("G_e") == "$G_{e}$"
    assert param_symbol("b0") == "$b_{0}$" and param_symbol("sigma_rel") == r"$\sigma_{rel}$"
    # Every label parses as mathtext.
    from matplotlib.mathtext import MathTextParser

    parser = MathTextParser("path")
    for text in ("log$_{10}$ $b_{1}$ [s$^{q}$/Pa]", r"$c_{\delta}$ [Pa s$^{\beta-\alpha}$]"):
        parser.parse(text)


def test_report_shows_units_and_the_physical_form(zener_run):
    result, _ = zener_run
    text = render_report(result)
    assert "<th class='text'>unit</th>" in text
    assert "Physical parameters (fractional_zener_ss" in text
    phys = result["zener"].physical["physical"]
    g_e = phys["G_e"]
    assert (f"<td class=\"text\">G_e</td><td class=\"text\">MPa</td>"
            f"<td data-value=\"{g_e['mean']!r}\">{g_e['mean']:.4g}</td>") in text
    assert "<td class=\"text\">b0</td><td class=\"text\">1/MPa</td>" in text
    # The physical form comes first for modulus data.
    section = text[text.index("<h2 id='parameters'>"):]
    assert section.index("<td class=\"text\">G_e</td>") < section.index("<td class=\"text\">b0</td>")
    sentence = next(t for t, _ in verdict(result) if t.startswith("In physical parameters"))
    assert f"G_e = {g_e['median']:.3g} MPa" in sentence and "tau = " in sentence


# ---------------------------------------------------------------------- not determined by the data
def test_not_determined_reads_the_hdi_of_a_quantity_with_a_unit_on_a_log_scale():
    assert UNDETERMINED_DECADES == 2.0
    # Without draws (a summary alone), the decades between the ends of the HDI.
    assert not_determined({"unit": "Pa", "hdi_low": 1.64e8, "hdi_high": 2.11e10}) == (
        "its 94 % HDI on a log scale spans 2.1 decades")
    assert not_determined({"unit": "Pa", "hdi_low": 1.0e3, "hdi_high": 9.9e4}) is None
    # As the fractional Maxwell's tau on the 20 °C adhesive isotherm: its order ran to 0.
    assert not_determined({"unit": "s", "hdi_low": 0.0, "hdi_high": 2.1e61}) == (
        "its 94 % HDI runs from 0 to 2.1e+61")
    assert not_determined({"unit": "s", "hdi_low": 3e-11, "hdi_high": math.inf}) == (
        "its 94 % HDI runs from 3e-11 to infinity")
    # Orders are judged against their prior (poorly_determined).
    assert not_determined({"unit": "", "hdi_low": 2.6e-6, "hdi_high": 0.7}) is None
    # A signed quantity whose HDI reaches across 0: not even its sign is fixed.
    assert not_determined({"unit": "Pa", "hdi_low": -5.0, "hdi_high": 1e6}) == (
        "its 94 % HDI runs from -5 to 1e+06, across 0: the data do not fix its sign")
    # An undefined HDI is not taken for a determined quantity.
    assert not_determined({"unit": "Pa", "hdi_low": math.nan, "hdi_high": math.nan}) == (
        "its 94 % HDI is undefined")


def _lognormal(width: float, n: int = 40_000, seed: int = 0):
    """Draws whose log10 is normal with a 94 % HDI ``width`` decades wide."""
    from scipy.stats import norm

    sd = width / (2 * norm.ppf(0.97))
    return 10.0 ** np.random.default_rng(seed).normal(-3.0, sd, n)


def test_not_determined_takes_the_hdi_of_the_logarithms_of_the_draws():
    # The HDI of the values leans towards small values: for a log-scale width of 1.8 decades
    # it spans about 2.5, and the rule read on it would flag a quantity the data fix to 1.8.
    x = _lognormal(1.8)
    s = summarise_draws(x, 1e-3, "Pa")
    assert math.log10(s["hdi_high"] / s["hdi_low"]) > 2.3
    assert not_determined(s, x) is None
    y = _lognormal(2.2)
    (width,) = re.fullmatch(r"its 94 % HDI on a log scale spans (\S+) decades",
                            not_determined(summarise_draws(y, 1e-3, "Pa"), y)).groups()
    assert float(width) == pytest.approx(2.2, abs=0.05)  # Monte Carlo error about 0.02


def test_a_quantity_and_its_reciprocal_get_the_same_verdict():
    # b0 of a Voigt and G_e = 1/b0 (as on the stored Tp150C run, whose b0 HDI spans 1.3
    # decades and G_e's 2.8): a log10 with a long upper tail.
    rng = np.random.default_rng(4)
    voigt = get_structure("voigt")
    for scale in (0.4, 0.8):
        b0 = 10.0 ** (-4.0 + rng.gamma(2.0, scale, 20_000))
        draws = {"a1": np.full(b0.size, 10.0), "b0": b0, "q": np.full(b0.size, 0.3)}
        forms = physical_forms(voigt, draws, {"a1": 10.0, "b0": 1e-3, "q": 0.3}, "modulus", "Pa")
        g_e, b = forms["physical"]["G_e"], forms["other"]["b0"]
        # The values' HDIs disagree by 2 decades or more (b0's under 2, G_e's over it for
        # the narrower posterior), ...
        spans = [math.log10(p["hdi_high"] / p["hdi_low"]) for p in (b, g_e)]
        assert spans[1] - spans[0] > 2.0
        if scale == 0.4:
            assert spans[0] < UNDETERMINED_DECADES < spans[1]
        # ... the verdicts do not.
        assert g_e["not_determined"] == b["not_determined"]
        assert g_e["not_determined_reason"] == b["not_determined_reason"]
        assert not_determined({"unit": "Pa"}, 1 / b0) == not_determined({"unit": "1/Pa"}, b0)
    assert [forms["physical"]["G_e"]["not_determined"]] == [True]  # the wider of the two


def test_undefined_zero_infinite_and_signed_draws():
    x = _lognormal(1.0)
    some_nan, many_nan = x.copy(), x.copy()
    some_nan[:400] = np.nan  # 1 %: left out
    many_nan[:4000] = np.nan  # 10 %, more than the 6 % outside a 94 % HDI
    assert not_determined({"unit": "s"}, some_nan) is None
    assert not_determined({"unit": "s"}, many_nan) == "it is undefined at 10 % of the draws"
    assert not_determined({"unit": "s"}, np.full(100, np.nan)) == (
        "it is undefined at 100 % of the draws")
    overflow = np.r_[x, np.full(x.size // 5, np.inf)]  # a time whose order ran to 0
    assert not_determined({"unit": "s"}, overflow).endswith("to infinity")
    underflow = np.r_[x, np.zeros(x.size // 5)]
    assert not_determined({"unit": "s"}, underflow).startswith("its 94 % HDI runs from 0 to ")
    rng = np.random.default_rng(1)
    assert not_determined({"unit": "Pa"}, rng.normal(0.0, 1.0, 5000)).endswith(
        "across 0: the data do not fix its sign")
    assert not_determined({"unit": "Pa"}, -x) is None  # negative, magnitude fixed
    assert not_determined({"unit": "Pa"}, np.r_[-x[:10], x]) is None  # a few strays


@pytest.fixture(scope="module")
def zener_on_voigt(tmp_path_factory):
    """A Zener fitted to a fractional Kelvin-Voigt modulus (G_e = c_q = 1000 Pa, q = 0.5, 5 %
    noise with σ known): the data do not fix its second spring G_m nor the time τ."""
    g = 1 / get_structure("voigt").response([1.0, 1e-3, 0.5], W, "compliance")
    noisy, sd = _noisy(g, 0.05, 0)
    data = FrequencyResponse(W, noisy, sd, kind="modulus", units="Pa", name="voigt modulus")
    return _compared(tmp_path_factory, data, "zener", seed=0, folder="zener_on_voigt")


def test_parameters_the_data_do_not_determine_are_marked(zener_on_voigt):
    result, out = zener_on_voigt
    (s,) = json.loads((out / "summary.json").read_text())["structures"]
    phys = s["parameters_physical"]
    marked = {n for n, p in phys.items() if p["not_determined"]}
    assert marked == {"G_m", "tau"}
    r = result["zener"]
    post = r.posterior
    draws = zener_by_hand(*(post.samples[:, post.param_names.index(n)]
                            for n in ("a1", "b0", "b1", "q")))
    for name in ("G_m", "tau"):
        p = phys[name]
        lo, hi = hdi(np.log10(draws[name]), 0.94)
        assert hi - lo > UNDETERMINED_DECADES
        assert p["not_determined_reason"] == (
            f"its 94 % HDI on a log scale spans {hi - lo:.1f} decades")
    assert phys["G_e"]["not_determined_reason"] is None
    assert phys["q"]["poorly_determined"] is False  # the order, judged against its prior
    assert abs(phys["G_e"]["median"] - 1000.0) < 50.0  # what the data do fix, unmarked
    with (out / "ranking.csv").open(newline="") as fh:
        (row,) = list(csv.DictReader(fh))
    # ranking.csv: the physical_parameters column is name=value unit as before; the names the
    # data do not determine are in a column of their own.
    cells = dict(part.split("=") for part in row["physical_parameters"].split("; "))
    assert list(cells) == ["G_e", "G_m", "c_q", "q", "tau"]
    for name, cell in cells.items():
        value, *unit = cell.split(" ", 1)
        assert float(value) == pytest.approx(phys[name]["median"], rel=1e-3)
        assert unit == ([phys[name]["unit"]] if phys[name]["unit"] else [])
    assert row["not_determined"] == "G_m; tau"
    assert row["poorly_determined"] == ""
    # The result's own summary, the report and the verdict say so instead of a bare number.
    line = next(ln for ln in r.summary().splitlines() if ln.strip().startswith("G_m"))
    assert line.endswith(f"Pa  (not determined: {phys['G_m']['not_determined_reason']})")
    text = render_report(result)
    assert (f"<td class='text flag'>not determined: {phys['tau']['not_determined_reason']}"
            "</td>") in text
    sentences = dict(verdict(result))
    values = next(t for t in sentences if t.startswith("In physical parameters"))
    assert "G_e = " in values and "G_m" not in values and "tau" not in values
    vague = (f"The data do not determine G_m ({phys['G_m']['not_determined_reason']}) and tau "
             f"({phys['tau']['not_determined_reason']}) of zener: their values are not "
             "estimates.")
    assert sentences[vague] is True  # flagged as a caution
    # The list of every structure's undetermined parameters includes the winner's.
    listed = next(t for t in sentences if t.startswith("Parameters that the data do not"))
    assert listed.endswith(": zener (G_m, tau).") and sentences[listed] is True


def test_compare_names_the_parameters_the_data_do_not_determine(zener_on_voigt, capsys):
    from bayesfo.cli.compare import _print_undetermined

    result, _ = zener_on_voigt
    _print_undetermined(result)
    assert capsys.readouterr().out == (
        "not determined by the data (94 % HDI over more than 2 decades on a log scale, reaching "
        "0 or infinity, or undefined; the values in the report, summary.json and ranking.csv "
        "are not estimates): zener: G_m, tau\n")
    # An order of several separated modes is named too: its mean lies between them.
    from dataclasses import replace

    r = result["zener"]
    q = replace(r.posterior.summary["q"], multimodal=True)
    split = replace(r, posterior=replace(r.posterior, summary={**r.posterior.summary, "q": q}))
    _print_undetermined(replace(result, results=tuple(
        split if x.name == "zener" else x for x in result.results)))
    assert capsys.readouterr().out.endswith(
        "orders with several separated modes (their means lie between the modes; the "
        "q_posteriors figure shows them): zener: q\n")


@pytest.fixture(scope="module")
def inverted_on_voigt():
    """The zener-inv card (a modulus (b0 + b1 s^q) / (1 + a1 s^q), which has no physical
    picture) alone on two decades of a Voigt modulus below its corner frequency: the data bound
    a1 only from above, and its log-uniform prior spreads it over decades below."""
    w = np.logspace(-2, 0, 12)
    g = 1 / get_structure("voigt").response([1.0, 1e-3, 0.5], w, "compliance")
    noisy, sd = _noisy(g, 0.05, 1)  # seed 0 gives a point of negative loss
    data = FrequencyResponse(w, noisy, sd, kind="modulus", units="Pa", name="voigt modulus")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bf.errors.PredictiveWarning)
        return bf.compare(data, "zener-inv", seed=0, workers=1, progress=False)


def test_the_verdict_names_the_undetermined_parameters_of_a_winner_without_a_picture(
        inverted_on_voigt, capsys):
    from bayesfo.cli.compare import _print_undetermined

    r = inverted_on_voigt["zener-inv"]
    assert r.physical["picture"] is None
    names = [n for n, s in r.natural_parameters.items() if s["not_determined"]]
    assert names == ["a1"]
    listed = [t for t, flagged in verdict(inverted_on_voigt)
              if t.startswith("Parameters that the data do not determine") and flagged]
    assert listed == [
        "Parameters that the data do not determine (94 % HDI over more than 2 decades on a log "
        "scale, reaching 0 or infinity, or undefined; their numbers are not estimates): "
        "zener-inv (a1)."]
    _print_undetermined(inverted_on_voigt)  # the terminal names the same ones
    assert "zener-inv: a1\n" in capsys.readouterr().out


def test_a_parameter_without_a_finite_median_is_named_not_dropped():
    from types import SimpleNamespace

    from bayesfo.output.verdict import _physical_sentence

    def summary(median, reason=None):
        return {"unit": "s", "median": median, "hdi_low": 1.0, "hdi_high": math.inf,
                "not_determined": reason is not None, "not_determined_reason": reason}

    result = SimpleNamespace(physical={"picture": "p", "physical": {
        "G_e": summary(10.0) | {"unit": "Pa", "hdi_high": 20.0},
        "tau": summary(math.inf, "its 94 % HDI runs from 1 to infinity")}})
    (values, _), (vague, flagged) = _physical_sentence("x", result)
    assert "G_e = 10 Pa" in values and "tau" not in values
    assert vague.startswith("The data do not determine tau (its 94 % HDI runs from 1 to "
                            "infinity) of x") and flagged


def test_the_report_shows_both_flags_of_a_parameter():
    from bayesfo.output.report import _flags

    s = {"not_determined": True, "not_determined_reason": "its 94 % HDI runs from 0 to 3",
         "poorly_determined": True}
    assert _flags(s) == ["not determined: its 94 % HDI runs from 0 to 3", "poorly determined"]


def _modulus_csv(tmp_path):
    g = get_structure("zener").response(np.array([ZENER]), W, "modulus")[0]
    noisy, _ = _noisy(g, 0.002, 5)
    return FrequencyResponse(W, noisy, kind="modulus", units="Pa").to_csv(tmp_path / "z.csv")


def test_identify_prints_units_and_the_physical_form(run_cli, tmp_path):
    path = _modulus_csv(tmp_path)
    status, out, err = run_cli("identify", path, "--structure", "zener", "--json")
    assert status == 0, err
    res = json.loads(out)
    assert res["units"] == {"a1": "s^q", "b0": "1/Pa", "b1": "s^q/Pa", "q": ""}
    assert (res["natural_form"], res["picture"]) == ("physical", "fractional_zener_ss")
    phys = res["parameters_physical"]
    p = res["parameters"]
    by_hand = zener_by_hand(p["a1"], p["b0"], p["b1"], p["q"])
    for name, value in by_hand.items():
        assert phys[name]["value"] == pytest.approx(value, rel=1e-12)
        assert phys[name]["value"] == pytest.approx(zener_by_hand(*ZENER)[name], rel=0.05)
    assert phys["G_m"]["unit"] == "Pa" and phys["c_q"]["unit"] == "Pa s^q"
    # The Poynting-Thomson alias reads the same fit as a spring in series with a Kelvin-Voigt
    # element: G_g = a1/b1, G_k = a1/(a1 b0 - b1), c_q = a1²/(a1 b0 - b1).
    status, out, err = run_cli("identify", path, "--structure", "fpt", "--json")
    assert status == 0, err
    res = json.loads(out)
    p, phys = res["parameters"], res["parameters_physical"]
    assert res["picture"] == "fractional_poynting_thomson"
    d = p["a1"] * p["b0"] - p["b1"]
    for name, value in (("G_g", p["a1"] / p["b1"]), ("G_k", p["a1"] / d),
                        ("c_q", p["a1"] ** 2 / d)):
        assert phys[name]["value"] == pytest.approx(value, rel=1e-12)
        assert phys[name]["unit"] == ("Pa s^q" if name == "c_q" else "Pa")
    status, out, _ = run_cli("identify", path, "--structure", "zener")
    assert status == 0
    assert "physical parameters (fractional_zener_ss):" in out
    assert "G_e = " in out and " Pa\n" in out and "b0 = " in out and " 1/Pa\n" in out
    assert out.index("G_e = ") < out.index("b0 = ")
