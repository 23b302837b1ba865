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
                  fit=None, **kwargs):
    """Posterior of ``structure`` on ``data``, started from the deterministic fits.

    Parameters
    ----------
    structure : Structure
    data : FrequencyResponse
    noise : {"auto", "known", "constant", "proportional"}
    priors : dict, optional
        Prior overrides ``{name: Prior}`` (structure or noise parameters).
    seed : int
        Seeds the optimiser's random starts and the sampler.
    fit : FitResult, optional
        A global optimisation already run on the same data (else it is run here).
    **kwargs
        Passed to :func:`~bayesfo.inference.posterior.sample_posterior`.

    Returns
    -------
    (PosteriorResult, FitResult)
    """
    lik = Likelihood(structure, data, noise=noise, priors=dict(priors or {}))
    if fit is None:
        fit = fit_structure(lik.structure, data, rng=seed, seed_methods=True)
    seeds = [fit.optima] if fit.optima.size else []
    lin = linear_seeds(lik.structure, data)
    if lin.size:
        seeds.append(lik.structure.to_scaled(lin, lik.scaling))
    if not seeds:
        seeds.append(np.atleast_2d(fit.theta_scaled))
    result = sample_posterior(lik, np.vstack(seeds), seed=seed, **kwargs)
    return result, fit
