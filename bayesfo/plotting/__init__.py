"""Figures. The only part of bayesfo that imports matplotlib (and only when a figure is drawn).

Plot functions take results (a :class:`~bayesfo.comparison.Comparison`, a
:class:`~bayesfo.comparison.StructureResult` or plain dicts), accept ``fig=`` or ``ax=``, and
return what they drew: a :class:`Drawn` with the figure, its axes, the plotted numbers and the
artists, so that what a figure shows can be checked against an independent computation.

Modules
-------
``style``
    The one figure style (:func:`style`, a matplotlib ``rc_context``) and the one style of each
    structure (:func:`~bayesfo.plotting.style.structure_styles`: colour, line style, marker by
    the structure's position among those requested), shared by comparison and batch figures.
``response``
    :func:`plot_bode`, :func:`plot_nyquist` (log-magnitude form for data over many decades),
    :func:`plot_residuals`: posterior response bands against the data; structures whose
    curves coincide are named in the legend.
``design``
    :func:`~bayesfo.plotting.design.plot_design`: the predictions over an instrument window
    with the proposed frequencies (:func:`bayesfo.design`).
``material``
    :func:`~bayesfo.plotting.material.plot_time_functions`: G(t) and J(t) (E(t) and D(t) for
    tensile data) with their bands.
``moduli``
    :func:`plot_moduli`: storage and loss parts (G′, G″ or J′, J″; E′, E″ for tensile data)
    and tan δ with the posterior bands.
``posterior``
    :func:`plot_corner`, :func:`plot_trace` (one structure).
``orders``
    :func:`plot_q_posteriors`: every fractional order of every structure.
``ranking``
    :func:`plot_ranking`: Δln Z and the information criteria.
``output``
    :func:`save_figure` (atomic) and :func:`write_figures` (every figure of a comparison).
``captions``
    :func:`~bayesfo.plotting.captions.figure_caption`: what each written figure shows for its
    structure and data (e.g. a trace that did not converge), without matplotlib.
``batch``
    :func:`~bayesfo.plotting.batch.plot_batch_summary`,
    :func:`~bayesfo.plotting.batch.plot_q_temperature`: figures of a batch of comparisons.
``studies``
    :func:`plot_rmse_surface` (thesis Figure 3.2).

Example
-------
>>> from bayesfo.plotting import plot_bode, write_figures        # doctest: +SKIP
>>> drawn = plot_bode(comparison)                                # doctest: +SKIP
>>> paths = write_figures(comparison, "out/figures")             # doctest: +SKIP
"""

from __future__ import annotations

from ._base import Drawn
from .moduli import plot_moduli
from .orders import plot_q_posteriors
from .output import save_figure, write_figures
from .posterior import plot_corner, plot_trace
from .ranking import plot_ranking
from .response import plot_bode, plot_nyquist, plot_residuals
from .studies import plot_rmse_surface
from .style import style

__all__ = [
    "Drawn",
    "plot_bode",
    "plot_corner",
    "plot_moduli",
    "plot_nyquist",
    "plot_q_posteriors",
    "plot_ranking",
    "plot_residuals",
    "plot_rmse_surface",
    "plot_trace",
    "save_figure",
    "style",
    "write_figures",
]
