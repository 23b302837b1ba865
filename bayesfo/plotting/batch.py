"""Figures of a batch of comparisons (``bayesfo batch``).

Both functions take the rows of ``batch_summary.csv`` / ``temperature_summary.csv`` as plain
dicts (see :mod:`bayesfo.batch`), draw on a new :class:`matplotlib.figure.Figure` (no pyplot
state) unless ``fig=`` is given, and return the figure. A structure has the style of
:func:`~bayesfo.plotting.style.structure_styles` by its position in the structures as requested
(colour, line style or bar hatch, marker): the same as in the figures of each comparison.
"""

from __future__ import annotations

import numpy as np

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
    from .style import structure_styles

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


def _q_errorbar(ax, x, rows, st, filled_mask):
    """q means with HDI bars in the style ``st`` of the structure; filled markers where
    ``filled_mask`` (the best structure), a cross where the posterior did not converge."""
    mean = np.array([r["q_mean"] for r in rows], dtype=float)
    low = np.array([r["q_hdi_low"] for r in rows], dtype=float)
    high = np.array([r["q_hdi_high"] for r in rows], dtype=float)
    yerr = np.vstack([np.clip(mean - low, 0, None), np.clip(high - mean, 0, None)])
    ax.errorbar(x, mean, yerr=yerr, fmt="none", ecolor=st.color, elinewidth=1.2, capsize=2.5)
    filled = np.asarray(filled_mask, dtype=bool)
    ax.plot(x[filled], mean[filled], st.marker, color=st.color, markersize=6, linestyle="none")
    ax.plot(x[~filled], mean[~filled], st.marker, markerfacecolor="white", color=st.color,
            markersize=6, linestyle="none")
    unconverged = np.array([r.get("converged") is False for r in rows], dtype=bool)
    if unconverged.any():
        ax.plot(x[unconverged], mean[unconverged], "x", color="0.15", markersize=4,
                linestyle="none")


def _q_legend(ax, labels, styles, **kwargs):
    """One entry per structure, and what filled and hollow markers mean (``ax`` may be the
    figure: a legend beside the axes)."""
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], marker=st.marker, color=st.color, linestyle="none", markersize=6)
               for st in styles]
    handles += [Line2D([], [], marker="o", color="0.3", linestyle="none", markersize=6),
                Line2D([], [], marker="o", color="0.3", markerfacecolor="white",
                       linestyle="none", markersize=6),
                Line2D([], [], marker="x", color="0.15", linestyle="none", markersize=4)]
    return ax.legend(handles, [*labels, "best structure", "not the best", "not converged"],
                     frameon=False, **kwargs)


def plot_batch_summary(rows, structures=None, fig=None):
    """Best structure and posterior q per data set.

    Top: the posterior model probabilities of the structures on each data set, stacked (equal
    prior odds; the name of the best structure above each bar). Bottom: the posterior mean of
    q (``beta`` for the generalised Maxwell model) with its 94 % HDI for every fractional
    structure, filled where the structure is the best on that data set, crossed where its
    posterior did not converge. Data sets that failed are marked on the axis. Data sets are in
    the order given, or in order of temperature when every one has a temperature.

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
    for r in rows:
        if r.get("best"):
            ax_p.annotate(r["structure"], (index[r["dataset"]], 1.0), xytext=(0, 3),
                          textcoords="offset points", ha="center", va="bottom", fontsize=7,
                          rotation=90 if n > 8 else 0)
    for d in failed:
        ax_p.annotate("failed", (index[d], 0.5), ha="center", va="center", fontsize=7,
                      color="tab:red", rotation=90)
    ax_p.set_ylim(0, 1.3 if n > 8 else 1.15)
    ax_p.set_yticks([0, 0.5, 1])
    ax_p.set_ylabel("posterior probability")
    ax_p.set_title("Best structure (equal prior odds) and posterior of q per data set",
                   fontsize=10)

    with_q = [s for s in structures if any(r.get("structure") == s and _has_q(r) for r in rows)]
    width = 0.6
    offsets = (np.linspace(-width / 2, width / 2, len(with_q)) if len(with_q) > 1
               else np.zeros(len(with_q)))
    labels = []
    for name, off in zip(with_q, offsets):
        sel = [r for r in rows if r.get("structure") == name and _has_q(r)]
        xs = np.array([index[r["dataset"]] + off for r in sel])
        qname = sel[0].get("q_parameter") or "q"
        labels.append(name if qname == "q" else f"{name} ({qname})")
        _q_errorbar(ax_q, xs, sel, styles[name], [bool(r.get("best")) for r in sel])
    ax_q.set_ylabel(f"q: posterior mean, {HDI_LABEL}")
    ax_q.set_xticks(x)
    ax_q.set_xticklabels([d + (" (failed)" if d in failed else "") for d in datasets],
                         rotation=45 if n > 4 else 0, ha="right" if n > 4 else "center",
                         fontsize=8)
    for label, d in zip(ax_q.get_xticklabels(), datasets):
        if d in failed:
            label.set_color("tab:red")
    handles = [ax_p.containers[i] for i in range(len(structures))]
    fig.legend(handles, structures, loc="outside right upper", fontsize=8, frameon=False,
               title="structure", title_fontsize=8)
    if with_q:
        _q_legend(fig, labels, [styles[s] for s in with_q], fontsize=7,
                  loc="outside right lower", title="q of", title_fontsize=8)
    ax_q.set_xlim(-0.7, n - 0.3)
    return fig


def plot_q_temperature(rows, structures=None, fig=None):
    """Posterior q against temperature per structure, and the best structure per temperature.

    Top: the posterior mean of q (``beta`` for the generalised Maxwell model) with its 94 % HDI
    against temperature, one colour per structure, filled where the structure is the best at
    that temperature, crossed where its posterior did not converge. Bottom: the posterior
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
    with_q = [s for s in structures if any(r.get("structure") == s and _has_q(r) for r in rows)]
    # Points of the structures side by side at each temperature: wider apart on the axis of a
    # single temperature, where nothing else needs the room.
    spread = 0.08 if one else 0.006
    offsets = (np.linspace(-spread, spread, len(with_q)) * span if len(with_q) > 1
               else np.zeros(len(with_q)))
    labels = []
    for name, off in zip(with_q, offsets):
        sel = sorted((r for r in rows if r.get("structure") == name and _has_q(r)),
                     key=lambda r: r["temperature_C"])
        t = np.array([float(r["temperature_C"]) for r in sel]) + off
        st = styles[name]
        if len(sel) > 1:
            ax_q.plot(t, [r["q_mean"] for r in sel], color=st.color, linestyle=st.linestyle,
                      linewidth=0.8, alpha=0.6)
        qname = sel[0].get("q_parameter") or "q"
        labels.append(name if qname == "q" else f"{name} ({qname})")
        _q_errorbar(ax_q, t, sel, st, [bool(r.get("best")) for r in sel])
    ax_q.set_ylabel(f"q: posterior mean, {HDI_LABEL}")
    if with_q:
        _q_legend(fig, labels, [styles[s] for s in with_q], fontsize=8,
                  loc="outside right upper", title="q of", title_fontsize=8)
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
