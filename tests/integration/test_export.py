"""Prony series for finite-element codes: each format parsed back, the fit's error against the
model, a liquid, bad input."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import bayesfo as bf
from bayesfo.errors import InputError
from bayesfo.predictions import prony_series

DATA = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = bf.compare(bf.read(DATA), "voigt,zener,maxwell-int,springpot", workers=1,
                            progress=False, seed=0)
    bf.write_outputs(result, out, figures=False)
    return result, out


def _numbers(line: str) -> list[float]:
    return [float(x) for x in re.split(r"[,\s]+", line.strip()) if x]


def parse(text: str, fmt: str) -> tuple[np.ndarray, np.ndarray, float]:
    """(tau, g, g_0) read back from a file in ``fmt``."""
    lines = text.splitlines()
    g0 = float(next(re.search(r"g_0 = (\S+)", x).group(1) for x in lines if "g_0 = " in x))
    if fmt == "csv":
        rows = [_numbers(x) for x in lines[lines.index("tau_s,g_i") + 1:]]
        return np.array([r[0] for r in rows]), np.array([r[1] for r in rows]), g0
    if fmt == "abaqus":
        rows = [_numbers(x) for x in lines[lines.index("*VISCOELASTIC, TIME=PRONY") + 1:]]
        assert all(r[1] == 0.0 for r in rows)  # no bulk relaxation
        return np.array([r[2] for r in rows]), np.array([r[0] for r in rows]) * g0, g0
    tb = next(x for x in lines if x.startswith("TB,PRONY"))
    n = int(tb.split(",")[4])
    values, expected = [], 1
    for x in lines:
        if x.startswith("TBDATA,"):
            parts = x.split(",")
            assert int(parts[1]) == expected  # each command continues where the last ended
            chunk = [float(v) for v in parts[2:]]
            assert len(chunk) <= 6
            values += chunk
            expected += len(chunk)
    assert len(values) == 2 * n
    return np.array(values[1::2]), np.array(values[0::2]) * g0, g0


@pytest.mark.parametrize("fmt", ["csv", "abaqus", "ansys"])
def test_each_format_reads_back_as_the_series(written, fmt, tmp_path, run_cli):
    result, out = written
    prony = prony_series(result)
    status, text, err = run_cli("export", out, "--format", fmt, "--out", tmp_path / f"p.{fmt}")
    assert status == 0, err
    tau, g, g0 = parse((tmp_path / f"p.{fmt}").read_text(), fmt)
    np.testing.assert_allclose(tau, prony.tau, rtol=1e-9)
    np.testing.assert_allclose(g, prony.g, rtol=1e-8)
    assert g0 == pytest.approx(prony.g_0, rel=1e-9)
    assert f"{prony.tau.size} terms of voigt" in text


def test_the_series_stands_for_the_model_within_its_band(written):
    result, _ = written
    prony = prony_series(result, per_decade=2)
    # Against the model's own medians over the data window, independently evaluated.
    t = np.logspace(np.log10(prony.window[0]), np.log10(prony.window[1]), 30)
    g_t = result.predict("relaxation_modulus", t)
    assert np.max(np.abs(prony.relaxation(t) / g_t.median - 1)) < 2e-3
    w = result.data.omega
    g = result.predict("storage", w).median + 1j * result.predict("loss", w).median
    assert np.max(np.abs(prony.modulus(w) - g) / np.abs(g)) < 2e-3
    assert prony.max_rel_error_relaxation < prony.band_rel_halfwidth
    assert np.all(prony.g > 0) and prony.g_inf > 0
    assert prony.g_0 == pytest.approx(prony.g_inf + prony.g.sum())


def test_a_number_of_terms_instead_of_terms_per_decade(written, tmp_path, run_cli):
    """--terms N: N relaxation times over the span of the per-decade grid (those of zero weight
    dropped), the first and last at its ends; more terms fit at least as well."""
    result, out = written
    few, many = prony_series(result, terms=4), prony_series(result, terms=24)
    span = prony_series(result, per_decade=10)
    assert few.tau.size <= 4 and many.tau.size <= 24
    assert few.tau.min() >= span.tau.min() * (1 - 1e-9)
    assert few.max_rel_error_modulus >= many.max_rel_error_modulus
    status, text, err = run_cli("export", out, "--format", "csv", "--out", tmp_path / "p.csv",
                                "--terms", "24")
    assert status == 0, err
    tau, g, _ = parse((tmp_path / "p.csv").read_text(), "csv")
    np.testing.assert_allclose(tau, many.tau, rtol=1e-9)
    status, _, err = run_cli("export", out, "--format", "csv", "--out", tmp_path / "q.csv",
                             "--terms", "1")
    assert status == 2 and "--terms must be 'auto' or an integer from 2 to 100, got 1" in err
    status, _, err = run_cli("export", out, "--format", "csv", "--out", tmp_path / "q.csv",
                             "--terms", "5", "--per-decade", "3")
    assert status == 2 and "not allowed with argument" in err


def test_a_liquid_relaxes_fully(written):
    result, _ = written
    prony = prony_series(result, structure="maxwell-int", liquid=True)
    assert prony.g_inf == 0.0 and prony.relaxation(1e6) == pytest.approx(0.0, abs=1e-12)


def test_the_long_time_modulus_follows_the_model(written, tmp_path, run_cli):
    """By default G_inf is 0 where the model relaxes fully (the Maxwell liquid) and fitted
    where it does not (the Voigt, whose long-time modulus is 1/b0); either can be forced, and
    the files and the command say which and what the model's own long-time modulus is."""
    result, out = written
    liquid = prony_series(result, structure="maxwell-int", per_decade=2)
    assert liquid.g_inf == 0.0 and liquid.model_g_inf == 0.0
    assert "g_inf = 0: the model relaxes fully (a liquid)" in liquid.text("csv")
    # Its two terms (two per decade) lie inside the data window: nothing is said of
    # extrapolation.
    assert liquid.tau.max() < liquid.window[1] and "extrapolation" not in liquid.text("csv")
    # A springpot relaxes fully, but slowly: fitted, G_inf stands for its relaxation beyond
    # the longest relaxation time.
    fitted = prony_series(result, structure="springpot", liquid=False)
    assert fitted.g_inf > 0 and fitted.model_g_inf == 0.0
    # Its terms reach beyond the data window: named as the model's extrapolation.
    assert fitted.tau.max() > fitted.window[1]
    assert (f"relaxation times {fitted.tau.min():.4g} to {fitted.tau.max():.4g} s: those beyond "
            "the data window stand for the model's extrapolation") in fitted.text("abaqus")
    assert (f"g_inf is the series' modulus beyond its longest relaxation time "
            f"({fitted.tau.max():.4g} s); the model relaxes fully (a liquid)") in fitted.text("csv")

    solid = prony_series(result, structure="voigt")
    b0 = np.asarray(result["voigt"].posterior.samples)[:, 1]
    # The median of 1/b0 over the prediction's draws (a subset of the posterior's): within
    # the spread of medians of subsets of that size.
    assert solid.model_g_inf == pytest.approx(np.median(1 / b0), rel=0.01)
    assert solid.g_inf > 0
    assert f"the model has the long-time modulus {solid.model_g_inf:.6g} Pa" \
        in solid.text("abaqus")
    assert prony_series(result, structure="voigt", liquid=True).g_inf == 0.0
    # *ELASTIC takes Young's modulus: the shear series' G0 is converted there by the user.
    assert (f"instantaneous modulus G0 = {solid.g_0:.10g}: give E0 = 2 (1 + nu) G0 with "
            "Poisson's ratio nu in *ELASTIC, MODULI=INSTANTANEOUS") in solid.text("abaqus")

    status, text, err = run_cli("export", out, "--format", "csv", "--out", tmp_path / "l.csv",
                                "--structure", "maxwell-int")
    assert status == 0, err
    assert "G_inf = 0 Pa" in text
    assert "the largest measured" not in text  # its G0 is within what was measured
    assert "note: g_inf = 0: the model relaxes fully (a liquid) (--no-liquid fits G_inf" in text
    status, text, err = run_cli("export", out, "--format", "csv", "--out", tmp_path / "f.csv",
                                "--structure", "springpot", "--no-liquid")
    assert status == 0, err
    assert "the model relaxes fully (a liquid) (--liquid sets G_inf = 0)" in text
    # The Voigt's G0, the model two decades past the data far above what was measured: said
    # on the command line too.
    status, text, err = run_cli("export", out, "--format", "abaqus", "--out", tmp_path / "v.inp",
                                "--structure", "voigt")
    assert status == 0, err
    prony = prony_series(result, structure="voigt")
    assert prony.g_0 > 1.5 * prony.measured_max
    assert (f"note: G0 is the model's modulus 2 decades past the highest measured frequency, "
            f"{prony.g_0 / prony.measured_max:.3g} x the largest measured |G*|") in text


def test_bad_requests(written, tmp_path, run_cli):
    result, out = written
    with pytest.raises(InputError, match="terms per decade must be an integer from 1 to 10"):
        prony_series(result, per_decade=0)
    status, _, err = run_cli("export", out, "--format", "csv", "--out", tmp_path / "x.csv",
                             "--structure", "nope")
    assert status == 2 and err.startswith("bayesfo: error: no structure 'nope'")
    status, _, err = run_cli("export", out, "--format", "nastran", "--out", tmp_path / "x")
    assert status == 2 and "invalid choice" in err


def parse_lsdyna(text: str) -> tuple[np.ndarray, np.ndarray, float]:
    """(tau, g, g_inf) from the fixed 10-character fields of *MAT_GENERAL_VISCOELASTIC."""
    lines = [x for x in text.splitlines() if not x.startswith("$")]
    start = lines.index("*MAT_GENERAL_VISCOELASTIC")
    card1, card2 = lines[start + 1], lines[start + 2]
    assert card1[:10].strip() == "1" and card1[10:30].strip() == ""  # MID; RO, BULK the user's
    assert all(float(card2[i:i + 10]) == 0.0 for i in range(0, 80, 10))  # no curve fit asked
    rows = []
    for x in lines[start + 3:lines.index("*END")]:
        assert len(x) == 40
        rows.append([float(x[i:i + 10]) for i in range(0, 40, 10)])
    rows = np.array(rows)
    assert np.all(rows[:, 2:] == 0.0)  # no bulk relaxation
    g_inf = float(np.sum(rows[rows[:, 1] == 0, 0]))
    terms = rows[rows[:, 1] > 0]
    return 1.0 / terms[:, 1], terms[:, 0], g_inf


def test_lsdyna_cards_read_back_as_the_series(written, tmp_path, run_cli):
    result, out = written
    status, text, err = run_cli("export", out, "--format", "lsdyna", "--terms", "12", "--out",
                                tmp_path / "p.k")
    assert status == 0, err
    prony = prony_series(result, terms=12)
    tau, g, g_inf = parse_lsdyna((tmp_path / "p.k").read_text())
    # Four significant digits in ten characters.
    np.testing.assert_allclose(tau, prony.tau, rtol=5e-4)
    np.testing.assert_allclose(g, prony.g, rtol=5e-4)
    assert g_inf == pytest.approx(prony.g_inf, rel=5e-4)
    t = np.logspace(-3, 1, 9)
    relaxation = g_inf + np.sum(g * np.exp(-t[:, None] / tau), axis=1)
    np.testing.assert_allclose(relaxation, prony.relaxation(t), rtol=1e-3)
    # More terms than the card takes: refused with the way out.
    status, _, err = run_cli("export", out, "--format", "lsdyna", "--per-decade", "10",
                             "--out", tmp_path / "many.k")
    assert status == 2 and "at most 18 terms" in err and "--terms 17" in err
    assert not (tmp_path / "many.k").exists()


def test_the_series_is_drawn_against_the_band(written, tmp_path, run_cli):
    import matplotlib.pyplot as plt

    from bayesfo.plotting.prony import plot_prony

    result, out = written
    prony = prony_series(result)
    drawn = plot_prony(result, prony)
    try:
        v = drawn.values
        np.testing.assert_allclose(v["series"], prony.relaxation(v["t"]))
        inside = (v["t"] >= prony.window[0]) & (v["t"] <= prony.window[1])
        # On a finer grid than the stated error's (50 times), within twice that error.
        assert np.max(np.abs(v["relative_error"][inside])) <= 2 * prony.max_rel_error_relaxation
        assert np.all(v["model_low"] <= v["model_median"]) and np.all(
            v["model_median"] <= v["model_high"])
    finally:
        plt.close(drawn.figure)
    status, text, err = run_cli("export", out, "--format", "csv", "--out", tmp_path / "p.csv",
                                "--figure", tmp_path / "p.png")
    assert status == 0, err
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    status, _, err = run_cli("export", out, "--format", "csv", "--out", tmp_path / "q.csv",
                             "--figure", tmp_path / "p.gif")
    assert status == 2 and "give a .png, .pdf or .svg file" in err
    assert not (tmp_path / "q.csv").exists()
