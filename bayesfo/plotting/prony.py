"""The Prony series of ``bayesfo export`` against the model it stands for: the relaxation
modulus G(t) of the series beside the model's posterior median and 94 % band, and the series'
relative error against the median with the band's half-width, over the data window and the
decade beyond each side (hatched as extrapolation)."""

from __future__ import annotations

import numpy as np

from ..data.symbols import modulus_symbol
from ..predictions import predict
from ..structures.physical import in_brackets
from ._base import Drawn, new_figure
from .style import EXTRAPOLATED

#: Points of the time grid.
N_TIMES = 150


def plot_prony(result, prony, *, structure=None, average=None, seed: int = 0,
               fig=None) -> Drawn:
    """G(t) of a Prony series (:func:`bayesfo.predictions.prony_series`) against the model's
    posterior median and 94 % band, and its relative error.

    Parameters
    ----------
    result : Comparison or MasterCurve
        What the series was fitted to.
    prony : Prony
    structure, average, seed
        As given to :func:`~bayesfo.predictions.prony_series` (the same draws).
    fig : matplotlib Figure, optional

    Returns
    -------
    Drawn
        Axes: (relaxation, error). Values: ``"t"``, ``"model_median"``, ``"model_low"``,
        ``"model_high"``, ``"series"``, ``"relative_error"`` (series against the median).
    """
    lo, hi = prony.window
    t = np.logspace(np.log10(lo) - 1, np.log10(hi) + 1, N_TIMES)
    model = predict(result, "relaxation_modulus", t, structure=structure, average=average,
                    seed=seed)
    series = prony.relaxation(t)
    error = series / model.median - 1
    half = (model.hdi_high - model.hdi_low) / 2 / np.abs(model.median)
    letter = modulus_symbol(prony.symbol)
    unit = in_brackets(prony.unit)

    fig = new_figure(fig, (6.4, 5.2))
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    top.fill_between(t, model.hdi_low, model.hdi_high, color="0.3", alpha=0.25, lw=0,
                     label=f"{prony.source}: 94 % band")
    top.loglog(t, model.median, "k-", lw=1.2, label="posterior median")
    (line,) = top.loglog(t, series, "--", color="#D55E00", lw=1.4,
                         label=f"Prony series, {prony.tau.size} terms")
    top.set_ylabel(f"{letter}(t){unit}")
    bottom.fill_between(t, -half, half, color="0.3", alpha=0.25, lw=0,
                        label="94 % band half-width")
    bottom.semilogx(t, error, "-", color="#D55E00", lw=1.2, label="series / median − 1")
    bottom.axhline(0.0, color="k", lw=0.6)
    bottom.set_xlabel("t [s]")
    bottom.set_ylabel("relative error")
    for ax in (top, bottom):
        ax.axvspan(t[0], lo, **EXTRAPOLATED, label="extrapolated")
        ax.axvspan(hi, t[-1], **EXTRAPOLATED)
        ax.set_xlim(t[0], t[-1])
        ax.legend(loc="best", fontsize=8)
    values = {"t": t, "model_median": model.median, "model_low": model.hdi_low,
              "model_high": model.hdi_high, "series": series, "relative_error": error}
    return Drawn.build(fig, (top, bottom), values, {"series": line},
                       caption=f"{letter}(t) of the Prony series against the model; the data "
                               "window is not hatched")
