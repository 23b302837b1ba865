"""The ranking of a comparison as a figure: evidence and the information criteria."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ._base import Drawn, new_figure
from ._compute import RANKING_SHOWN
from .style import COLUMN_WIDTH, FLAG_COLOR, comparison_styles, style

#: Below this Δ (nats) the Δ axes switch to a symmetric-log scale, linear within ±SYMLOG_LINEAR.
SYMLOG_FROM = -20.0
SYMLOG_LINEAR = 1.0
CRITERIA = (
    # (value key, label, marker, face colour, dodge)
    ("delta_loo", "elpd$_{LOO}$ ± se", "o", "black", 0.22),
    ("delta_aic_half", "−AIC/2", "^", "0.55", 0.0),
    ("delta_bic_half", "−BIC/2", "s", "white", -0.22),
)
#: Pareto k̂ above which PSIS-LOO is unreliable (Vehtari et al. 2017; as the comparison flags).
PARETO_K_WARN = 0.7
#: Why the figure shows PSIS-LOO and not WAIC, said once under the criteria.
WAIC_NOTE = ("WAIC not shown: it estimates the same as PSIS-LOO, whose Pareto k̂\n"
             f"(right: largest per structure; > {PARETO_K_WARN:g}, open marker) says where "
             "LOO is unreliable")


#: A structure whose ln Z trails the best by more than this many nats is listed in the note,
#: not drawn: its tick labels (−10,000,000,000,000) would run together on the axis.
HOPELESS_NATS = 1.0e6


def _nan(v) -> float:
    return np.nan if v is None else float(v)


def _format_p(p: float) -> str:
    if not np.isfinite(p):
        return "P n/a"
    return "P < 0.001" if p < 0.001 else f"P = {p:.3f}"


def _set_delta_scale(ax, values) -> None:
    """Linear axis, or symmetric-log with ticks at 0, ±1, ±10, … labelled as plain numbers."""
    from matplotlib.ticker import MaxNLocator, NullLocator

    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    ax.axvline(0.0, color="0.3", lw=0.6, zorder=0)
    if not (v.size and v.min() < SYMLOG_FROM):
        # At least a nat in view: smaller differences are not worth a mention (Kass–Raftery).
        x0, x1 = ax.get_xlim()
        ax.set_xlim(min(x0, -1.0), max(x1, 0.25))
        ax.xaxis.set_major_locator(MaxNLocator(nbins=5))
        return
    ax.set_xscale("symlog", linthresh=SYMLOG_LINEAR, linscale=0.5)
    low = int(np.ceil(np.log10(-v.min())))
    high = int(np.ceil(np.log10(v.max()))) if v.max() > SYMLOG_LINEAR else -1
    ticks = [-(10.0**k) for k in range(low, -1, -1)] + [0.0] + [10.0**k for k in range(high + 1)]
    ax.set_xticks(ticks, [f"{t:,.0f}".replace("-", "−") for t in ticks])
    ax.xaxis.set_minor_locator(NullLocator())


def _label(name: str, converged: bool, fits: str) -> str:
    """A structure's tick label, with what the reader must know about it: a posterior that is
    not certified, and a structure that does not describe the data (adequacy checks)."""
    notes = [] if converged else ["not converged"]
    notes += {"no": ["misfits the data"], "small": ["small misfit"],
              "partly": ["misfit hidden by noise"]}.get(fits, [])
    return "\n".join([name, *notes])


def _right_labels(ax, y, labels):
    """A twin axes of ``ax`` carrying ``labels`` at ``y`` on the right (no ticks, no spines)."""
    right = ax.twinx()
    right.set_ylim(-0.6, len(labels) - 0.4)
    right.set_yticks(y, labels)
    right.tick_params(axis="y", length=0, labelsize=6.5)
    right.grid(False)
    for spine in right.spines.values():
        spine.set_visible(False)
    return right


def _split_rows(rows: list, limit: int | None) -> tuple[list, list, list]:
    """The rows drawn, the rows left out for the limit, and the hopeless ones (Δln Z below
    −:data:`HOPELESS_NATS`), each in the order of the ranking."""
    hopeless = [r for r in rows if r.get("delta_log_evidence") is not None
                and r["delta_log_evidence"] < -HOPELESS_NATS]
    kept = [r for r in rows if r not in hopeless]
    if limit is None:
        return kept, [], hopeless
    return kept[:limit], kept[limit:], hopeless


def _not_shown_note(left: list, hopeless: list) -> str:
    """What the figure leaves out, in words (empty when nothing)."""
    import textwrap

    def span(rows):
        d = [r["delta_log_evidence"] for r in rows if r.get("delta_log_evidence") is not None]
        if not d:
            return ""
        text = f"{max(d):,.3g}" + ("" if max(d) == min(d) else f" to {min(d):,.3g}")
        return f" (Δln Z {text})".replace("-", "−")

    def names(rows):
        shown = ", ".join(r["structure"] for r in rows[:4])
        return shown + (f" and {len(rows) - 4} more" if len(rows) > 4 else "")

    parts = []
    if left:
        parts.append(f"{len(left)} more structure{'s' if len(left) > 1 else ''}{span(left)}: "
                     f"{names(left)}")
    if hopeless:
        parts.append(f"{names(hopeless)}, ln Z over {HOPELESS_NATS:,.0f} nats below the best"
                     f"{span(hopeless)}")
    if not parts:
        return ""
    text = ("Not drawn: " + "; ".join(parts)
            + "; every structure is in the report's ranking table and ranking.csv")
    return "\n".join(textwrap.wrap(text, 68, break_on_hyphens=False))


def plot_ranking(comparison, fig=None, *, limit: int | None = RANKING_SHOWN) -> Drawn:
    """The structures' log-evidence and information criteria relative to the best.

    Top: Δln Z ± its error (bridge sampling) to the structure with the highest ln Z, with the
    posterior model probability on the right. Bottom: the criteria on the same scale of nats,
    higher is better: Δelpd (PSIS-LOO) ± the standard error of the difference (from the
    pointwise differences, as ``arviz.compare``'s ``dse``; the standard error of each elpd
    itself, ``loo_se`` of the table, is larger and not a measure of the difference), −ΔAIC/2
    and −ΔBIC/2 (BIC/−2
    approximates ln Z, AIC/−2 the expected log predictive density), each relative to its best
    structure. Structures run from the best (top) down in the order of the ranking; a structure
    whose posterior did not converge has a red label and a red marker. When differences exceed
    20 nats the axes are symmetric-logarithmic (linear within ±2 nats).

    The largest Pareto k̂ of each structure's PSIS-LOO is on the right of the criteria; above
    0.7 (red) PSIS-LOO is unreliable at some frequency and its marker is open with a red edge.
    WAIC is not drawn, and a note under the figure says why once: it estimates the same
    expected log predictive density as PSIS-LOO, has no diagnostic of its own, and arviz's
    variance warning on it fires for nearly every structure of real data, so a flag per
    structure would carry no information.

    At most ``limit`` structures are drawn, the best by the ranking; those beyond, and any
    whose ln Z trails the best by more than :data:`HOPELESS_NATS`, are named in a note under
    the figure (``values["not_shown"]``), so that the figure stays readable for any number
    of structures.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    fig : matplotlib.figure.Figure, optional
        Empty figure to draw in; default a new single-column figure.
    limit : int or None
        How many structures to draw (None: every one but the hopeless).

    Returns
    -------
    Drawn
        ``axes`` = (evidence, criteria). ``values`` (one entry per ranked structure, top to
        bottom): ``"structures"``, ``"y"``, ``"delta_log_evidence"``, ``"log_evidence_err"``,
        ``"posterior_probability"``, ``"delta_loo"``, ``"delta_loo_se"``, ``"delta_aic_half"``,
        ``"delta_bic_half"``, ``"converged"`` (NaN where a value is missing), ``"not_shown"``
        (the structures named in the note instead, in the order of the ranking), ``"fits"``
        (``"yes"``, ``"partly"``, ``"small"``, ``"no"`` from the adequacy checks; labels say
        "misfit hidden by noise", "misfits the data" or "small misfit"), ``"pareto_k_max"``; ``"note"`` (why WAIC is not shown).
        ``artists``: ``"<name>/log_evidence"`` (``ErrorbarContainer``), one
        ``ErrorbarContainer`` per criterion under its value key (the markers of PSIS-LOO shown
        only where k̂ ≤ 0.7), ``"delta_loo_unreliable"`` (``Line2D``: the open markers where
        k̂ > 0.7), ``"pareto_k"`` (the axes whose tick labels give k̂) and ``"note"``
        (``Text``).

    Raises
    ------
    InputError
        If no structure of the comparison succeeded.
    """
    rows = [row for row in comparison.table() if row.get("rank") is not None]
    if not rows:
        raise InputError("the comparison has no structure that ran")
    if limit is not None and (isinstance(limit, bool) or not isinstance(limit, int)
                              or limit < 1):
        raise InputError(f"argument 'limit' must be a positive integer or None, got {limit!r}")
    rows, left, hopeless = _split_rows(rows, limit)
    left_out = _not_shown_note(left, hopeless)
    n = len(rows)
    names = [row["structure"] for row in rows]
    y = np.arange(n - 1, -1, -1, dtype=float)
    best_aic = min(row["aic"] for row in rows)
    best_bic = min(row["bic"] for row in rows)
    values = {
        "structures": np.array(names), "y": y,
        "delta_log_evidence": np.array([_nan(r["delta_log_evidence"]) for r in rows]),
        "log_evidence_err": np.array([_nan(r["log_evidence_err"]) for r in rows]),
        "posterior_probability": np.array([_nan(r["posterior_probability"]) for r in rows]),
        "delta_loo": np.array([r["delta_loo"] for r in rows], float),
        "delta_loo_se": np.array([_nan(r.get("delta_loo_se")) for r in rows]),
        "delta_aic_half": np.array([-(r["aic"] - best_aic) / 2 for r in rows], float),
        "delta_bic_half": np.array([-(r["bic"] - best_bic) / 2 for r in rows], float),
        "converged": np.array([bool(r["converged"]) for r in rows]),
        "fits": np.array([r.get("fits") or "" for r in rows]),
        "pareto_k_max": np.array([_nan(r.get("pareto_k_max")) for r in rows]),
        "note": WAIC_NOTE + ("\n" + left_out if left_out else ""),
        "not_shown": [r["structure"] for r in left + hopeless],
    }
    styles = comparison_styles(comparison)
    artists = {}
    with style():
        fig = new_figure(fig, (COLUMN_WIDTH, min(9.5, 1.45 + 0.62 * n)))
        ax_z, ax_c = fig.subplots(2, 1, sharey=True, height_ratios=[1, 1.15])
        for i, name in enumerate(names):
            dz = values["delta_log_evidence"][i]
            ok = values["converged"][i]
            st = styles.get(name)
            c, m = (st.color, st.marker) if st is not None else ("0.4", "o")
            cont = ax_z.errorbar([dz], [y[i]], xerr=[values["log_evidence_err"][i]], fmt=m,
                                 ms=4.5, color=c, mfc=c if ok else "white",
                                 mec=c if ok else FLAG_COLOR, mew=1.1, elinewidth=1.0, zorder=4)
            artists[f"{name}/log_evidence"] = cont
            if not np.isfinite(dz):
                ax_z.text(0.0, y[i], "no ln Z  ", ha="right", va="center", fontsize=6.5)
        _set_delta_scale(ax_z, values["delta_log_evidence"])
        ax_z.set_xlabel(r"$\Delta \ln Z$ to the best [nats]")
        k = values["pareto_k_max"]
        bad = np.isfinite(k) & (k > PARETO_K_WARN)
        for key, label, marker, face, dodge in CRITERIA:
            err = values["delta_loo_se"] if key == "delta_loo" else None
            cont = ax_c.errorbar(values[key], y + dodge, xerr=err, fmt=marker, ms=3.6,
                                 color="black", mfc=face, mec="black", mew=0.7, elinewidth=0.8,
                                 label=label, zorder=4)
            artists[key] = cont
        # PSIS-LOO where its Pareto k̂ says it is unreliable: an open marker with a red edge.
        loo_marks = artists["delta_loo"].lines[0]
        loo_marks.set_markevery(np.flatnonzero(~bad).tolist())
        (artists["delta_loo_unreliable"],) = ax_c.plot(
            values["delta_loo"][bad], (y + CRITERIA[0][4])[bad], ls="none", marker="o", ms=3.6,
            mfc="white", mec=FLAG_COLOR, mew=0.9, zorder=5)
        k_labels = ["k̂ n/a" if not np.isfinite(v) else f"k̂ {v:.2f}" for v in k]
        right_c = _right_labels(ax_c, y, k_labels)
        for tick, flagged in zip(right_c.get_yticklabels(), bad):
            if flagged:
                tick.set_color(FLAG_COLOR)
        artists["pareto_k"] = right_c
        _set_delta_scale(ax_c, np.concatenate([values[k] for k, *_ in CRITERIA]
                                              + [values["delta_loo"] + values["delta_loo_se"]]))
        ax_c.set_xlabel(r"$\Delta$ to the best [nats], higher is better")
        artists["note"] = fig.supxlabel(values["note"], fontsize=6.0, color="0.25")
        # Posterior probabilities on the right of the evidence (the last axes of the figure).
        _right_labels(ax_z, y, [_format_p(p) for p in values["posterior_probability"]])
        # Right-aligned with the axes: their right edge stays inside the figure however long
        # the structure names on the left are.
        ax_c.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), ncols=3, borderaxespad=0.1,
                    handletextpad=0.3, columnspacing=0.8)
        for ax in (ax_z, ax_c):
            ax.set_ylim(-0.6, n - 0.4)
            ax.set_yticks(y, [_label(nm, ok, fit) for nm, ok, fit
                              in zip(names, values["converged"], values["fits"])])
            ax.grid(axis="y", visible=False)
            for tick, ok in zip(ax.get_yticklabels(), values["converged"]):
                if not ok:
                    tick.set_color(FLAG_COLOR)
        ax_c.tick_params(axis="y", labelleft=True)
    return Drawn.build(fig, (ax_z, ax_c), values, artists)
