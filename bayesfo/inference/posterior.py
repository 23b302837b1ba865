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
and has ``converged = False``. The result (:class:`~bayesfo.inference.results.PosteriorResult`)
and the sampling coordinates (:mod:`bayesfo.inference.transform`) live in their own modules.
"""

from __future__ import annotations

import math
import sys
import warnings

import numpy as np

from ..errors import ConvergenceWarning, InputError
from ._arviz import ess_min, rhat_max
from .likelihood import Likelihood
from .results import (
    ESS_MIN,
    RHAT_MAX,
    PosteriorResult,
    _inference_data,
    _summaries,
    posterior_from_particles,
    result_from_draws,
    save_netcdf,
)
from .transform import Transform, _log_prob_fn

__all__ = ["ConvergenceWarning", "PosteriorResult", "initial_walkers", "posterior_from_particles",
           "result_from_draws", "sample_posterior", "save_netcdf", "support_seeds"]


def support_seeds(lik: Likelihood, seeds_scaled, rng: np.random.Generator, *,
                  mode_window: float = 10.0) -> tuple[np.ndarray, np.ndarray]:
    """The seeds (structure parameters, scaled; the noise parameter is added) moved into the
    support, those within ``mode_window`` of the best log-likelihood, best first, with their
    log-likelihoods: a seed outside the support is moved onto its boundary
    (:func:`_into_support`); without any seed in the support, the most likely of 2 000 prior
    draws in it join them."""
    seeds = np.atleast_2d(np.asarray(seeds_scaled, dtype=float))
    if lik.noise_param:
        seeds = np.column_stack([seeds, lik.noise_estimate(seeds)])
    tr = Transform(lik)
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
    order = np.argsort(-ll[keep])
    return seeds[keep][order], ll[keep][order]


def initial_walkers(lik: Likelihood, seeds_scaled, n_walkers: int, rng: np.random.Generator,
                    *, mode_window: float = 10.0, jitter: float = 1e-3) -> np.ndarray:
    """Walker positions (θ, scaled) around the seeds' modes, inside the support.

    ``seeds_scaled`` holds structure parameters (without noise) on the scaled problem. Seeds whose
    best log-likelihood is more than ``mode_window`` below the best seed are dropped; the rest
    share the walkers round-robin, each walker a Gaussian jitter of relative size up to
    ``jitter`` in the sampling coordinates that lies in the support.
    """
    tr = Transform(lik)
    seeds, _ = support_seeds(lik, seeds_scaled, rng, mode_window=mode_window)
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


def _into_support(lik: Likelihood, tr: Transform, theta, anchor, *, steps: int = 40):
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


def _snooker_move():
    """The DE snooker move of ter Braak & Vrugt (2008), on emcee's four-way split of the walkers.

    For walker x, three walkers z, z1, z2 of the complementary sets (in random roles): with e the
    unit vector of x − z, the proposal is x' = x + γ·e·eᵀ(z1 − z2) (γ = 1.7), accepted with the
    extra factor (|x' − z| / |x − z|)^(d−1).

    emcee's own DESnookerMove up to 3.1.6 (:data:`LAST_UNFIXED_EMCEE`) is not used: it divides x − z by
    √|x − z| instead of |x − z| (the step is then the projection times |x − z|) and takes half
    the exponent d − 1, so it does not leave the target invariant (fixed upstream by
    dfm/emcee#531; a later release's own move is used, with the null move below). Its walkers
    come out narrower than the target, alone and in bayesfo's mixture of moves, where this move
    agrees with importance sampling and random-walk Metropolis (BENCHMARKS.md, "Measurements
    behind design choices").

    A proposal through a walker's own position (z = x: walkers that coincide, all of them
    pinned in a corner of the prior box, as the integer Voigt is on the 26-decade NREL curve)
    is not defined; it is made a null move (staying put is a rejected proposal, which leaves
    the target invariant).
    """
    import emcee

    if _release(emcee.__version__) > LAST_UNFIXED_EMCEE:
        # A release with the fix: emcee's own move, with only the null move added.
        class _Guarded(emcee.moves.DESnookerMove):
            def get_proposal(self, s, c, random):
                with np.errstate(invalid="ignore", divide="ignore"):
                    q, factors = super().get_proposal(s, c, random)
                return _null_where_undefined(s, q, factors)

        return _Guarded()

    class _SnookerMove(emcee.moves.DESnookerMove):
        def get_proposal(self, s, c, random):
            ns, ndim = s.shape
            # One walker from each of the three complementary sets, in random roles.
            picks = np.stack([cj[random.randint(len(cj), size=ns)] for cj in c[:3]], axis=1)
            roles = np.argsort(random.rand(ns, 3), axis=1)
            picks = np.take_along_axis(picks, roles[:, :, None], axis=1)
            z, z1, z2 = picks[:, 0], picks[:, 1], picks[:, 2]
            with np.errstate(invalid="ignore", divide="ignore"):
                delta = s - z
                norm = np.linalg.norm(delta, axis=1)
                e = delta / norm[:, None]
                q = s + self.gammas * np.sum(e * (z1 - z2), axis=1)[:, None] * e
                factors = (ndim - 1.0) * (np.log(np.linalg.norm(q - z, axis=1)) - np.log(norm))
            return _null_where_undefined(s, q, factors)

    return _SnookerMove()


#: The last emcee release whose DESnookerMove does not leave the target invariant (the fix is
#: dfm/emcee#531); a later release's own move is used.
LAST_UNFIXED_EMCEE = (3, 1, 6)


def _release(version: str) -> tuple[int, int, int]:
    """``"3.1.6"`` → (3, 1, 6); ``"3.2"`` → (3, 2, 0); what follows the numbers is ignored."""
    import re

    found = re.match(r"(\d+)(?:\.(\d+))?(?:\.(\d+))?", version)
    return tuple(int(x) for x in found.groups(default="0")) if found else (0, 0, 0)


def _null_where_undefined(s, q, factors):
    """Proposals that are not finite (through a walker's own position) become null moves."""
    bad = ~np.all(np.isfinite(q), axis=1) | ~np.isfinite(factors)
    q[bad] = s[bad]
    return q, np.where(bad, 0.0, factors)


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
    give_up: bool = False,
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
    tau_factor, max_steps, check_every : float, int, int
        Run until the chain is ``tau_factor``·τ long (τ changing by < 10 % between checks) and
        R-hat < 1.01 and bulk and tail ESS ≥ 400 hold, at most ``max_steps`` steps, checking
        every ``check_every`` steps.
    max_draws : int
        Upper bound on the stored draws (thinning is raised to respect it).
    progress : bool, optional
        Progress bar (tqdm); default: on when stderr is a terminal.
    predictive : bool
        Store the posterior predictive and the model response in the DataTree.
    give_up : bool
        Stop once a fifth of ``max_steps`` has run if the autocorrelation time estimated so far
        already needs more than ``max_steps`` for ``tau_factor`` of them (such estimates only
        grow with the chain). ``compare`` sets it: the tempered ladder then gives the
        posterior, and the walkers stop well before ``max_steps`` (BENCHMARKS.md, "Measurements
        behind design choices").

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
    tr = Transform(lik)
    p0 = tr.to_u(initial_walkers(lik, seeds_scaled, n_walkers, rng))
    # DE with γ = 1 carries a walker by the distance between two others: from one mode to
    # another where walkers sit in both (ter Braak 2006). Max-order members have such modes
    # (a degree-k polynomial in s^q is one of degree 2k in s^(q/2)); without this move the
    # walkers keep the split between the modes they started with.
    moves = [(emcee.moves.DEMove(), 0.5), (emcee.moves.DEMove(gamma0=1.0), 0.1),
             (_snooker_move(), 0.2), (emcee.moves.StretchMove(), 0.2)]
    sampler = emcee.EnsembleSampler(n_walkers, ndim, _log_prob_fn(lik, tr), moves=moves,
                                    vectorize=True)
    sampler.random_state = np.random.RandomState(seed).get_state()

    old_tau = np.inf
    tau = np.full(ndim, np.nan)
    settled = gave_up = False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for _ in sampler.sample(p0, iterations=max_steps, progress=progress,
                                progress_kwargs={"desc": lik.structure.name, "leave": False}):
            it = sampler.iteration
            if it % check_every:
                continue
            tau = sampler.get_autocorr_time(tol=0, discard=it // 5)
            if (give_up and it >= max_steps // 5 and np.all(np.isfinite(tau))
                    and tau_factor * float(np.max(tau)) > max_steps):
                # τ estimated from a short chain only understates the true τ (a ridge's grows
                # with the chain): the cap cannot be met; stop and leave it to the ladder.
                gave_up = True
                break
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
    if gave_up:
        messages.append(
            f"{lik.structure.name}: stopped after {n_steps} steps: the autocorrelation time "
            f"(at least {float(np.max(tau)):.0f} steps) needs more than the cap of {max_steps} "
            f"steps for {tau_factor:g} of them"
        )
    elif not settled:
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
    n = sampler.iteration
    burn, thin = _burn_thin(n, tau)
    chain = tr.to_theta(sampler.get_chain(discard=burn, thin=thin))  # (steps, walkers, ndim)
    steps, walkers, _ = chain.shape
    groups = chain.reshape(steps, WALKER_GROUPS, walkers // WALKER_GROUPS, -1)
    groups = groups.transpose(1, 0, 2, 3).reshape(WALKER_GROUPS, -1, chain.shape[2])
    by_walker = chain.transpose(1, 0, 2)
    rhat = rhat_max(groups)
    bulk, tail = ess_min(by_walker, "bulk"), ess_min(by_walker, "tail")
    return rhat, bulk, tail, bool(rhat < RHAT_MAX and min(bulk, tail) >= ESS_MIN)


