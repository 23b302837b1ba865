"""Figures of a comparison: what is drawn equals an independent computation from the results."""

from __future__ import annotations

import os
import struct
import warnings
from dataclasses import replace

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from arviz_stats import compare as arviz_compare  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402
from scipy.integrate import trapezoid  # noqa: E402

from bayesfo.comparison import StructureResult, compare  # noqa: E402
from bayesfo.data import FrequencyResponse  # noqa: E402
from bayesfo.errors import DataWarning, InputError, PredictiveWarning  # noqa: E402
from bayesfo.plotting import (  # noqa: E402
    plot_bode,
    plot_corner,
    plot_moduli,
    plot_nyquist,
    plot_q_posteriors,
    plot_ranking,
    plot_residuals,
    plot_trace,
    write_figures,
)
from bayesfo.plotting.style import FLAG_COLOR  # noqa: E402
from bayesfo.structures import get_structure  # noqa: E402

W = np.logspace(-1, 3, 24)
HOLDOUT = [W[5], W[15]]
ALL = 10**6  # more than the stored draws: the bands use every draw


@pytest.fixture(scope="module")
def comparison():
    """Noisy fractional-Zener compliance (5 % noise, σ known), two frequencies held out."""
    rng = np.random.default_rng(0)
    g = get_structure("zener").response([1.0, 1e-3, 2e-4, 0.6], W, "compliance")
    sd = 0.05 * np.abs(g)
    noisy = g + sd / np.sqrt(2) * (rng.normal(size=W.size) + 1j * rng.normal(size=W.size))
    data = FrequencyResponse(W, noisy, sd, kind="compliance", units="1/Pa", name="zener sim")
    structures = [get_structure(n) for n in ("voigt", "zener", "zener-int")]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = compare(data, structures, seed=0, progress=False, holdout=HOLDOUT)
    # The misspecified structures may get unreliable PSIS-LOO, and the 5 % noise turns the
    # loss of one point positive (a data warning); nothing else may warn.
    assert all(w.category in (PredictiveWarning, DataWarning) for w in caught), \
        [str(w.message) for w in caught]
    return result


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _draws(result):
    return result.posterior.samples[:, : result.structure.n_params]


def test_bode_median_and_bands_equal_the_quantiles_of_the_draws(comparison):
    drawn = plot_bode(comparison, n_draws=ALL)
    omega = drawn.values["omega"]
    w_all = np.r_[comparison.data.omega, comparison.holdout.omega]
    assert omega[0] == pytest.approx(w_all.min()) and omega[-1] == pytest.approx(w_all.max())
    assert np.allclose(np.diff(np.log(omega)), np.log(omega[1] / omega[0]))
    assert [k.split("/")[0] for k in drawn.artists if k.endswith("/magnitude_median")] == \
        comparison.ranking[:3]
    for name in comparison.ranking:
        r = comparison[name]
        g = r.structure.response(_draws(r), omega, "compliance")
        line = drawn.artists[f"{name}/magnitude_median"]
        np.testing.assert_allclose(line.get_xdata(), omega)
        np.testing.assert_allclose(line.get_ydata(), np.median(np.abs(g), axis=0), rtol=1e-12)
        np.testing.assert_allclose(drawn.values[f"{name}/magnitude_q05"],
                                   np.quantile(np.abs(g), 0.05, axis=0), rtol=1e-12)
        np.testing.assert_allclose(drawn.values[f"{name}/magnitude_q75"],
                                   np.quantile(np.abs(g), 0.75, axis=0), rtol=1e-12)
        # A compliance has its phase in (−90°, 0°]: no unwrapping needed to compare.
        phase = np.degrees(np.angle(g))
        np.testing.assert_allclose(drawn.artists[f"{name}/phase_median"].get_ydata(),
                                   np.median(phase, axis=0), atol=1e-9)
        # The 90 % band drawn is the one between the 5 % and 95 % quantiles.
        band = drawn.artists[f"{name}/magnitude_band90"].get_paths()[0].vertices
        assert band[:, 1].min() == pytest.approx(np.quantile(np.abs(g), 0.05, axis=0).min())
        assert band[:, 1].max() == pytest.approx(np.quantile(np.abs(g), 0.95, axis=0).max())


def test_bode_default_thinning_stays_close_to_all_draws(comparison):
    full = plot_bode(comparison, n_draws=ALL)
    thin = plot_bode(comparison)
    for name in comparison.ranking:
        width = full.values[f"{name}/magnitude_q95"] - full.values[f"{name}/magnitude_q05"]
        diff = np.abs(thin.values[f"{name}/magnitude_median"]
                      - full.values[f"{name}/magnitude_median"])
        assert np.all(diff <= 0.25 * width)
    # Same seed, same figure; another seed, other draws.
    again = plot_bode(comparison)
    other = plot_bode(comparison, seed=5)
    name = comparison.ranking[0]
    key = f"{name}/magnitude_q95"
    np.testing.assert_array_equal(thin.values[key], again.values[key])
    assert not np.array_equal(thin.values[key], other.values[key])


def test_bode_draws_the_data_and_the_held_out_points(comparison):
    drawn = plot_bode(comparison, structures=["zener"])
    data = comparison.data
    order = np.argsort(data.omega)
    line = drawn.artists["data/magnitude"].lines[0]
    np.testing.assert_allclose(line.get_xdata(), data.omega[order])
    np.testing.assert_allclose(line.get_ydata(), np.abs(data.response[order]))
    # One-sd error bars: σ/√2 in |G| (segments from y − e to y + e).
    segs = drawn.artists["data/magnitude"].lines[2][0].get_segments()
    half = np.array([(s[1, 1] - s[0, 1]) / 2 for s in segs])
    np.testing.assert_allclose(half, data.sigma[order] / np.sqrt(2), rtol=1e-12)
    held = comparison.holdout
    np.testing.assert_allclose(drawn.values["holdout/omega"], np.sort(held.omega))
    np.testing.assert_allclose(drawn.values["holdout/magnitude"],
                               np.abs(held.response[np.argsort(held.omega)]))
    labels = [t.get_text() for t in drawn.figure.legends[0].get_texts()]
    assert labels == ["zener", "data ± 1 sd", "held out"]
    mag_ax, phase_ax = drawn.axes
    assert mag_ax.get_xscale() == "log" and mag_ax.get_yscale() == "log"
    assert mag_ax.get_ylabel().endswith("[1/Pa]") and "rad/s" in phase_ax.get_xlabel()
    assert "deg" in phase_ax.get_ylabel()


def test_moduli_equal_the_storage_and_loss_parts_of_the_draws(comparison):
    """A compliance J* = J′ − iJ″: the panels are Re J, −Im J and their ratio, for the data and
    for the quantiles of the posterior responses."""
    drawn = plot_moduli(comparison, n_draws=ALL)
    omega = drawn.values["omega"]
    for name in comparison.ranking:
        r = comparison[name]
        g = r.structure.response(_draws(r), omega, "compliance")
        for quantity, x in (("storage", g.real), ("loss", -g.imag),
                            ("tan_delta", -g.imag / g.real)):
            np.testing.assert_allclose(drawn.values[f"{name}/{quantity}_median"],
                                       np.median(x, axis=0), rtol=1e-12)
            np.testing.assert_allclose(drawn.values[f"{name}/{quantity}_q95"],
                                       np.quantile(x, 0.95, axis=0), rtol=1e-12)
        assert np.all(drawn.values[f"{name}/loss_median"] > 0)
    data = comparison.data
    order = np.argsort(data.omega)
    j = data.response[order]
    np.testing.assert_allclose(drawn.values["data/storage"], j.real)
    np.testing.assert_allclose(drawn.values["data/loss"], -j.imag)
    # The fixture's noise makes J″ of a point negative: it is not drawn on the log axis, in the
    # loss and the tan δ panel, and the legend says so.
    negative = int(np.count_nonzero(-j.imag <= 0))
    assert negative >= 1
    assert drawn.values["left_out"] == 2 * negative
    line = drawn.artists["data/loss"].lines[0]
    np.testing.assert_allclose(line.get_ydata(), (-j.imag)[-j.imag > 0])
    assert f"{2 * negative} data values not positive" in drawn.artists["note"].get_text()
    # Error bars of one sd of each part, σ/√2 (the upper half: the lower one is cut above 0).
    segs = drawn.artists["data/storage"].lines[2][0].get_segments()
    upper = np.array([s[1, 1] for s in segs]) - j.real
    np.testing.assert_allclose(upper, data.sigma[order] / np.sqrt(2), rtol=1e-12)
    storage_ax, loss_ax, tan_ax = drawn.axes
    assert storage_ax.get_ylabel() == "J′ [1/Pa]" and loss_ax.get_ylabel() == "J″ [1/Pa]"
    assert "delta" in tan_ax.get_ylabel()
    assert all(ax.get_yscale() == "log" for ax in drawn.axes)
    drawn.figure.canvas.draw()
    box = drawn.figure.legends[0].get_window_extent()
    assert 0 <= box.x0 and box.x1 <= drawn.figure.bbox.width


def test_time_functions_are_the_inverse_transforms_of_the_draws(comparison):
    """G(t) and J(t) bands equal the quantiles of bayesfo.predictions.evaluate over the draws;
    the window the data inform is 1/ω_max … 1/ω_min, the grid a decade beyond each end."""
    from bayesfo.plotting.material import plot_time_functions
    from bayesfo.predictions import evaluate

    drawn = plot_time_functions(comparison, n_draws=ALL)
    t = drawn.values["time"]
    w = comparison.data.omega
    np.testing.assert_allclose(drawn.values["window"], [1 / w.max(), 1 / w.min()])
    assert t[0] == pytest.approx(0.1 / w.max()) and t[-1] == pytest.approx(10 / w.min())
    for name in comparison.ranking:
        r = comparison[name]
        for q in ("relaxation_modulus", "creep_compliance"):
            v = evaluate(r.structure, _draws(r), q, t)
            np.testing.assert_allclose(drawn.values[f"{name}/{q}_median"],
                                       np.median(v, axis=0), rtol=1e-9)
            np.testing.assert_allclose(drawn.values[f"{name}/{q}_q05"],
                                       np.quantile(v, 0.05, axis=0), rtol=1e-9)
        # A solid relaxes and creeps monotonically: G falls, J rises along t (to its plateau,
        # where the inversion's rounding, 1e-13 relative, is all that changes).
        g = drawn.values[f"{name}/relaxation_modulus_median"]
        j = drawn.values[f"{name}/creep_compliance_median"]
        assert np.all(np.diff(g) < 1e-9 * g[1:]) and np.all(np.diff(j) > -1e-9 * j[1:])
        assert g[0] > 1.5 * g[-1] and j[-1] > 1.5 * j[0]
    g_ax, j_ax = drawn.axes
    assert g_ax.get_ylabel() == "G(t) [Pa]" and j_ax.get_ylabel() == "J(t) [1/Pa]"


def test_moduli_refuse_a_transfer_function(comparison):
    from bayesfo.plotting.moduli import storage_loss

    generic = replace(comparison, data=FrequencyResponse(W, np.ones(W.size) + 1j, kind="generic"))
    with pytest.raises(InputError, match="modulus or compliance data.*Bode"):
        plot_moduli(generic)
    assert plt.get_fignums() == []
    g = np.array([2.0 + 1.0j])
    assert storage_loss(g, "modulus") == (2.0, 1.0)
    assert storage_loss(g, "compliance") == (2.0, -1.0)


def test_structures_argument_is_checked(comparison):
    with pytest.raises(InputError, match="'structures'.*'maxwell'.*voigt"):
        plot_bode(comparison, structures=["maxwell"])
    with pytest.raises(InputError, match="n_draws"):
        plot_nyquist(comparison, n_draws=0)


def test_nyquist_median_curve_and_data(comparison):
    drawn = plot_nyquist(comparison, structures=["zener", "voigt"], n_draws=ALL, n_lines=10)
    omega = drawn.values["omega"]
    for name in ("zener", "voigt"):
        r = comparison[name]
        g = r.structure.response(_draws(r), omega, "compliance")
        line = drawn.artists[f"{name}/median"]
        np.testing.assert_allclose(line.get_xdata(), np.median(g.real, axis=0), rtol=1e-12)
        np.testing.assert_allclose(line.get_ydata(), np.median(g.imag, axis=0), rtol=1e-12)
        assert len(drawn.artists[f"{name}/draws"].get_segments()) == 10
    pts = drawn.artists["data"].lines[0]
    order = np.argsort(comparison.data.omega)
    np.testing.assert_allclose(pts.get_xdata(), comparison.data.response.real[order])
    np.testing.assert_allclose(pts.get_ydata(), comparison.data.response.imag[order])
    assert drawn.axes[0].get_aspect() == 1.0


def test_residuals_are_normalised_by_the_noise(comparison):
    drawn = plot_residuals(comparison, n_draws=ALL)
    data = comparison.data
    order = np.argsort(data.omega)
    w, g, s = data.omega[order], data.response[order], data.sigma[order] / np.sqrt(2)
    for name in comparison.ranking:
        r = comparison[name]
        pred = r.structure.response(_draws(r), w, "compliance")
        median = np.median(pred.real, axis=0) + 1j * np.median(pred.imag, axis=0)
        np.testing.assert_allclose(drawn.artists[f"{name}/real"].get_ydata(),
                                   (g - median).real / s, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(drawn.artists[f"{name}/imag"].get_ydata(),
                                   (g - median).imag / s, rtol=1e-9, atol=1e-12)
    # The structure that made the data leaves standard-normal residuals; the misspecified
    # ones do not.
    z = np.r_[drawn.values["zener/real"], drawn.values["zener/imag"]]
    assert 0.4 < np.mean(z**2) < 2.0
    v = np.r_[drawn.values["voigt/real"], drawn.values["voigt/imag"]]
    assert np.mean(v**2) > 4.0
    assert drawn.values["zener/holdout_real"].shape == (2,)


def test_residuals_relative_without_sigma_and_on_one_axes(comparison):
    data = replace(comparison.data, sigma=None)
    no_sigma = replace(comparison, data=data, holdout=None)
    fig, ax = plt.subplots()
    drawn = plot_residuals(no_sigma, structures=["zener"], ax=ax, n_draws=ALL)
    assert drawn.axes[0] is drawn.axes[1] is ax
    pred = drawn.values["zener/prediction"]
    g = data.response[np.argsort(data.omega)]
    np.testing.assert_allclose(drawn.values["zener/real"], 100 * (g - pred).real / np.abs(g))
    assert "%" in ax.get_ylabel()


def test_q_densities_integrate_to_one_in_ranking_order(comparison):
    drawn = plot_q_posteriors(comparison)
    names = list(drawn.values["structures"])
    # zener-int has no free order; the others keep the order of the ranking.
    assert names == [n for n in comparison.ranking if n != "zener-int"]
    for name in names:
        grid = drawn.values[f"{name}/grid"]
        dens = drawn.values[f"{name}/density"]
        assert grid[0] == 0.0 and grid[-1] == 1.0  # the prior range of q
        assert trapezoid(dens, grid) == pytest.approx(1.0, abs=0.01)
        np.testing.assert_allclose(drawn.values[f"{name}/prior_density"], 1.0)
        q = comparison[name].posterior.summary["q"]
        assert abs(grid[np.argmax(dens)] - q.median) < 2 * q.sd
        hdi = drawn.artists[f"{name}/hdi"].get_xdata()
        np.testing.assert_allclose(hdi, [q.hdi_low, q.hdi_high])
    baselines = [float(drawn.values[f"{n}/baseline"]) for n in names]
    assert baselines == sorted(baselines, reverse=True)  # best on top


def test_q_posteriors_show_a_poorly_determined_order(comparison):
    # Draws of q spread over the prior, as for a high-order structure: the ridge is no higher
    # than the prior line, and the label is flagged.
    r = comparison["voigt"]
    post = r.posterior
    samples = post.samples.copy()
    samples[:, post.param_names.index("q")] = np.random.default_rng(1).uniform(0, 1, len(samples))
    q = replace(post.summary["q"], poorly_determined=True)
    wide = StructureResult(r.structure, r.fit, replace(post, samples=samples,
                                                       summary={**post.summary, "q": q}),
                           r.criteria)
    results = tuple(wide if x.name == "voigt" else x for x in comparison.results)
    drawn = plot_q_posteriors(replace(comparison, results=results), ridge_height=0.8)
    dens = drawn.values["voigt/density"]
    prior_line = drawn.artists["voigt/prior"].get_ydata() - drawn.values["voigt/baseline"]
    assert np.median(prior_line) > 0.8 * 0.8  # the prior reaches most of the ridge's height
    assert dens.max() < 1.3  # against 1 for the prior
    label = drawn.artists["voigt/label"]
    assert "poorly determined" in label.get_text()
    assert to_rgba(label.get_color()) == to_rgba(FLAG_COLOR)
    sharp = drawn.artists["zener/prior"].get_ydata() - drawn.values["zener/baseline"]
    assert np.max(sharp) < 0.1  # a well-determined order towers over its prior


def test_q_posteriors_need_a_free_order(comparison):
    only_int = replace(comparison, results=(comparison["zener-int"],))
    with pytest.raises(InputError, match="fractional order"):
        plot_q_posteriors(only_int)


def test_ranking_bars_equal_the_table(comparison):
    drawn = plot_ranking(comparison)
    table = comparison.table()
    assert list(drawn.values["structures"]) == [row["structure"] for row in table]
    for row, y in zip(table, drawn.values["y"]):
        cont = drawn.artists[f"{row['structure']}/log_evidence"]
        assert cont.lines[0].get_xdata()[0] == pytest.approx(row["delta_log_evidence"], abs=1e-12)
        assert cont.lines[0].get_ydata()[0] == y
    np.testing.assert_allclose(drawn.values["log_evidence_err"],
                               [row["log_evidence_err"] for row in table])
    best_bic = min(row["bic"] for row in table)
    np.testing.assert_allclose(drawn.values["delta_bic_half"],
                               [-(row["bic"] - best_bic) / 2 for row in table])
    loo = drawn.artists["delta_loo"].lines[0]
    np.testing.assert_allclose(loo.get_xdata(), [row["delta_loo"] for row in table])
    right = drawn.axes[0].figure.axes[-1]
    p_labels = [t.get_text() for t in right.get_yticklabels()]
    assert p_labels[0] == f"P = {table[0]['posterior_probability']:.3f}"


def test_ranking_loo_error_is_that_of_the_difference(comparison):
    drawn = plot_ranking(comparison)
    idata = {n: comparison[n].posterior.idata for n in comparison.ranking}
    with warnings.catch_warnings():
        # arviz repeats the Pareto-k warnings that compare() already turned into flags.
        warnings.simplefilter("ignore")
        ref = arviz_compare(idata)
    rows = {row["structure"]: row for row in comparison.table()}
    for name, se in zip(drawn.values["structures"], drawn.values["delta_loo_se"]):
        assert se == pytest.approx(float(ref.loc[name, "dse"]), rel=1e-6, abs=1e-9)
        # Computed once, with the criteria: the table and summary.json hold the same number.
        assert rows[name]["delta_loo_se"] == se == comparison[name].criteria.delta_loo_se


def test_ranking_flags_a_posterior_that_did_not_converge(comparison):
    bad = comparison["zener"]
    flagged = StructureResult(bad.structure, bad.fit, replace(bad.posterior, converged=False),
                              bad.criteria)
    results = tuple(flagged if r.name == "zener" else r for r in comparison.results)
    drawn = plot_ranking(replace(comparison, results=results))
    # Labels: the name, then what to know (not converged; a misfit, from the adequacy checks).
    ticks = {t.get_text().split("\n")[0]: t for t in drawn.axes[0].get_yticklabels()}
    assert ticks["zener"].get_text().startswith("zener\nnot converged")
    assert to_rgba(ticks["zener"].get_color()) == to_rgba(FLAG_COLOR)
    assert "not converged" not in ticks["voigt"].get_text()
    assert to_rgba(ticks["voigt"].get_color()) != to_rgba(FLAG_COLOR)


def test_corner_marks_the_mode_and_the_optimum(comparison):
    r = comparison["zener"]
    drawn = plot_corner(r)
    names = r.posterior.param_names
    ndim = len(names)
    assert len(drawn.axes) == ndim * ndim
    log = np.array([r.criteria.priors[n]["prior"] == "log-uniform" for n in names])
    coords = np.where(log, np.log10(r.posterior.samples), r.posterior.samples)
    np.testing.assert_allclose(drawn.values["samples"] * drawn.values["factor"], coords)
    expected_map = np.where(log, np.log10(r.posterior.map_theta), r.posterior.map_theta)
    np.testing.assert_allclose(drawn.values["map"] * drawn.values["factor"], expected_map)
    expected_fit = np.where(log, np.log10(r.fit.theta), r.fit.theta)
    np.testing.assert_allclose(drawn.values["fit"] * drawn.values["factor"], expected_fit)
    for i in range(ndim):
        diag = drawn.axes[i * ndim + i]
        xs = {round(float(line.get_xdata()[0]), 12) for line in diag.lines}
        assert round(float(drawn.values["map"][i]), 12) in xs
        counts, _ = np.histogram(drawn.values["samples"][:, i], bins=30,
                                 range=tuple(drawn.values["range"][i]))
        heights = np.concatenate([p.get_xy()[:, 1] for p in diag.patches])
        assert heights.max() == counts.max()
    labels = [t.get_text() for t in drawn.artists["legend"].get_texts()]
    assert labels == ["posterior mode (MAP draw)", "least-squares optimum"]
    assert drawn.axes[ndim * (ndim - 1)].get_xlabel().startswith("log$_{10}$")
    with pytest.raises(InputError, match="'fig'.*layout"):
        plot_corner(r, fig=plt.figure(layout="constrained"))
    plt.close(drawn.figure)


def test_corner_marks_the_linear_methods(comparison):
    from bayesfo.identify.optimize import linear_fits

    r = comparison["zener"]
    fits = linear_fits(r.structure, comparison.data)
    assert sorted(fits) == [f"method {k}" for k in range(1, 6)]
    # compare() keeps them with the optimum, so figures need not fit again.
    assert sorted(r.fit.linear) == sorted(fits)
    for label, theta in fits.items():
        np.testing.assert_array_equal(r.fit.linear[label], theta)
    # Method 2 at a fixed q is an independent linear least-squares problem: check one entry.
    assert 0.0 < fits["method 2"][-1] <= 1.0
    drawn = plot_corner(r, linear=fits)
    names = r.posterior.param_names
    log = np.array([r.criteria.priors[n]["prior"] == "log-uniform" for n in names])
    k = r.structure.n_params
    for row, label in zip(drawn.values["linear"], drawn.values["linear_labels"]):
        theta = fits[label]
        with np.errstate(invalid="ignore"):
            expected = np.where(log[:k], np.log10(theta), theta)
        np.testing.assert_allclose(row[:k] * drawn.values["factor"][:k], expected)
        assert np.all(np.isnan(row[k:]))  # noise parameters have no linear fit
    # The crosses are drawn in the lower-left panel of the first two parameters.
    ndim = len(names)
    panel = drawn.axes[1 * ndim + 0]
    xy = np.concatenate([np.column_stack(line.get_data()) for line in panel.lines
                         if line.get_marker() == "x"])
    np.testing.assert_allclose(xy, drawn.values["linear"][:, [0, 1]])
    labels = [t.get_text() for t in drawn.artists["legend"].get_texts()]
    assert labels[-1] == "linear methods (5, best q each)"
    plt.close(drawn.figure)


@pytest.fixture(scope="module")
def walkers(comparison):
    """The Voigt of ``comparison`` by emcee (the default route takes importance sampling)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PredictiveWarning)
        warnings.simplefilter("ignore", DataWarning)  # as in the fixture
        return compare(comparison.data, [get_structure("voigt")], seed=0, progress=False,
                       sampler="emcee")["voigt"]


def test_trace_shows_every_walker(walkers):
    # The walkers of emcee (draws resampled from importance weights are drawn as one
    # histogram per parameter instead).
    r = walkers
    assert r.posterior.sampler == "emcee"
    drawn = plot_trace(r)
    post = r.posterior
    n_kept = post.samples.shape[0] // post.n_walkers
    for j, name in enumerate(post.param_names):
        walkers = post.samples[:, j].reshape(post.n_walkers, n_kept)  # walker-major draws
        np.testing.assert_allclose(drawn.values[name], walkers)
        lines = drawn.artists[name]
        assert len(lines) == post.n_walkers
        shown = np.log10(walkers[3]) if name in ("a1", "b0") else walkers[3]
        label = drawn.axes[j].get_ylabel()
        factor = 1.0 if "×" not in label else 10.0 ** int(label.split("{")[-1].split("}")[0])
        np.testing.assert_allclose(lines[3].get_ydata() * factor, shown, rtol=1e-12)
    assert len(drawn.axes) == len(post.param_names) + 1  # and the log posterior


def _png_size(path):
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


def test_write_figures_skips_failed_structures_and_closes_figures(comparison, tmp_path):
    failed = StructureResult(get_structure("maxwell"), error="could not be run (test)")
    with_failure = replace(comparison, results=comparison.results + (failed,))
    before = plt.get_fignums()
    written = write_figures(with_failure, tmp_path, formats=("png",), structure_figures=None)
    assert plt.get_fignums() == before
    expected = ["ranking", "bode", "moduli", "time_functions", "nyquist", "residuals",
                "q_posteriors"]
    for name in comparison.ranking:
        expected += [f"corner_{name}"]
        if comparison[name].posterior.sampler != "importance":  # walkers or ladder runs
            expected += [f"trace_{name}"]
    assert list(written) == expected
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(f"{n}.png" for n in expected)
    width, height = _png_size(written["bode"][0])
    assert width == 700  # 3.5 in at 200 dpi: one journal column
    assert width < height


def test_trace_figures_where_walkers_or_runs_have_something_to_show(comparison, walkers,
                                                                   tmp_path):
    # emcee's walkers get a trace figure; draws resampled from importance weights do not (their
    # histograms are the corner plot's diagonal).
    zener = comparison["zener"]
    assert zener.posterior.sampler == "importance"
    mixed = replace(comparison, results=(walkers, zener))
    written = write_figures(mixed, tmp_path, structure_figures=None)
    assert {n for n in written if n.startswith(("corner_", "trace_"))} == {
        "corner_voigt", "trace_voigt", "corner_zener"}
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("trace")) == [
        "trace_voigt.png"]


def test_write_figures_single_structure_and_formats(comparison, tmp_path):
    single = replace(comparison, results=(comparison["zener-int"],))
    written = write_figures(single, tmp_path, formats=("png", "svg"))
    # No free order: no q figure.
    traced = ["trace_zener-int"] if single.results[0].posterior.sampler != "importance" else []
    assert list(written) == ["ranking", "bode", "moduli", "time_functions", "nyquist", "residuals",
                             "corner_zener-int", *traced]
    assert all([p.suffix for p in paths] == [".png", ".svg"] for paths in written.values())
    with pytest.raises(InputError, match="'formats'.*'xyz'"):
        write_figures(single, tmp_path, formats=("png", "xyz"))


def test_write_figures_in_worker_processes_gives_the_same_files(comparison, tmp_path):
    from bayesfo.parallel import process_pool

    serial = write_figures(comparison, tmp_path / "serial", formats=("png",))
    steps = []

    def fails():
        raise OSError(28, "No space left on device")

    with process_pool(2) as pool:
        pooled = write_figures(comparison, tmp_path / "pooled", formats=("png",), pool=pool,
                               meanwhile=lambda: steps.append("meanwhile"))
        # Where the work done meanwhile fails, its error is raised once the workers have
        # ended the figures they were drawing: nothing is written into the directory after.
        with pytest.raises(OSError, match="No space left"):
            write_figures(comparison, tmp_path / "failed", formats=("png",), pool=pool,
                          meanwhile=fails)
        left = sorted(p.name for p in (tmp_path / "failed").rglob("*"))
        assert not [n for n in left if n.startswith(".")], left  # no save half-done
        assert all(f.endswith(".png") for f in left)
    assert steps == ["meanwhile"]
    assert list(pooled) == list(serial)
    for name, paths in serial.items():
        # Agg renders the same pixels in any process: the figures are the same figures.
        assert pooled[name][0].read_bytes() == paths[0].read_bytes(), name
    assert left == sorted(p.name for p in (tmp_path / "failed").rglob("*"))


def _mark_child(monkeypatch, marker, fail: bool = False):
    """Make the forked figure process leave ``marker`` (and, with ``fail``, fail at its first
    figure): the wrapper runs in the child, which the test cannot see otherwise."""
    import bayesfo.plotting.output as output

    draw_in_child = output._draw_in_child

    def child(*args):
        marker.write_text("ran")
        if fail:
            def broken(*a, **k):
                raise RuntimeError("the forked process fails")

            output._save_all = broken  # in the child only
        draw_in_child(*args)

    monkeypatch.setattr(output, "_draw_in_child", child)


@pytest.mark.parametrize("child_fails", [False, True])
def test_write_figures_in_two_processes_gives_the_files_of_one(comparison, tmp_path,
                                                               monkeypatch, child_fails):
    """Two processes (this one and one forked from it) write the files that one writes; if the
    forked one fails, this one draws what it had taken."""
    from bayesfo.plotting.output import can_fork

    if not can_fork():
        pytest.skip("another thread runs in this process: no fork")
    marker = tmp_path / "child-ran"
    _mark_child(monkeypatch, marker, fail=child_fails)
    serial = write_figures(comparison, tmp_path / "serial", formats=("png",))
    steps = []
    two = write_figures(comparison, tmp_path / "two", formats=("png",), processes=2,
                        meanwhile=lambda: steps.append("meanwhile"))
    assert marker.read_text() == "ran" and steps == ["meanwhile"]
    assert list(two) == list(serial)
    for name, paths in serial.items():
        assert two[name] == [tmp_path / "two" / f"{name}.png"]
        assert two[name][0].read_bytes() == paths[0].read_bytes(), name
    assert sorted(p.name for p in (tmp_path / "two").iterdir()) == \
        sorted(p.name for p in (tmp_path / "serial").iterdir())
    with pytest.raises(InputError, match="'processes' must be 1 or 2"):
        write_figures(comparison, tmp_path / "three", formats=("png",), processes=3)


def test_figures_are_handed_out_costliest_first(comparison):
    from bayesfo.plotting.output import _draw_order, figure_jobs

    names = [n for n, _ in figure_jobs(comparison)]
    order = _draw_order(comparison, names)
    assert sorted(order) == sorted(names)
    corners = [n for n in order if n.startswith("corner_")]
    assert order[: len(corners)] == corners
    sizes = [comparison[n[len("corner_"):]].structure.n_params for n in corners]
    assert sizes == sorted(sizes, reverse=True)
    assert order.index("q_posteriors") < order.index("bode") < order.index("nyquist")
    assert all(order.index(n) > order.index("residuals") for n in order if n.startswith("trace_"))


@pytest.mark.parametrize("draws", ["narrow", "at the bound", "spread"])
def test_density_1d_equals_the_reflected_kernel_sum_everywhere(draws):
    """Points far from every draw are taken as 0 instead of summing kernels there: the density
    is the full reflected kernel sum to 1e-12 of its peak."""
    from scipy import stats

    from bayesfo.plotting._compute import density_1d

    rng = np.random.default_rng(3)
    x = {"narrow": 0.568 + 0.002 * rng.standard_normal(2000),
         "at the bound": 0.01 * rng.standard_exponential(2000),
         "spread": rng.beta(0.5, 0.5, 1500)}[draws]
    grid, dens = density_1d(x, 0.0, 1.0)
    kde = stats.gaussian_kde(x)
    full = kde(grid) + kde(-grid) + kde(2.0 - grid)
    assert np.max(np.abs(dens - full)) <= 1e-12 * full.max()
    assert trapezoid(dens, grid) == pytest.approx(1.0, abs=2e-3)


@pytest.mark.parametrize("names, columns", [
    (["voigt", "zener", "maxwell"], 3),
    (["maxwell (misfits)", "fractional_zener_sl (misfits)", "fractional_maxwell_gel (misfits)",
      "fractional_maxwell_liquid (misfits)", "fractional_kelvin_voigt (misfits)"], None),
    # The demo's: three columns would hold 2, 1, 1 entries, the first two of them long.
    (["fractional_kelvin_voigt (small misfit)", "zener (misfits)", "voigt (misfits)"], None),
])
def test_the_response_legend_stays_inside_the_figure(names, columns):
    """Long structure names take fewer legend columns instead of running past the figure's
    edges (three columns of them were cut at both sides); short ones keep three."""
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    from bayesfo.plotting._base import new_figure
    from bayesfo.plotting._legend import _legend
    from bayesfo.plotting.style import COLUMN_WIDTH, style

    with style():
        fig = new_figure(None, (COLUMN_WIDTH, 4.0))
        fig.subplots(2, 1, sharex=True)
        labels = [*names, "data"]
        legend = _legend(fig, [Line2D([], []) for _ in labels], labels)
        fig.canvas.draw()
        box = legend.get_window_extent()
        assert 0 <= box.x0 and box.x1 <= fig.bbox.width, (box, fig.bbox)
        if columns is not None:
            assert legend._ncols == columns
        else:
            assert legend._ncols < 3
        plt.close(fig)


def _die_holding(lock):
    lock.acquire()
    os._exit(0)  # killed inside the shared table's section: the lock is never released


def test_a_forked_figure_process_that_dies_holding_the_lock_does_not_block_the_parent():
    import multiprocessing
    import threading

    from bayesfo.plotting import output

    ctx = multiprocessing.get_context("fork" if output.can_fork() else "spawn")
    lock = ctx.Lock()
    state = ctx.RawArray("b", 3)
    state[0] = output._TAKEN
    child = ctx.Process(target=_die_holding, args=(lock,))
    child.start()
    child.join()
    got = []
    taker = threading.Thread(target=lambda: got.append(output._take(state, lock, output._HERE,
                                                                     child)), daemon=True)
    taker.start()
    taker.join(30)
    assert not taker.is_alive(), "the parent waits forever on the dead child's lock"
    assert got == [1] and list(state) == [output._TAKEN, output._HERE, output._FREE]


def test_only_the_leading_structures_get_corner_and_trace_figures(comparison, tmp_path):
    written = write_figures(comparison, tmp_path / "one", structure_figures=1)
    best = comparison.ranking[0]
    traced = [f"trace_{best}"] if comparison[best].posterior.sampler != "importance" else []
    assert [n for n in written if n.startswith(("corner_", "trace_"))] == [
        f"corner_{best}", *traced]
    assert all(p.suffix == ".png" for paths in written.values() for p in paths)  # the default
    every = write_figures(comparison, tmp_path / "all", structure_figures=None)
    assert {n for n in every if n.startswith("corner_")} == {
        f"corner_{n}" for n in comparison.ranking}
    # By default, the leading structures, from the ranking table's columns: of the best three,
    # those within 5 of the best ln Z, and each that a criterion ranks first.
    rows = [r for r in comparison.table() if r["rank"] is not None]
    expected = [r["structure"] for r in rows
                if (r["rank"] <= 3 and r["delta_log_evidence"] > -5)
                or 1 in (r["rank_loo"], r["rank_waic"], r["rank_aic"], r["rank_bic"])]
    default = write_figures(comparison, tmp_path / "default")
    assert [n for n in default if n.startswith("corner_")] == [f"corner_{n}" for n in expected]
    with pytest.raises(InputError, match="'structure_figures' must be 'leading', a non-negative"):
        write_figures(comparison, tmp_path / "bad", structure_figures=-1)
    assert not (tmp_path / "bad").exists() or not list((tmp_path / "bad").iterdir())


def test_corner_and_trace_of_modulus_data_draw_the_physical_parameters():
    """On modulus data the figures name the parameters as the report's tables do (the
    physical G_e, c_q, q of the fractional Voigt, not the card's a1, b0), with their units, the
    positive ones on log10 axes; the drawn numbers are those of physical_parameters."""
    from pathlib import Path

    from bayesfo.data import read
    from bayesfo.structures.physical import physical_parameters

    data = read(Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp"
                / "Tp020C.csv")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PredictiveWarning)
        r = compare(data, "voigt", noise="proportional", seed=0, progress=False)["voigt"]
    post, s = r.posterior, r.structure
    phys = physical_parameters(s, post.samples[:, :s.n_params], "modulus", "Pa", derived=False)
    assert list(phys) == ["G_e", "c_q", "q"]
    expected = np.column_stack([np.log10(phys["G_e"][0]), np.log10(phys["c_q"][0]),
                                phys["q"][0], np.log10(post.samples[:, -1])])
    drawn = plot_corner(r)
    np.testing.assert_allclose(drawn.values["samples"] * drawn.values["factor"], expected,
                               rtol=1e-12)
    bottom = [drawn.axes[12 + j].get_xlabel() for j in range(4)]
    assert bottom[0].startswith("log$_{10}$ $G_{e}$ [Pa]") and "[Pa s$^{q}$]" in bottom[1]
    assert bottom[2].startswith("$q$")
    # The least-squares optimum is marked in the same parameters.
    fit = physical_parameters(s, r.fit.theta, "modulus", "Pa", derived=False)
    np.testing.assert_allclose(drawn.values["fit"][:2] * drawn.values["factor"][:2],
                               np.log10([fit["G_e"][0], fit["c_q"][0]]), rtol=1e-12)
    trace = plot_trace(r)
    assert [k for k in trace.values if k not in ("draw", "lp", "converged")] == [
        "G_e", "c_q", "q", "sigma_rel"]
    np.testing.assert_allclose(np.ravel(trace.values["G_e"]), phys["G_e"][0], rtol=1e-12)
    plt.close("all")


def test_a_narrow_log_axis_gets_three_plain_labels():
    """A logarithmic axis of less than a decade is labelled with plain numbers, at the sparsest
    multiples of each power of ten that put three ticks in view (0.71 to 1.19: 0.8, 0.9, 1,
    where 1, 2, 3, 5, 7 gave 1 alone); a log axis within 0.01-1e4 elsewhere gets plain labels
    too (40, 60, 100), one reaching beyond keeps powers of ten."""
    import matplotlib.pyplot as plt

    from bayesfo.plotting._base import plain_log_labels
    from bayesfo.plotting.moduli import _readable_log_ticks

    fig, (a, b, c) = plt.subplots(1, 3)
    try:
        for ax, (lo, hi) in ((a, (0.71, 1.19)), (b, (35.0, 250.0)), (c, (1e-3, 1e3))):
            ax.set_yscale("log")
            ax.set_ylim(lo, hi)
        _readable_log_ticks(a)
        plain_log_labels(fig)
        fig.canvas.draw()

        def shown(ax):
            lo, hi = ax.get_ylim()
            return [t.get_text() for t, v in zip(ax.get_yticklabels(), ax.get_yticks(),
                                                  strict=True) if lo <= v <= hi and t.get_text()]

        assert shown(a) == ["0.8", "0.9", "1"]
        assert shown(b) == ["100"] and "40" in [t.get_text() for t in b.get_yticklabels(
            minor=True)]
        assert all("10^" in t or "mathdefault" in t for t in shown(c))
    finally:
        plt.close(fig)
