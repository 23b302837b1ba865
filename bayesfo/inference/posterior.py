"""Posterior sampling with emcee, seeded by the deterministic fits, and its summaries.

The sampler works in coordinates u where log-uniform parameters are replaced by their logarithm
(there the prior is flat and scale parameters spanning decades mix well); the density includes the
Jacobian, so samples are from the posterior of the declared priors. Walkers start around every
distinct admissible optimum of the global optimisation and the linear methods that lies within
``mode_window`` log-likelihood units of the best one (jittered, kept inside the support), and move
with a mixture of differential-evolution (including the mode-hopping γ = 1 variant), DE-snooker
and stretch moves, which can jump between the q modes of high-order structures (thesis Table A.9).

The run length is set by the integrated autocorrelation time τ (emcee): it continues until it is
at least ``tau_factor``·τ steps long and τ has settled, up to ``max_steps``. Burn-in is 2·τ_max,
thinning τ_min/2. Convergence is judged with arviz' rank-normalised split R-hat across four groups
of walkers and bulk and tail effective sample sizes over walkers; a run that misses them issues a :class:`ConvergenceWarning`
and has ``converged = False``.
"""

from __future__ import annotations

import errno
import math
import os
import shutil
import sys
import tempfile
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._io import publish
from ..errors import ConvergenceWarning, InputError
from ..priors import LogUniform, Uniform
from ._arviz import arviz
from .likelihood import Likelihood

HDI_PROB = 0.94
RHAT_MAX = 1.01
ESS_MIN = 400


@dataclass(frozen=True)
class ParameterSummary:
    """Posterior summary of one parameter, in physical units.

    ``poorly_determined``: the 94 % HDI covers more than half of the prior range (in the sampling
    coordinate, i.e. in log for log-uniform priors). ``multimodal``: the marginal density has more
    than one clearly separated peak.
    """

    mean: float
    sd: float
    hdi_low: float
    hdi_high: float
    map: float
    median: float
    poorly_determined: bool
    multimodal: bool

    def to_dict(self) -> dict:
        return {k: (bool(v) if isinstance(v, (bool, np.bool_)) else float(v))
                for k, v in self.__dict__.items()}


@dataclass(frozen=True, eq=False)
class PosteriorResult:
    """Posterior draws of one structure on one data set, with diagnostics.

    Attributes
    ----------
    structure : str
    param_names : tuple of str
        Structure parameters, then ``sigma``/``sigma_rel`` when the noise is sampled.
    noise, noise_reason : str
        The noise model and why it was chosen.
    samples : ndarray, shape (n_draws, ndim)
        Thinned post-burn-in draws in physical units (walkers × kept steps).
    samples_scaled : ndarray
        The same draws on the scaled problem.
    log_likelihood : ndarray, shape (n_draws,)
        Total log-likelihood of each draw (physical units).
    summary : dict
        ``{name: ParameterSummary}``.
    map_theta : ndarray
        The draw with the highest posterior density (physical units).
    max_log_likelihood : float
        Highest log-likelihood among the draws.
    tau : ndarray
        Integrated autocorrelation time of each parameter [steps].
    n_steps, burn, thin, n_walkers : int
    acceptance : float
        Mean acceptance fraction.
    rhat_max, ess_bulk_min, ess_tail_min : float
    converged : bool
    messages : tuple of str
        Warnings raised during the run.
    sampler : str
        ``"emcee"``; ``"ladder"`` for the final particles of independent tempered-ladder runs
        (:func:`posterior_from_particles`; each run is one chain of the diagnostics);
        ``"importance"`` for draws resampled from certified importance weights
        (:func:`bayesfo.inference.importance.importance_posterior`; R-hat does not apply, the
        ESS is that of the weights).
    idata : arviz.InferenceData
        Posterior, log_likelihood (per frequency), posterior_predictive, observed_data and
        sample_stats, coordinates named by frequency.
    """

    structure: str
    param_names: tuple[str, ...]
    noise: str
    noise_reason: str
    samples: np.ndarray
    samples_scaled: np.ndarray
    log_likelihood: np.ndarray
    summary: dict
    map_theta: np.ndarray
    max_log_likelihood: float
    tau: np.ndarray
    n_steps: int
    burn: int
    thin: int
    n_walkers: int
    acceptance: float
    rhat_max: float
    ess_bulk_min: float
    ess_tail_min: float
    converged: bool
    messages: tuple[str, ...] = ()
    idata: object = field(default=None, repr=False)
    sampler: str = "emcee"

    @property
    def ess_min(self) -> float:
        return min(self.ess_bulk_min, self.ess_tail_min)

    def to_dict(self) -> dict:
        return {
            "structure": self.structure,
            "noise": self.noise,
            "noise_reason": self.noise_reason,
            "parameters": {k: v.to_dict() for k, v in self.summary.items()},
            "max_log_likelihood": self.max_log_likelihood,
            "tau": dict(zip(self.param_names, map(float, self.tau))),
            "n_steps": self.n_steps, "burn": self.burn, "thin": self.thin,
            "n_walkers": self.n_walkers, "n_draws": int(self.samples.shape[0]),
            "acceptance": self.acceptance,
            "rhat_max": self.rhat_max, "ess_bulk_min": self.ess_bulk_min,
            "ess_tail_min": self.ess_tail_min, "ess_min": self.ess_min,
            "converged": self.converged, "messages": list(self.messages),
            "sampler": self.sampler,
        }


class _Transform:
    """θ ↔ u (log for log-uniform priors) and the log-Jacobian.

    In u, uniform and log-uniform priors are flat: their log density is the constant
    ``flat_const`` inside the box [lo_u, hi_u]; other priors (normal) are evaluated as such.
    """

    def __init__(self, lik: Likelihood):
        priors = lik.prior_list
        self.log = np.array([isinstance(p, LogUniform) for p in priors])
        flat = np.array([isinstance(p, (LogUniform, Uniform)) for p in priors])
        lo, hi = np.array([p.bounds for p in priors], dtype=float).T
        self.lo_u = np.where(self.log, np.log(np.where(self.log, lo, 1.0)), lo)
        self.hi_u = np.where(self.log, np.log(np.where(self.log, hi, 1.0)), hi)
        self.flat_const = float(-np.sum(np.log(self.hi_u - self.lo_u)[flat]))
        self.other = [(i, p) for i, p in enumerate(priors) if not flat[i]]

    def to_theta(self, u):
        return np.where(self.log, np.exp(np.clip(u, -700, 700)), u)

    def to_u(self, theta):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.log, np.log(np.abs(theta)), theta)


def _log_parts_fn(lik: Likelihood, tr: _Transform):
    """(log prior density in u, log-likelihood) of a batch of points in u, both −inf outside
    the support; the tempered ladder weighs the two parts differently."""
    k = lik.structure.n_params
    kind, grid = lik.data.kind, lik.grid

    def log_parts(u):
        u = np.atleast_2d(u)
        log_prior = np.full(u.shape[0], -np.inf)
        log_lik = np.full(u.shape[0], -np.inf)
        rows = np.flatnonzero(np.all((u >= tr.lo_u) & (u <= tr.hi_u), axis=1))
        if not rows.size:
            return log_prior, log_lik
        theta = tr.to_theta(u[rows])
        ok = lik.structure.constraints_hold(theta[:, :k], kind, grid)
        rows, theta = rows[ok], theta[ok]
        if rows.size:
            lp = np.full(rows.size, tr.flat_const)
            for i, prior in tr.other:
                lp = lp + prior.log_prob(theta[:, i])
            log_prior[rows] = lp
            log_lik[rows] = lik(theta)
        return log_prior, log_lik

    return log_parts


def _log_prob_fn(lik: Likelihood, tr: _Transform):
    """Log posterior density in u (the hot path: one vectorised call per half-ensemble)."""
    log_parts = _log_parts_fn(lik, tr)

    def log_prob(u):
        log_prior, log_lik = log_parts(u)
        return log_prior + log_lik

    return log_prob


def initial_walkers(lik: Likelihood, seeds_scaled, n_walkers: int, rng: np.random.Generator,
                    *, mode_window: float = 10.0, jitter: float = 1e-3) -> np.ndarray:
    """Walker positions (θ, scaled) around the seeds' modes, inside the support.

    ``seeds_scaled`` holds structure parameters (without noise) on the scaled problem. Seeds whose
    best log-likelihood is more than ``mode_window`` below the best seed are dropped; the rest
    share the walkers round-robin, each walker a Gaussian jitter of relative size up to
    ``jitter`` in the sampling coordinates that lies in the support.
    """
    seeds = np.atleast_2d(np.asarray(seeds_scaled, dtype=float))
    if lik.noise_param:
        seeds = np.column_stack([seeds, lik.noise_estimate(seeds)])
    tr = _Transform(lik)
    # Project the seeds into the prior box (in the sampling coordinates), then keep those that
    # satisfy the constraints; without any, start from prior draws inside the support.
    span = tr.hi_u - tr.lo_u
    margin = np.where(np.isfinite(span), 1e-6 * span, 0.0)
    u = np.clip(tr.to_u(seeds), tr.lo_u + margin, tr.hi_u - margin)
    seeds = tr.to_theta(u)
    ok = lik.in_support(seeds)
    if ok.any():
        anchor = seeds[ok][np.argmax(lik(seeds[ok]))]
    else:
        draws = np.column_stack([p.sample(rng, 2000) for p in lik.prior_list])
        draws = draws[lik.in_support(draws)]
        if not draws.size:
            raise InputError(
                f"no starting point of structure '{lik.structure.name}' lies in the prior "
                "support (stable, dissipative, within the prior ranges)"
            )
        best = draws[np.argsort(-lik(draws))[:8]]
        anchor = best[0]
    # A seed just outside the support (e.g. an optimum with a slightly unstable root when the
    # truth lies on the stability boundary) is moved onto the boundary (see _into_support), so
    # its mode is not lost.
    repaired = [_into_support(lik, tr, theta, anchor) for theta in seeds[~ok]]
    seeds = np.vstack([seeds[ok], *[r[None, :] for r in repaired if r is not None]])
    if not ok.any():
        seeds = np.vstack([seeds, best])
    ll = lik(seeds)
    keep = ll >= ll.max() - mode_window
    seeds = seeds[keep][np.argsort(-ll[keep])]
    u_seeds = tr.to_u(seeds)
    # Jittered copies of every seed, the jitter shrinking from ``jitter`` to 1e-4 of it: a seed
    # on the boundary of the support (a coefficient at zero, q at its bound) keeps only the
    # copies on the inner side, so many are drawn at once and the walkers take distinct ones.
    n_try = 64 * (n_walkers // len(u_seeds) + 1)
    pools = []
    for base in u_seeds:
        scale = jitter * np.logspace(0, -4, n_try)[:, None] * (1.0 + np.abs(base))
        cand = tr.to_theta(base + scale * rng.normal(size=(n_try, base.size)))
        pools.append(cand[lik.in_support(cand)])
    pools = [p for p in pools if len(p)] or [tr.to_theta(u_seeds)]
    # Round-robin over the seeds; walker i takes copy i // len(pools) of its seed's pool.
    return np.array([pools[i % len(pools)][(i // len(pools)) % len(pools[i % len(pools)])]
                     for i in range(n_walkers)])


def _into_support(lik: Likelihood, tr: _Transform, theta, anchor, *, steps: int = 40):
    """A point in the support near ``theta`` (outside it): ``theta`` with one coordinate set to
    zero (or to the lower bound of a log-uniform prior), the most likely of those that are in
    the support; else the point of the segment from ``anchor`` (in the support) to ``theta``
    nearest to ``theta`` and still in the support, by bisection in the sampling coordinates.
    None if ``theta`` is not finite."""
    u_out, u_in = tr.to_u(np.asarray(theta, float)[None, :])[0], tr.to_u(anchor[None, :])[0]
    if not np.all(np.isfinite(u_out)):
        return None
    # First the simplest repairs: one coordinate set to zero (or its smallest allowed value),
    # which puts a root that crossed the boundary back on it (an integrator when b0 = 0).
    small = np.where(tr.log, tr.lo_u, np.clip(0.0, tr.lo_u, tr.hi_u))
    cand = np.repeat(u_out[None, :], len(u_out), axis=0)
    cand[np.arange(len(u_out)), np.arange(len(u_out))] = small
    cand = tr.to_theta(cand[np.all(np.isfinite(cand), axis=1)])
    cand = cand[lik.in_support(cand)] if len(cand) else cand
    if len(cand):
        return cand[np.argmax(lik(cand))]
    lo, hi = 0.0, 1.0  # fraction of the way from the anchor towards theta
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        if lik.in_support(tr.to_theta((u_in + mid * (u_out - u_in))[None, :]))[0]:
            lo = mid
        else:
            hi = mid
    return tr.to_theta((u_in + lo * (u_out - u_in))[None, :])[0]


def sample_posterior(
    lik: Likelihood,
    seeds_scaled,
    *,
    seed: int = 0,
    n_walkers: int | None = None,
    tau_factor: float = 50.0,
    max_steps: int = 10_000,
    check_every: int = 250,
    max_draws: int = 2000,
    progress: bool | None = None,
    predictive: bool = True,
) -> PosteriorResult:
    """Sample the posterior of ``lik`` with emcee.

    Parameters
    ----------
    lik : Likelihood
    seeds_scaled : array_like, shape (k, n_structure_params)
        Starting modes on the scaled problem (e.g. ``FitResult.optima`` and linear seeds).
    seed : int
        Seed of the walker jitter, the moves and the posterior predictive draws.
    n_walkers : int, optional
        Default max(32, 4·ndim), rounded up to a multiple of 4 (the walker groups of R-hat).
    tau_factor, max_steps, check_every
        Run until the chain is ``tau_factor``·τ long (τ changing by < 10 % between checks) and
        R-hat < 1.01 and bulk and tail ESS ≥ 400 hold, at most ``max_steps`` steps, checking
        every ``check_every`` steps.
    max_draws : int
        Upper bound on the stored draws (thinning is raised to respect it).
    progress : bool, optional
        Progress bar (tqdm); default: on when stderr is a terminal.
    predictive : bool
        Store the posterior predictive and the model response in the InferenceData.

    Returns
    -------
    PosteriorResult
    """
    import emcee

    rng = np.random.default_rng(seed)
    ndim = lik.ndim
    n_walkers = n_walkers or max(32, 4 * ndim)
    n_walkers += -n_walkers % WALKER_GROUPS  # equal groups for R-hat (and even for emcee)
    if n_walkers < 2 * ndim:
        raise InputError(f"n_walkers must be at least {2 * ndim} for {ndim} parameters")
    if progress is None:
        progress = sys.stderr.isatty()
    tr = _Transform(lik)
    p0 = tr.to_u(initial_walkers(lik, seeds_scaled, n_walkers, rng))
    # DE with γ = 1 carries a walker by the distance between two others: from one mode to
    # another where walkers sit in both (ter Braak 2006). Max-order members have such modes
    # (a degree-k polynomial in s^q is one of degree 2k in s^(q/2)); without this move the
    # walkers keep the split between the modes they started with.
    moves = [(emcee.moves.DEMove(), 0.5), (emcee.moves.DEMove(gamma0=1.0), 0.1),
             (emcee.moves.DESnookerMove(), 0.2), (emcee.moves.StretchMove(), 0.2)]
    sampler = emcee.EnsembleSampler(n_walkers, ndim, _log_prob_fn(lik, tr), moves=moves,
                                    vectorize=True)
    sampler.random_state = np.random.RandomState(seed).get_state()

    old_tau = np.inf
    tau = np.full(ndim, np.nan)
    settled = False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for _ in sampler.sample(p0, iterations=max_steps, progress=progress,
                                progress_kwargs={"desc": lik.structure.name, "leave": False}):
            it = sampler.iteration
            if it % check_every:
                continue
            tau = sampler.get_autocorr_time(tol=0, discard=it // 5)
            if np.all(np.isfinite(tau)):
                settled = bool(np.all(tau * tau_factor < it)
                               and np.all(np.abs(old_tau - tau) < 0.1 * tau))
                old_tau = tau
                # Long enough by τ: stop when the walkers also agree (R-hat) and the draws
                # carry enough information (ESS); otherwise keep going up to the cap.
                if settled and _diagnostics(sampler, tau, tr, lik.param_names)[3]:
                    break
                settled = False
    n_steps = sampler.iteration
    if not np.all(np.isfinite(tau)):
        tau = sampler.get_autocorr_time(tol=0, discard=n_steps // 5)
    tau_max = float(np.nanmax(tau)) if np.any(np.isfinite(tau)) else n_steps / 10
    tau_min = float(np.nanmin(tau)) if np.any(np.isfinite(tau)) else 1.0
    burn, thin = _burn_thin(n_steps, np.array([tau_min, tau_max]))
    kept = (n_steps - burn) // thin
    if kept * n_walkers > max_draws:
        thin = int(math.ceil((n_steps - burn) * n_walkers / max_draws))
    chain_u = sampler.get_chain(discard=burn, thin=thin)  # (steps, walkers, ndim)
    log_post = sampler.get_log_prob(discard=burn, thin=thin)
    chain = tr.to_theta(chain_u)
    n_kept = chain.shape[0]
    flat_scaled = chain.transpose(1, 0, 2).reshape(-1, ndim)  # walker-major: chain = walker
    pointwise = lik.pointwise(flat_scaled)
    loglik = pointwise.sum(axis=1)
    flat_phys = lik.to_physical(flat_scaled)
    lp_flat = log_post.T.reshape(-1)

    post = {name: flat_phys[:, i].reshape(n_walkers, n_kept) for i, name in enumerate(lik.param_names)}
    diag_tau = tau if np.all(np.isfinite(tau)) else np.full(ndim, tau_max)
    rhat_max, ess_bulk_min, ess_tail_min, _ = _diagnostics(sampler, diag_tau, tr, lik.param_names)
    messages = []
    if not settled:
        messages.append(
            f"{lik.structure.name}: stopped at the cap of {max_steps} steps before the chain was "
            f"{tau_factor:g} autocorrelation times long (tau up to {tau_max:.0f} steps)"
        )
    if not rhat_max < RHAT_MAX:
        messages.append(f"{lik.structure.name}: R-hat {rhat_max:.3f} is not below {RHAT_MAX}")
    if not min(ess_bulk_min, ess_tail_min) >= ESS_MIN:
        messages.append(
            f"{lik.structure.name}: effective sample size {min(ess_bulk_min, ess_tail_min):.0f} "
            f"is below {ESS_MIN}"
        )
    converged = not messages
    if messages:
        warnings.warn("; ".join(messages), ConvergenceWarning, stacklevel=2)

    best = int(np.argmax(lp_flat))
    map_theta = flat_phys[best]
    summary = _summaries(lik, tr, flat_phys, chain_u.transpose(1, 0, 2).reshape(-1, ndim), map_theta)
    idata = _inference_data(lik, post, pointwise, flat_scaled, lp_flat, n_walkers, n_kept,
                            rng if predictive else None)
    return PosteriorResult(
        structure=lik.structure.name,
        param_names=lik.param_names,
        noise=lik.noise,
        noise_reason=lik.noise_reason,
        samples=flat_phys,
        samples_scaled=flat_scaled,
        log_likelihood=loglik,
        summary=summary,
        map_theta=map_theta,
        max_log_likelihood=float(loglik.max()),
        tau=np.asarray(tau, dtype=float),
        n_steps=int(n_steps),
        burn=int(burn),
        thin=int(thin),
        n_walkers=int(n_walkers),
        acceptance=float(np.mean(sampler.acceptance_fraction)),
        rhat_max=rhat_max,
        ess_bulk_min=ess_bulk_min,
        ess_tail_min=ess_tail_min,
        converged=converged,
        messages=tuple(messages),
        idata=idata,
    )


def posterior_from_particles(lik: Likelihood, runs, *, seed: int = 0,
                             predictive: bool = True) -> PosteriorResult:
    """The posterior as the final particles of independent tempered-ladder runs.

    Each run (a :class:`~bayesfo.inference.smc.LadderRun`, or its particles in the sampling
    coordinates) carries prior draws to the posterior through resampling and Metropolis moves,
    so its particles are posterior draws that no walker had to reach by a long chain; where
    the emcee walkers did not converge (ridges, several modes) they are the posterior that is
    reported. The certificate is the agreement of the runs: each run is one chain of the
    rank-normalised split R-hat, and the bulk and tail ESS are computed over the runs (the
    particles of a run are put in random order first: their order after resampling follows
    their ancestors, not a chain). That ESS is an upper bound (particles of a run that share
    ancestors count as independent), capped by the number of distinct particles: the
    certificate rests on R-hat, the agreement of runs that share nothing but the guide.

    Parameters
    ----------
    lik : Likelihood
    runs : sequence of LadderRun or of ndarray, shape (n_particles, ndim)
        At least two runs, the same number of particles each.
    seed : int
        Seed of the shuffle and of the posterior predictive draws.
    predictive : bool
        Store the posterior predictive and the model response in the InferenceData.

    Returns
    -------
    PosteriorResult
        With ``sampler="ladder"``; ``n_walkers`` is the number of runs, ``n_steps`` 0 and
        ``tau`` NaN (no chain); ``converged`` when R-hat < 1.01 and the ESS ≥ 400.
    """
    az = arviz()
    rng = np.random.default_rng(seed)
    tr = _Transform(lik)
    chain_u = np.stack([np.asarray(getattr(r, "particles", r), dtype=float) for r in runs])
    n_runs, n_kept, _ = chain_u.shape
    if n_runs < 2:
        raise ValueError("at least two runs are needed to certify the posterior")
    chain_u = np.stack([c[rng.permutation(n_kept)] for c in chain_u])
    chains = az.convert_to_dataset({name: tr.to_theta(chain_u)[:, :, i]
                                    for i, name in enumerate(lik.param_names)})
    rhat_max = max(float(v) for v in az.rhat(chains).data_vars.values())
    distinct = float(len(np.unique(chain_u.reshape(-1, chain_u.shape[2]), axis=0)))
    ess_bulk = min(distinct, min(float(v) for v in az.ess(chains, method="bulk").data_vars.values()))
    ess_tail = min(distinct, min(float(v) for v in az.ess(chains, method="tail").data_vars.values()))
    messages = []
    if not rhat_max < RHAT_MAX:
        messages.append(f"{lik.structure.name}: the tempered-ladder runs disagree (R-hat "
                        f"{rhat_max:.3f} is not below {RHAT_MAX})")
    if not min(ess_bulk, ess_tail) >= ESS_MIN:
        messages.append(f"{lik.structure.name}: the tempered-ladder particles give an effective "
                        f"sample size of {min(ess_bulk, ess_tail):.0f}, below {ESS_MIN}")
    acceptance = [float(np.mean(r.acceptance[-1:])) for r in runs if hasattr(r, "acceptance")]
    post = result_from_draws(lik, chain_u, sampler="ladder", rhat=rhat_max, ess_bulk=ess_bulk,
                             ess_tail=ess_tail, messages=tuple(messages),
                             converged=not messages, seed=seed, predictive=predictive,
                             acceptance=float(np.mean(acceptance)) if acceptance else np.nan)
    post.idata.posterior.attrs.update(sampler="tempered ladder", runs=n_runs)
    return post


def result_from_draws(lik: Likelihood, chain_u, *, sampler: str, rhat: float, ess_bulk: float,
                      ess_tail: float, messages: tuple, converged: bool, seed: int = 0,
                      predictive: bool = True, acceptance: float = np.nan) -> PosteriorResult:
    """A :class:`PosteriorResult` from posterior draws that another route than emcee produced
    (``chain_u``: chains × draws × parameters in the sampling coordinates), with that route's
    diagnostics. ``n_walkers`` is the number of chains, ``n_steps`` 0 and ``tau`` NaN."""
    rng = np.random.default_rng(seed)
    tr = _Transform(lik)
    chain_u = np.asarray(chain_u, dtype=float)
    n_chains, n_kept, ndim = chain_u.shape
    flat_u = chain_u.reshape(-1, ndim)  # chain-major
    flat_scaled = tr.to_theta(flat_u)
    pointwise = lik.pointwise(flat_scaled)
    loglik = pointwise.sum(axis=1)
    flat_phys = lik.to_physical(flat_scaled)
    lp_flat = _log_prob_fn(lik, tr)(flat_u)
    post = {name: flat_phys[:, i].reshape(n_chains, n_kept)
            for i, name in enumerate(lik.param_names)}
    best = int(np.argmax(lp_flat))
    map_theta = flat_phys[best]
    summary = _summaries(lik, tr, flat_phys, flat_u, map_theta)
    idata = _inference_data(lik, post, pointwise, flat_scaled, lp_flat, n_chains, n_kept,
                            rng if predictive else None)
    idata.posterior.attrs.update(sampler=sampler)
    return PosteriorResult(
        structure=lik.structure.name, param_names=lik.param_names, noise=lik.noise,
        noise_reason=lik.noise_reason, samples=flat_phys, samples_scaled=flat_scaled,
        log_likelihood=loglik, summary=summary, map_theta=map_theta,
        max_log_likelihood=float(loglik.max()), tau=np.full(ndim, np.nan), n_steps=0, burn=0,
        thin=1, n_walkers=n_chains, acceptance=acceptance, rhat_max=rhat, ess_bulk_min=ess_bulk,
        ess_tail_min=ess_tail, converged=converged, messages=tuple(messages), idata=idata,
        sampler=sampler,
    )


WALKER_GROUPS = 4


MIN_DRAWS_PER_WALKER = 100


def _burn_thin(n_steps: int, tau) -> tuple[int, int]:
    """Burn-in 2·τ_max (at most half the run) and thinning τ_min/2, reduced so that every walker
    keeps at least ``MIN_DRAWS_PER_WALKER`` draws (short, capped runs still get diagnostics)."""
    burn = min(int(math.ceil(2 * np.nanmax(tau))), n_steps // 2)
    thin = max(1, int(np.nanmin(tau) // 2))
    thin = max(1, min(thin, (n_steps - burn) // MIN_DRAWS_PER_WALKER))
    return burn, thin


def _diagnostics(sampler, tau, tr, names):
    """(R-hat max, bulk ESS min, tail ESS min, pass) after a burn-in of 2·τ_max, thinned by
    τ_min/2.

    R-hat is the rank-normalised split R-hat across ``WALKER_GROUPS`` groups of walkers (each
    group's walkers, step by step, form one chain): it compares the groups with each other and
    the first half of the run with the second. The effective sample sizes treat every walker
    as a chain.
    """
    az = arviz()
    n = sampler.iteration
    burn, thin = _burn_thin(n, tau)
    chain = tr.to_theta(sampler.get_chain(discard=burn, thin=thin))  # (steps, walkers, ndim)
    steps, walkers, _ = chain.shape
    groups = chain.reshape(steps, WALKER_GROUPS, walkers // WALKER_GROUPS, -1)
    groups = groups.transpose(1, 0, 2, 3).reshape(WALKER_GROUPS, -1, chain.shape[2])
    by_group = az.convert_to_dataset({name: groups[:, :, i] for i, name in enumerate(names)})
    by_walker = az.convert_to_dataset({name: chain[:, :, i].T for i, name in enumerate(names)})
    rhat = max(float(v) for v in az.rhat(by_group).data_vars.values())
    bulk = min(float(v) for v in az.ess(by_walker, method="bulk").data_vars.values())
    tail = min(float(v) for v in az.ess(by_walker, method="tail").data_vars.values())
    return rhat, bulk, tail, bool(rhat < RHAT_MAX and min(bulk, tail) >= ESS_MIN)


def _count_modes(u: np.ndarray, lo: float, hi: float) -> int:
    """Peaks of a kernel density of ``u`` with a prominence of at least 5 % of the highest and
    half their own height.

    The bandwidth is Silverman's robust rule, 0.9·min(sd, IQR/1.34)·n^(-1/5): the standard
    deviation of draws from two separated modes is that of their distance, and a bandwidth set
    by it smooths a minor mode away.
    """
    from scipy import signal, stats

    if np.ptp(u) <= 0 or u.size < 20:
        return 1
    sd = float(np.std(u))
    spread = min(sd, float(np.subtract(*np.percentile(u, [75, 25]))) / 1.34) or sd
    grid = np.linspace(max(lo, u.min()), min(hi, u.max()), 512)
    dens = stats.gaussian_kde(u, bw_method=0.9 * spread * u.size ** -0.2 / sd)(grid)
    padded = np.r_[0.0, dens, 0.0]
    peaks, props = signal.find_peaks(padded, prominence=0.05 * dens.max())
    # A mode stands out: the valley to its higher neighbour is below half its own height (a
    # flat or noisy density has bumps of small relative prominence).
    real = props["prominences"] >= 0.5 * padded[peaks]
    return max(1, int(np.sum(real)))


def _summaries(lik, tr, flat_phys, flat_u, map_theta) -> dict:
    az = arviz()

    out = {}
    for i, (name, prior) in enumerate(zip(lik.param_names, lik.prior_list)):
        x = flat_phys[:, i]
        lo, hi = az.hdi(x, hdi_prob=HDI_PROB)
        plo, phi = prior.bounds
        if tr.log[i]:
            plo, phi = math.log(plo), math.log(phi)
        u = flat_u[:, i]
        ulo, uhi = az.hdi(u, hdi_prob=HDI_PROB)
        wide = bool(np.isfinite(phi - plo) and (uhi - ulo) > 0.5 * (phi - plo))
        out[name] = ParameterSummary(
            mean=float(x.mean()), sd=float(x.std(ddof=1)), hdi_low=float(lo), hdi_high=float(hi),
            map=float(map_theta[i]), median=float(np.median(x)), poorly_determined=wide,
            multimodal=_count_modes(u, plo, phi) > 1,
        )
    return out


def _inference_data(lik, post, pointwise, flat_scaled, lp_flat, n_walkers, n_kept, rng):
    az = arviz()

    omega = lik.data.omega
    shape = (n_walkers, n_kept, omega.size)
    g = lik.data.response
    groups = dict(
        posterior=post,
        log_likelihood={"G": pointwise.reshape(shape)},
        observed_data={"G_real": g.real, "G_imag": g.imag},
        sample_stats={"lp": lp_flat.reshape(n_walkers, n_kept)},
    )
    if rng is not None:
        model = lik.model(flat_scaled) * lik.scaling.g_ref
        if lik.noise == "known":
            sd = np.broadcast_to(lik.data.sigma, model.shape)
        else:
            s = flat_scaled[:, -1:] * lik.scaling.g_ref
            sd = s * np.ones(model.shape) if lik.noise == "constant" else flat_scaled[:, -1:] * np.abs(g)
        noise = sd / math.sqrt(2.0) * (rng.normal(size=model.shape) + 1j * rng.normal(size=model.shape))
        rep = model + noise
        groups["posterior_predictive"] = {"G_real": rep.real.reshape(shape), "G_imag": rep.imag.reshape(shape)}
        groups["posterior"] = dict(post, model_real=model.real.reshape(shape), model_imag=model.imag.reshape(shape))
    dims = {k: ["omega"] for k in ("G", "G_real", "G_imag", "model_real", "model_imag")}
    idata = az.from_dict(**groups, coords={"omega": omega}, dims=dims)
    idata.posterior.attrs.update(
        structure=lik.structure.name, noise=lik.noise, kind=lik.data.kind,
        omega_units="rad/s", data=lik.data.label,
    )
    return idata


def _netcdf_bytes_needed(idata) -> int:
    """An upper bound of the size of ``idata`` as NetCDF: its arrays uncompressed, plus the
    HDF5 headers of every variable and group."""
    total = 0
    for group in idata.groups():
        ds = idata[group]
        total += ds.nbytes + 16_384 * (len(ds.variables) + 1)
    return total + 65_536


def save_netcdf(idata, path) -> Path:
    """Write InferenceData to NetCDF through a temporary file and an atomic rename.

    Raises
    ------
    OSError
        ``ENOSPC`` before anything is written when the file system has less free space than the
        file may need: HDF5 fails on a full disk with errors it cannot recover from (the
        process crashes at exit), so the space is checked first.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    needed = _netcdf_bytes_needed(idata)
    free = shutil.disk_usage(path.parent).free
    if free < needed:
        raise OSError(errno.ENOSPC, f"{needed} bytes may be needed for {path.name}, "
                                    f"{free} are free", str(path.parent))
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".nc", dir=path.parent)
    os.close(fd)
    try:
        idata.to_netcdf(tmp)
        publish(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path
