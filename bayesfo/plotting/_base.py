"""What a plot function returns, and how it gets its figure."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np


@dataclass(frozen=True, eq=False)
class Drawn:
    """What a plot function drew: the figure, its axes, the plotted numbers and the artists.

    Attributes
    ----------
    figure : matplotlib.figure.Figure
    axes : tuple of matplotlib.axes.Axes
        The axes drawn on, in the order the function documents.
    values : Mapping[str, ndarray]
        The plotted numbers, under keys the function documents (e.g. ``"voigt/magnitude_median"``),
        in the units of the axes before any display offsets.
    artists : Mapping[str, object]
        The matplotlib artists, under the same keys as the values they show.
    caption : str
        What the figure shows for the results it was drawn from (e.g. that the walkers of a
        trace did not converge), for a caption under it; empty where the function gives none.
    """

    figure: Any
    axes: tuple
    values: Mapping[str, np.ndarray]
    artists: Mapping[str, Any]
    caption: str = ""

    @classmethod
    def build(cls, figure, axes, values: dict, artists: dict, caption: str = "") -> Drawn:
        plain_log_labels(figure)
        frozen = {}
        for k, v in values.items():
            a = np.array(v)
            a.setflags(write=False)
            frozen[k] = a
        return cls(figure, tuple(axes), MappingProxyType(frozen), MappingProxyType(dict(artists)),
                   caption)


def new_figure(fig, size, *, layout: str = "constrained"):
    """``fig``, or a new pyplot figure of ``size`` inches (the caller closes it)."""
    if fig is not None:
        return fig
    import matplotlib.pyplot as plt

    return plt.figure(figsize=size, layout=layout)


def axes_or_new(ax, size):
    """(figure, axes): those of ``ax``, or a new figure with one axes."""
    if ax is not None:
        return ax.figure, ax
    fig = new_figure(None, size)
    return fig, fig.add_subplot()


#: A logarithmic axis whose view lies within these bounds is labelled with plain numbers (40, 60,
#: 100, 0.2) instead of powers of ten (4×10¹, 6×10¹, 10², 2×10⁻¹); one that reaches beyond
#: keeps them all as powers.
PLAIN_LOG_RANGE = (1e-2, 1e4)


def plain_log_labels(figure) -> None:
    """Label the logarithmic axes of ``figure`` that lie within :data:`PLAIN_LOG_RANGE` with
    plain numbers: the same ticks labelled, as ``{:g}`` (decided at each draw, from the view
    then). Axes with a formatter of their own are left as they are."""
    from matplotlib.ticker import LogFormatterSciNotation

    plain = _plain_formatter()
    for ax in figure.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() != "log":
                continue
            for get, put in ((axis.get_major_formatter, axis.set_major_formatter),
                             (axis.get_minor_formatter, axis.set_minor_formatter)):
                old = get()
                if type(old) is LogFormatterSciNotation:
                    put(plain(base=old._base, labelOnlyBase=old.labelOnlyBase,
                              minor_thresholds=old.minor_thresholds, linthresh=old._linthresh))


_PLAIN = []


def _plain_formatter():
    """The formatter class of :func:`plain_log_labels` (defined once matplotlib is loaded)."""
    if not _PLAIN:
        from matplotlib.ticker import LogFormatterSciNotation

        class PlainLogFormatter(LogFormatterSciNotation):
            """Powers of ten as plain numbers where the whole view lies within
            :data:`PLAIN_LOG_RANGE`; the labels of :class:`LogFormatterSciNotation` elsewhere."""

            def __call__(self, x, pos=None):
                label = super().__call__(x, pos)
                if self.axis is None:
                    return label
                lo, hi = sorted(self.axis.get_view_interval())
                if not (PLAIN_LOG_RANGE[0] <= lo and hi < PLAIN_LOG_RANGE[1]):
                    return label
                # Within a decade every tick is labelled: the usual subset (2, 3, 5 times a
                # power) can leave one label on an axis of 0.6 to 1.5.
                if label or (lo > 0 and math.log10(hi / lo) < 1.0):
                    return f"{x:g}"
                return label

        _PLAIN.append(PlainLogFormatter)
    return _PLAIN[0]
