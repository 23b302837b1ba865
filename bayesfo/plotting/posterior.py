"""Posterior figures: corner plot and walker traces of one structure, and the fractional order of
every structure side by side."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ._base import Drawn, axes_or_new, new_figure
from ._compute import (
    decade_exponent,
    density_1d,
    ok_results,
    order_parameter,
    prior_density,
    prior_range,
    sampling_coordinates,
    scaled_label,
    to_coordinates,
)
from .style import COLUMN_WIDTH, FLAG_COLOR, PAGE_WIDTH, colors_for, style

#: Probability mass inside the 2-D contours of the corner plot (the bands of the response plots).
CORNER_LEVELS = (0.5, 0.9)
MAP_COLOR = "black"
#: The prior of an order when the results do not state it (the cards' prior of q).
DEFAULT_ORDER_PRIOR = {"prior": "uniform", "low": 0.0, "high": 1.0}
FIT_COLOR = "0.5"


def _check_result(result, what: str = "result"):
    if getattr(result, "error", None) is not None:
        raise InputError(f"argument '{what}': structure '{result.name}' failed: {result.error}")
    if getattr(result, "posterior", None) is None:
        raise InputError(f"argument '{what}' has no posterior")


def plot_corner(result, fig=None, *, color: str | None = None, bins: int = 30,
                linear: dict | None = None) -> Drawn:
    """Corner plot (``corner.corner``) of one structure's posterior, with the posterior mode,
    the least-squares optimum and, when given, the linear methods' fits marked.

    Parameters are shown in the coordinates of the summaries' flags: log10 of parameters with
    a log-uniform prior (axis labels say so), the parameter itself otherwise, divided by a
    power of ten when its values are very small or large (the label gives the factor); noise
    parameters sampled with the structure are included. Contours enclose 50 % and 90 % of the
    draws.

    Parameters
    ----------
    result : bayesfo.comparison.StructureResult
    fig : matplotlib.figure.Figure, optional
        Empty figure without a layout engine (corner places the axes); default a new figure,
        one column wide up to two parameters, a page wide from five.
    color : str, optional
        Colour of the draws (default the first of the palette).
    bins : int
        Histogram bins per parameter.
    linear : dict, optional
        ``{label: theta}`` of deterministic fits in physical units (e.g.
        :func:`bayesfo.identify.optimize.linear_fits`: methods 1–5 at their best q), drawn as
        small crosses in the two-dimensional panels; fits outside the plotted range (or with a
        non-positive value of a log-uniform parameter) are not visible.

    Returns
    -------
    Drawn
        ``axes``: the ndim × ndim grid, row-major (``axes[i * ndim + j]``). ``values``:
        ``"samples"`` (n_draws, ndim) in the plotted coordinates, ``"map"`` (the draw of
        highest posterior density), ``"fit"`` (the least-squares optimum; NaN for noise
        parameters or when no admissible optimum was found), ``"range"`` (ndim, 2) and
        ``"factor"`` (the divisor of each column: plotted = coordinate / factor), and with
        ``linear`` ``"linear"`` (k, ndim) in the plotted coordinates (NaN for noise
        parameters) and ``"linear_labels"``. ``artists``: ``"legend"``.

    Raises
    ------
    InputError
        If the structure failed or has no posterior, or ``fig`` has a layout engine that
        does not allow placing axes (constrained layout).
    """
    import corner
    from matplotlib.lines import Line2D

    _check_result(result)
    post = result.posterior
    samples, labels, is_log = sampling_coordinates(result)
    ndim = samples.shape[1]
    exponents = np.array([decade_exponent(samples[:, i]) for i in range(ndim)])
    factor = 10.0 ** exponents
    samples = samples / factor
    labels = [scaled_label(lab, int(e)) for lab, e in zip(labels, exponents)]
    mode = to_coordinates(post.map_theta, is_log) / factor
    fit = np.full(ndim, np.nan)
    if result.fit is not None and result.fit.admissible:
        k = result.structure.n_params
        fit[:k] = to_coordinates(result.fit.theta, is_log[:k]) / factor[:k]
    lin_labels = list(linear or {})
    lin = np.full((len(lin_labels), ndim), np.nan)
    k = result.structure.n_params
    for row, label in zip(lin, lin_labels):
        with np.errstate(invalid="ignore", divide="ignore"):
            row[:k] = to_coordinates(np.asarray(linear[label], float), is_log[:k]) / factor[:k]
    ranges = []
    for i in range(ndim):
        lo, hi = np.quantile(samples[:, i], [0.0005, 0.9995])
        marks = [m for m in (mode[i], fit[i]) if np.isfinite(m)]
        lo, hi = min([lo, *marks]), max([hi, *marks])
        pad = 0.05 * (hi - lo) if hi > lo else max(1e-6, 1e-3 * abs(lo))
        ranges.append((lo - pad, hi + pad))
    color = color or "#0072B2"
    with style():
        side = min(PAGE_WIDTH, max(COLUMN_WIDTH, 1.45 * ndim))
        if fig is None:
            fig = new_figure(None, (side, side), layout="none")
        elif fig.get_layout_engine() is not None and not fig.get_layout_engine().adjust_compatible:
            raise InputError("argument 'fig': corner places its axes itself (subplots_adjust); "
                             "pass a figure without a layout engine, e.g. layout='none'")
        corner.corner(
            samples, bins=bins, range=ranges, labels=labels, fig=fig, color=color,
            levels=CORNER_LEVELS, smooth=0.8, plot_datapoints=False, fill_contours=True,
            max_n_ticks=3, labelpad=0.15, label_kwargs={"fontsize": 8},
            hist_kwargs={"lw": 0.9}, contour_kwargs={"linewidths": 0.6},
        )
        marks = [(mode, MAP_COLOR, "s", "--", "posterior mode (MAP draw)")]
        if np.any(np.isfinite(fit)):
            marks.append((fit, FIT_COLOR, "^", ":", "least-squares optimum"))
        handles = []
        for x, c, m, ls, label in marks:
            xs = [float(v) if np.isfinite(v) else None for v in x]
            corner.overplot_lines(fig, xs, color=c, lw=0.9, ls=ls)
            if ndim > 1:
                pts = np.where(np.isfinite(x), x, np.nan)[None, :]
                corner.overplot_points(fig, pts, marker=m, color=c, ms=4, mec="white", mew=0.4)
            handles.append(Line2D([], [], color=c, ls=ls, lw=0.9, marker=m, ms=4, label=label))
        if lin_labels and ndim > 1:
            corner.overplot_points(fig, lin, marker="x", color=FIT_COLOR, ms=3.5, mew=0.8)
            handles.append(Line2D([], [], color=FIT_COLOR, ls="", marker="x", ms=3.5, mew=0.8,
                                  label=f"linear methods ({len(lin_labels)}, best q each)"))
        # corner's margins scale with its 2-inch panels; ticks and labels need fixed room.
        w, h = fig.get_size_inches()
        fig.subplots_adjust(left=0.72 / w, bottom=0.72 / h, right=1 - 0.08 / w,
                            top=1 - 0.08 / h, wspace=0.06, hspace=0.06)
        for ax in fig.axes:
            ax.tick_params(labelsize=6.5)
        title = f"{result.name}: {post.samples.shape[0]} draws"
        if not post.converged:
            title += " (not converged)"
        legend = fig.legend(handles=handles, loc="upper right", bbox_to_anchor=(0.98, 0.98),
                            title=title, alignment="left")
        if not post.converged:
            legend.get_title().set_color(FLAG_COLOR)
    values = {"samples": samples, "map": mode, "fit": fit, "range": np.array(ranges),
              "factor": factor}
    if lin_labels:
        values.update(linear=lin, linear_labels=tuple(lin_labels))
    return Drawn.build(fig, fig.axes, values, {"legend": legend})


def plot_trace(result, fig=None, *, color: str | None = None) -> Drawn:
    """Trace of every walker for each parameter (and the log posterior density).

    Uses the stored InferenceData (``posterior.idata``: chain = walker), i.e. the draws kept
    after burn-in and thinning. Parameters with a log-uniform prior are drawn as log10, as in
    :func:`plot_corner`.

    Parameters
    ----------
    result : bayesfo.comparison.StructureResult
    fig : matplotlib.figure.Figure, optional
        Empty figure to draw in; default a new single-column figure.
    color : str, optional
        Colour of the walkers (default the first of the palette).

    Returns
    -------
    Drawn
        ``axes``: one per parameter in the order of ``posterior.param_names``, then the log
        posterior when stored. ``values``: ``"<param>"`` (n_walkers, n_kept) in physical units
        (the axes show them as labelled: log10 or divided by a power of ten),
        ``"lp"`` and ``"draw"`` (the x values). ``artists``: ``"<param>"`` (list of ``Line2D``,
        one per walker).

    Raises
    ------
    InputError
        If the structure failed or has no posterior InferenceData.
    """
    _check_result(result)
    post = result.posterior
    if post.idata is None or not hasattr(post.idata, "posterior"):
        raise InputError(f"argument 'result': structure '{result.name}' has no InferenceData")
    ds = post.idata.posterior
    _, labels, is_log = sampling_coordinates(result)
    lp = None
    if hasattr(post.idata, "sample_stats") and "lp" in post.idata.sample_stats:
        lp = np.asarray(post.idata.sample_stats["lp"].values)
    color = color or "#0072B2"
    if getattr(post, "sampler", "emcee") in ("ladder", "importance"):
        return _plot_particles(result, fig, ds, lp, labels, is_log)
    values, artists = {}, {}
    with style():
        n_rows = len(post.param_names) + (lp is not None)
        fig = new_figure(fig, (COLUMN_WIDTH, 0.55 + 0.62 * n_rows))
        axes = np.atleast_1d(fig.subplots(n_rows, 1, sharex=True))
        n_kept = ds.sizes["draw"]
        draw = np.arange(n_kept)
        values["draw"] = draw
        alpha = max(0.15, min(0.6, 8.0 / ds.sizes["chain"]))
        for ax, name, label, log in zip(axes, post.param_names, labels, is_log):
            y = np.asarray(ds[name].transpose("chain", "draw").values)
            values[name] = y
            shown = to_coordinates(y, log)
            e = decade_exponent(shown)
            artists[name] = ax.plot(draw, shown.T / 10.0**e, color=color, lw=0.4, alpha=alpha)
            ax.set_ylabel(scaled_label(label, e).replace(" (×", "\n(×"))
        if lp is not None:
            values["lp"] = lp
            artists["lp"] = axes[-1].plot(draw, lp.T, color="0.3", lw=0.4, alpha=alpha)
            axes[-1].set_ylabel("log post.")
        axes[-1].set_xlabel("kept draw")
        title = (f"{result.name}: {post.n_walkers} walkers × {post.n_steps} steps, "
                 f"burn-in {post.burn}\nthinned ×{post.thin}; "
                 f"R-hat {post.rhat_max:.3f}, ESS {post.ess_min:.0f}")
        if not post.converged:
            title += ": not converged"
        fig.suptitle(title, color=FLAG_COLOR if not post.converged else "black", fontsize=7.5)
        fig.align_ylabels(axes)
    return Drawn.build(fig, axes, values, artists)


def _plot_particles(result, fig, ds, lp, labels, is_log) -> Drawn:
    """:func:`plot_trace` for a posterior without a chain to trace: tempered-ladder particles
    (one histogram per run: the runs certify the posterior by agreeing) or draws resampled
    from importance weights (one histogram)."""
    post = result.posterior
    ladder = post.sampler == "ladder"
    if not ladder:  # importance sampling: one set of resampled draws, no runs to compare
        ds = ds.stack(sample=("chain", "draw")).drop_vars(["chain", "draw", "sample"])
        ds = ds.expand_dims(chain=1).rename({"sample": "draw"})
        lp = None if lp is None else lp.reshape(1, -1)
    runs = ds.sizes["chain"]
    colors = ("#0072B2", "#E69F00", "#009E73", "#CC79A7")
    values, artists = {}, {}
    with style():
        n_rows = len(post.param_names) + (lp is not None)
        fig = new_figure(fig, (COLUMN_WIDTH, 0.55 + 0.62 * n_rows))
        axes = np.atleast_1d(fig.subplots(n_rows, 1))
        rows = [(name, label, log) for name, label, log in zip(post.param_names, labels, is_log)]
        for ax, (name, label, log) in zip(axes, rows):
            y = np.asarray(ds[name].transpose("chain", "draw").values)
            values[name] = y
            shown = to_coordinates(y, log)
            e = decade_exponent(shown)
            bins = np.histogram_bin_edges(shown / 10.0**e, bins=40)
            artists[name] = [ax.hist(shown[i] / 10.0**e, bins=bins, histtype="step",
                                     color=colors[i % len(colors)], lw=0.8,
                                     label=f"run {i + 1}")[2][0] for i in range(runs)]
            ax.set_xlabel(scaled_label(label, e), labelpad=1)
            ax.set_yticks([])
        if lp is not None:
            values["lp"] = lp
            artists["lp"] = [axes[-1].hist(lp[i], bins=40, histtype="step", lw=0.8,
                                           color=colors[i % len(colors)])[2][0]
                             for i in range(runs)]
            axes[-1].set_xlabel("log posterior density", labelpad=1)
            axes[-1].set_yticks([])
        values["draw"] = np.arange(ds.sizes["draw"])
        if ladder:
            axes[0].legend(fontsize=6, frameon=False, loc="upper right")
            title = (f"{result.name}: {runs} tempered-ladder runs × {ds.sizes['draw']} "
                     f"particles\nR-hat {post.rhat_max:.3f}, ESS {post.ess_min:.0f} across "
                     "the runs")
        else:
            title = (f"{result.name}: {ds.sizes['draw']} draws resampled from importance "
                     f"weights\n(ESS of the weights {post.ess_min:.0f})")
        if not post.converged:
            title += ": the runs disagree"
        fig.suptitle(title, color=FLAG_COLOR if not post.converged else "black", fontsize=7.5)
    return Drawn.build(fig, axes, values, artists)


def plot_q_posteriors(comparison, ax=None, *, ridge_height: float = 0.85) -> Drawn:
    """Posterior density of the fractional order of every structure, one ridge per structure.

    Structures are ordered as in the ranking (best on top); the order is ``q``, or ``beta`` for
    the generalised Maxwell model; structures without a free order (``-int``) are left out. Each
    ridge is a kernel density of the draws, reflected at the prior bounds, scaled to its own
    peak; the dashed line is the prior density on the same scale, so a ridge that is no higher
    than its prior line is as uncertain as the prior. The bar under a ridge is the 94 % HDI
    and the tick the posterior mean; the text gives mean ± sd, red when the summary flags the
    order as poorly determined (HDI wider than half the prior range).

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    ax : matplotlib.axes.Axes, optional
    ridge_height : float
        Height of the highest point of each ridge, in units of the ridge spacing.

    Returns
    -------
    Drawn
        ``axes`` = (ax,). ``values``: per structure ``"<name>/grid"``, ``"<name>/density"``
        (unscaled: it integrates to one over the prior range), ``"<name>/prior_density"``,
        ``"<name>/hdi"`` and ``"<name>/baseline"``; ``"structures"`` (names, top to bottom).
        ``artists``: ``"<name>/ridge"`` (``PolyCollection``), ``"<name>/prior"``,
        ``"<name>/hdi"`` (``Line2D``), ``"<name>/label"`` (``Text``).

    Raises
    ------
    InputError
        If no structure of the comparison has a free fractional order.
    """
    from matplotlib.transforms import blended_transform_factory

    results = [(r, order_parameter(r)) for r in ok_results(comparison)]
    results = [(r, p) for r, p in results if p is not None]
    if not results:
        raise InputError("no structure of the comparison has a free fractional order (q or beta)")
    colors = colors_for(comparison.ranking)
    n = len(results)
    values, artists = {"structures": np.array([r.name for r, _ in results])}, {}
    spans = []
    with style():
        fig, ax = axes_or_new(ax, (COLUMN_WIDTH, 0.75 + 0.42 * n))
        text_at = blended_transform_factory(ax.transAxes, ax.transData)
        for i, (r, p) in enumerate(results):
            post = r.posterior
            x = post.samples[:, post.param_names.index(p)]
            prior = r.criteria.get("priors", {}).get(p, DEFAULT_ORDER_PRIOR)
            lo, hi = prior_range(prior, x)
            spans.append((lo, hi))
            grid, dens = density_1d(x, lo, hi)
            pd = prior_density(prior, grid)
            peak = float(dens.max())
            base = float(n - 1 - i)
            s = post.summary[p]
            values.update({f"{r.name}/grid": grid, f"{r.name}/density": dens,
                           f"{r.name}/prior_density": pd, f"{r.name}/baseline": base,
                           f"{r.name}/hdi": (s.hdi_low, s.hdi_high)})
            c = colors[r.name]
            top = base + ridge_height * dens / peak
            artists[f"{r.name}/ridge"] = ax.fill_between(grid, base, top, color=c, alpha=0.45,
                                                         lw=0, zorder=2 + i)
            ax.plot(grid, top, color=c, lw=0.9, zorder=2 + i)
            (artists[f"{r.name}/prior"],) = ax.plot(grid, base + ridge_height * pd / peak,
                                                    color="0.35", lw=0.7, ls="--", zorder=2 + i)
            (artists[f"{r.name}/hdi"],) = ax.plot([s.hdi_low, s.hdi_high], [base, base], color=c,
                                                  lw=2.6, solid_capstyle="butt", zorder=3 + i)
            ax.plot([s.mean, s.mean], [base - 0.1, base + 0.1], color="black", lw=0.9,
                    zorder=3 + i)
            sym = "q" if p == "q" else r"\beta"
            label = f"${sym}$ = {s.mean:.3g} ± {s.sd:.2g}"
            if s.poorly_determined:
                label += "\npoorly determined"
            if not post.converged:
                label += "\nnot converged"
            artists[f"{r.name}/label"] = ax.text(
                1.02, base + 0.12, label, transform=text_at, fontsize=6.5, va="bottom",
                color=FLAG_COLOR if s.poorly_determined or not post.converged else "black",
                clip_on=False)
        ax.set_yticks([n - 1 - i for i in range(n)],
                      [r.name if p == "q" else f"{r.name} (β)" for r, p in results])
        ax.set_ylim(-0.35, n - 1 + ridge_height + 0.25)
        lo = min(s[0] for s in spans)
        hi = max(s[1] for s in spans)
        ax.set_xlim(lo, hi)
        ax.grid(axis="y", visible=False)
        ax.set_xlabel("fractional order $q$" + (r" ($\beta$ for maxwell)"
                                                if any(p == "beta" for _, p in results) else "")
                      + "; dashed: prior")
    return Drawn.build(fig, (ax,), values, artists)
