"""The van Gurp–Palmen test of time–temperature superposition: synthetic isotherms of a
thermorheologically simple material (one relaxation process, one shift law) pass it; those of a
complex one (two processes whose shifts follow different laws) fail it where the processes
overlap in the window; isotherms without common |G*| are not tested."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from bayesfo.data import FrequencyResponse  # noqa: E402
from bayesfo.tts import arrhenius, wlf  # noqa: E402
from bayesfo.tts.validity import TOLERANCE_DEG, describe, loss_angle_deg, van_gurp_palmen  # noqa: E402

W = np.logspace(-1, 2, 16)
TEMPS = np.arange(0.0, 101.0, 10.0)


def _maxwell(w, g, tau, alpha):
    """A fractional Maxwell liquid: a spring g in series with a springpot of order alpha."""
    s = (1j * w * tau) ** alpha
    return g * s / (1 + s)


def _isotherms(complex_: bool, seed: int, kind: str = "modulus", noise: float = 0.01):
    """Two fractional Maxwell processes; in the complex material the slow one shifts by
    Arrhenius (60 kJ/mol) instead of WLF (C1 8, C2 120 °C at 50 °C)."""
    rng = np.random.default_rng(seed)
    out = []
    for t in TEMPS:
        fast = wlf(t, 50.0, 8.0, 120.0)
        slow = arrhenius(t, 50.0, 60e3) if complex_ else fast
        g = _maxwell(W * 10**fast, 1e6, 0.01, 0.6) + _maxwell(W * 10**slow, 1e5, 10.0, 0.9)
        g = g * (1 + noise / np.sqrt(2) * (rng.normal(size=W.size) + 1j * rng.normal(size=W.size)))
        out.append(FrequencyResponse(W, g if kind == "modulus" else 1 / g, kind=kind))
    return out


@pytest.mark.parametrize("seed", range(4))
def test_a_simple_material_passes(seed):
    check = van_gurp_palmen(_isotherms(False, seed), TEMPS)
    assert check["valid"] is True and check["failing"] == [] and check["untested"] == []
    assert len(check["pairs"]) == len(TEMPS) - 1
    for p in check["pairs"]:
        # 1 % noise: the loss angles agree to a few tenths of a degree.
        assert abs(p["delta_deg"]) < 0.8 and 0 < p["se_deg"] < 0.5
    assert describe(check).startswith("superposition holds")


@pytest.mark.parametrize("seed", range(4))
def test_a_complex_material_fails_where_its_processes_shift_apart(seed):
    check = van_gurp_palmen(_isotherms(True, seed), TEMPS)
    assert check["valid"] is False
    failing = {tuple(p) for p in check["failing"]}
    # Near the laws' common reference (50 °C) the shifts differ little; between 40 and 80 °C
    # the slow process has moved by a decade against the fast one and the curves part by 2°.
    assert {(40.0, 50.0), (50.0, 60.0), (60.0, 70.0)} <= failing
    assert (0.0, 10.0) not in failing
    worst = max(abs(p["delta_deg"]) for p in check["pairs"])
    assert worst > 1.5 * TOLERANCE_DEG
    assert "fails the van Gurp–Palmen test" in describe(check) and "50/60 °C" in describe(check)


def test_compliance_data_give_the_same_test():
    """δ is the loss angle of a compliance too (−arg J*): the reciprocal data give the same
    differences."""
    mod = van_gurp_palmen(_isotherms(True, 0), TEMPS)
    comp = van_gurp_palmen(_isotherms(True, 0, kind="compliance"), TEMPS)
    assert comp["valid"] is False and comp["failing"] == mod["failing"]
    for a, b in zip(mod["pairs"], comp["pairs"], strict=True):
        assert b["delta_deg"] == pytest.approx(a["delta_deg"], abs=1e-9)
    g = np.array([1.0 + 1.0j])
    assert loss_angle_deg(g, "modulus") == pytest.approx(45.0)
    assert loss_angle_deg(1 / g, "compliance") == pytest.approx(45.0)


def test_isotherms_without_common_magnitude_are_not_tested():
    low = FrequencyResponse(W, 1e3 * (1 + 0.5j) * W**0.1, kind="modulus")
    high = FrequencyResponse(W, 1e6 * (1 + 0.5j) * W**0.1, kind="modulus")
    check = van_gurp_palmen([low, high], [0.0, 10.0])
    assert check["valid"] is None and check["untested"] == [[0.0, 10.0]]
    assert "could not be made" in describe(check)


def test_the_van_gurp_palmen_figure_draws_every_isotherm_unshifted():
    from types import SimpleNamespace

    from bayesfo.plotting.mastercurve import plot_van_gurp_palmen

    data = _isotherms(True, 0)
    check = van_gurp_palmen(data, TEMPS)
    mc = SimpleNamespace(temperatures=tuple(TEMPS), isotherms=tuple(data), data=data[0],
                         tts_checks={"van_gurp_palmen": check})
    drawn = plot_van_gurp_palmen(mc)
    for d, t in zip(data, TEMPS, strict=True):
        line = drawn.artists[f"{t:g}"]
        np.testing.assert_allclose(line.get_xdata(), np.abs(d.response))
        np.testing.assert_allclose(line.get_ydata(), np.degrees(np.angle(d.response)))
    assert drawn.artists["title"].get_text().startswith("parting: ")
    import matplotlib.pyplot as plt

    plt.close(drawn.figure)


def test_the_residual_figure_gives_each_isotherms_misfit_against_a_known_master():
    """Isotherms made from a springpot master at known shifts: with the true parameters and
    shifts as the 'posterior', the residuals are 0; an isotherm scaled by 1.1 has residuals
    of exactly 10 % of each part over |G*| (closed form), and its rms is drawn as missed."""
    from types import SimpleNamespace

    import matplotlib.pyplot as plt

    from bayesfo.plotting.mastercurve import plot_isotherm_residuals
    from bayesfo.predictions import evaluate
    from bayesfo.structures import get_structure

    springpot = get_structure("springpot")
    theta = np.array([2.0e5, 0.4])
    temps = [0.0, 20.0, 40.0]
    shifts = np.array([1.5, 0.0, -1.2])
    data = []
    for k, s in enumerate(shifts):
        w = W * 10.0 ** s
        g = evaluate(springpot, theta, "storage", w)[0] + 1j * evaluate(springpot, theta,
                                                                          "loss", w)[0]
        data.append(FrequencyResponse(W, g * (1.1 if k == 2 else 1.0), kind="modulus"))
    draws = 50
    mc = SimpleNamespace(
        temperatures=tuple(temps), isotherms=tuple(data), data=data[0], master=springpot,
        structure="springpot", reference_temperature=20.0,
        master_draws=np.tile(theta, (draws, 1)), shift_draws=np.tile(shifts, (draws, 1)),
        vertical_draws=None, log_shift_mean=shifts,
        tts_checks={"isotherm_fit": {"temperatures": temps, "rms_relative": [0.01, 0.012, 0.1],
                                     "misfit": [40.0]}})
    drawn = plot_isotherm_residuals(mc)
    for k, t in enumerate(temps):
        g = data[k].response / (1.1 if k == 2 else 1.0)
        for name, part in (("storage", g.real), ("loss", g.imag)):
            expected = (10.0 if k == 2 else 0.0) * part / np.abs(g)
            np.testing.assert_allclose(drawn.values[f"{t:g}/{name}_pct"], expected, atol=1e-9)
            line = drawn.artists[f"{t:g}/{name}"]
            np.testing.assert_allclose(line.get_xdata(), W * 10.0 ** shifts[k])
    # the level: three times the median isotherm's rms
    assert drawn.values["misfit_level"] == pytest.approx(3 * 0.012)
    colours = drawn.artists["rms"].get_facecolors()
    assert tuple(np.round(colours[2][:3], 3)) != tuple(np.round(colours[0][:3], 3))
    plt.close(drawn.figure)


def test_isotherms_shifted_by_whole_grid_steps_merge_their_common_frequencies():
    # Two isotherms on one log grid, the second shifted by exactly three of its steps: three
    # reduced frequencies coincide up to rounding (1e-10 relative here); they are averaged into
    # one point each, never refused as a frequency given twice.
    from bayesfo.tts.isotherms import _isotherms, _reduced

    w = np.logspace(-1, 2, 12)
    step = 3.0 / 11.0
    g = (1.0 + 0.5j) * w**0.3
    a = FrequencyResponse(w, g, kind="modulus")
    b = FrequencyResponse(w, 2.0 * g, kind="modulus")
    iso = _isotherms([(a, 0.0), (b, 10.0)], 0.0)
    shifts = np.array([0.0, 3 * step * (1 + 1e-10)])
    reduced = _reduced(iso, shifts)
    assert reduced.n_frequencies == 2 * 12 - 9
    # each common frequency: the mean of the two isotherms' values there (a at w[3], b at its
    # own w[0], shifted onto w[3])
    common = np.isclose(reduced.omega, w[3], rtol=1e-8)
    assert common.sum() == 1
    assert np.isclose(reduced.response[common][0], (g[3] + 2.0 * g[0]) / 2)


def test_parts_without_common_values_are_untested_not_agreeing():
    """Isotherms whose G′, G″ and tan δ share no values (the adhesive at −40, 0 and 150 °C):
    the overlay's search ended at its window's edge (−1.999 decades for every part), where the
    curves come closest, and the parts "agreed" (issue 65)."""
    from pathlib import Path

    import bayesfo as bf
    from bayesfo.tts.validity import shifts_by_part

    folder = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp"
    isotherms = [bf.read(folder / f"{n}.csv") for n in ("Tm040C", "Tp000C", "Tp150C")]
    check = shifts_by_part(isotherms, [-40.0, 0.0, 150.0])
    assert check["consistent"] is None
    assert all(p[part] is None for p in check["pairs"] for part in ("storage", "loss",
                                                                     "tan_delta"))
    assert van_gurp_palmen(isotherms, [-40.0, 0.0, 150.0])["valid"] is None


def test_mastercurve_warns_of_negative_loss_as_compare_does(monkeypatch):
    """The adhesive at −40 °C has points of G″ < 0: compare and inspect said so, mastercurve
    did not (issue 65). The fits are not run here: the warning comes before them."""
    from pathlib import Path

    import bayesfo as bf
    import bayesfo.parallel
    from bayesfo.errors import DataWarning
    from bayesfo.tts import mastercurve

    class Stop(Exception):
        pass

    def stop(*args, **kwargs):
        raise Stop

    monkeypatch.setattr(bayesfo.parallel, "executor", stop)
    folder = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp"
    isotherms = [(bf.read(folder / f"{n}.csv"), t) for n, t in (("Tm040C", -40.0),
                                                                 ("Tm030C", -30.0))]
    with pytest.warns(DataWarning, match=r"the isotherm at -40 °C .*: 1 of 17 points have "
                                         r"negative loss \(Im G < 0\)"), pytest.raises(Stop):
        mastercurve(isotherms, "zener")


def test_mastercurve_warns_of_isotherms_hundreds_of_degrees_apart(monkeypatch):
    """293.15 (kelvin meant, °C read) beside 10 °C: a master curve with WLF C1 0.80."""
    from pathlib import Path

    import bayesfo as bf
    import bayesfo.parallel
    from bayesfo.errors import DataWarning
    from bayesfo.tts import mastercurve

    class Stop(Exception):
        pass

    def stop(*args, **kwargs):
        raise Stop

    monkeypatch.setattr(bayesfo.parallel, "executor", stop)
    folder = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp"
    isotherms = [(bf.read(folder / "Tp010C.csv"), 10.0), (bf.read(folder / "Tp020C.csv"),
                                                          293.15)]
    with pytest.warns(DataWarning, match=r"the isotherms at 10 and 293.15 °C are 283.15 °C "
                                         r"apart"), pytest.raises(Stop):
        mastercurve(isotherms, "zener")


@pytest.mark.parametrize("kind", ["modulus", "compliance"])
def test_the_vertical_shifts_are_taken_out_before_the_loss_angles_are_compared(kind):
    """A simple material whose isotherms are scaled by b_T (a modulus divided, a compliance
    multiplied, by it): as measured, δ at equal |G*| differs between neighbours by degrees and
    the test fails; with the vertical shifts given it passes as the unscaled material does."""
    log_b = 0.15 * (TEMPS - 50.0) / 10.0  # ±0.75 decade across the range
    moduli = [d.response / 10**b for d, b in zip(_isotherms(False, 1), log_b, strict=True)]
    scaled = [FrequencyResponse(W, g if kind == "modulus" else 1 / g, kind=kind)
              for g in moduli]
    assert van_gurp_palmen(scaled, TEMPS)["valid"] is False
    check = van_gurp_palmen(scaled, TEMPS, log_vertical=log_b)
    assert check["valid"] is True and check["untested"] == []
    assert all(abs(p["delta_deg"]) < 0.8 for p in check["pairs"])
