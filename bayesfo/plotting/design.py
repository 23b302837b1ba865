"""The figure of a measurement design: the structures' predictions over the instrument window
with the data and the proposed frequencies, and the expected information of one measurement."""

from __future__ import annotations

import numpy as np

from ._base import Drawn, new_figure
from ._compute import quantiles, response_draws, unwrapped_phase_deg
from .response import OMEGA_LABEL, _band
from .style import COLUMN_WIDTH, DATA_COLOR, comparison_styles, quantity_symbol, style


def plot_design(result, plan, *, fig=None, n_draws: int = 300, seed: int = 0) -> Drawn:
    """Magnitude and phase of each considered structure (posterior median and 90 % band) over
    the design's window, the data, the proposed frequencies (vertical lines, numbered in the
    order chosen), and below the expected information of one measurement at each candidate.

    Parameters
    ----------
    result : Comparison
    plan : bayesfo.planning.Design

    Returns
    -------
    Drawn
        Axes (magnitude, phase, information). Values: ``"omega"`` (the candidates),
        ``"information"``, ``"proposed"``, per structure ``"<name>/magnitude_median"``.
    """
    with style():
        fig = new_figure(fig, (COLUMN_WIDTH + 0.4, 5.2))
        axes = fig.subplots(3, 1, sharex=True, height_ratios=[1.2, 1.0, 0.8])
        omega = plan.omega
        styles = comparison_styles(result)
        values = {"omega": omega, "information": plan.information,
                  "proposed": np.array([p["omega"] for p in plan.proposed])}
        artists = {}
        handles, labels = [], []
        for name, prob in zip(plan.structures, plan.probabilities, strict=True):
            r = result[name]
            g = response_draws(r, omega, result.data.kind, n_draws, seed)
            st = styles[name]
            for ax, q, x in ((axes[0], "magnitude", np.abs(g)),
                             (axes[1], "phase", unwrapped_phase_deg(g, omega))):
                qs = quantiles(x)
                values[f"{name}/{q}_median"] = qs[0.5]
                _, _, line = _band(ax, omega, qs, st)
                artists[f"{name}/{q}_median"] = line
            handles.append(line)
            labels.append(f"{name} (P {prob:.2f})")
        d = result.data
        order = np.argsort(d.omega)
        for ax, y in ((axes[0], np.abs(d.response[order])),
                      (axes[1], unwrapped_phase_deg(d.response[order], d.omega[order]))):
            (data_line,) = ax.plot(d.omega[order], y, "o", ms=3, color=DATA_COLOR, zorder=5)
        handles.append(data_line)
        labels.append("data")
        axes[2].plot(omega, plan.information, "-", color="0.2", lw=1.2)
        groups = []  # proposals within a tenth of a decade share one label ("1,2")
        for i, p in enumerate(plan.proposed):
            for ax in axes:
                ax.axvline(p["omega"], color="#CC3311", lw=0.9, ls="--", zorder=1)
            near = next((g for g in groups
                         if abs(np.log10(p["omega"] / g[0])) < 0.1), None)
            if near is None:
                groups.append([p["omega"], str(i + 1)])
            else:
                near[1] += f",{i + 1}"
        for w, text in groups:
            axes[0].annotate(text, (w, 1.0), xycoords=("data", "axes fraction"),
                             ha="center", va="bottom", fontsize=7, color="#CC3311")
        for ax in axes:
            ax.axvspan(d.omega.min(), d.omega.max(), color="0.92", zorder=0, lw=0)
        sym = quantity_symbol(d.kind)
        axes[0].set_xscale("log")
        axes[0].set_yscale("log")
        axes[0].set_ylabel(f"|${sym}$|" + (f" [{d.units}]" if d.units else ""))
        axes[1].set_ylabel(f"arg ${sym}$ [deg]")
        axes[2].set_ylabel("information\n[nats]")
        axes[2].set_xlabel(OMEGA_LABEL + " (grey: measured window)")
        artists["legend"] = fig.legend(handles, labels, loc="outside upper center", ncols=2,
                                       fontsize=7)
    return Drawn.build(fig, tuple(axes), values, artists)
