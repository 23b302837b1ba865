"""Publication figures (issue 19): what a reader sees, checked on the drawn artists.

Most tests draw from small stand-ins for results (posterior draws scattered around chosen
parameters, no sampling), so that the figures' logic is tested in seconds; the slow test runs
the demo comparison itself.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402

from bayesfo.comparison import Criteria  # noqa: E402
from bayesfo.data import FrequencyResponse, read  # noqa: E402
from bayesfo.errors import InputError  # noqa: E402
from bayesfo.plotting import (  # noqa: E402
    plot_bode,
    plot_corner,
    plot_nyquist,
    plot_q_posteriors,
    plot_ranking,
    plot_residuals,
    plot_trace,
)
from bayesfo.plotting.batch import plot_batch_summary, plot_q_temperature  # noqa: E402
from bayesfo.plotting.captions import figure_caption, trace_caption  # noqa: E402
from bayesfo.plotting.style import FLAG_COLOR, structure_styles  # noqa: E402
from bayesfo.structures import get_structure  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"
#: Posterior medians of the demo comparison (Tp020C, seed 0): Voigt and Zener predict the same.
DEMO_THETA = {
    "voigt": ("voigt", [1.7888, 1.6564e-5, 0.56926]),
    "zener": ("zener", [1.7861, 1.65486e-5, 3.37e-10, 0.56945]),
    "maxwell": ("maxwell", [1.2565e6, 8.9016, 0.19372, 0.54660]),
}


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


# ---------------------------------------------------------------------------------------------
# Stand-ins for results


def _summary(x):
    lo, hi = np.quantile(x, [0.03, 0.97])
    return SimpleNamespace(mean=float(x.mean()), sd=float(x.std()), hdi_low=float(lo),
                           hdi_high=float(hi), median=float(np.median(x)), map=float(x[0]),
                           poorly_determined=False, multimodal=False)


def _result(name, structure, theta, rel_sd=0.002, n=120, seed=0, priors=None, converged=True,
            names=None):
    """A result with ``n`` draws of ``theta`` scattered by ``rel_sd`` (relative)."""
    rng = np.random.default_rng(seed)
    theta = np.asarray(theta, float)
    draws = theta * (1.0 + rel_sd * rng.standard_normal((n, theta.size)))
    names = tuple(names or structure.param_names)
    post = SimpleNamespace(
        samples=draws, param_names=names, summary={p: _summary(draws[:, i])
                                                   for i, p in enumerate(names)},
        converged=converged, map_theta=draws[0], sampler="emcee", idata=None,
        rhat_max=1.002 if converged else 1.08, ess_min=900.0 if converged else 120.0,
        n_walkers=8, n_steps=n // 8, burn=0, thin=1)
    return SimpleNamespace(name=name, structure=structure, posterior=post, error=None, fit=None,
                           criteria=SimpleNamespace(**{**dict.fromkeys(Criteria.names()),
                                                       "priors": priors or {}}),
                           adequacy=None, fits="yes")


@dataclass
class _Comparison:
    """What the figures read of a comparison: data, results (in the order requested), the
    ranking, and for the ranking figure the table."""

    data: object
    results: tuple
    holdout: object = None
    rows: list = field(default_factory=list)

    @property
    def ranking(self):
        return [r.name for r in self.results]

    def __getitem__(self, name):
        return next(r for r in self.results if r.name == name)

    def table(self):
        return self.rows


def _demo_comparison(names=("voigt", "zener", "maxwell")):
    data = read(DEMO)
    results = tuple(_result(n, get_structure(DEMO_THETA[n][0]), DEMO_THETA[n][1], seed=i)
                    for i, n in enumerate(names))
    return _Comparison(data, results)


def _boxes(texts, renderer):
    return [t.get_window_extent(renderer) for t in texts if t.get_visible() and t.get_text()]


def _shown(axis):
    """The tick labels of ``axis`` that are drawn: those of ticks inside the view."""
    lo, hi = sorted(axis.get_view_interval())
    span = hi - lo
    return [t.label1 for t in axis.get_major_ticks()
            if lo - 1e-9 * span <= t.get_loc() <= hi + 1e-9 * span]


def _overlap(a, b) -> float:
    """Area [px²] shared by two display boxes."""
    w = min(a.x1, b.x1) - max(a.x0, b.x0)
    h = min(a.y1, b.y1) - max(a.y0, b.y0)
    return max(w, 0.0) * max(h, 0.0)


def _inside(box, fig, tol=0.5) -> bool:
    return (box.x0 >= -tol and box.y0 >= -tol and box.x1 <= fig.bbox.width + tol
            and box.y1 <= fig.bbox.height + tol)


def _draw(fig):
    """Draw ``fig`` (on an Agg canvas: batch figures are made without pyplot); its renderer."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not hasattr(fig.canvas, "get_renderer"):
        FigureCanvasAgg(fig)
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def _overlap_1d(a, b) -> float:
    return max(0.0, min(a[1], b[1]) - max(a[0], b[0]))


def _rotated_extent(label, renderer):
    """Extent of an x tick label rotated by 45° (right-aligned, top-anchored) in its own
    directions [display px]: ``(across, along)`` intervals, from its unrotated size."""
    from matplotlib.text import Text

    assert label.get_rotation() == 45.0 and label.get_ha() == "right"
    flat = Text(text=label.get_text(), fontproperties=label.get_fontproperties(),
                figure=label.figure)
    w, h = flat.get_window_extent(renderer).size
    box = label.get_window_extent(renderer)
    d = np.array([1.0, 1.0]) / np.sqrt(2.0)  # along the text
    n = np.array([-1.0, 1.0]) / np.sqrt(2.0)  # across it, towards its top
    # The top right corner of the text is the top of its box, h/√2 left of the box's right.
    corner = np.array([box.x1 - h / np.sqrt(2.0), box.y1])
    corners = np.array([corner, corner - w * d, corner - h * n, corner - w * d - h * n])
    # The four corners span the label's box: the reading of the geometry is right.
    np.testing.assert_allclose([corners[:, 0].min(), corners[:, 1].min(), corners[:, 0].max(),
                                corners[:, 1].max()], [box.x0, box.y0, box.x1, box.y1], atol=1.5)
    return ((float(min(corners @ n)), float(max(corners @ n))),
            (float(min(corners @ d)), float(max(corners @ d))))


def _assert_nothing_clipped(fig, renderer):
    """Everything drawn (tick labels, labels, titles, legends) lies inside the figure."""
    box = fig.get_tightbbox(renderer)  # inches
    width, height = fig.get_size_inches()
    tol = 0.5 / fig.dpi
    assert box.x0 >= -tol and box.y0 >= -tol, box
    assert box.x1 <= width + tol and box.y1 <= height + tol, box


# ---------------------------------------------------------------------------------------------
# 1. Corner plots of many parameters


def test_corner_of_nine_parameters_keeps_labels_clear_of_ticks_and_inside_the_figure():
    structure = get_structure("max-n3m3")
    names = (*structure.param_names, "sigma_rel")
    theta = [6.2, 7.0, 1.3, 2.5e-5, 5.5e-5, 1.4e-5, 2.1e-8, 0.597, 2.7e-3]
    priors = {n: {"prior": "uniform", "low": 0.0, "high": 20.0} for n in names}
    priors["q"] = {"prior": "uniform", "low": 0.0, "high": 1.0}
    priors["sigma_rel"] = {"prior": "log-uniform", "low": 1e-5, "high": 1.0}
    r = _result("max-n3m3", structure, theta, rel_sd=0.08, n=800, priors=priors, names=names)
    drawn = plot_corner(r)
    fig = drawn.figure
    renderer = _draw(fig)
    ndim = len(names)
    grid = np.array(drawn.axes, dtype=object).reshape(ndim, ndim)
    ticks = [b for ax in grid.ravel() for b in _boxes([*_shown(ax.xaxis), *_shown(ax.yaxis)],
                                                       renderer)]
    labels = [b for ax in grid.ravel() for b in _boxes([ax.xaxis.label, ax.yaxis.label],
                                                       renderer)]
    assert len(labels) == 2 * ndim - 1  # x labels of the bottom row, y labels of the left column
    assert grid[-1, -1].get_xlabel().startswith("log$_{10}$")  # sigma_rel, log-uniform prior
    for lab in labels:
        assert all(_overlap(lab, t) < 1.0 for t in ticks), "an axis label covers tick labels"
        assert _inside(lab, fig), "an axis label is clipped by the figure edge"
    for i, a in enumerate(labels):
        assert all(_overlap(a, b) < 1.0 for b in labels[i + 1:]), "axis labels overlap"
    for t in ticks:
        assert _inside(t, fig), "a tick label is clipped by the figure edge"
    assert _inside(drawn.artists["legend"].get_window_extent(renderer), fig)
    _assert_nothing_clipped(fig, renderer)
    # No two tick labels run into each other across the gaps between panels: the horizontal
    # ones of the left column by their boxes, the x labels rotated by 45° as rotated boxes.
    left_ticks = [b for ax in grid[1:, 0] for b in _boxes(_shown(ax.yaxis), renderer)]
    for i, a in enumerate(left_ticks):
        assert all(_overlap(a, b) < 1.0 for b in left_ticks[i + 1:]), "y tick labels collide"
    rotated = [_rotated_extent(t, renderer) for ax in grid[-1, :] for t in _shown(ax.xaxis)
               if t.get_visible() and t.get_text()]
    for i, (u0, t0) in enumerate(rotated):
        for u1, t1 in rotated[i + 1:]:
            assert not (_overlap_1d(u0, u1) > 0.5 and _overlap_1d(t0, t1) > 0.5), \
                "x tick labels collide"
    # The rightmost tick label of the bottom row, the one clipped before, ends inside its panel.
    right = _boxes(_shown(grid[-1, -1].xaxis), renderer)
    assert max(b.x1 for b in right) <= grid[-1, -1].bbox.x1 + 1.0


# ---------------------------------------------------------------------------------------------
# 2. Nyquist diagrams of data over many decades


def _voigt_comparison(omega, sigma=True):
    voigt = get_structure("voigt")
    theta = [1.0, 1e-2, 0.5]
    g = voigt.response(np.array([theta]), omega, "modulus")[0]
    sd = 0.02 * np.abs(g) if sigma else None
    data = FrequencyResponse(omega, g, sd, kind="modulus", units="Pa", name="voigt sim")
    return _Comparison(data, (_result("voigt", voigt, theta, rel_sd=0.01),))


def test_nyquist_is_log_magnitude_for_data_over_many_decades():
    comp = _voigt_comparison(np.logspace(-4, 6, 40))  # |G| from 100 to 1e5: 3 decades
    drawn = plot_nyquist(comp, n_lines=5)
    ax = drawn.axes[0]
    assert str(drawn.values["form"]) == "log" and float(drawn.values["decades"]) > 2.9
    assert ax.name == "polar"
    title = drawn.artists["title"].get_text()
    assert "log-magnitude" in title and "log scale" in title and "angle arg" in title
    # The median curve: its angle and log10 of its magnitude.
    med = drawn.values["voigt/real_median"] + 1j * drawn.values["voigt/imag_median"]
    line = drawn.artists["voigt/median"]
    np.testing.assert_allclose(np.exp(1j * line.get_xdata()), med / np.abs(med), atol=1e-12)
    origin = int(drawn.values["log_origin"])
    assert origin == 2  # the decade below the smallest |G| of the data (100.7)
    np.testing.assert_allclose(line.get_ydata(), np.maximum(np.log10(np.abs(med)), origin))
    pts = drawn.artists["data"].lines[0]
    g = drawn.values["data/real"] + 1j * drawn.values["data/imag"]
    np.testing.assert_allclose(pts.get_ydata(), np.log10(np.abs(g)))
    assert ax.get_rmin() == origin and ax.get_rmax() > np.log10(np.abs(g)).max()
    # Radial ticks are decades of |G|; every text of the figure is inside it.
    assert [t.get_text() for t in ax.get_yticklabels()][:2] == ["$10^{2}$", "$10^{3}$"]
    _assert_nothing_clipped(drawn.figure, _draw(drawn.figure))


def test_nyquist_stays_linear_for_a_narrow_span_and_the_form_can_be_chosen():
    comp = _voigt_comparison(np.logspace(-1, 1, 12))  # |G| spans less than a decade
    drawn = plot_nyquist(comp, n_lines=0)
    assert str(drawn.values["form"]) == "linear"
    ax = drawn.axes[0]
    assert ax.name == "rectilinear" and ax.get_aspect() == 1.0
    assert "linear" in drawn.artists["title"].get_text()
    assert ax.get_xlabel().startswith("Re") and ax.get_ylabel().startswith("Im")
    forced = plot_nyquist(comp, n_lines=0, form="log")
    assert forced.axes[0].name == "polar"
    # A Cartesian axes handed in is replaced by a polar one at its place.
    fig, given = plt.subplots()
    drawn = plot_nyquist(comp, n_lines=0, form="log", ax=given)
    assert drawn.axes[0].name == "polar" and drawn.axes[0].figure is fig
    assert given not in fig.axes
    with pytest.raises(InputError, match="'form'"):
        plot_nyquist(comp, form="polar")


# ---------------------------------------------------------------------------------------------
# 3. Structures that predict the same response


def _style_of(line):
    return (to_rgba(line.get_color()), line.get_linestyle(), line.get_marker())


def test_coinciding_structures_stay_visible_and_are_named():
    comp = _demo_comparison()
    bode = plot_bode(comp, n_draws=60)
    for q in ("magnitude", "phase"):
        v, z = bode.artists[f"voigt/{q}_median"], bode.artists[f"zener/{q}_median"]
        assert v.get_linestyle() != z.get_linestyle()
        assert to_rgba(v.get_color()) != to_rgba(z.get_color())
        # The two curves do agree within a line width: that is what the note says.
        span = np.log10(np.divide(*bode.axes[0].get_ylim()[::-1])) if q == "magnitude" else \
            np.ptp(bode.axes[1].get_ylim())
        yv, yz = v.get_ydata(), z.get_ydata()
        if q == "magnitude":
            yv, yz = np.log10(yv), np.log10(yz)
        assert np.max(np.abs(yv - yz)) < 0.008 * span
    note = bode.artists["note"].get_text()
    assert note == str(bode.values["note"]) == "voigt and zener coincide"

    nyq = plot_nyquist(comp, n_draws=60, n_lines=3)
    assert str(nyq.values["form"]) == "linear"
    assert nyq.artists["voigt/median"].get_linestyle() != nyq.artists["zener/median"].get_linestyle()
    assert nyq.artists["note"].get_text() == "voigt and zener coincide"

    res = plot_residuals(comp, n_draws=60)
    v, z = res.artists["voigt/real"], res.artists["zener/real"]
    assert v.get_marker() != z.get_marker()
    # Offset along ω, so that the points sit side by side.
    ratio = np.log10(np.asarray(z.get_xdata()) / np.asarray(v.get_xdata()))
    np.testing.assert_allclose(ratio, float(res.values["dodge"]))
    assert float(res.values["dodge"]) >= 0.02
    assert "voigt and zener coincide" in res.artists["note"].get_text()
    # The legend title is the note: it is drawn, above the axes.
    assert bode.figure.legends[0].get_title() is bode.artists["note"]


def test_no_note_when_curves_differ():
    comp = _demo_comparison(("voigt", "maxwell"))
    for drawn in (plot_bode(comp, n_draws=40), plot_nyquist(comp, n_draws=40, n_lines=0),
                  plot_residuals(comp, n_draws=40)):
        assert str(drawn.values["note"]) == ""
        assert "note" not in drawn.artists


# ---------------------------------------------------------------------------------------------
# 4. Tight posteriors of the fractional order


def test_tight_order_gets_a_zoomed_inset_with_its_hdi_and_prior():
    prior = {"q": {"prior": "uniform", "low": 0.0, "high": 1.0}}
    comp = _demo_comparison(("voigt", "zener"))
    tight = _result("voigt", get_structure("voigt"), DEMO_THETA["voigt"][1], rel_sd=0.002,
                    n=600, priors=prior)
    broad = _result("zener", get_structure("zener"), [1.7861, 1.65e-5, 3e-10, 0.5], rel_sd=0.25,
                    n=600, priors=prior, seed=1)
    comp = _Comparison(comp.data, (tight, broad))
    drawn = plot_q_posteriors(comp)
    assert "voigt/inset" in drawn.artists and "zener/inset" not in drawn.artists
    inset = drawn.artists["voigt/inset"]
    assert inset in drawn.axes and len(drawn.axes) == 2
    s = tight.posterior.summary["q"]
    lo, hi = inset.get_xlim()
    width = s.hdi_high - s.hdi_low
    assert lo < s.hdi_low and hi > s.hdi_high and hi - lo < 5 * width  # zoomed to the HDI
    np.testing.assert_allclose(drawn.artists["voigt/inset_hdi"].get_xdata(),
                               [s.hdi_low, s.hdi_high])
    # The ridge is resolved in the inset: many points between a tenth and nine tenths of it.
    ridge = drawn.artists["voigt/inset_ridge"].get_paths()[0].vertices[:, 1]
    assert np.sum((ridge > 0.1) & (ridge < 0.9)) > 20
    # The dashed prior is drawn in the inset at its height relative to the peak, and its ratio
    # is stated.
    prior_line = drawn.artists["voigt/inset_prior"]
    assert prior_line.get_linestyle() == "--"
    peak = drawn.values["voigt/density"].max()
    np.testing.assert_allclose(prior_line.get_ydata(), 1.0 / peak, rtol=1e-9)
    assert f"{peak:.3g}" in drawn.artists["voigt/inset_note"].get_text()
    # The HDI is stated beside the ridge.
    label = drawn.artists["voigt/label"].get_text()
    assert "HDI" in label and f"{s.hdi_low:.4f}" in label
    # In the main axes the outline stops where the ridge meets its base: the prior shows there.
    outline = drawn.artists["voigt/outline"].get_ydata()
    grid = drawn.values["voigt/grid"]
    assert np.isnan(outline[grid < 0.5]).all()
    assert drawn.artists["voigt/prior"].get_zorder() > drawn.artists["voigt/outline"].get_zorder()


# ---------------------------------------------------------------------------------------------
# 5. One style per structure, in compare and batch figures


def test_twelve_structures_have_distinct_styles_shared_by_compare_and_batch_figures():
    names = [f"s{i:02d}" for i in range(12)]
    styles = structure_styles(names)
    assert len({st.key for st in styles.values()}) == 12
    data = read(DEMO)
    voigt = get_structure("voigt")
    results = tuple(_result(n, voigt, [1.79 * (1 + 0.05 * i), 1.66e-5, 0.569], n=30, seed=i)
                    for i, n in enumerate(names))
    comp = _Comparison(data, results)
    bode = plot_bode(comp, structures=names, n_draws=20, n_grid=40)
    res = plot_residuals(comp, structures=names, n_draws=20)
    compare_style = {}
    for n in names:
        line = bode.artists[f"{n}/magnitude_median"]
        pts = res.artists[f"{n}/real"]
        assert to_rgba(line.get_color()) == to_rgba(pts.get_color())
        compare_style[n] = (to_rgba(line.get_color()), line.get_linestyle(), pts.get_marker())
    assert len(set(compare_style.values())) == 12

    rows = [{"dataset": f"T{t}", "temperature_C": float(t), "status": "ok", "structure": n,
             "rank": i + 1, "posterior_probability": 1 / 12, "best": i == 0, "converged": True,
             "q_mean": 0.5, "q_hdi_low": 0.45, "q_hdi_high": 0.55}
            for t in (0, 40) for i, n in enumerate(names)]
    fig = plot_q_temperature(rows, names)
    ax_p = fig.axes[1]
    batch_style = {line.get_label(): _style_of(line) for line in ax_p.get_lines()}
    assert batch_style == compare_style
    # The probability bars of the batch summary: the same colours, hatches for line styles.
    fig = plot_batch_summary(rows, names)
    bars = {c.get_label(): c.patches[0] for c in fig.axes[0].containers}
    for n in names:
        assert to_rgba(bars[n].get_facecolor()) == compare_style[n][0]
    assert len({(to_rgba(b.get_facecolor()), b.get_hatch()) for b in bars.values()}) == 12
    # The title is the figure's (the legends beside the axes narrow them); a best structure
    # that fails the posterior predictive checks is labelled as the least misfit.
    assert fig.get_suptitle().startswith("Best structure (equal prior odds)")
    assert not fig.axes[0].get_title()
    rows[0]["adequate"] = False
    labels = [t.get_text() for t in plot_batch_summary(rows, names).axes[0].texts]
    assert labels == [f"{names[0]}\n(misfits)", names[0]]


# ---------------------------------------------------------------------------------------------
# 6. A batch of one isotherm


def test_single_isotherm_gets_a_sensible_temperature_axis():
    rows = [{"dataset": "Tp190C", "temperature_C": 190.0, "status": "ok", "structure": n,
             "rank": i + 1, "posterior_probability": p, "best": i == 0, "converged": True,
             "q_mean": q, "q_hdi_low": q - 0.02, "q_hdi_high": q + 0.02}
            for i, (n, p, q) in enumerate((("voigt", 0.7, 0.57), ("zener", 0.3, 0.56)))]
    fig = plot_q_temperature(rows, ["voigt", "zener"])
    ax_q, ax_p = fig.axes[:2]
    renderer = _draw(fig)
    assert ax_p.get_xlim() == (180.0, 200.0)
    assert list(ax_p.get_xticks()) == [190.0]
    assert [t.get_text() for t in ax_p.get_xticklabels()] == ["190"]
    assert ax_p.xaxis.get_offset_text().get_text() == ""
    assert "one temperature (190 °C)" in ax_q.get_title()
    # The structures' points sit apart around 190 °C, within the axis.
    xs = sorted(float(line.get_xdata()[0]) for line in ax_p.get_lines())
    assert len(xs) == 2 and xs[0] < 190.0 < xs[1] and xs[1] - xs[0] < 5.0
    _assert_nothing_clipped(fig, renderer)


# ---------------------------------------------------------------------------------------------
# 7. Captions of traces


def _with_trace(result):
    from arviz_base import from_dict

    post = result.posterior
    n_walkers = post.n_walkers
    draws = post.samples.reshape(n_walkers, -1, post.samples.shape[1])
    idata = from_dict({"posterior": {p: draws[:, :, i] for i, p in enumerate(post.param_names)}})
    post.idata = idata
    return result


def test_trace_caption_states_what_the_trace_of_that_structure_shows():
    voigt = get_structure("voigt")
    good = _with_trace(_result("voigt", voigt, [1.79, 1.66e-5, 0.569], n=80))
    bad = _with_trace(_result("my/model", voigt, [1.79, 1.66e-5, 0.569], n=80, converged=False))
    drawn = plot_trace(good)
    assert bool(drawn.values["converged"])
    assert "overlap and show no trend" in drawn.caption and drawn.caption == trace_caption(good)
    drawn = plot_trace(bad)
    assert not bool(drawn.values["converged"])
    assert "NOT converged" in drawn.caption
    assert "overlap" not in drawn.caption and "well-mixed" not in drawn.caption
    assert "R-hat 1.080" in drawn.caption and "ESS 120" in drawn.caption
    # Captions by figure name, the structure found by its file stem ("my/model" → "my_model").
    comp = _Comparison(read(DEMO), (good, bad))
    assert figure_caption("trace_my_model", comp) == drawn.caption
    assert "not converge" in figure_caption("corner_my_model", comp)
    assert figure_caption("trace_unknown", comp) is None


# ---------------------------------------------------------------------------------------------
# 8. PSIS-LOO with Pareto k instead of WAIC flags


def test_ranking_shows_pareto_k_and_says_once_why_waic_is_not_shown():
    comp = _demo_comparison(("voigt", "zener", "maxwell"))
    k = {"voigt": 0.86, "zener": 0.55, "maxwell": 0.91}
    rng = np.random.default_rng(0)
    rows = []
    for i, r in enumerate(comp.results):
        r.criteria.loo_pointwise = rng.normal(-10.0 - 3 * i, 0.5, 17)
        rows.append({"rank": i + 1, "structure": r.name, "delta_log_evidence": -2.0 * i,
                     "log_evidence_err": 0.1, "posterior_probability": [0.7, 0.3, 0.0][i],
                     "delta_loo": -3.0 * 17 * i, "aic": 10.0 + 5 * i, "bic": 12.0 + 6 * i,
                     "converged": True, "fits": "yes", "pareto_k_max": k[r.name]})
    comp.rows = rows
    drawn = plot_ranking(comp)
    bad = np.array([k[n] > 0.7 for n in drawn.values["structures"]])
    np.testing.assert_allclose(drawn.values["pareto_k_max"], [k[n] for n in
                                                              drawn.values["structures"]])
    # PSIS-LOO where k̂ > 0.7: open markers with a red edge, the filled ones only elsewhere.
    open_marks = drawn.artists["delta_loo_unreliable"]
    np.testing.assert_allclose(open_marks.get_xdata(), drawn.values["delta_loo"][bad])
    assert to_rgba(open_marks.get_markeredgecolor()) == to_rgba(FLAG_COLOR)
    assert open_marks.get_markerfacecolor() == "white"
    assert list(drawn.artists["delta_loo"].lines[0].get_markevery()) == list(np.flatnonzero(~bad))
    # k̂ is stated on the right of the criteria, red above 0.7.
    ticks = drawn.artists["pareto_k"].get_yticklabels()
    assert [t.get_text() for t in ticks] == [f"k̂ {k[n]:.2f}" for n in drawn.values["structures"]]
    assert [to_rgba(t.get_color()) == to_rgba(FLAG_COLOR) for t in ticks] == list(bad)
    # WAIC: not drawn, and why is said once.
    texts = [t.get_text() for t in drawn.figure.findobj(matplotlib.text.Text)]
    assert sum("WAIC" in t for t in texts) == 1
    assert drawn.artists["note"].get_text().startswith("WAIC not shown")
    assert not any("unreliable (large pointwise" in t for t in texts)
    # The posterior probabilities stay the last axes (right of the evidence).
    right = drawn.figure.axes[-1]
    assert right.get_yticklabels()[0].get_text() == "P = 0.700"


# ---------------------------------------------------------------------------------------------
# The demo itself


@pytest.mark.slow
def test_demo_figures_show_voigt_and_zener_apart(tmp_path):
    from bayesfo.comparison import compare
    from bayesfo.plotting import write_figures

    with warnings.catch_warnings():
        # Pareto-k, noise and convergence warnings of the demo: compare reports them, and the
        # figures show them; they are not the subject here.
        warnings.simplefilter("ignore")
        comp = compare(read(DEMO), "voigt,zener,maxwell", seed=0, progress=False)
    for drawn in (plot_bode(comp), plot_nyquist(comp), plot_residuals(comp)):
        assert "voigt and zener coincide" in str(drawn.values["note"])
    q = plot_q_posteriors(comp)
    assert "voigt/inset" in q.artists and "zener/inset" in q.artists
    written = write_figures(comp, tmp_path, formats=("png",))
    assert set(written) >= {"ranking", "bode", "moduli", "nyquist", "residuals", "q_posteriors"}
    for name in written:
        caption = figure_caption(name, comp)
        assert caption, name
        if name.startswith("trace_"):
            structure = comp[name[len("trace_"):]]
            assert ("NOT converged" in caption) == (not structure.posterior.converged)


def test_a_long_coincidence_note_is_wrapped_inside_the_figure():
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    from bayesfo.plotting._legend import _legend, _wrapped

    note = ("fractional_kelvin_voigt, voigt and zener coincide in magnitude; voigt and zener "
            "coincide in phase")
    assert _wrapped(note).split("\n") == [
        "fractional_kelvin_voigt, voigt and zener coincide in", "magnitude",
        "voigt and zener coincide in phase"]
    fig = plt.figure(figsize=(5, 4), layout="constrained")
    fig.add_subplot()
    handles = [Line2D([], []) for _ in range(3)]
    legend = _legend(fig, handles, ["a", "b", "c"], note)
    fig.canvas.draw()
    box = legend.get_title().get_window_extent()
    frame = fig.bbox
    assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and box.y1 <= frame.y1
    plt.close(fig)


def test_structures_that_misfit_are_marked_in_the_response_legends():
    # Adequacy as the checks report it: maxwell rejected, zener within the small-misfit band.
    # voigt passes only where its fitted noise does not swamp the data.
    comp = _demo_comparison(("voigt", "zener", "maxwell"))
    comp.results[0].fits, comp.results[1].fits, comp.results[2].fits = "partly", "small", "no"
    expected = ["voigt (misfit hidden by noise)", "zener (small misfit)", "maxwell (misfits)"]
    for drawn in (plot_bode(comp, n_draws=40), plot_nyquist(comp, n_draws=40, n_lines=0),
                  plot_residuals(comp, n_draws=40)):
        shown = [t.get_text() for legend in drawn.figure.legends for t in legend.get_texts()]
        shown += [t.get_text() for ax in drawn.figure.axes if ax.get_legend()
                  for t in ax.get_legend().get_texts()]
        assert [s for s in shown if s.split(" (")[0] in ("voigt", "zener", "maxwell")] == expected


def test_every_order_of_a_two_springpot_model_gets_its_ridge():
    """The two-springpot Kelvin–Voigt model has two orders: both are drawn, β (its first order)
    under the structure's name and α in a row of its own, each density from its own draws."""
    comp = _demo_comparison(("voigt",))
    fkv = _result("fractional_kelvin_voigt", get_structure("fractional_kelvin_voigt"),
                  [9.4e4, 7.1e4, 0.59, 0.14], rel_sd=0.05, n=600, seed=3)
    comp = _Comparison(comp.data, (fkv, comp.results[0]))
    drawn = plot_q_posteriors(comp)
    assert list(drawn.values["structures"]) == ["fractional_kelvin_voigt",
                                                "fractional_kelvin_voigt:alpha", "voigt"]
    ticks = [t.get_text() for t in drawn.axes[0].get_yticklabels()]
    assert ticks == ["fractional_kelvin_voigt ($\\beta$)", " ($\\alpha$)", "voigt"]
    for key, column in (("fractional_kelvin_voigt", 3), ("fractional_kelvin_voigt:alpha", 2)):
        s = fkv.posterior.summary[fkv.posterior.param_names[column]]
        np.testing.assert_allclose(drawn.values[f"{key}/hdi"], (s.hdi_low, s.hdi_high))
        grid, dens = drawn.values[f"{key}/grid"], drawn.values[f"{key}/density"]
        mean = np.sum(grid * dens) / np.sum(dens)
        assert mean == pytest.approx(fkv.posterior.samples[:, column].mean(), abs=0.01)


# ---------------------------------------------------------------------------------------------
# Many structures: the ranking and the order figures stay readable


def _many(n: int):
    """A comparison of ``n`` Voigt-like results, ranked in order, the last hopeless."""
    voigt = get_structure("voigt")
    results, rows = [], []
    for i in range(n):
        name = f"structure-{i:02d}-with-a-long-name"
        theta = [1.79, 1.66e-5, 0.3 + 0.6 * i / n]
        results.append(_result(name, voigt, theta, rel_sd=0.01, seed=i))
        delta = -1.3e13 if i == n - 1 else -2.5 * i
        rows.append({"rank": i + 1, "structure": name, "delta_log_evidence": delta,
                     "log_evidence_err": 0.05, "posterior_probability": 0.0 if i else 1.0,
                     "delta_loo": -2.0 * i, "delta_loo_se": 0.5, "aic": 10.0 + 5 * i,
                     "bic": 12.0 + 5 * i, "converged": True, "fits": "no",
                     "pareto_k_max": 0.3})
    comp = _Comparison(read(DEMO), tuple(results))
    comp.rows = rows
    return comp


def test_fifty_structures_keep_the_ranking_and_order_figures_readable():
    from bayesfo.plotting._compute import ORDER_STRUCTURES, RANKING_SHOWN

    comp = _many(50)
    drawn = plot_ranking(comp)
    names = list(drawn.values["structures"])
    assert names == [r["structure"] for r in comp.rows[:RANKING_SHOWN]]
    # The rest, and the hopeless one, named under the figure rather than drawn.
    assert list(drawn.values["not_shown"]) == [r["structure"] for r in comp.rows[RANKING_SHOWN:]]
    note = drawn.artists["note"].get_text().replace("\n", " ")
    assert f"{50 - RANKING_SHOWN - 1} more structures (Δln Z −30 to −120)" in note
    assert ("structure-49-with-a-long-name, ln Z over 1,000,000 nats below the best (Δln Z "
            "−1.3e+13)") in note
    fig = drawn.figure
    renderer = _draw(fig)
    _assert_nothing_clipped(fig, renderer)
    for ax in drawn.axes:
        labels = _boxes(ax.get_yticklabels(), renderer)
        assert len(labels) == RANKING_SHOWN
        for i, a in enumerate(labels):
            assert all(_overlap(a, b) < 1.0 for b in labels[i + 1:]), "tick labels overlap"
    # The Δ axis spans the drawn structures, not the hopeless one.
    assert drawn.axes[0].get_xlim()[0] > -1e3

    q = plot_q_posteriors(comp)
    assert len(q.values["structures"]) == ORDER_STRUCTURES
    assert list(q.values["not_shown"]) == [r.name for r in comp.results[ORDER_STRUCTURES:]]
    fig = q.figure
    renderer = _draw(fig)
    _assert_nothing_clipped(fig, renderer)
    assert fig.get_size_inches()[1] < 8.0
    labels = _boxes(q.axes[0].get_yticklabels(), renderer)
    for i, a in enumerate(labels):
        assert all(_overlap(a, b) < 1.0 for b in labels[i + 1:]), "tick labels overlap"
    # All of them, when asked.
    every = plot_ranking(comp, limit=None)
    assert len(every.values["structures"]) == 49 and list(every.values["not_shown"]) == [
        "structure-49-with-a-long-name"]
    with pytest.raises(InputError, match="limit"):
        plot_ranking(comp, limit=0)


def test_batch_figures_give_every_order_and_name_the_data_sets_once():
    # 20 isotherms of one file: the ids share the file's stem, said once under the axis; the
    # two-springpot model's α and β each drawn; no structure name written over the bars.
    temps = list(range(-40, 160, 10))
    ids = [f"test_frequency_sweep_tts_ARES-T{'m' if t < 0 else 'p'}{abs(t):03d}C" for t in temps]
    rows = []
    for d, t in zip(ids, temps, strict=True):
        a, b = 0.6 + 0.001 * t, 0.1 + 0.0005 * t
        rows.append({"dataset": d, "temperature_C": float(t), "status": "ok",
                     "structure": "fractional_kelvin_voigt", "rank": 1, "best": True,
                     "posterior_probability": 0.9, "converged": True, "q_parameter": "beta",
                     "q_mean": b, "q_hdi_low": b - 0.01, "q_hdi_high": b + 0.01,
                     "order_summaries": {"alpha": {"mean": a, "hdi_low": a - 0.02,
                                                   "hdi_high": a + 0.02},
                                         "beta": {"mean": b, "hdi_low": b - 0.01,
                                                  "hdi_high": b + 0.01}}})
        rows.append({"dataset": d, "temperature_C": float(t), "status": "ok",
                     "structure": "zener", "rank": 2, "best": False,
                     "posterior_probability": 0.1, "converged": True, "q_parameter": "q",
                     "q_mean": 0.5, "q_hdi_low": 0.48, "q_hdi_high": 0.52,
                     "order_summaries": {"q": {"mean": 0.5, "hdi_low": 0.48,
                                               "hdi_high": 0.52}}})
    fig = plot_batch_summary(rows, ["zener", "fractional_kelvin_voigt"])
    renderer = _draw(fig)
    ax_p, ax_q = fig.axes[:2]
    assert [t.get_text() for t in ax_q.get_xticklabels()] == [d.split("-")[-1] for d in ids]
    assert ax_q.get_xlabel() == "data set (test_frequency_sweep_tts_ARES-…)"
    legend = [t.get_text() for t in fig.legends[-1].get_texts()]
    assert legend[:3] == ["zener", "fractional_kelvin_voigt (α)", "fractional_kelvin_voigt (β)"]
    # α's means at every data set, in order of temperature
    means = sorted({round(float(y), 6) for line in ax_q.get_lines()
                    for y in np.atleast_1d(line.get_ydata())})
    for t in temps:
        assert round(0.6 + 0.001 * t, 6) in means and round(0.1 + 0.0005 * t, 6) in means
    assert not ax_p.texts  # no names over the bars of 20 data sets
    title = ax_p.title.get_window_extent(renderer)
    for text in fig.findobj(matplotlib.text.Text):
        if text is not ax_p.title and text.get_visible() and text.get_text():
            assert _overlap(text.get_window_extent(renderer), title) < 1.0, text.get_text()
    _assert_nothing_clipped(fig, renderer)
    # The temperature figure: both orders against temperature too.
    fig = plot_q_temperature(rows, ["zener", "fractional_kelvin_voigt"])
    legend = [t.get_text() for t in fig.legends[-1].get_texts()]
    assert "fractional_kelvin_voigt (α)" in legend and "fractional_kelvin_voigt (β)" in legend
