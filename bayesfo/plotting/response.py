"""Model responses against the data: Bode and Nyquist diagrams and normalised residuals.

Curves are posterior summaries of the *model response* G(jω; θ) over posterior draws of θ
(physical units, at most ``n_draws`` of them chosen with ``numpy.random.default_rng(seed)``),
i.e. parameter uncertainty without the measurement noise. Quantiles are taken pointwise in ω
and separately for each plotted quantity (|G|, arg G, Re G, Im G).

Error bars of the data: σ is the standard deviation of the complex value (real and imaginary
parts σ/√2 each, see :class:`~bayesfo.data.FrequencyResponse`), so one standard deviation is
σ/√2 along each of Re G and Im G, σ/√2 in |G| and σ/(√2 |G|) rad in arg G (small-noise
approximation).

Each structure has its own colour, line style and marker (:func:`~bayesfo.plotting.style.
structure_styles`), so that curves drawn on top of each other stay visible; when the curves of
two structures agree within a line width everywhere, the legend says so ("voigt and zener
coincide").

This module is longer than the project's 500-line guide: Bode, Nyquist (linear and
log-magnitude) and residuals share the posterior bands, the legend with its coincidence note
and the per-structure styles.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ._base import Drawn, axes_or_new, new_figure
from ._compute import (
    N_DRAWS,
    N_GRID,
    NYQUIST_LOG_DECADES,
    coincidence_note,
    coincident_groups,
    legend_name,
    magnitude_decades,
    omega_grid,
    quantiles,
    response_draws,
    select_results,
    thin_indices,
    unwrapped_phase_deg,
)
from ._legend import _legend, _note_artists
from .style import (
    COLUMN_WIDTH,
    DATA_COLOR,
    comparison_styles,
    quantity_symbol,
    style,
    unit_suffix,
)

OMEGA_LABEL = r"$\omega$ [rad/s]"
BAND_ALPHA = {90: 0.16, 50: 0.34}
HOLDOUT_STYLE = dict(marker="D", mfc="white", mec=DATA_COLOR, color=DATA_COLOR, ms=4.0, mew=0.9)
DATA_STYLE = dict(fmt="o", color=DATA_COLOR, ms=3.0, elinewidth=0.7, zorder=5)


def _key(name: str, quantity: str, p: float) -> str:
    return f"{name}/{quantity}_" + ("median" if p == 0.5 else f"q{round(100 * p):02d}")


def _band(ax, x, qs, st):
    """90 % and 50 % bands and the median line of a structure of style ``st``; returns the
    three artists."""
    outer = ax.fill_between(x, qs[0.05], qs[0.95], color=st.color, alpha=BAND_ALPHA[90], lw=0)
    inner = ax.fill_between(x, qs[0.25], qs[0.75], color=st.color, alpha=BAND_ALPHA[50], lw=0)
    (line,) = ax.plot(x, qs[0.5], **st.line(lw=1.1))
    return outer, inner, line


def positive_band(ax, x, draws, st, name: str, quantity: str, values: dict,
                  artists: dict) -> None:
    """The quantiles of ``draws`` (draws × len(x)) under ``values["<name>/<quantity>_..."]``,
    and their bands and median on ``ax`` (a log axis: where a quantile is not positive, a
    misfitting structure's, that stretch is left out) under ``artists``."""
    qs = quantiles(draws)
    for p, v in qs.items():
        values[_key(name, quantity, p)] = v
    shown = {p: np.where(v > 0, v, np.nan) for p, v in qs.items()}
    outer, inner, line = _band(ax, x, shown, st)
    artists[f"{name}/{quantity}_band90"] = outer
    artists[f"{name}/{quantity}_band50"] = inner
    artists[f"{name}/{quantity}_median"] = line


def _band_handle(st):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    return (Patch(color=st.color, alpha=BAND_ALPHA[90], lw=0),
            Patch(color=st.color, alpha=BAND_ALPHA[50], lw=0), Line2D([], [], **st.line(lw=1.1)))


def _span(ax, log: bool = False) -> float:
    lo, hi = ax.get_ylim()
    return float(np.log10(hi / lo)) if log else float(hi - lo)


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
        ``_band90``, ``PolyCollection``) and the data (``ErrorbarContainer``); ``"note"``
        (the legend title ``Text``) when the median curves of structures coincide, its text
        also under ``values["note"]`` (empty otherwise).

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
    styles = comparison_styles(comparison)
    sym = quantity_symbol(data.kind, data.symbol)
    values, artists = {"omega": omega}, {}
    handles, labels = [], []
    with style():
        fig = new_figure(fig, (COLUMN_WIDTH, 4.0))
        ax_mag, ax_ph = fig.subplots(2, 1, sharex=True)
        for r in results:
            g = response_draws(r, omega, data.kind, n_draws, seed)
            st = styles[r.name]
            for ax, quantity, x in ((ax_mag, "magnitude", np.abs(g)),
                                    (ax_ph, "phase", unwrapped_phase_deg(g, omega))):
                qs = quantiles(x)
                for p, v in qs.items():
                    values[_key(r.name, quantity, p)] = v
                outer, inner, line = _band(ax, omega, qs, st)
                artists[f"{r.name}/{quantity}_band90"] = outer
                artists[f"{r.name}/{quantity}_band50"] = inner
                artists[f"{r.name}/{quantity}_median"] = line
            handles.append(_band_handle(st))
            labels.append(legend_name(r))
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
        names = [r.name for r in results]
        note = coincidence_note({
            "magnitude": coincident_groups(
                {n: np.log10(values[f"{n}/magnitude_median"]) for n in names},
                _span(ax_mag, log=True)),
            "phase": coincident_groups({n: values[f"{n}/phase_median"] for n in names},
                                       _span(ax_ph))})
        values["note"] = note
        legend = _legend(fig, handles, labels, note)
        artists.update(_note_artists(legend, note))
    return Drawn.build(fig, (ax_mag, ax_ph), values, artists)


def plot_nyquist(comparison, structures=None, ax=None, *, n_draws: int = N_DRAWS, seed: int = 0,
                 n_grid: int = N_GRID, n_lines: int = 40, form: str = "auto") -> Drawn:
    """Nyquist diagram of the data and each structure's posterior: linear (Im G against Re G on
    equal axes) or, for data over many decades of |G|, log-magnitude (polar: angle arg G,
    radius log10 |G|).

    The posterior is shown as its pointwise median curve (median of Re G and of Im G
    separately at each ω of the grid) and, for its spread, ``n_lines`` thin curves of single
    posterior draws: in the complex plane a band of separate quantiles of Re and Im has no
    natural shape, while the draws show where the curve may run and how it is correlated
    along ω.

    On linear axes, data over many decades of |G| crowd into one corner, so by default
    (``form="auto"``) the diagram is log-magnitude when |G| of the data spans more than
    :data:`~bayesfo.plotting._compute.NYQUIST_LOG_DECADES` decades: the same complex plane
    with the true angle arg G and the radius log10 |G| from the decade below the smallest
    measured |G| (values below it are drawn at the centre). The title states the form.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    structures : sequence of str or StructureResult, optional
        Default: the best three by the ranking.
    ax : matplotlib.axes.Axes, optional
        For the log-magnitude form a polar axes; a Cartesian one is replaced by a polar axes
        at the same place.
    n_draws, seed, n_grid : int
        As in :func:`plot_bode`.
    n_lines : int
        Single-draw curves per structure (a subset of the ``n_draws``; 0 for none).
    form : {"auto", "linear", "log"}
        The form of the diagram (see above).

    Returns
    -------
    Drawn
        ``axes`` = (ax,). ``values``: ``"omega"``; ``"form"`` (``"linear"`` or ``"log"``),
        ``"decades"`` (of |G| of the data); ``"data/real"``, ``"data/imag"`` (and
        ``"data/err"`` = σ/√2 when σ is known; ``"holdout/…"`` likewise); per structure
        ``"<name>/real_median"``, ``"<name>/imag_median"`` and ``"<name>/draws"`` (complex,
        shape (n_lines, n_grid)); for the log form ``"log_origin"`` (log10 |G| at the centre).
        ``"note"``: which structures coincide (empty when none). ``artists``:
        ``"<name>/median"`` (``Line2D``: x, y = Re, Im, or angle [rad], log10 |G| in the log
        form), ``"<name>/draws"`` (``LineCollection``), ``"data"``, ``"holdout"``, ``"title"``
        and ``"note"`` (the legend title) when curves coincide.

    Raises
    ------
    InputError
        If a structure is not in the comparison or failed, or ``form`` is unknown.
    """
    from matplotlib.collections import LineCollection

    if form not in ("auto", "linear", "log"):
        raise InputError(f"argument 'form' must be 'auto', 'linear' or 'log', got {form!r}")
    results = select_results(comparison, structures)
    data = comparison.data
    holdout = comparison.holdout
    decades = magnitude_decades(data.response,
                                None if holdout is None else holdout.response)
    if form == "auto":
        form = "log" if decades > NYQUIST_LOG_DECADES else "linear"
    log = form == "log"
    omega = omega_grid(comparison, n_grid)
    styles = comparison_styles(comparison)
    sym = quantity_symbol(data.kind, data.symbol)
    units = unit_suffix(data.units)
    values = {"omega": omega, "form": form, "decades": decades}
    artists = {}
    handles, labels = [], []
    measured = np.concatenate([data.response] + ([] if holdout is None else [holdout.response]))
    measured = measured[np.abs(measured) > 0]
    if log:
        origin = math.floor(math.log10(np.abs(measured).min()))
        centre = float(np.angle(np.mean(measured / np.abs(measured))))
        values["log_origin"] = origin

    def coords(g):
        """(x, y) of complex values in the plotted form."""
        g = np.asarray(g)
        if not log:
            return g.real, g.imag
        with np.errstate(divide="ignore"):
            r = np.maximum(np.log10(np.abs(g)), origin)
        return centre + np.angle(g * np.exp(-1j * centre)), r

    own_figure = ax is None
    with style():
        fig, ax = (_polar_axes(ax, (COLUMN_WIDTH, 3.6)) if log
                   else axes_or_new(ax, (COLUMN_WIDTH, 3.4)))
        medians = {}
        for r in results:
            g = response_draws(r, omega, data.kind, n_draws, seed)
            st = styles[r.name]
            re_med, im_med = np.median(g.real, axis=0), np.median(g.imag, axis=0)
            values[f"{r.name}/real_median"] = re_med
            values[f"{r.name}/imag_median"] = im_med
            medians[r.name] = re_med + 1j * im_med
            if n_lines > 0:
                sub = g[thin_indices(g.shape[0], n_lines, seed + 1)]
                values[f"{r.name}/draws"] = sub
                segs = np.stack(coords(sub), axis=-1)
                coll = LineCollection(segs, colors=st.color, linewidths=0.4, alpha=0.25,
                                      zorder=1)
                ax.add_collection(coll)
                artists[f"{r.name}/draws"] = coll
            (line,) = ax.plot(*coords(medians[r.name]), **st.line(lw=1.2, zorder=3))
            artists[f"{r.name}/median"] = line
            handles.append(line)
            labels.append(legend_name(r))
        for prefix, d in (("data", data), ("holdout", holdout)):
            if d is None:
                continue
            w, g, *_ = _points(d, phase=False)
            err = None if d.sigma is None else d.sigma[np.argsort(d.omega)] / math.sqrt(2.0)
            values.update({f"{prefix}/omega": w, f"{prefix}/real": g.real,
                           f"{prefix}/imag": g.imag})
            if err is not None:
                values[f"{prefix}/err"] = err
            x, y = coords(g)
            # One sd along Re and Im is σ/√2 in |G| and σ/(√2 |G|) rad in arg G.
            xerr, yerr = ((err, err) if not log or err is None else
                          (np.minimum(err / np.abs(g), np.pi),
                           err / (np.abs(g) * math.log(10.0))))
            if prefix == "data":
                cont = ax.errorbar(x, y, xerr=xerr, yerr=yerr, **DATA_STYLE)
                handles.append(cont)
                labels.append("data ± 1 sd" if err is not None else "data")
            else:
                cont = ax.errorbar(x, y, xerr=xerr, yerr=yerr, fmt="none",
                                   ecolor=DATA_COLOR, elinewidth=0.7, zorder=6)
                (pts,) = ax.plot(x, y, ls="none", zorder=6, **HOLDOUT_STYLE)
                handles.append(pts)
                labels.append("held out")
            artists[prefix] = cont
        if log:
            top, aspect = _log_nyquist_axes(ax, origin, measured, medians, coords)
            if own_figure:
                # The sector keeps its shape: the figure's height follows it, so that the
                # sector fills the column width and its labels stay inside the figure.
                fig.set_size_inches(COLUMN_WIDTH, min(6.0, 1.35 + 2.9 * aspect))
            span = top - origin
            planar = {n: (y - origin) * np.exp(1j * x)
                      for n, (x, y) in ((n, coords(m)) for n, m in medians.items())}
            title = (f"log-magnitude Nyquist: |${sym}$| spans {decades:.1f} decades\n"
                     f"radius |${sym}$|{units} on a log scale, angle arg ${sym}$")
        else:
            ax.autoscale_view()
            ax.set_aspect("equal", adjustable="datalim")
            ax.set_xlabel(f"Re ${sym}${units}")
            ax.set_ylabel(f"Im ${sym}${units}")
            ax.ticklabel_format(style="sci", scilimits=(-3, 4), useMathText=True)
            (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
            span = max(x1 - x0, y1 - y0)
            planar = medians
            title = "Nyquist diagram (linear axes)"
        artists["title"] = ax.set_title(title, fontsize=7.0)
        note = coincidence_note({"plane": coincident_groups(planar, span)})
        values["note"] = note
        if own_figure:
            legend = _legend(fig, handles, labels, note)
        else:
            legend = ax.legend(handles, labels, loc="best", title=note or None,
                               title_fontsize=7.0)
        artists.update(_note_artists(legend, note))
    return Drawn.build(fig, (ax,), values, artists)


def _polar_axes(ax, size):
    """(figure, polar axes): ``ax`` if polar, else a polar axes in its place (or a new one)."""
    if ax is None:
        fig = new_figure(None, size)
        return fig, fig.add_subplot(projection="polar")
    if ax.name == "polar":
        return ax.figure, ax
    fig = ax.figure
    spec = ax.get_subplotspec()
    where = spec if spec is not None else ax.get_position()
    ax.remove()
    return fig, (fig.add_subplot(where, projection="polar") if spec is not None
                 else fig.add_axes(where, projection="polar"))


#: Narrowest sector of a log-magnitude Nyquist diagram [deg].
MIN_SECTOR = 45.0


def _log_nyquist_axes(ax, origin, measured, medians, coords) -> float:
    """Sector, radial decades and angles of a log-magnitude Nyquist diagram; returns the
    outer radius (log10 |G|) and the height/width ratio of the sector."""
    import matplotlib.ticker as mticker

    seen = np.degrees(coords(measured)[0])
    model = np.degrees(np.concatenate([coords(m)[0] for m in medians.values()] or [seen]))
    # The sector holds the data with half a degree to spare and the model curves within a
    # degree (a curve that ends just outside is cut rather than the sector widened by 15°).
    lo = 15.0 * math.floor(min(seen.min() - 0.5, model.min() + 1.0) / 15.0)
    hi = 15.0 * math.ceil(max(seen.max() + 0.5, model.max() - 1.0) / 15.0)
    if hi - lo < MIN_SECTOR:
        # A sector wide enough that the angle reads at a glance: from 0° up for data of
        # positive phase (moduli), down for negative phase (compliances).
        if lo >= 0.0:
            hi = lo + MIN_SECTOR
        elif hi <= 0.0:
            lo = hi - MIN_SECTOR
        else:
            extra = MIN_SECTOR - (hi - lo)
            lo, hi = lo - 15.0 * math.floor(extra / 30.0), hi + 15.0 * math.ceil(extra / 30.0)
    if hi - lo >= 300.0:
        lo, hi = -180.0, 180.0
    ax.set_thetamin(lo)
    ax.set_thetamax(hi)
    step = 15.0 if hi - lo <= 120.0 else 30.0 if hi - lo <= 240.0 else 45.0
    ticks = np.arange(lo, hi + 0.1, step)
    ax.set_thetagrids(ticks, [f"{t:g}°".replace("-", "−") for t in ticks])
    top = max([float(coords(measured)[1].max())]
              + [float(coords(m)[1].max()) for m in medians.values()])
    top = origin + 1.05 * (top - origin) if top > origin else origin + 1.0
    ax.set_rlim(origin, top)
    # Whole decades, none so near the rim that its label meets the angle labels.
    decades = np.arange(origin, math.floor(top) + 1)
    every = max(1, math.ceil(decades.size / 6))
    decades = [k for k in decades[::every] if top - k > 0.08 * (top - origin)]
    ax.yaxis.set_major_locator(mticker.FixedLocator(decades))
    ax.yaxis.set_major_formatter(mticker.FuncFormatter(lambda v, _: f"$10^{{{v:.0f}}}$"))
    ax.tick_params(axis="y", labelsize=6.5)
    ax.tick_params(axis="x", labelsize=6.5, pad=1.0)
    ax.set_rlabel_position(lo)
    ax.xaxis.grid(True, color="0.85", lw=0.4, alpha=1.0)
    ax.yaxis.grid(True, color="0.8", lw=0.5, alpha=1.0)
    arc = np.radians(np.linspace(lo, hi, 91))
    xs, ys = np.r_[0.0, np.cos(arc)], np.r_[0.0, np.sin(arc)]
    return top, float(np.ptp(ys) / np.ptp(xs))


#: Largest offset along ω between the residual points of neighbouring structures [decades].
DODGE_MAX = 0.04


def dodge_step(omega, n_structures: int) -> float:
    """Offset along ω [decades] between neighbouring structures' residual points: at most
    :data:`DODGE_MAX`, and the points of all structures at one frequency take at most 80 % of
    the median spacing of the frequencies (so they stay nearer their own frequency)."""
    if n_structures < 2:
        return 0.0
    lw = np.unique(np.log10(np.asarray(omega, float)))
    spacing = float(np.median(np.diff(lw))) if lw.size > 1 else 1.0
    return min(DODGE_MAX, 0.8 * spacing / n_structures)


def plot_residuals(comparison, structures=None, ax=None, *, n_draws: int = N_DRAWS,
                   seed: int = 0) -> Drawn:
    """Residuals of the data from each structure's posterior median prediction, against ω.

    The prediction is the pointwise posterior median of Re G and of Im G at the measured
    frequencies. With σ known the residuals are divided by σ/√2, the standard deviation of each
    part, so that they are standard normal when the model is right (dotted lines at ±2);
    otherwise they are relative to the measured |G|, in percent. Each structure has its own
    marker, and its points are offset along ω (by :func:`dodge_step`, at most 0.04 decades
    between neighbours) to keep them apart; when the residuals of structures agree within a
    marker's size the legend says that they coincide. Held-out points have a black edge.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    structures : sequence of str or StructureResult, optional
        Default: the best three by the ranking.
    ax : matplotlib.axes.Axes or pair of Axes, optional
        Two axes (real part, imaginary part), or one axes for both (real parts filled, imaginary
        parts open markers). Default: a new figure with two stacked axes.
    n_draws, seed : int
        As in :func:`plot_bode`.

    Returns
    -------
    Drawn
        ``axes`` = (real, imag) (the same axes twice when one was given). ``values``:
        ``"data/omega"``; per structure ``"<name>/real"``, ``"<name>/imag"`` (normalised
        residuals at ``data/omega``), ``"<name>/prediction"`` (complex median prediction), and
        with held-out points ``"holdout/omega"``, ``"<name>/holdout_real"``,
        ``"<name>/holdout_imag"``; ``"scale"`` (the divisor of the data points); ``"dodge"``
        (decades between neighbouring structures); ``"note"`` (which structures coincide, or
        empty). ``artists``: ``"<name>/real"``, ``"<name>/imag"`` (``Line2D``), the hold-out
        ones, and ``"note"`` (the legend title) when residuals coincide.

    Raises
    ------
    InputError
        If a structure is not in the comparison or failed.
    """
    results = select_results(comparison, structures)
    data = comparison.data
    styles = comparison_styles(comparison)
    known = data.sigma is not None
    values, artists = {}, {}
    step = dodge_step(data.omega, len(results))
    values["dodge"] = step
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
                dodge = w * 10 ** (step * (i - (len(results) - 1) / 2))
                st = styles[r.name]
                c = st.color
                edge = c if prefix == "data" else DATA_COLOR
                for part, a, y in (("real", ax_re, res.real), ("imag", ax_im, res.imag)):
                    filled = not (single and part == "imag")
                    label = legend_name(r) if prefix == "data" and part == "real" else None
                    (pts,) = a.plot(dodge, y, ls="none", marker=st.marker, color=c,
                                    mfc=c if filled else "white", mec=edge,
                                    ms=3.4 if filled else 3.8,
                                    mew=0.8 if prefix == "data" else 1.0, label=label,
                                    zorder=3 + (prefix != "data"))
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
        names = [r.name for r in results]
        # Markers are about 1.5 % of an axes high: residuals closer than that sit on each other.
        panels = {"Re": coincident_groups({n: values[f"{n}/real"] for n in names},
                                          _span(ax_re), fraction=0.015),
                  "Im": coincident_groups({n: values[f"{n}/imag"] for n in names},
                                          _span(ax_im), fraction=0.015)}
        note = coincidence_note(panels)
        values["note"] = note
        handles, labels = ax_re.get_legend_handles_labels()
        if comparison.holdout is not None:
            from matplotlib.lines import Line2D

            handles.append(Line2D([], [], ls="none", marker="o", mfc="0.75", mec=DATA_COLOR,
                                  mew=1.0, ms=3.8))
            labels.append("held out (black edge)")
        if single:
            legend = ax_re.legend(handles, labels, loc="best",
                                  title="filled Re, open Im" + (f"; {note}" if note else ""))
        else:
            legend = _legend(fig, handles, labels, note)
        artists.update(_note_artists(legend, note))
    return Drawn.build(fig, (ax_re, ax_im), values, artists)
