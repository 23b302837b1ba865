"""What a master curve's output directory stores of its posterior, so that
:func:`bayesfo.load` can restore the :class:`~bayesfo.tts.result.MasterCurve` and predictions and
Prony series follow from it as from a comparison.

``bayesfo mastercurve`` writes, besides ``summary.json`` and ``master.csv``:

``<structure>.nc``
    The joint posterior of the chosen master structure, as ``compare`` writes a structure's
    (draws of the master parameters, of every ``log10_aT_*`` and ``log10_bT_*`` and of the
    noise; the pointwise log-likelihood; the posterior predictive; the joint data) with the
    attributes ``compare`` adds (:data:`~bayesfo.inference.results.NETCDF_FORMAT`), and in ``observed_data``:
    ``point_isotherm`` (the isotherm of each point, indexing ``summary.json["isotherms"]``) and
    ``sigma`` where the data carry σ.

and in ``summary.json``: ``"isotherms"`` (``[{"temperature", "name", "n_frequencies"}]`` in the
order of the points), for a relaxation-spectrum master ``"spectrum"`` (its relaxation times
``tau_s`` [s]; :mod:`bayesfo.tts.spectrum`) and ``"posterior"`` (the joint posterior's summary, as ``compare`` writes a
structure's: every parameter's ``mean``, ``sd``, ``hdi_low``, ``hdi_high``, …, the noise model,
the sampler and its diagnostics).
"""

from __future__ import annotations

import numpy as np

from ..inference.results import NETCDF_FORMAT
from .spectrum import Spectrum


def netcdf_of(mc):
    """The DataTree that ``<structure>.nc`` stores: a shallow copy of the joint posterior's
    with the attributes :func:`bayesfo.load` needs (the master curve is left as it was)."""
    post = mc.posterior
    tree = post.idata.copy(deep=False)
    tree.posterior.attrs.update(
        bayesfo_format=NETCDF_FORMAT, n_steps=int(post.n_steps), burn=int(post.burn),
        thin=int(post.thin), acceptance=float(post.acceptance),
        tau=np.asarray(post.tau, dtype=float).ravel())
    observed = {"point_isotherm": np.concatenate(
        [np.full(d.n_frequencies, i, dtype=np.int64) for i, d in enumerate(mc.isotherms)])}
    if mc.data.sigma is not None:
        observed["sigma"] = np.asarray(mc.data.sigma, dtype=float)
    tree.observed_data.attrs.update(observed)
    return tree


def summary_fields(mc) -> dict:
    """The blocks of ``summary.json`` that restore the master curve: ``"isotherms"`` and
    ``"posterior"``."""
    post = mc.posterior
    out = {"isotherms": [{"temperature": t, "name": d.label, "n_frequencies": d.n_frequencies}
                         for t, d in zip(mc.temperatures, mc.isotherms, strict=True)],
           "posterior": {"name": mc.structure, **post.to_dict()}}
    if isinstance(mc.master, Spectrum):
        out["spectrum"] = mc.master.to_dict()
    return out
