"""What follows from the models in the time domain: the relaxation modulus G(t) and the creep
compliance J(t) of each structure's posterior, with credible bands.

G(t) and J(t) are those of :func:`bayesfo.predict` (fixed-Talbot inversion of G*(s)/s and
J*(s)/s for every draw; :mod:`bayesfo.predictions`), for thinned posterior draws. The times run
from a tenth of 1/ω_max to ten times 1/ω_min; the data inform about 1/ω_max … 1/ω_min, and the
stretches beyond are hatched as extrapolation. Tensile data (``symbol`` E) are labelled E(t) and
D(t), the tensile relaxation modulus and creep compliance.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..predictions.functions import QUANTITIES, evaluate_together, quantity_unit
from ..structures.physical import in_brackets
from ._base import Drawn, axes_or_new, new_figure
from ._compute import N_DRAWS, legend_name, select_results, structure_draws
from ._legend import _legend
from .response import _band_handle, positive_band
from .style import COLUMN_WIDTH, EXTRAPOLATED, comparison_styles, style

#: Points of the time grid.
N_TIMES = 120


def time_grid(data, n: int = N_TIMES) -> np.ndarray:
    """Log-spaced times [s] from 0.1/ω_max to 10/ω_min."""
    return np.logspace(np.log10(0.1 / data.omega.max()), np.log10(10.0 / data.omega.min()), n)


def plot_time_functions(comparison, structures=None, fig=None, *, n_draws: int = N_DRAWS,
                        seed: int = 0) -> Drawn:
    """The relaxation modulus G(t) and the creep compliance J(t) of each structure: posterior
    median and 50 %/90 % bands, on logarithmic axes, the extrapolated times hatched.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
        Of modulus or compliance data.
    structures : sequence of str, optional
        Default: the best three by the ranking.
    n_draws, seed : int
        Posterior draws used (at most) and the seed of their choice.

    Returns
    -------
    Drawn
        ``axes`` = (G(t), J(t)). ``values``: ``"time"``, ``"window"`` (1/ω_max, 1/ω_min) and per
        structure ``"<name>/relaxation_modulus_median"``, ``_q05``, ``_q25``, ``_q75``,
        ``_q95`` and the same for ``creep_compliance``. ``artists``: the median lines under the
        same keys, and the bands (``_band50``, ``_band90``).

    Raises
    ------
    InputError
        For generic (transfer-function) data, or an unknown or failed structure.
    """
    data = comparison.data
    if data.kind not in ("modulus", "compliance"):
        raise InputError("G(t) and J(t) are defined for modulus or compliance data, not for "
                         f"{data.kind!r} data")
    results = select_results(comparison, structures)
    t = time_grid(data)
    window = (1.0 / data.omega.max(), 1.0 / data.omega.min())
    styles = comparison_styles(comparison)
    values, artists = {"time": t, "window": np.array(window)}, {}
    handles, labels = [], []
    quantities = ("relaxation_modulus", "creep_compliance")
    # G(t) and J(t) for shear data, E(t) and D(t) for tensile data
    symbols = {"relaxation_modulus": f"{data.modulus_symbol}(t)",
               "creep_compliance": f"{data.compliance_symbol}(t)"}
    with style():
        fig = new_figure(fig, (COLUMN_WIDTH, 4.4))
        axes = fig.subplots(2, 1, sharex=True)
        for r in results:
            theta = structure_draws(r, n_draws, seed)
            st = styles[r.name]
            both = evaluate_together(r.structure, theta, quantities, t)
            for ax, q in zip(axes, quantities, strict=True):
                v = both[q]
                positive_band(ax, t, np.where(np.isfinite(v), v, np.nan), st, r.name, q,
                              values, artists)
            handles.append(_band_handle(st))
            labels.append(legend_name(r))
        for ax, q in zip(axes, quantities, strict=True):
            ax.set_xscale("log")
            ax.set_yscale("log")
            u = quantity_unit(q, data) if data.units else ""
            ax.set_ylabel(symbols[q] + (f" [{u}]" if u else ""))
            lo, hi = t[0], t[-1]
            ax.axvspan(lo, window[0], **EXTRAPOLATED)
            ax.axvspan(window[1], hi, **EXTRAPOLATED)
            ax.set_xlim(lo, hi)
        axes[-1].set_xlabel("t [s] (hatched: beyond the measured window)")
        _legend(fig, handles, labels)
    return Drawn.build(fig, axes, values, artists)


def plot_prediction(prediction, *, ax=None) -> Drawn:
    """A material function of :func:`bayesfo.predict` (any quantity, one structure, an average
    or a master curve): its posterior median and 94 % band, the arguments outside the data
    window hatched as extrapolation; logarithmic axes where the values are positive.

    Returns
    -------
    Drawn
        Values: ``"x"``, ``"median"``, ``"hdi_low"``, ``"hdi_high"``.
    """
    p = prediction
    fig, ax = axes_or_new(ax, (COLUMN_WIDTH, 3.2))
    finite = np.isfinite(p.median)
    positive = bool(finite.any()) and bool(np.all(p.hdi_low[finite] > 0))
    ax.set_xscale("log")
    if positive:
        ax.set_yscale("log")
    band = ax.fill_between(p.x, p.hdi_low, p.hdi_high, color="0.3", alpha=0.25, lw=0,
                           label="94 % band")
    who = (p.structure if p.weights is None else
           f"{p.average} average of " + ", ".join(
               k for k, w in sorted(p.weights.items(), key=lambda kv: -kv[1]) if w >= 0.01))
    if getattr(p, "temperature", None) is not None:
        who += f" at {p.temperature:g} °C"
    (line,) = ax.plot(p.x, p.median, "k-", lw=1.2, label="posterior median")
    ax.set_title(who, fontsize=8, wrap=True)
    out = np.asarray(p.extrapolated, bool)
    if out.any() and p.window is not None:
        # Shade what lies beyond the measured window, to its ends.
        lo, hi = p.window
        if p.x.min() < lo:
            ax.axvspan(p.x.min(), lo, **EXTRAPOLATED, label="extrapolated")
        if p.x.max() > hi:
            ax.axvspan(hi, p.x.max(), **EXTRAPOLATED,
                       label=None if p.x.min() < lo else "extrapolated")
    elif out.any():
        # Shade each run of extrapolated arguments, to the midpoint with the next one inside.
        edges = np.sqrt(p.x[1:] * p.x[:-1])
        bounds = np.r_[p.x[0], edges, p.x[-1]]
        for k, i in enumerate(np.flatnonzero(out)):
            ax.axvspan(bounds[i], bounds[i + 1], **EXTRAPOLATED,
                       label=None if k else "extrapolated")
    domain = QUANTITIES[p.quantity][0]
    ax.set_xlabel({"omega": "ω [rad/s]", "time": "t [s]", "tau": "τ [s]"}[domain])
    ax.set_ylabel(f"{p.symbol}" + in_brackets(p.unit))
    ax.legend(loc="best", fontsize=8)
    values = {"x": p.x, "median": p.median, "hdi_low": p.hdi_low, "hdi_high": p.hdi_high}
    return Drawn.build(fig, (ax,), values, {"median": line, "band": band},
                       caption=f"{p.symbol}: posterior median and 94 % band; extrapolated "
                               "arguments hatched")
