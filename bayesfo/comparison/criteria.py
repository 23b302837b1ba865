"""Criteria of one structure from its fit and posterior: maximum log-likelihood, AIC, AICc, BIC,
WAIC and PSIS-LOO, RMSE, held-out predictive density, the evidence ln Z by the chosen route,
and the posterior model probabilities across structures."""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np

from ..data import FrequencyResponse
from ..errors import InputError, PredictiveWarning
from ..identify.optimize import FitResult
from ..inference import Likelihood, PosteriorResult
from ..inference import loo as psis_loo
from ..inference import waic as waic_of
from ..inference.bound import model_probabilities, probability_bound

PARETO_K_WARN = 0.7


def _frequencies(omega, shown: int = 6) -> str:
    """``omega = 1, 2, 3 rad/s``, or the first few and how many more, for a warning line."""
    text = ", ".join(f"{w:.4g}" for w in omega[:shown])
    if len(omega) > shown:
        text += f" and {len(omega) - shown} more"
    return f"omega = {text} rad/s"


def fit_log_likelihood(lik: Likelihood, fit: FitResult) -> float:
    """The log-likelihood at the optimiser's optimum (with the maximum-likelihood noise for it);
    -inf where the optimum is not admissible or lies outside the prior's support."""
    theta_fit = np.atleast_2d(fit.theta_scaled)
    if lik.noise_param:
        theta_fit = np.column_stack([theta_fit, lik.noise_estimate(theta_fit)])
    if not (fit.admissible and lik.in_support(theta_fit)[0]):
        return -math.inf
    return float(lik(theta_fit)[0])


def _criteria(lik: Likelihood, fit: FitResult, post: PosteriorResult) -> dict:
    n_real = 2 * lik.data.n_frequencies
    k = lik.ndim
    # Maximum log-likelihood: the sampler's best draw or the optimiser's optimum (with the
    # maximum-likelihood noise for that optimum), whichever is higher.
    max_ll = max(post.max_log_likelihood, fit_log_likelihood(lik, fit))
    aic = 2 * k - 2 * max_ll
    aicc = aic + (2 * k * (k + 1) / (n_real - k - 1) if n_real - k - 1 > 0 else math.inf)
    bic = k * math.log(n_real) - 2 * max_ll
    warn = []
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        loo = psis_loo(post.idata)
        waic = waic_of(post.idata.log_likelihood["G"].values)
    # WAIC estimates the same as PSIS-LOO, whose Pareto k̂ says where it fails (WAIC stays in
    # summary.json and ranking.csv).
    pareto_k = np.asarray(loo.pareto_k)
    k_max = float(np.max(pareto_k))
    if k_max > PARETO_K_WARN:
        bad = lik.data.omega[pareto_k > PARETO_K_WARN]
        msg = (f"{post.structure}: Pareto k up to {k_max:.2f} at {_frequencies(bad)}; "
               "PSIS-LOO is unreliable there")
        warn.append(msg)
        warnings.warn(msg, PredictiveWarning, stacklevel=3)
    elpd = {"waic": waic, "loo": (float(loo.elpd), float(loo.se))}
    for name, (value, se) in elpd.items():
        if not (math.isfinite(value) and math.isfinite(se)):
            # Pointwise log-likelihoods that differ by more than ~700 nats between draws
            # overflow the importance ratios: the criterion is undefined, not a number.
            pointwise = post.idata.log_likelihood["G"].values.reshape(-1, lik.data.n_frequencies)
            spread = float(np.ptp(pointwise, axis=0).max())
            msg = (f"{post.structure}: {name.upper()} cannot be computed: the pointwise "
                   f"log-likelihood varies by up to {spread:.3g} nats between posterior draws "
                   "(the structure misfits these data far beyond its noise scale)")
            warn.append(msg)
            warnings.warn(msg, PredictiveWarning, stacklevel=3)
            elpd[name] = (math.nan, math.nan)  # null in summary.json, empty in ranking.csv
    model = lik.structure.response(
        post.map_theta[: lik.structure.n_params], lik.data.omega, lik.data.kind
    )
    rmse = float(np.sqrt(np.sum(np.abs(lik.data.response - model) ** 2)) / lik.data.n_frequencies)
    return {
        "max_log_likelihood": max_ll, "aic": aic, "aicc": aicc, "bic": bic,
        "waic": elpd["waic"][0], "waic_se": elpd["waic"][1],
        "loo": elpd["loo"][0], "loo_se": elpd["loo"][1], "pareto_k_max": k_max,
        "pareto_k": pareto_k.tolist(), "loo_pointwise": np.asarray(loo.elpd_i).tolist(),
        "rmse": rmse, "warnings": warn,
        "priors": lik.describe_priors(),
    }


def _holdout(lik, post, held_out: FrequencyResponse) -> dict:
    """Log pointwise predictive density and RMSE on held-out frequencies."""
    from scipy.special import logsumexp

    # Same structure, noise model, priors and units as the fit: the draws apply unchanged.
    held = Likelihood(lik.structure, held_out, noise=lik.noise, priors=lik.priors,
                      scaling=lik.scaling, require_points=False)
    draws = post.samples_scaled
    pointwise = held.pointwise(draws)
    lpd = logsumexp(pointwise, axis=0) - np.log(draws.shape[0])
    model = lik.structure.response(post.map_theta[: lik.structure.n_params], held_out.omega,
                                   held_out.kind)
    rmse = float(np.sqrt(np.sum(np.abs(held_out.response - model) ** 2)) / held_out.n_frequencies)
    return {"holdout_lpd": float(lpd.sum()), "holdout_lpd_pointwise": lpd.tolist(),
            "holdout_rmse": rmse, "holdout_omega": held_out.omega.tolist()}


def delta_loo_se(results) -> dict[str, float]:
    """``{name: se}``: the standard error of each structure's difference in PSIS-LOO elpd to
    the structure with the highest elpd, sqrt(N·var(elpd_i,best − elpd_i)) over the N
    frequencies, as ``arviz.compare`` computes its ``dse`` (0 for the best structure).

    From the pointwise elpd the criteria keep (``loo_pointwise``): ``arviz.compare`` would give
    the same numbers (tested) but runs PSIS again for every structure, hundreds of times the
    work. Structures whose elpd is not finite are left out.
    """
    pointwise = {r.name: np.asarray(r.criteria.loo_pointwise, float) for r in results
                 if r.error is None and r.criteria.loo_pointwise is not None}
    pointwise = {k: v for k, v in pointwise.items() if np.all(np.isfinite(v))}
    if not pointwise:
        return {}
    best = max(pointwise, key=lambda n: pointwise[n].sum())
    return {name: float(np.sqrt(lpd.size * np.var(pointwise[best] - lpd)))
            for name, lpd in pointwise.items()}


def _model_probabilities(results, prior_odds: dict) -> list:
    """The results with what is computed across structures in their criteria: the posterior
    model probabilities (from ln Z and the prior odds) and the standard error of each
    structure's Δelpd LOO (:func:`delta_loo_se`). New objects (``dataclasses.replace``); a
    structure without an evidence has no probability, one left out by the evidence bound the
    upper bound of its probability (``bound["posterior_probability_bound"]``)."""
    unknown = set(prior_odds) - {r.name for r in results}
    if unknown:
        raise InputError(f"prior odds given for unknown structure '{sorted(unknown)[0]}'")
    dse = delta_loo_se(results)
    results = [replace(r, criteria=replace(r.criteria, delta_loo_se=dse[r.name]))
               if r.name in dse else r for r in results]
    with_z = [r for r in results if r.error is None and r.criteria.evidence is not None]
    if not with_z:
        return list(results)
    log_prior = [math.log(prior_odds.get(r.name, 1.0)) for r in with_z]
    p = model_probabilities([r.log_z for r in with_z], log_prior)
    prob = {id(r): float(x) for r, x in zip(with_z, p, strict=True)}
    out = []
    for r in results:
        if id(r) in prob:
            r = replace(r, criteria=replace(r.criteria, posterior_probability=prob[id(r)]))
        elif r.error is None and r.criteria.bound is not None:
            # Not sampled: its probability is at most that at its bound (ln Z ≤ max ln L).
            upper = probability_bound(r.criteria.bound["log_evidence_bound"],
                                      [z.log_z for z in with_z],
                                      math.log(prior_odds.get(r.name, 1.0)), log_prior)
            r = replace(r, criteria=replace(r.criteria, bound={
                **r.criteria.bound, "posterior_probability_bound": upper}))
        out.append(r)
    return out
