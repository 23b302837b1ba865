"""Results in a notebook: a short one-line repr and an HTML table that carries the numbers the
command line prints, for a comparison, a master curve, a prediction and a Prony series."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

import bayesfo as bf
from bayesfo.comparison.table import number
from bayesfo.predictions import prony_series

DATA = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp"


@pytest.fixture(scope="module")
def comparison():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return bf.compare(bf.read(DATA / "Tp020C.csv"), "zener,maxwell-int", workers=1,
                          progress=False, seed=0)


@pytest.fixture(scope="module")
def master():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return bf.mastercurve([(bf.read(DATA / f"Tp{t:03d}C.csv"), float(t)) for t in (20, 30)],
                              structures="zener", law="free", seed=0)


def _short(text: str) -> None:
    assert "\n" not in text and len(text) < 220 and "array(" not in text


def test_a_comparison_renders_its_ranking(comparison):
    html = comparison._repr_html_()
    _short(repr(comparison))
    best = comparison.table()[0]
    assert html.startswith("<div class='bayesfo'>") and "<table>" in html
    assert f"{number(best['log_evidence'])} ± {number(best['log_evidence_err'])}" in html
    assert f"<td>{number(best['posterior_probability'], '.3f')}</td>" in html
    assert "17 frequencies" in html and "in Pa" in html


def test_a_prediction_and_a_prony_series_render_their_numbers(comparison):
    p = comparison.predict("storage", [1.0, 10.0, 100.0])
    _short(repr(p))
    assert repr(p) == "<Prediction of G′ [Pa] from zener at 3 points (1 to 100 rad/s)>"
    html = p._repr_html_()
    assert f"<td>{p.median[1]:.5g}</td>" in html
    assert f"[{p.hdi_low[2]:.5g}, {p.hdi_high[2]:.5g}]" in html
    many = comparison.predict("storage", [10.0 ** k for k in range(-3, 4)] * 3)
    assert "<td>…</td>" in many._repr_html_()  # 21 points: the middle elided
    prony = prony_series(comparison)
    _short(repr(prony))
    assert f"{prony.tau.size} terms, G0 = {prony.g_0:.6g} Pa" in repr(prony)
    html = prony._repr_html_()
    assert f"G0 = {prony.g_0:.6g}, G_inf = {prony.g_inf:.6g} Pa" in html
    assert f"<td>{prony.tau[0]:.6g}</td><td>{prony.g[0]:.6g}</td>" in html
    assert f"max |dG(t)|/G(t) = {prony.max_rel_error_relaxation:.3g}" in html


def test_a_master_curve_renders_its_shifts(master):
    _short(repr(master))
    assert repr(master).startswith("<MasterCurve of zener at 30 °C from 2 isotherms (20 to 30 °C)")
    html = master._repr_html_()
    a = master.shift_factors()[0]["log10_aT"]
    assert f"<td>20</td><td>{a['mean']:.3f}</td>" in html
    # The reference isotherm's shift is 0: shown as 0.000, never -0.000.
    assert "<td>30</td><td>0.000</td><td>0.000</td><td>[0.000, 0.000]</td>" in html
    assert "-0.000" not in html
