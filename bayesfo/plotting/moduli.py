"""Storage and loss parts and the loss tangent: the rheologist's view of a comparison.

For a modulus G* = G′ + iG″ the figure shows G′(ω), G″(ω) and tan δ = G″/G′; for a compliance
J* = J′ − iJ″ (the loss compliance J″ ≥ 0, see :class:`~bayesfo.data.FrequencyResponse`) it
shows J′, J″ and tan δ = J″/J′. Tensile data (``symbol`` E, a DMA's E′, E″) are labelled E′, E″
(compliance D′, D″). Generic transfer functions have no storage and loss parts:
:func:`plot_moduli` refuses them.

The bands are those of the Bode figure (:mod:`bayesfo.plotting.response`): pointwise 50 % and
90 % intervals of the model response over posterior draws of the parameters, without the
measurement noise. The error bars of the data are one standard deviation of each part, σ/√2
(σ is that of the complex value), and for tan δ its first-order propagation,
tan δ · (σ/√2) · √(1/G′² + 1/G″²). Axes are logarithmic: points whose loss part or tan δ is not
positive cannot be drawn on them, and the legend says how many were left out.
"""

from __future__ import annotations

import math

import numpy as np

from ..data.symbols import parts as part_symbols
from ..errors import InputError
from ._base import Drawn, new_figure
from ._compute import (
    N_DRAWS,
    N_GRID,
    legend_name,
    omega_grid,
    response_draws,
    select_results,
)
from ._legend import _legend, _note_artists
from .response import DATA_STYLE, HOLDOUT_STYLE, OMEGA_LABEL, _band_handle, positive_band
from .style import COLUMN_WIDTH, comparison_styles, style, unit_suffix

#: Symbols of the panels for each kind of shear data: (storage, loss); tensile data (symbol E)
#: take E′, E″ and D′, D″ (:func:`bayesfo.data.symbols.parts`).
PARTS = {"modulus": ("G′", "G″"), "compliance": ("J′", "J″")}
QUANTITIES = ("storage", "loss", "tan_delta")


def storage_loss(g: np.ndarray, kind: str) -> tuple[np.ndarray, np.ndarray]:
    """(storage, loss) parts of complex responses of ``kind``: (Re G, Im G) for a modulus,
    (Re J, −Im J) for a compliance."""
    if kind == "modulus":
        return g.real, g.imag
    if kind == "compliance":
        return g.real, -g.imag
    raise InputError(f"storage and loss parts are defined for modulus or compliance data, not "
                     f"for {kind!r} data; use the Bode or Nyquist figure")


def _data_parts(d, kind: str) -> dict:
    order = np.argsort(d.omega)
    w = d.omega[order]
    storage, loss = storage_loss(d.response[order], kind)
    with np.errstate(divide="ignore", invalid="ignore"):
        tan = loss / storage
    out = {"omega": w, "storage": storage, "loss": loss, "tan_delta": tan}
    if d.sigma is not None:
        s = d.sigma[order] / math.sqrt(2.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            out.update(storage_err=s, loss_err=s,
                       tan_delta_err=np.abs(tan) * s * np.hypot(1 / storage, 1 / loss))
    return out


def _readable_log_ticks(ax) -> None:
    """Plain labels (0.6, 0.8, 1) on a log axis spanning less than a decade, where matplotlib
    labels every minor tick in the form 6 × 10⁻¹ and the labels run together."""
    import matplotlib.ticker as mticker

    lo, hi = ax.get_ylim()
    if not (lo > 0 and hi / lo < 10):
        return
    # The sparsest set of multiples of each power of ten that puts three ticks in view: on an
    # axis of 0.71 to 1.19, 1, 2, 3, 5, 7 gave only 1.
    for subs in ((1.0, 2.0, 3.0, 5.0, 7.0), (1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0),
                 tuple(np.round(np.arange(1.0, 10.0, 0.5), 1)),
                 tuple(np.round(np.arange(1.0, 10.0, 0.1), 1))):
        powers = 10.0 ** np.arange(np.floor(np.log10(lo)), np.ceil(np.log10(hi)) + 1)
        ticks = np.outer(powers, subs).ravel()
        if np.sum((ticks >= lo) & (ticks <= hi)) >= 3:
            break
    ax.yaxis.set_major_locator(mticker.LogLocator(base=10, subs=subs))
    ax.yaxis.set_major_formatter(mticker.FuncFormatter(lambda v, _: f"{v:g}"))
    ax.yaxis.set_minor_formatter(mticker.NullFormatter())


def plot_moduli(comparison, structures=None, fig=None, *, n_draws: int = N_DRAWS,
                seed: int = 0, n_grid: int = N_GRID) -> Drawn:
    """Storage part, loss part and loss tangent of the data and each structure's posterior.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
        Of modulus or compliance data.
    structures : sequence of str or StructureResult, optional
        Structures to draw (default: the best three by the ranking).
    fig : matplotlib.figure.Figure, optional
        Figure to draw in (three axes are added); default a new single-column figure.
    n_draws, seed, n_grid : int
        As for :func:`~bayesfo.plotting.plot_bode`.

    Returns
    -------
    Drawn
        ``axes`` = (storage, loss, tan δ). ``values``: ``"omega"`` (grid); ``"data/omega"``
        (sorted), ``"data/storage"``, ``"data/loss"``, ``"data/tan_delta"`` and, when σ is
        known, their ``_err``; the same under ``"holdout/"``; per structure
        ``"<name>/<quantity>_median"``, ``_q05``, ``_q25``, ``_q75``, ``_q95`` for each of
        ``storage``, ``loss``, ``tan_delta``; ``"left_out"``: the data points not drawn
        because a part or tan δ is not positive. ``artists``: median lines, bands
        (``"<name>/<quantity>_band50"``, ``_band90``) and the data (``ErrorbarContainer``).

    Raises
    ------
    InputError
        For generic (transfer-function) data, or a structure not in the comparison or failed.
    """
    data = comparison.data
    storage_loss(np.zeros(1, complex), data.kind)  # refuses generic data before any work
    results = select_results(comparison, structures)
    sym_storage, sym_loss = part_symbols(data.symbol, data.kind)
    omega = omega_grid(comparison, n_grid)
    styles = comparison_styles(comparison)
    values, artists = {"omega": omega}, {}
    handles, labels = [], []
    with style():
        fig = new_figure(fig, (COLUMN_WIDTH, 5.2))
        axes = fig.subplots(3, 1, sharex=True)
        for r in results:
            g = response_draws(r, omega, data.kind, n_draws, seed)
            storage, loss = storage_loss(g, data.kind)
            with np.errstate(divide="ignore", invalid="ignore"):
                curves = (storage, loss, loss / storage)
            st = styles[r.name]
            for ax, quantity, x in zip(axes, QUANTITIES, curves, strict=True):
                positive_band(ax, omega, x, st, r.name, quantity, values, artists)
            handles.append(_band_handle(st))
            labels.append(legend_name(r))
        left_out = 0
        for prefix, d in (("data", data), ("holdout", comparison.holdout)):
            if d is None:
                continue
            parts = _data_parts(d, data.kind)
            values.update({f"{prefix}/{k}": v for k, v in parts.items()})
            kw = DATA_STYLE if prefix == "data" else dict(HOLDOUT_STYLE, ls="none", zorder=6,
                                                           elinewidth=0.7)
            for ax, quantity in zip(axes, QUANTITIES, strict=True):
                y = parts[quantity]
                keep = np.isfinite(y) & (y > 0)
                left_out += int(np.count_nonzero(~keep)) if prefix == "data" else 0
                err = parts.get(f"{quantity}_err")
                if err is not None:
                    # A bar reaching below zero is cut at the bottom of the log axis.
                    err = np.where(np.isfinite(err), err, 0.0)[keep]
                    err = np.vstack([np.minimum(err, 0.999 * y[keep]), err])
                artists[f"{prefix}/{quantity}"] = ax.errorbar(parts["omega"][keep], y[keep],
                                                              yerr=err, **kw)
            handles.append(artists[f"{prefix}/storage"])
            labels.append(("data ± 1 sd" if "storage_err" in parts else "data")
                          if prefix == "data" else "held out")
        values["left_out"] = left_out
        unit = unit_suffix(data.units)
        for ax, label in zip(axes, (sym_storage + unit, sym_loss + unit,
                                    r"tan $\delta$"), strict=True):
            ax.set_yscale("log")
            ax.set_ylabel(label)
        _readable_log_ticks(axes[2])
        axes[0].set_xscale("log")
        axes[-1].set_xlabel(OMEGA_LABEL)
        note = (f"{left_out} data value{'s' if left_out != 1 else ''} not positive, not drawn "
                "on the log axes" if left_out else "")
        legend = _legend(fig, handles, labels, note)
        artists.update(_note_artists(legend, note))
    return Drawn.build(fig, axes, values, artists)
