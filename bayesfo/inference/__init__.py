"""Bayesian inference: likelihood and noise models, certified posteriors, evidence, diagnostics.

:func:`certified_posterior` (:mod:`.certified`) is the entry point that ``compare`` uses: from
the optima of a likelihood, a posterior certified by importance sampling, the tempered ladder
or emcee, with its ln Z and, in words, how it was reached. :func:`run_posterior` runs emcee
alone from the global optimisation and the linear seeds. The ArviZ statistics (``hdi``,
``psis``, ``loo``, ``waic``, R-hat and ESS) and the DataTree's files (``open_tree``) are named
here for the layers after this one.
"""

from __future__ import annotations

import numpy as np

from ..identify.optimize import fit_structure, linear_seeds
from ._arviz import (  # the ArviZ statistics and container, for the layers after this one
    ess_min,
    external_storage,
    group_names,
    hdi,
    hdi_columns,
    loo,
    open_tree,
    psis,
    rhat_max,
    waic,
)
from ._arviz import preload as preload_arviz
from ._mixture import _GaussianMixture as GaussianMixture
from .certified import CertifiedPosterior, certified_posterior
from .likelihood import NOISE_MODELS, Likelihood, choose_noise
from .posterior import ConvergenceWarning, PosteriorResult, sample_posterior, save_netcdf

__all__ = [
    "CertifiedPosterior", "ConvergenceWarning", "GaussianMixture", "Likelihood", "NOISE_MODELS", "PosteriorResult",
    "certified_posterior", "choose_noise", "ess_min", "external_storage", "group_names", "hdi",
    "hdi_columns", "loo", "open_tree", "preload_arviz", "psis", "rhat_max", "run_posterior",
    "sample_posterior", "save_netcdf", "starting_points", "waic",
]


def starting_points(lik: Likelihood, fit) -> tuple[np.ndarray, np.ndarray]:
    """(modes, more starts) of a posterior in the scaled coordinates of ``lik``: the admissible
    optima of the global optimisation ``fit``, and the linear estimates of the structure's
    coefficients (none where the structure has no linear form). Where the fit kept no optimum
    (none admissible), there are no modes, and its best point leads the starts: the posterior
    then has no importance proposal (see :func:`certified_posterior`)."""
    # Through physical units: the fit may have used another scaling than the likelihood.
    best = fit.optima if fit.optima.size else np.atleast_2d(fit.theta_scaled)
    best = lik.structure.to_scaled(lik.structure.to_physical(best, fit.scaling), lik.scaling)
    lin = linear_seeds(lik.structure, lik.data)
    starts = lik.structure.to_scaled(lin, lik.scaling) if lin.size else np.empty((0, best.shape[1]))
    if not fit.optima.size:
        return best[:0], np.vstack([best, starts])
    return best, starts


def run_posterior(structure, data, *, noise: str = "auto", priors=None, seed: int = 0,
                  fit=None, scaling=None, **kwargs):
    """Posterior of ``structure`` on ``data``, started from the deterministic fits.

    Parameters
    ----------
    structure : Structure
    data : FrequencyResponse
    noise : {"auto", "known", "constant", "proportional", "relative_parts"}
        See :mod:`bayesfo.inference.likelihood`; ``auto`` here follows the rule of
        :func:`choose_noise`, which never picks ``relative_parts`` (:func:`bayesfo.compare`
        chooses by evidence instead).
    priors : dict, optional
        Prior overrides ``{name: Prior}`` (structure or noise parameters).
    seed : int
        Seeds the optimiser's random starts and the sampler.
    fit : FitResult, optional
        A global optimisation already run on the same data (else it is run here).
    scaling : Scaling, optional
        Units of the scaled problem on which the priors are declared (see :class:`Likelihood`).
    **kwargs
        Passed to :func:`~bayesfo.inference.posterior.sample_posterior`.

    Returns
    -------
    (PosteriorResult, FitResult)
    """
    lik = Likelihood(structure, data, noise=noise, priors=dict(priors or {}), scaling=scaling)
    if fit is None:
        fit = fit_structure(lik.structure, data, rng=seed, seed_methods=True, scaling=lik.scaling)
    modes, starts = starting_points(lik, fit)
    result = sample_posterior(lik, np.vstack([modes, starts]), seed=seed, **kwargs)
    return result, fit
