"""Figures of a batch of comparisons (``bayesfo batch``).

Both functions take the rows of ``batch_summary.csv`` / ``temperature_summary.csv`` as plain
dicts (see :mod:`bayesfo.batch`), draw on a new :class:`matplotlib.figure.Figure` (no pyplot
state) unless ``fig=`` is given, and return the figure. A structure has the style of
:func:`~bayesfo.plotting.style.structure_styles` by its position in the structures as requested
(colour, line style or bar hatch, marker): the same as in the figures of each comparison.
"""

from __future__ import annotations

import numpy as np

from ..comparison.table import ORDER_SYMBOLS
from .style import structure_styles

HDI_LABEL = "94 % HDI"


#: Hatches of the probability bars, one per line style of :data:`~.style.LINESTYLES`, so that
#: bars of structures with one colour differ as their curves do.
HATCHES = {"-": "", "--": "////", ":": "....", "-.": "xxxx"}
#: Width of the temperature axis [°C] when all data sets have one temperature.
ONE_TEMPERATURE_WIDTH = 20.0


def _structure_styles(rows, order=None):
    """``{name: StructureStyle}``: by position in ``order`` (the structures as requested, as
    in :func:`~.style.comparison_styles`), then the others alphabetically, including
    structures without results, so that a structure has one style in every figure."""
    names = list(dict.fromkeys(order or []))
    others = {r["structure"] for r in rows if r.get("structure")} - set(names)
    return structure_styles(names + sorted(others))


def _figure(fig, width, height):
    if fig is not None:
        fig.clear()
        return fig
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")


def _structures_in_order(rows, order=None):
    """Structures with results in ``rows``: in ``order``, then the others alphabetically (so a
    structure has the same colour in every figure of a batch)."""
    present = {r["structure"] for r in rows if r.get("structure") and r.get("rank") is not None}
    order = list(order or [])
    return [n for n in order if n in present] + sorted(present - set(order))


def _has_q(row) -> bool:
    return all(row.get(k) is not None for k in ("q_mean", "q_hdi_low", "q_hdi_high"))


#: Markers of a structure's second and further orders (its first has the structure's marker).
ORDER_MARKERS = ("D", "v", "P", "X")


def _order_series(rows, name: str, marker: str) -> list[tuple]:
    """Every fractional order of structure ``name`` across the rows: ``(label, marker, rows,
    mean, low, high)`` per order, from the rows' ``order_summaries`` (every order, as the
    batch's table gives them) or, for rows read back from ``batch_summary.csv``, its one
    ``q_*`` columns. The first order has the structure's marker, the others
    :data:`ORDER_MARKERS`; the label names the order by its symbol unless it is a plain q."""
    sel = [r for r in rows if r.get("structure") == name]
    keys = list(dict.fromkeys(k for r in sel for k in (r.get("order_summaries") or {})))
    if keys:
        found = [(k, [r for r in sel if k in (r.get("order_summaries") or {})]) for k in keys]
        stats = [[[r["order_summaries"][k][f] for r in rs] for f in ("mean", "hdi_low",
                                                                     "hdi_high")]
                 for k, rs in found]
    else:
        rs = [r for r in sel if _has_q(r)]
        if not rs:
            return []
        found = [(rs[0].get("q_parameter") or "q", rs)]
        stats = [[[r[f] for r in rs] for f in ("q_mean", "q_hdi_low", "q_hdi_high")]]
    out = []
    for i, ((k, rs), (mean, low, high)) in enumerate(zip(found, stats, strict=True)):
        label = name if (k == "q" and len(found) == 1) else f"{name} ({ORDER_SYMBOLS.get(k, k)})"
        out.append((label, marker if i == 0 else ORDER_MARKERS[(i - 1) % len(ORDER_MARKERS)],
                    rs, *(np.asarray(v, dtype=float) for v in (mean, low, high))))
    return out


def _q_errorbar(ax, x, st, filled_mask, series):
    """One order's means with HDI bars (``series``: one of :func:`_order_series`) in the colour
    of the structure's style ``st``; filled markers where ``filled_mask`` (the best
    structure), a cross where the posterior did not converge."""
    _, marker, rows, mean, low, high = series
    yerr = np.vstack([np.clip(mean - low, 0, None), np.clip(high - mean, 0, None)])
    ax.errorbar(x, mean, yerr=yerr, fmt="none", ecolor=st.color, elinewidth=1.2, capsize=2.5)
    filled = np.asarray(filled_mask, dtype=bool)
    ax.plot(x[filled], mean[filled], marker, color=st.color, markersize=6, linestyle="none")
    ax.plot(x[~filled], mean[~filled], marker, markerfacecolor="white", color=st.color,
            markersize=6, linestyle="none")
    unconverged = np.array([r.get("converged") is False for r in rows], dtype=bool)
    if unconverged.any():
        ax.plot(x[unconverged], mean[unconverged], "x", color="0.15", markersize=4,
                linestyle="none")


def _q_legend(ax, labels, styles, markers=None, **kwargs):
    """One entry per structure's order (``markers``: of each entry, default the styles'), and
    what filled and hollow markers mean (``ax`` may be the figure: a legend beside the
    axes)."""
    from matplotlib.lines import Line2D

    markers = markers or [st.marker for st in styles]
    handles = [Line2D([], [], marker=m, color=st.color, linestyle="none", markersize=6)
               for st, m in zip(styles, markers, strict=True)]
    handles += [Line2D([], [], marker="o", color="0.3", linestyle="none", markersize=6),
                Line2D([], [], marker="o", color="0.3", markerfacecolor="white",
                       linestyle="none", markersize=6),
                Line2D([], [], marker="x", color="0.15", linestyle="none", markersize=4)]
    return ax.legend(handles, [*labels, "best structure", "not the best", "not converged"],
                     frameon=False, **kwargs)


def _common_prefix(names: list[str]) -> str:
    """The start every name shares, up to and including its last separator (``-``, ``_``,
    space, ``:``, ``/``); empty for one name or none shared."""
    import os

    if len(names) < 2:
        return ""
    common = os.path.commonprefix(names)
    cut = max(common.rfind(c) for c in "-_ :/")
    return common[:cut + 1] if cut >= 0 and all(len(n) > cut + 1 for n in names) else ""


def plot_batch_summary(rows, structures=None, fig=None):
    """Best structure and posterior orders per data set.

    Top: the posterior model probabilities of the structures on each data set, stacked (equal
    prior odds; the legend names the structures by colour and hatch, and up to eight data sets
    the name of the best is written above its bar). Bottom: the posterior mean of every
    fractional order of every fractional structure (q; α, β, δ by symbol where a structure
    has several) with its 94 % HDI, filled where the structure is the best on that data set,
    crossed where its posterior did not converge. Data sets that failed are marked on the
    axis; the start all their names share is said once under the axis, not repeated in every
    label. Data sets are in the order given, or in order of temperature when every one has a
    temperature.

    Parameters
    ----------
    rows : sequence of dict
        Rows of ``batch_summary.csv`` (:attr:`bayesfo.batch.BatchResult.rows`).
    structures : sequence of str, optional
        Order of the structures (legend, colours); others follow alphabetically.
    fig : matplotlib Figure, optional
        Drawn on (cleared first); default: a new figure sized for the number of data sets.

    Returns
    -------
    matplotlib.figure.Figure
        With two axes: probabilities, then q.
    """
    rows = list(rows)
    datasets = list(dict.fromkeys(r["dataset"] for r in rows))
    temps = {r["dataset"]: r.get("temperature_C") for r in rows}
    if all(temps[d] not in (None, "") for d in datasets):
        # Isotherms: in order of temperature, not of name (Tm010C would precede Tm040C).
        datasets.sort(key=lambda d: float(temps[d]))
    failed = {r["dataset"] for r in rows if r.get("status") != "ok"}
    styles = _structure_styles(rows, structures)
    structures = _structures_in_order(rows, structures)
    n = len(datasets)
    fig = _figure(fig, min(max(6.0, 0.5 * n + 2.5), 30.0), 6.0)
    ax_p, ax_q = fig.subplots(2, 1, sharex=True, height_ratios=[1, 1.4])
    x = np.arange(n, dtype=float)
    index = {d: i for i, d in enumerate(datasets)}

    bottom = np.zeros(n)
    for name in structures:
        p = np.zeros(n)
        for r in rows:
            if r.get("structure") == name and r.get("posterior_probability") is not None:
                p[index[r["dataset"]]] = r["posterior_probability"]
        st = styles[name]
        ax_p.bar(x, p, bottom=bottom, color=st.color, width=0.75, label=name,
                 hatch=HATCHES.get(st.linestyle, ""), edgecolor="white", linewidth=0.4)
        bottom += p
    if n <= 8:  # beyond, the names would run into each other (and vertical, into the title)
        for r in rows:
            if r.get("best"):
                # A best structure that fails the posterior predictive checks is the one that
                # misfits least, which its label says.
                misfits = r.get("adequate") in (False, "False")
                ax_p.annotate(r["structure"] + ("\n(misfits)" if misfits else ""),
                              (index[r["dataset"]], 1.0), xytext=(0, 3),
                              textcoords="offset points", ha="center", va="bottom", fontsize=7,
                              color="tab:red" if misfits else "black")
    for d in failed:
        ax_p.annotate("failed", (index[d], 0.5), ha="center", va="center", fontsize=7,
                      color="tab:red", rotation=90)
    ax_p.set_ylim(0, 1.22 if n <= 8 else 1.02)
    ax_p.set_yticks([0, 0.5, 1])
    ax_p.set_ylabel("posterior probability")
    # The figure's title, not the axes': the legends beside the axes narrow them, and an axes
    # title as wide as the figure was cut at both ends (two lines: clear of the legend's).
    fig.suptitle("Best structure (equal prior odds) and posterior\nof the fractional orders per "
                 "data set", fontsize=10)

    series = [(name, sr) for name in structures
              for sr in _order_series(rows, name, styles[name].marker)]
    width = 0.6
    offsets = (np.linspace(-width / 2, width / 2, len(series)) if len(series) > 1
               else np.zeros(len(series)))
    for (name, sr), off in zip(series, offsets):
        xs = np.array([index[r["dataset"]] + off for r in sr[2]])
        _q_errorbar(ax_q, xs, styles[name], [bool(r.get("best")) for r in sr[2]], sr)
    ax_q.set_ylabel(f"order: posterior mean, {HDI_LABEL}")
    prefix = _common_prefix(datasets)
    ax_q.set_xticks(x)
    ax_q.set_xticklabels([d[len(prefix):] + (" (failed)" if d in failed else "")
                          for d in datasets],
                         rotation=45 if n > 4 else 0, ha="right" if n > 4 else "center",
                         fontsize=8)
    if prefix:
        ax_q.set_xlabel(f"data set ({prefix}…)")
    for label, d in zip(ax_q.get_xticklabels(), datasets):
        if d in failed:
            label.set_color("tab:red")
    handles = [ax_p.containers[i] for i in range(len(structures))]
    fig.legend(handles, structures, loc="outside right upper", fontsize=8, frameon=False,
               title="structure", title_fontsize=8)
    if series:
        _q_legend(fig, [sr[0] for _, sr in series], [styles[name] for name, _ in series],
                  [sr[1] for _, sr in series], fontsize=7, loc="outside right lower",
                  title="order of", title_fontsize=8)
    ax_q.set_xlim(-0.7, n - 0.3)
    return fig


def plot_q_temperature(rows, structures=None, fig=None):
    """Posterior orders against temperature per structure, and the best structure per
    temperature.

    Top: the posterior mean of every fractional order of every structure (q; α, β, δ by
    symbol where a structure has several; the rows' ``order_summaries``, else their ``q_*``
    columns) with its 94 % HDI against temperature, one colour per structure, filled where
    the structure is the best at that temperature, crossed where its posterior did not
    converge. Bottom: the posterior
    probability of each structure against temperature (equal prior odds), so the best structure
    per temperature is the top curve. With a single temperature the axis is
    :data:`ONE_TEMPERATURE_WIDTH` °C wide around it, with that temperature as its only tick and
    the title saying that there is no trend to show.

    Parameters
    ----------
    rows : sequence of dict
        Rows of ``temperature_summary.csv`` (:func:`bayesfo.batch.temperature_rows`).
    structures : sequence of str, optional
        Order of the structures (legend, colours); others follow alphabetically.
    fig : matplotlib Figure, optional

    Returns
    -------
    matplotlib.figure.Figure
        With two axes: q, then probabilities.
    """
    rows = [r for r in rows if r.get("temperature_C") is not None]
    styles = _structure_styles(rows, structures)
    structures = _structures_in_order(rows, structures)
    fig = _figure(fig, 6.5, 6.0)
    ax_q, ax_p = fig.subplots(2, 1, sharex=True, height_ratios=[1.6, 1])
    temps = sorted({float(r["temperature_C"]) for r in rows})
    one = len(temps) == 1
    span = (temps[-1] - temps[0]) if not one else ONE_TEMPERATURE_WIDTH
    by_t = sorted(rows, key=lambda r: float(r["temperature_C"]))
    series = [(name, sr) for name in structures
              for sr in _order_series(by_t, name, styles[name].marker)]
    # Points of the structures side by side at each temperature: wider apart on the axis of a
    # single temperature, where nothing else needs the room.
    spread = 0.08 if one else 0.006
    offsets = (np.linspace(-spread, spread, len(series)) * span if len(series) > 1
               else np.zeros(len(series)))
    for (name, sr), off in zip(series, offsets):
        sel = sr[2]
        t = np.array([float(r["temperature_C"]) for r in sel]) + off
        st = styles[name]
        if len(sel) > 1:
            ax_q.plot(t, sr[3], color=st.color, linestyle=st.linestyle, linewidth=0.8,
                      alpha=0.6)
        _q_errorbar(ax_q, t, st, [bool(r.get("best")) for r in sel], sr)
    ax_q.set_ylabel(f"order: posterior mean, {HDI_LABEL}")
    if series:
        _q_legend(fig, [sr[0] for _, sr in series], [styles[name] for name, _ in series],
                  [sr[1] for _, sr in series], fontsize=8, loc="outside right upper",
                  title="order of", title_fontsize=8)
    ax_q.set_title("Posterior of the fractional order against temperature", fontsize=10)

    # At a single temperature the probabilities sit side by side too.
    p_offsets = (np.linspace(-spread, spread, len(structures)) * span if one and
                 len(structures) > 1 else np.zeros(len(structures)))
    for name, off in zip(structures, p_offsets):
        sel = sorted((r for r in rows if r.get("structure") == name
                      and r.get("posterior_probability") is not None),
                     key=lambda r: r["temperature_C"])
        if sel:
            st = styles[name]
            ax_p.plot([float(r["temperature_C"]) + off for r in sel],
                      [r["posterior_probability"] for r in sel],
                      color=st.color, linestyle=st.linestyle, marker=st.marker, markersize=4,
                      linewidth=1, label=name)
    ax_p.set_ylim(-0.05, 1.05)
    ax_p.set_ylabel("posterior probability")
    ax_p.set_xlabel("temperature [°C]")
    ax_p.legend(fontsize=8, frameon=False, ncols=min(len(structures), 3) or 1)
    if one:
        # One isotherm: an axis of a sensible width around it, its temperature as the only
        # tick, and a note that there is no trend to read.
        t0 = temps[0]
        ax_p.set_xlim(t0 - ONE_TEMPERATURE_WIDTH / 2, t0 + ONE_TEMPERATURE_WIDTH / 2)
        ax_p.set_xticks([t0], [f"{t0:g}"])
        ax_q.set_title(f"Posterior of the fractional order at one temperature ({t0:g} °C):\n"
                       "a single isotherm, so no trend with temperature to show", fontsize=10)
    return fig
