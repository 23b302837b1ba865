"""Posterior figures of one structure: corner plot and walker traces (the fractional orders of
every structure side by side are in :mod:`bayesfo.plotting.orders`).

This module is longer than the project's 500-line guide: corner and trace share the label,
unit and range helpers; the corner's label placement (tick-label measurement) is the candidate
to move out next.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ._base import Drawn, new_figure
from ._compute import (
    decade_exponent,
    natural_coordinates,
    scaled_label,
    to_coordinates,
)
from .captions import corner_caption, trace_caption
from .style import COLUMN_WIDTH, FLAG_COLOR, PAGE_WIDTH, style

#: Probability mass inside the 2-D contours of the corner plot (the bands of the response plots).
CORNER_LEVELS = (0.5, 0.9)
MAP_COLOR = "black"
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

    The parameters are those the report's tables name: for modulus data the structure's physical parameters (``G_e``,
    ``c_q``, ``q`` of the fractional Voigt; positive ones on log10 axes), else the card's
    parameters as sampled (log10 of those with a log-uniform prior), each divided by a power
    of ten when its values are very small or large (the label gives the factor); noise
    parameters sampled with the structure are included. Each label carries the parameter's
    unit, derived from the data's units (``log10 G_e [Pa]``, ``a1 [s^q]``; orders have none)
    when the result knows them (:attr:`~bayesfo.comparison.StructureResult.units`). Contours
    enclose 50 % and 90 % of the draws. However many parameters, the axis labels clear the tick labels and every label stays
    inside the figure: they are placed, and the margins set, from the drawn tick labels.

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
        parameters) and ``"linear_labels"``; ``"converged"``. ``artists``: ``"legend"``.
        ``caption``: what the figure shows (:func:`~bayesfo.plotting.captions.corner_caption`).

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
    coords = natural_coordinates(result)
    samples, labels = coords.coordinates(post.samples), coords.labels
    ndim = samples.shape[1]
    exponents = np.array([decade_exponent(samples[:, i]) for i in range(ndim)])
    factor = 10.0 ** exponents
    samples = samples / factor
    # The factor on a second line: narrow panels of many parameters keep their labels apart.
    labels = [scaled_label(lab, int(e)).replace(" (×", "\n(×")
              for lab, e in zip(labels, exponents)]
    mode = coords.coordinates(post.map_theta)[0] / factor

    def card_point(theta):  # the card's coefficients of a fit, without noise parameters
        row = np.full(len(post.param_names), np.nan)
        row[[post.param_names.index(n) for n in result.structure.param_names]] = theta
        return coords.coordinates(row)[0] / factor

    fit = np.full(ndim, np.nan)
    if result.fit is not None and result.fit.admissible:
        fit = card_point(result.fit.theta)
    lin_labels = list(linear or {})
    lin = np.array([card_point(np.asarray(linear[label], float)) for label in lin_labels]
                   ).reshape(len(lin_labels), ndim)
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
        _tidy_corner(fig, ndim)
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
    values["converged"] = bool(post.converged)
    return Drawn.build(fig, fig.axes, values, {"legend": legend}, corner_caption(result))


#: Room [points] between tick labels and an axis label, and between any text and the edge.
LABEL_PAD = 2.5
EDGE_PAD = 3.0


def _corner_text(fig, ndim):
    """(left column, bottom row) of the corner grid: the axes with labels and tick labels."""
    grid = np.array(fig.axes[: ndim * ndim], dtype=object).reshape(ndim, ndim)
    return list(grid[1:, 0]), list(grid[-1, :])


def _tick_boxes(labels, renderer):
    return [t.get_window_extent(renderer) for t in labels if t.get_visible() and t.get_text()]


def _shown_ticks(axis):
    """(position, label) of the ticks of ``axis`` inside its view."""
    lo, hi = sorted(axis.get_view_interval())
    eps = 1e-9 * (hi - lo)
    return [(t.get_loc(), t.label1) for t in axis.get_major_ticks()
            if lo - eps <= t.get_loc() <= hi + eps]


def _lay_out_ticks(left, bottom) -> None:
    """The ticks and tick labels of the left column's y axes and of the bottom row's x axes
    where the figure's present margins put them: what drawing the figure does to them, without
    drawing the other panels' contours and histograms (most of a drawing's cost)."""
    for ax in left:
        ax.yaxis.get_majorticklabels()  # updates the axis's ticks
    for ax in bottom:
        ax.xaxis.get_majorticklabels()


def _declutter(fig, left, bottom):
    """Hide the first tick label of a panel where it would run into the last one of its
    neighbour across the narrow gap between panels: x labels rotated by 45° need their ticks
    √2 text heights apart, horizontal y labels one text height."""
    _lay_out_ticks(left, bottom)
    px = fig.dpi / 72.0

    def height(label):
        return 1.25 * label.get_fontsize() * px

    for prev, cur in zip(bottom, bottom[1:]):
        a, b = _shown_ticks(prev.xaxis), _shown_ticks(cur.xaxis)
        if not a or not b:
            continue
        x_prev = max(prev.transData.transform((loc, 0.0))[0] for loc, _ in a)
        loc, label = min(b, key=lambda t: t[0])
        x_cur = cur.transData.transform((loc, 0.0))[0]
        if x_cur - x_prev < np.sqrt(2.0) * height(label) + 1.0 * px:
            label.set_visible(False)
    for upper, lower in zip(left, left[1:]):
        a, b = _shown_ticks(upper.yaxis), _shown_ticks(lower.yaxis)
        if not a or not b:
            continue
        y_upper = min(upper.transData.transform((0.0, loc))[1] for loc, _ in a)
        loc, label = max(b, key=lambda t: t[0])
        y_lower = lower.transData.transform((0.0, loc))[1]
        if y_upper - y_lower < height(label) + 1.0 * px:
            label.set_visible(False)


def _tidy_corner(fig, ndim, iterations: int = 4):
    """Axis labels clear of the tick labels, and every label inside the figure.

    corner places the axis labels at a fixed fraction of a panel, which does not clear tick
    labels rotated across narrow panels, and its margins do not follow the size of the tick
    labels. Here the y tick labels are horizontal, the x tick labels rotated by 45° and
    right-aligned at their tick (so none reaches past the right edge of its panel), the axis
    labels of the left column and of the bottom row are placed :data:`LABEL_PAD` points beyond
    all the tick labels of that column or row, as measured with the ticks laid out, and the
    margins are set so that the outermost text keeps :data:`EDGE_PAD` points from the
    figure's edges. A tick label that would run into its neighbour's across the gap between
    two panels is hidden (:func:`_declutter`).
    """
    left, bottom = _corner_text(fig, ndim)
    for ax in bottom:
        for t in ax.get_xticklabels():
            t.set(rotation=45, ha="right", va="top", rotation_mode="anchor")
    for ax in left:
        for t in ax.get_yticklabels():
            t.set(rotation=0, ha="right", va="center", rotation_mode="default")
    px = fig.dpi / 72.0

    def place_labels(drawn: bool = False):
        # One x for the y labels of the left column and one y for the x labels of the bottom
        # row, beyond every tick label of the column or row: a label taller or wider than its
        # panel then clears the tick labels of its neighbours too, and the labels align.
        # ``drawn``: the ticks have been laid out since the panels last moved. An axis label
        # placed by set_label_coords has its extent without another drawing.
        if not drawn:
            _lay_out_ticks(left, bottom)
        renderer = fig.canvas.get_renderer()
        boxes = [b for ax in left for b in _tick_boxes(ax.get_yticklabels(), renderer)]
        x = min([b.x0 for b in boxes] + [ax.bbox.x0 for ax in left]) - LABEL_PAD * px
        for ax in left:
            ax.yaxis.set_label_coords((x - ax.bbox.x0) / ax.bbox.width, 0.5)
        boxes = [b for ax in bottom for b in _tick_boxes(ax.get_xticklabels(), renderer)]
        y = min([b.y0 for b in boxes] + [ax.bbox.y0 for ax in bottom]) - LABEL_PAD * px
        for ax in bottom:
            ax.xaxis.set_label_coords(0.5, (y - ax.bbox.y0) / ax.bbox.height)
        return renderer

    _declutter(fig, left, bottom)  # lays out the ticks
    for i in range(iterations):
        renderer = place_labels(drawn=i == 0)
        boxes = [b for ax in left + bottom
                 for b in _tick_boxes([*ax.get_xticklabels(), *ax.get_yticklabels(),
                                       ax.xaxis.label, ax.yaxis.label], renderer)]
        if not boxes:
            return
        width, height = fig.bbox.width, fig.bbox.height
        grow_left = EDGE_PAD * px - min(b.x0 for b in boxes)
        grow_bottom = EDGE_PAD * px - min(b.y0 for b in boxes)
        grow_right = max(b.x1 for b in boxes) - (width - EDGE_PAD * px)
        if max(abs(grow_left), abs(grow_bottom), max(grow_right, 0.0)) < 0.5:
            return
        sp = fig.subplotpars
        fig.subplots_adjust(left=sp.left + grow_left / width,
                            bottom=sp.bottom + grow_bottom / height,
                            right=min(sp.right, sp.right - grow_right / width))
    _declutter(fig, left, bottom)  # the panels as the last margins left them
    place_labels(drawn=True)  # against the tick labels where the last margins put them


def plot_trace(result, fig=None, *, color: str | None = None) -> Drawn:
    """Trace of every walker for each parameter (and the log posterior density).

    Uses the stored DataTree (``posterior.idata``: chain = walker), i.e. the draws kept
    after burn-in and thinning, in the parameters, coordinates and labels of
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
        ``axes``: one per parameter drawn (those of :func:`plot_corner`), then the log
        posterior when stored. ``values``: ``"<param>"`` (n_walkers, n_kept) in the
        parameter's units (the axes show them as labelled: log10 or divided by a power of ten),
        ``"lp"`` and ``"draw"`` (the x values), ``"converged"``. ``artists``: ``"<param>"``
        (list of ``Line2D``, one per walker). ``caption``: what the traces show for this
        structure (:func:`~bayesfo.plotting.captions.trace_caption`: they overlap and show no
        trend only when the draws converged; otherwise which target they miss).

    Raises
    ------
    InputError
        If the structure failed or has no posterior DataTree.
    """
    _check_result(result)
    post = result.posterior
    if post.idata is None or not hasattr(post.idata, "posterior"):
        raise InputError(f"argument 'result': structure '{result.name}' has no posterior draws")
    ds = post.idata.posterior.dataset
    coords = natural_coordinates(result)
    chains = _drawn_chains(post, ds, coords)
    lp = None
    if hasattr(post.idata, "sample_stats") and "lp" in post.idata.sample_stats:
        lp = np.asarray(post.idata.sample_stats["lp"].values)
    color = color or "#0072B2"
    if getattr(post, "sampler", "emcee") in ("ladder", "importance"):
        return _plot_particles(result, fig, ds, lp, coords, chains)
    values, artists = {}, {}
    with style():
        n_rows = len(coords.names) + (lp is not None)
        fig = new_figure(fig, (COLUMN_WIDTH, 0.55 + 0.62 * n_rows))
        axes = np.atleast_1d(fig.subplots(n_rows, 1, sharex=True))
        n_kept = ds.sizes["draw"]
        draw = np.arange(n_kept)
        values["draw"] = draw
        alpha = max(0.15, min(0.6, 8.0 / ds.sizes["chain"]))
        for i, (ax, name, label, log) in enumerate(zip(axes, coords.names, coords.labels,
                                                        coords.is_log)):
            y = chains[..., i]
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
    values["converged"] = bool(post.converged)
    return Drawn.build(fig, axes, values, artists, trace_caption(result))


def _drawn_chains(post, ds, coords) -> np.ndarray:
    """The stored draws (chain, draw) as the parameters drawn: shape (chain, draw, ndim)."""
    theta = np.stack([np.asarray(ds[n].transpose("chain", "draw").values, float)
                      for n in post.param_names], axis=-1)
    c, d, p = theta.shape
    return coords.values(theta.reshape(c * d, p)).reshape(c, d, -1)


def _plot_particles(result, fig, ds, lp, coords, chains) -> Drawn:
    """:func:`plot_trace` for a posterior without a chain to trace: tempered-ladder particles
    (one histogram per run: the runs certify the posterior by agreeing) or draws resampled
    from importance weights (one histogram)."""
    post = result.posterior
    ladder = post.sampler == "ladder"
    if not ladder:  # importance sampling: one set of resampled draws, no runs to compare
        chains = chains.reshape(1, -1, chains.shape[-1])
        lp = None if lp is None else lp.reshape(1, -1)
    runs, n_draws = chains.shape[:2]
    colors = ("#0072B2", "#E69F00", "#009E73", "#CC79A7")
    values, artists = {}, {}
    with style():
        n_rows = len(coords.names) + (lp is not None)
        fig = new_figure(fig, (COLUMN_WIDTH, 0.55 + 0.62 * n_rows))
        axes = np.atleast_1d(fig.subplots(n_rows, 1))
        rows = list(zip(coords.names, coords.labels, coords.is_log))
        for i, (ax, (name, label, log)) in enumerate(zip(axes, rows)):
            y = chains[..., i]
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
        values["draw"] = np.arange(n_draws)
        if ladder:
            axes[0].legend(fontsize=6, frameon=False, loc="upper right")
            title = (f"{result.name}: {runs} tempered-ladder runs × {n_draws} "
                     f"particles\nR-hat {post.rhat_max:.3f}, ESS {post.ess_min:.0f} across "
                     "the runs")
        else:
            # Two short lines: a long structure name on one line ran past the column's edges.
            title = (f"{result.name}: {n_draws} draws\nresampled from importance weights "
                     f"(ESS of the weights {post.ess_min:.0f})")
        if not post.converged:
            title += ": the runs disagree"
        fig.suptitle(title, color=FLAG_COLOR if not post.converged else "black", fontsize=7.5)
    values["converged"] = bool(post.converged)
    return Drawn.build(fig, axes, values, artists, trace_caption(result))
