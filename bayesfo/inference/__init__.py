"""Bayesian inference: likelihood and noise models, posterior sampling, diagnostics.

:func:`run_posterior` is the one-call entry point: global optimisation (the modes), linear
seeds, then emcee.
"""

from __future__ import annotations

import numpy as np

from ..identify.optimize import fit_structure, linear_seeds
from .likelihood import NOISE_MODELS, Likelihood, choose_noise
from .posterior import ConvergenceWarning, PosteriorResult, sample_posterior, save_netcdf

__all__ = [
    "ConvergenceWarning", "Likelihood", "NOISE_MODELS", "PosteriorResult", "choose_noise",
    "run_posterior", "sample_posterior", "save_netcdf",
]


def run_posterior(structure, data, *, noise: str = "auto", priors=None, seed: int = 0,
                  fit=None, scaling=None, **kwargs):
    """Posterior of ``structure`` on ``data``, started from the deterministic fits.

    Parameters
    ----------
    structure : Structure
    data : FrequencyResponse
    noise : {"auto", "known", "constant", "proportional", "relative_parts"}
        See :mod:`bayesfo.inference.likelihood`; ``auto`` (:func:`choose_noise`) never chooses
        ``relative_parts``.
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
    # Modes go through physical units: a fit passed in may have used another scaling.
    modes = fit.optima if fit.optima.size else np.atleast_2d(fit.theta_scaled)
    seeds = [lik.structure.to_scaled(lik.structure.to_physical(modes, fit.scaling), lik.scaling)]
    lin = linear_seeds(lik.structure, data)
    if lin.size:
        seeds.append(lik.structure.to_scaled(lin, lik.scaling))
    result = sample_posterior(lik, np.vstack(seeds), seed=seed, **kwargs)
    return result, fit
