"""Model responses against the data: Bode and Nyquist diagrams and normalised residuals.

Curves are posterior summaries of the *model response* G(jω; θ) over posterior draws of θ
(physical units, at most ``n_draws`` of them chosen with ``numpy.random.default_rng(seed)``),
i.e. parameter uncertainty without the measurement noise. Quantiles are taken pointwise in ω
and separately for each plotted quantity (|G|, arg G, Re G, Im G).

Error bars of the data: σ is the standard deviation of the complex value (real and imaginary
parts σ/√2 each, see :class:`~bayesfo.data.FrequencyResponse`), so one standard deviation is
σ/√2 along each of Re G and Im G, σ/√2 in |G| and σ/(√2 |G|) rad in arg G (small-noise
approximation).
"""

from __future__ import annotations

import math

import numpy as np

from ._base import Drawn, axes_or_new, new_figure
from ._compute import (
    N_DRAWS,
    N_GRID,
    omega_grid,
    quantiles,
    response_draws,
    select_results,
    thin_indices,
    unwrapped_phase_deg,
)
from .style import COLUMN_WIDTH, DATA_COLOR, colors_for, quantity_symbol, style, unit_suffix

OMEGA_LABEL = r"$\omega$ [rad/s]"
BAND_ALPHA = {90: 0.16, 50: 0.34}
HOLDOUT_STYLE = dict(marker="D", mfc="white", mec=DATA_COLOR, color=DATA_COLOR, ms=4.0, mew=0.9)
DATA_STYLE = dict(fmt="o", color=DATA_COLOR, ms=3.0, elinewidth=0.7, zorder=5)


def _key(name: str, quantity: str, p: float) -> str:
    return f"{name}/{quantity}_" + ("median" if p == 0.5 else f"q{round(100 * p):02d}")


def _band(ax, x, qs, color):
    """90 % and 50 % bands and the median line; returns the three artists."""
    outer = ax.fill_between(x, qs[0.05], qs[0.95], color=color, alpha=BAND_ALPHA[90], lw=0)
    inner = ax.fill_between(x, qs[0.25], qs[0.75], color=color, alpha=BAND_ALPHA[50], lw=0)
    (line,) = ax.plot(x, qs[0.5], color=color, lw=1.1)
    return outer, inner, line


def _band_handle(color):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    return (Patch(color=color, alpha=BAND_ALPHA[90], lw=0),
            Patch(color=color, alpha=BAND_ALPHA[50], lw=0), Line2D([], [], color=color, lw=1.1))


def _legend(fig, handles, labels):
    from matplotlib.legend_handler import HandlerTuple

    ncols = min(len(handles), 3)
    return fig.legend(handles, labels, loc="outside upper center", ncols=ncols,
                      handler_map={tuple: HandlerTuple(ndivide=1, pad=0.0)})


def _points(data, phase: bool):
    """Sorted ω, |G|, unwrapped phase and their one-standard-deviation errors (or None)."""
    order = np.argsort(data.omega)
    w = data.omega[order]
    g = data.response[order]
    mag = np.abs(g)
    ph = unwrapped_phase_deg(g, w) if phase else None
    if data.sigma is None:
        return w, g, mag, ph, None, None
    s = data.sigma[order] / math.sqrt(2.0)
    return w, g, mag, ph, s, np.degrees(np.minimum(s / mag, np.pi))


def plot_bode(comparison, structures=None, fig=None, *, n_draws: int = N_DRAWS, seed: int = 0,
              n_grid: int = N_GRID) -> Drawn:
    """Bode diagram: magnitude and phase of the data and of each structure's posterior.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    structures : sequence of str or StructureResult, optional
        Structures to draw (default: the best three by the ranking).
    fig : matplotlib.figure.Figure, optional
        Figure to draw in (two axes are added); default a new single-column figure.
    n_draws : int
        Posterior draws pushed through the model (at most; fewer if the posterior has fewer).
    seed : int
        Seed of the choice of draws.
    n_grid : int
        Points of the log-spaced ω grid from the lowest to the highest measured frequency.

    Returns
    -------
    Drawn
        ``axes`` = (magnitude, phase). ``values``: ``"omega"`` (grid [rad/s]);
        ``"data/omega"``, ``"data/magnitude"``, ``"data/phase"`` [deg] (sorted by ω, phase
        unwrapped), ``"data/magnitude_err"``, ``"data/phase_err"`` (when σ is known); the same
        under ``"holdout/"`` for held-out points; per structure ``"<name>/magnitude_median"``,
        ``"<name>/magnitude_q05"``, ``_q25``, ``_q75``, ``_q95`` and the same for ``phase``.
        ``artists``: the median lines (``Line2D``) and bands (``"<name>/magnitude_band50"``,
        ``_band90``, ``PolyCollection``) and the data (``ErrorbarContainer``).

    Raises
    ------
    InputError
        If a structure is not in the comparison or failed.

    Examples
    --------
    >>> drawn = plot_bode(comparison)                                    # doctest: +SKIP
    >>> drawn.figure.savefig("bode.png")                                 # doctest: +SKIP
    """
    import matplotlib.ticker as mticker

    results = select_results(comparison, structures)
    data = comparison.data
    omega = omega_grid(comparison, n_grid)
    colors = colors_for(comparison.ranking)
    sym = quantity_symbol(data.kind)
    values, artists = {"omega": omega}, {}
    handles, labels = [], []
    with style():
        fig = new_figure(fig, (COLUMN_WIDTH, 4.0))
        ax_mag, ax_ph = fig.subplots(2, 1, sharex=True)
        for r in results:
            g = response_draws(r, omega, data.kind, n_draws, seed)
            c = colors[r.name]
            for ax, quantity, x in ((ax_mag, "magnitude", np.abs(g)),
                                    (ax_ph, "phase", unwrapped_phase_deg(g, omega))):
                qs = quantiles(x)
                for p, v in qs.items():
                    values[_key(r.name, quantity, p)] = v
                outer, inner, line = _band(ax, omega, qs, c)
                artists[f"{r.name}/{quantity}_band90"] = outer
                artists[f"{r.name}/{quantity}_band50"] = inner
                artists[f"{r.name}/{quantity}_median"] = line
            handles.append(_band_handle(c))
            labels.append(r.name)
        for prefix, d in (("data", data), ("holdout", comparison.holdout)):
            if d is None:
                continue
            w, _, mag, ph, mag_err, ph_err = _points(d, phase=True)
            values.update({f"{prefix}/omega": w, f"{prefix}/magnitude": mag, f"{prefix}/phase": ph})
            if mag_err is not None:
                values.update({f"{prefix}/magnitude_err": mag_err, f"{prefix}/phase_err": ph_err})
            kw = DATA_STYLE if prefix == "data" else dict(HOLDOUT_STYLE, fmt="none", zorder=6,
                                                           elinewidth=0.7)
            for ax, y, err, q in ((ax_mag, mag, mag_err, "magnitude"),
                                  (ax_ph, ph, ph_err, "phase")):
                artists[f"{prefix}/{q}"] = ax.errorbar(w, y, yerr=err, **kw)
                if prefix == "holdout":
                    (marks,) = ax.plot(w, y, ls="none", zorder=6, **HOLDOUT_STYLE)
            if prefix == "data":
                handles.append(artists["data/magnitude"])
                labels.append("data ± 1 sd" if mag_err is not None else "data")
            else:
                handles.append(marks)
                labels.append("held out")
        ax_mag.set_xscale("log")
        ax_mag.set_yscale("log")
        ax_mag.set_ylabel(f"|${sym}$|{unit_suffix(data.units)}")
        ax_ph.set_ylabel(f"arg ${sym}$ [deg]")
        ax_ph.set_xlabel(OMEGA_LABEL)
        ax_ph.yaxis.set_major_locator(mticker.MaxNLocator(nbins=5, steps=[1, 1.5, 3, 5, 10]))
        _legend(fig, handles, labels)
    return Drawn.build(fig, (ax_mag, ax_ph), values, artists)


def plot_nyquist(comparison, structures=None, ax=None, *, n_draws: int = N_DRAWS, seed: int = 0,
                 n_grid: int = N_GRID, n_lines: int = 40) -> Drawn:
    """Nyquist diagram (Im G against Re G) of the data and each structure's posterior.

    The posterior is shown as its pointwise median curve (median of Re G and of Im G
    separately at each ω of the grid) and, for its spread, ``n_lines`` thin curves of single
    posterior draws: in the complex plane a band of separate quantiles of Re and Im has no
    natural shape, while the draws show where the curve may run and how it is correlated
    along ω.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    structures : sequence of str or StructureResult, optional
        Default: the best three by the ranking.
    ax : matplotlib.axes.Axes, optional
    n_draws, seed, n_grid
        As in :func:`plot_bode`.
    n_lines : int
        Single-draw curves per structure (a subset of the ``n_draws``; 0 for none).

    Returns
    -------
    Drawn
        ``axes`` = (ax,). ``values``: ``"omega"``; ``"data/real"``, ``"data/imag"`` (and
        ``"data/err"`` = σ/√2 when σ is known; ``"holdout/…"`` likewise); per structure
        ``"<name>/real_median"``, ``"<name>/imag_median"`` and ``"<name>/draws"`` (complex,
        shape (n_lines, n_grid)). ``artists``: ``"<name>/median"`` (``Line2D``),
        ``"<name>/draws"`` (``LineCollection``), ``"data"``, ``"holdout"``.

    Raises
    ------
    InputError
        If a structure is not in the comparison or failed.
    """
    from matplotlib.collections import LineCollection

    results = select_results(comparison, structures)
    data = comparison.data
    omega = omega_grid(comparison, n_grid)
    colors = colors_for(comparison.ranking)
    sym = quantity_symbol(data.kind)
    units = unit_suffix(data.units)
    values, artists = {"omega": omega}, {}
    handles, labels = [], []
    with style():
        fig, ax = axes_or_new(ax, (COLUMN_WIDTH, 3.4))
        for r in results:
            g = response_draws(r, omega, data.kind, n_draws, seed)
            c = colors[r.name]
            re_med, im_med = np.median(g.real, axis=0), np.median(g.imag, axis=0)
            values[f"{r.name}/real_median"] = re_med
            values[f"{r.name}/imag_median"] = im_med
            if n_lines > 0:
                sub = g[thin_indices(g.shape[0], n_lines, seed + 1)]
                values[f"{r.name}/draws"] = sub
                segs = np.stack([sub.real, sub.imag], axis=-1)
                coll = LineCollection(segs, colors=c, linewidths=0.4, alpha=0.25, zorder=1)
                ax.add_collection(coll)
                artists[f"{r.name}/draws"] = coll
            (line,) = ax.plot(re_med, im_med, color=c, lw=1.2, zorder=3)
            artists[f"{r.name}/median"] = line
            handles.append(line)
            labels.append(r.name)
        for prefix, d in (("data", data), ("holdout", comparison.holdout)):
            if d is None:
                continue
            w, g, *_ = _points(d, phase=False)
            err = None if d.sigma is None else d.sigma[np.argsort(d.omega)] / math.sqrt(2.0)
            values.update({f"{prefix}/omega": w, f"{prefix}/real": g.real,
                           f"{prefix}/imag": g.imag})
            if err is not None:
                values[f"{prefix}/err"] = err
            if prefix == "data":
                cont = ax.errorbar(g.real, g.imag, xerr=err, yerr=err, **DATA_STYLE)
                handles.append(cont)
                labels.append("data ± 1 sd" if err is not None else "data")
            else:
                cont = ax.errorbar(g.real, g.imag, xerr=err, yerr=err, fmt="none",
                                   ecolor=DATA_COLOR, elinewidth=0.7, zorder=6)
                (pts,) = ax.plot(g.real, g.imag, ls="none", zorder=6, **HOLDOUT_STYLE)
                handles.append(pts)
                labels.append("held out")
            artists[prefix] = cont
        ax.autoscale_view()
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel(f"Re ${sym}${units}")
        ax.set_ylabel(f"Im ${sym}${units}")
        ax.ticklabel_format(style="sci", scilimits=(-3, 4), useMathText=True)
        ax.legend(handles, labels, loc="best")
    return Drawn.build(fig, (ax,), values, artists)


def plot_residuals(comparison, structures=None, ax=None, *, n_draws: int = N_DRAWS,
                   seed: int = 0) -> Drawn:
    """Residuals of the data from each structure's posterior median prediction, against ω.

    The prediction is the pointwise posterior median of Re G and of Im G at the measured
    frequencies. With σ known the residuals are divided by σ/√2, the standard deviation of each
    part, so that they are standard normal when the model is right (dotted lines at ±2);
    otherwise they are relative to the measured |G|, in percent. Points of different
    structures are offset slightly along ω (by ±1.5 % of a decade per structure) to keep them
    apart; held-out points are drawn as diamonds.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    structures : sequence of str or StructureResult, optional
        Default: the best three by the ranking.
    ax : matplotlib.axes.Axes or pair of Axes, optional
        Two axes (real part, imaginary part), or one axes for both (real parts filled, imaginary
        parts open markers). Default: a new figure with two stacked axes.
    n_draws, seed
        As in :func:`plot_bode`.

    Returns
    -------
    Drawn
        ``axes`` = (real, imag) (the same axes twice when one was given). ``values``:
        ``"data/omega"``; per structure ``"<name>/real"``, ``"<name>/imag"`` (normalised
        residuals at ``data/omega``), ``"<name>/prediction"`` (complex median prediction), and
        with held-out points ``"holdout/omega"``, ``"<name>/holdout_real"``,
        ``"<name>/holdout_imag"``; ``"scale"`` (the divisor of the data points).
        ``artists``: ``"<name>/real"``, ``"<name>/imag"`` (``Line2D``) and the hold-out ones.

    Raises
    ------
    InputError
        If a structure is not in the comparison or failed.
    """
    results = select_results(comparison, structures)
    data = comparison.data
    colors = colors_for(comparison.ranking)
    known = data.sigma is not None
    values, artists = {}, {}
    with style():
        if ax is None:
            fig = new_figure(None, (COLUMN_WIDTH, 3.6))
            ax_re, ax_im = fig.subplots(2, 1, sharex=True)
        elif isinstance(ax, (list, tuple, np.ndarray)):
            ax_re, ax_im = ax
            fig = ax_re.figure
        else:
            fig, ax_re, ax_im = ax.figure, ax, ax
        single = ax_re is ax_im
        sets = [("data", data)] + ([("holdout", comparison.holdout)]
                                   if comparison.holdout is not None else [])
        for prefix, d in sets:
            order = np.argsort(d.omega)
            w, g = d.omega[order], d.response[order]
            scale = d.sigma[order] / math.sqrt(2.0) if known else np.abs(g) / 100.0
            values[f"{prefix}/omega"] = w
            values["scale" if prefix == "data" else "holdout/scale"] = scale
            for i, r in enumerate(results):
                pred_draws = response_draws(r, w, d.kind, n_draws, seed)
                pred = np.median(pred_draws.real, axis=0) + 1j * np.median(pred_draws.imag, axis=0)
                res = (g - pred) / scale
                tag = "" if prefix == "data" else "holdout_"
                values[f"{r.name}/{tag}prediction"] = pred
                values[f"{r.name}/{tag}real"] = res.real
                values[f"{r.name}/{tag}imag"] = res.imag
                dodge = w * 10 ** (0.015 * (i - (len(results) - 1) / 2))
                c = colors[r.name]
                marker = "o" if prefix == "data" else "D"
                for part, a, y in (("real", ax_re, res.real), ("imag", ax_im, res.imag)):
                    filled = not (single and part == "imag") and prefix == "data"
                    label = r.name if prefix == "data" and part == "real" else None
                    (pts,) = a.plot(dodge, y, ls="none", marker=marker, color=c,
                                    mfc=c if filled else "white", mec=c, ms=3.2 if filled else 3.6,
                                    mew=0.8, label=label)
                    artists[f"{r.name}/{tag}{part}"] = pts
        ylabel = "residual / (σ/√2)" if known else "residual / |data| [%]"
        for a, part in ((ax_re, "Re"), (ax_im, "Im")):
            a.axhline(0.0, color="0.3", lw=0.6, zorder=0)
            if known:
                for y in (-2.0, 2.0):
                    a.axhline(y, color="0.5", lw=0.6, ls=":", zorder=0)
            a.set_xscale("log")
            a.set_ylabel(ylabel if single else f"{part} {ylabel}")
        ax_im.set_xlabel(OMEGA_LABEL)
        handles, labels = ax_re.get_legend_handles_labels()
        if comparison.holdout is not None:
            from matplotlib.lines import Line2D

            handles.append(Line2D([], [], ls="none", **HOLDOUT_STYLE))
            labels.append("held out")
        if single:
            ax_re.legend(handles, labels, loc="best", title="filled Re, open Im")
        else:
            _legend(fig, handles, labels)
    return Drawn.build(fig, (ax_re, ax_im), values, artists)
