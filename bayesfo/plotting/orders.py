"""The posterior of every fractional order of every structure side by side: one ridge per order,
zoomed insets for orders determined too sharply to see at the axis' scale."""

from __future__ import annotations

import numpy as np

from ..comparison.table import order_parameters
from ..errors import InputError
from ._base import Drawn, axes_or_new
from ._compute import (
    ORDER_STRUCTURES,
    density_1d,
    ok_results,
    order_parameter,
    prior_density,
    prior_range,
)
from .style import COLUMN_WIDTH, FLAG_COLOR, comparison_styles, style

#: The prior of an order when the results do not state it (the cards' prior of q).
DEFAULT_ORDER_PRIOR = {"prior": "uniform", "low": 0.0, "high": 1.0}

#: A ridge whose 94 % HDI is narrower than this fraction of the axis gets a zoomed inset.
ZOOM_FRACTION = 0.06
#: Below this fraction of its peak a ridge's outline is not drawn (its prior line shows there).
OUTLINE_FLOOR = 2e-3


def plot_q_posteriors(comparison, ax=None, *, ridge_height: float = 0.85,
                      limit: int | None = ORDER_STRUCTURES) -> Drawn:
    """Posterior density of every fractional order of every structure, one ridge per order.

    Structures are ordered as in the ranking (best on top); a structure's first order is
    ``q``, else ``beta`` (the generalised Maxwell model), else ``alpha`` (see
    :func:`bayesfo.comparison.table.order_parameter`), and its other orders (the second
    springpot's α of the two-springpot models, κ of the Zener liquid–liquid) follow in rows
    of their own, each named by its symbol; structures without a free order (``-int``) are left
    out. Each
    ridge is a kernel density of the draws, reflected at the prior bounds, scaled to its own
    peak; the dashed line is the prior density on the same scale, so a ridge that is no higher
    than its prior line is as uncertain as the prior. The bar under a ridge is the 94 % HDI
    and the tick the posterior mean; the text gives mean ± sd and the HDI, red when the summary
    flags the order as poorly determined (HDI wider than half the prior range).

    A ridge whose HDI is narrower than :data:`ZOOM_FRACTION` of the axis would be a spike: it
    gets an inset beside it, zoomed to the HDI and its surroundings, with the same ridge, HDI
    bar, mean tick and dashed prior line, and the ratio of the peak to the prior density
    stated (so a prior line on the floor of the inset reads as what it is).

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    ax : matplotlib.axes.Axes, optional
    ridge_height : float
        Height of the highest point of each ridge, in units of the ridge spacing.
    limit : int or None
        The orders of how many structures to draw, the best by the ranking (None: all); the
        structures beyond are named under the axis (``values["not_shown"]``).

    Returns
    -------
    Drawn
        ``axes`` = (ax, inset, …): the ridge axes, then the zoomed insets top to bottom.
        ``values``: per structure ``"<name>/grid"``, ``"<name>/density"`` (unscaled: it
        integrates to one over the prior range), ``"<name>/prior_density"``, ``"<name>/hdi"``,
        ``"<name>/baseline"`` and, for a zoomed ridge, ``"<name>/zoom"`` (the inset's x
        range), where ``<name>`` is the structure for its first order and
        ``<structure>:<order>`` for the others (``"fractional_kelvin_voigt:alpha"``);
        ``"structures"`` (these keys, top to bottom); ``"not_shown"`` (the structures beyond
        ``limit``, named under the axis). ``artists``: ``"<name>/ridge"``
        (``PolyCollection``), ``"<name>/outline"``, ``"<name>/prior"``, ``"<name>/hdi"``
        (``Line2D``), ``"<name>/label"`` (``Text``) and for a zoomed ridge ``"<name>/inset"``
        (``Axes``), ``"<name>/inset_ridge"``, ``"<name>/inset_prior"``, ``"<name>/inset_hdi"``
        and ``"<name>/inset_note"``; ``"key"`` (``Text``: what bar, tick and dashes mean,
        under the figure) when the function made the figure itself.

    Raises
    ------
    InputError
        If no structure of the comparison has a free fractional order.
    """
    from matplotlib.transforms import blended_transform_factory


    # One ridge per fractional order: a structure's first order (q, else β, else α) under its
    # name, its other orders (the second springpot's) under "<name>:<order>".
    if limit is not None and (isinstance(limit, bool) or not isinstance(limit, int)
                              or limit < 1):
        raise InputError(f"argument 'limit' must be a positive integer or None, got {limit!r}")
    results, keys = [], []
    with_orders = [r for r in ok_results(comparison) if order_parameter(r) is not None]
    left = [] if limit is None else with_orders[limit:]
    for r in with_orders[:limit]:
        first = order_parameter(r)
        names = r.posterior.param_names if r.posterior is not None else r.structure.param_names
        for p in [first] + [k for k in order_parameters(names) if k != first]:
            results.append((r, p))
            keys.append(r.name if p == first else f"{r.name}:{p}")
    if not results:
        raise InputError("no structure of the comparison has a free fractional order "
                         "(q, beta or alpha)")
    styles = comparison_styles(comparison)
    n = len(results)
    values, artists = {"structures": np.array(keys), "not_shown": [r.name for r in left]}, {}
    rows = []
    for i, (r, p) in enumerate(results):
        post = r.posterior
        x = post.samples[:, post.param_names.index(p)]
        prior = (r.criteria.priors or {}).get(p, DEFAULT_ORDER_PRIOR)
        lo, hi = prior_range(prior, x)
        grid, dens = density_1d(x, lo, hi)
        rows.append((r, p, x, prior, (lo, hi), grid, dens))
    x_lo = min(row[4][0] for row in rows)
    x_hi = max(row[4][1] for row in rows)
    tight = [(row[0].posterior.summary[row[1]].hdi_high - row[0].posterior.summary[row[1]].hdi_low)
             < ZOOM_FRACTION * (x_hi - x_lo) for row in rows]
    insets = []
    with style():
        row_height = 0.62 if any(tight) else 0.42
        own_figure = ax is None
        fig, ax = axes_or_new(ax, (COLUMN_WIDTH, 0.75 + row_height * n))
        text_at = blended_transform_factory(ax.transAxes, ax.transData)
        for i, (r, p, x, prior, _, grid, dens) in enumerate(rows):
            key = keys[i]
            post = r.posterior
            pd = prior_density(prior, grid)
            peak = float(dens.max())
            base = float(n - 1 - i)
            s = post.summary[p]
            values.update({f"{key}/grid": grid, f"{key}/density": dens,
                           f"{key}/prior_density": pd, f"{key}/baseline": base,
                           f"{key}/hdi": (s.hdi_low, s.hdi_high)})
            c = styles[r.name].color
            top = base + ridge_height * dens / peak
            artists[f"{key}/ridge"] = ax.fill_between(grid, base, top, color=c, alpha=0.45,
                                                         lw=0, zorder=2 + i)
            # The outline stops where the ridge meets its baseline, so that the dashed prior
            # line is not hidden under it.
            outline = np.where(dens / peak > OUTLINE_FLOOR, top, np.nan)
            (artists[f"{key}/outline"],) = ax.plot(grid, outline, color=c, lw=0.9,
                                                      zorder=2 + i)
            (artists[f"{key}/prior"],) = ax.plot(grid, base + ridge_height * pd / peak,
                                                    color="0.35", lw=0.7, ls="--", zorder=3 + i)
            (artists[f"{key}/hdi"],) = ax.plot([s.hdi_low, s.hdi_high], [base, base], color=c,
                                                  lw=2.6, solid_capstyle="butt", zorder=3 + i)
            ax.plot([s.mean, s.mean], [base - 0.1, base + 0.1], color="black", lw=0.9,
                    zorder=3 + i)
            sym = _ORDER_SYMBOLS.get(p, p)
            digits = _hdi_digits(s.hdi_high - s.hdi_low)
            label = (f"${sym}$ = {s.mean:.3g} ± {s.sd:.2g}\n"
                     f"HDI {s.hdi_low:.{digits}f}–{s.hdi_high:.{digits}f}")
            if s.poorly_determined:
                label += "\npoorly determined"
            if not post.converged:
                label += "\nnot converged"
            artists[f"{key}/label"] = ax.text(
                1.02, base + 0.05, label, transform=text_at, fontsize=6.5, va="bottom",
                color=FLAG_COLOR if s.poorly_determined or not post.converged else "black",
                clip_on=False)
            if tight[i]:
                insets.append(_zoom_inset(ax, key, s, grid, dens, pd, base, c,
                                          (x_lo, x_hi), ridge_height, values, artists))
        ax.set_yticks([n - 1 - i for i in range(n)],
                      [(r.name if key == r.name else "") + ("" if p == "q" else
                                                            f" (${_ORDER_SYMBOLS.get(p, p)}$)")
                       for (r, p), key in zip(results, keys, strict=True)])
        ax.set_ylim(-0.35, n - 1 + ridge_height + 0.25)
        ax.set_xlim(x_lo, x_hi)
        ax.grid(axis="y", visible=False)
        others = sorted({p for _, p in results if p != "q"}, key=list(_ORDER_SYMBOLS).index)
        label = ("fractional order" + (" $q$" if any(p == "q" for _, p in results) else "")
                 + (" (" + ", ".join(f"${_ORDER_SYMBOLS[p]}$" for p in others)
                    + " where named)" if others else ""))
        key_text = f"bar: {HDI_LABEL}, tick: mean; dashed: prior" + _not_shown(left)
        if own_figure:
            # Under the whole figure, centred on it: under the axes (pushed right by long
            # structure names) a line this long would run past the figure's right edge.
            ax.set_xlabel(label)
            artists["key"] = fig.supxlabel(key_text, fontsize=ax.xaxis.label.get_fontsize())
        else:
            ax.set_xlabel(label + "\n" + key_text)
    return Drawn.build(fig, (ax, *insets), values, artists)


def _not_shown(left) -> str:
    """The lines naming the structures whose orders are not drawn ('' for none)."""
    if not left:
        return ""
    import textwrap

    names = ", ".join(r.name for r in left[:4]) + (f" and {len(left) - 4} more"
                                                   if len(left) > 4 else "")
    text = (f"not drawn: the orders of {len(left)} more structure"
            f"{'s' if len(left) > 1 else ''} ({names}; in the report)")
    return "\n" + "\n".join(textwrap.wrap(text, 50, break_on_hyphens=False))


#: Symbols of the fractional orders (:data:`bayesfo.comparison.table.ORDER_PARAMS`).
_ORDER_SYMBOLS = {"q": "q", "beta": r"\beta", "alpha": r"\alpha", "delta": r"\delta",
                  "kappa": r"\kappa", "gamma": r"\gamma"}

#: The posterior's highest-density interval in the labels (as the summaries).
HDI_LABEL = "94 % HDI"


def _hdi_digits(width: float) -> int:
    """Decimals that resolve an interval of ``width`` to about two significant digits."""
    if not np.isfinite(width) or width <= 0:
        return 3
    return int(min(6, max(2, 1 - np.floor(np.log10(width)))))


def _zoom_inset(ax, name, s, grid, dens, pd, base, color, span, ridge_height, values, artists):
    """An inset beside a spike-like ridge: the ridge zoomed to its HDI and surroundings."""
    from matplotlib.transforms import blended_transform_factory

    x_lo, x_hi = span
    width = max(s.hdi_high - s.hdi_low, 1e-12)
    z_lo, z_hi = s.hdi_low - width, s.hdi_high + width
    values[f"{name}/zoom"] = (z_lo, z_hi)
    # On the side of the axis away from the spike, in the upper part of its row.
    centre = (s.mean - x_lo) / (x_hi - x_lo)
    x0 = 0.04 if centre > 0.5 else 0.54
    where = blended_transform_factory(ax.transAxes, ax.transData)
    inset = ax.inset_axes([x0, base + 0.32, 0.42, 0.55 * ridge_height], transform=where,
                          zorder=20)
    peak = float(dens.max())
    inside = (grid >= z_lo) & (grid <= z_hi)
    g, d = grid[inside], dens[inside] / peak
    artists[f"{name}/inset"] = inset
    artists[f"{name}/inset_ridge"] = inset.fill_between(g, 0.0, d, color=color, alpha=0.45, lw=0)
    inset.plot(g, d, color=color, lw=0.8)
    (artists[f"{name}/inset_prior"],) = inset.plot(g, pd[inside] / peak, color="0.35", lw=0.7,
                                                   ls="--")
    (artists[f"{name}/inset_hdi"],) = inset.plot([s.hdi_low, s.hdi_high], [0.0, 0.0],
                                                 color=color, lw=2.6, solid_capstyle="butt",
                                                 clip_on=False)
    inset.plot([s.mean, s.mean], [-0.1, 0.12], color="black", lw=0.8, clip_on=False)
    prior_at = float(np.max(pd[inside])) if np.any(inside) else 0.0
    ratio = peak / prior_at if prior_at > 0 else np.inf
    note = ("prior ≈ 0" if not np.isfinite(ratio) else
            f"peak {ratio:.3g}× prior" if ratio < 1e4 else f"peak {ratio:.0e}× prior")
    # Above the inset, not inside it: the zoomed ridge fills its middle, and a note in a
    # corner ran into its flank.
    artists[f"{name}/inset_note"] = inset.set_title(note, fontsize=5.0, loc="left", pad=1.5,
                                                    color="0.25")
    inset.set_xlim(z_lo, z_hi)
    inset.set_ylim(-0.12, 1.08)
    inset.set_yticks([])
    # Ticks at the HDI's ends, their labels pointing away from each other: two labels of a
    # narrow inset otherwise run together ("0.5640.570").
    digits = _hdi_digits(width)
    inset.set_xticks([s.hdi_low, s.hdi_high],
                     [f"{s.hdi_low:.{digits}f}", f"{s.hdi_high:.{digits}f}"])
    for label, side in zip(inset.get_xticklabels(), ("right", "left"), strict=True):
        label.set_horizontalalignment(side)
    inset.tick_params(axis="x", labelsize=5.5, length=2, pad=1)
    inset.grid(False)
    inset.patch.set_alpha(0.9)
    for side in ("top", "right", "left"):
        inset.spines[side].set_visible(True)
        inset.spines[side].set_linewidth(0.5)
    inset.spines["bottom"].set_linewidth(0.5)
    ax.indicate_inset([z_lo, base - 0.12, z_hi - z_lo, ridge_height + 0.15], inset,
                      edgecolor="0.45", lw=0.5, alpha=0.8)
    return inset
