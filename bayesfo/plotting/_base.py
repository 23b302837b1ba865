"""What a plot function returns, and how it gets its figure."""

from __future__ import annotations

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
