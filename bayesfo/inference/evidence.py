"""Log-evidence ln Z of a structure, by two independent routes.

``bridge_evidence``
    Bridge sampling (Meng and Wong 1996, in the iterative form of Gronau et al. 2017) from the
    emcee posterior draws: a proposal fitted to half of the draws (in the sampling coordinates,
    log for log-uniform priors; a mixture of multivariate normals on k-means clusters, k chosen
    by BIC, one normal for a compact posterior), the other half and as many proposal
    draws in the bridge, and the relative mean-squared error of Frühwirth-Schnatter (2004)
    with the autocorrelation of the draws taken into account through their effective size.
``ladder_evidence``
    Bridge sampling as above, from the particles of sequential Monte Carlo over a tempered
    ladder (``bayesfo.inference.smc``) instead of the emcee draws: the particles start from the
    prior and keep every mode with its weight, where emcee's walkers may not (ridges and
    several modes of over-parameterised structures); the walkers' draws guide its moves
    towards the narrow modes they found. The default route when the emcee posterior did not
    converge.
``nested_evidence``
    Nested sampling with dynesty, on the same prior (its quantile function is the prior
    transform) and the same likelihood.

Both integrate the likelihood over the prior restricted to its support (stable, dissipative,
card inequalities). The prior is normalised on that support, so ln Z = ln Z' − ln P(S), where
Z' is the integral over the support of the untruncated prior and P(S) its prior mass, estimated
by Monte Carlo from the prior (exactly 1 when every prior draw is admissible). Priors are proper,
so the evidence is defined; it depends on them, and the output states them.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np
from scipy.special import logsumexp

from ..errors import InputError
from ._arviz import ess_draws, psis
from ._mixture import _GaussianMixture
from .likelihood import Likelihood
from .results import PosteriorResult, exponent_intervals
from .smc import _upper_count, ladder_runs_together
from .transform import Transform, _log_prob_fn


@dataclass(frozen=True)
class Evidence:
    """ln Z with its standard error.

    Attributes
    ----------
    log_z, log_z_err : float
        Natural-log evidence (physical units of the data, like the log-likelihood) and its
        standard error.
    method : str
        ``"bridge"`` (from the emcee draws), ``"ladder"`` (bridge sampling from the particles of
        a tempered ladder) or ``"nested"``.
    log_support : float
        ln P(S), the log prior mass of the support (0 when the whole prior range is admissible).
    n_likelihood : int
        Likelihood evaluations spent by the estimator.
    seconds : float
        Wall time.
    reached_log_likelihood : float or None
        Tempered ladder only: the highest log-likelihood among the final particles of the run
        that reached least high (a run that ends well below the best fit has missed mass).
    given_noise : Evidence or None
        Where ``log_z`` is the evidence of a structure with the noise model as a nuisance
        (marginalised over the candidate noise models, :func:`~bayesfo.comparison.steps.
        choose_noise`): the estimate under the chosen noise model alone, which the posterior
        is conditional on. None where ``log_z`` is that estimate itself.
    """

    log_z: float
    log_z_err: float
    method: str
    log_support: float
    n_likelihood: int
    seconds: float
    reached_log_likelihood: float | None = None
    given_noise: Evidence | None = None

    def to_dict(self) -> dict:
        out = dict(self.__dict__)
        if self.given_noise is not None:
            out["given_noise"] = self.given_noise.to_dict()
        return out

    @property
    def conditional(self) -> Evidence:
        """The estimate under one noise model: :attr:`given_noise` where ``log_z`` is
        marginalised over several, else this estimate."""
        return self if self.given_noise is None else self.given_noise


#: Admissible prior draws :func:`log_support_fraction` draws on for, where its first draws hold
#: fewer: the standard error of ln P(S) is about one over the square root of this count.
SUPPORT_COUNT = 100

#: Prior draws :func:`log_support_fraction` makes at most (as many as the tempered ladder's
#: search for its starting particles, ``smc._prior_particles``).
MAX_SUPPORT_DRAWS = 5_000_000

#: Prior draws without an admissible one after which :func:`log_support_fraction` gives up: the
#: support then holds less than 1.5·10⁻⁵ of the prior (at 95 %).
EMPTY_SUPPORT_DRAWS = 200_000


def log_support_fraction(lik: Likelihood, rng: np.random.Generator, n: int = 20_000,
                         max_draws: int = MAX_SUPPORT_DRAWS) -> tuple[float, float]:
    """ln P(S) and its standard error from ``n`` prior draws, or more where few are admissible.

    Where fewer than :data:`SUPPORT_COUNT` of the first ``n`` draws lie in the support, the
    estimate draws on in batches, sized by the share seen so far, until that many are admissible
    or ``max_draws`` are drawn, or once an upper bound of the admissible count
    (``smc._upper_count``, 5 standard deviations above the share seen) could not reach
    :data:`SUPPORT_COUNT` within ``max_draws`` (the estimate then rests on fewer, with the
    larger error that says so), or, with none admissible, after :data:`EMPTY_SUPPORT_DRAWS`.
    A structure whose support holds 1 in 10 000 prior draws gets an estimate with an error of
    about 0.1 nats instead of none (or one of a single draw). The same generator state gives
    the same numbers; where the first draws hold enough, they are the numbers of ``n`` draws
    alone.

    Raises
    ------
    InputError
        If no prior draw lies in the support.
    """
    drawn = k = 0
    batch = n
    while True:
        draws = np.column_stack([p.sample(rng, batch) for p in lik.prior_list])
        k += int(lik.in_support(draws).sum())
        drawn += batch
        if (k >= SUPPORT_COUNT or drawn >= max_draws
                or (k == 0 and drawn >= EMPTY_SUPPORT_DRAWS)
                or k + _upper_count(k, drawn, max_draws - drawn) < SUPPORT_COUNT):
            break
        # Enough for the count at the share seen (one draw where none was admissible), with a
        # margin; at least n, at most 200 000 at once (the support check's temporaries).
        batch = int(min(max(1.5 * (SUPPORT_COUNT - k) * drawn / max(k, 1), n), 200_000,
                        max_draws - drawn))
    if k == 0:
        raise InputError(
            f"none of {drawn} prior draws of structure '{lik.structure.name}' is stable and "
            "dissipative: the prior has (almost) no admissible mass"
        )
    if k == drawn:
        return 0.0, 0.0
    p = k / drawn
    return math.log(p), math.sqrt((1 - p) / (drawn * p))


def _ess(x: np.ndarray) -> float:
    """Effective size of the draws (walker-major rows) of a scalar, by arviz."""
    return ess_draws(x)


def bridge_evidence(lik: Likelihood, posterior: PosteriorResult, *, seed: int = 0,
                    max_iter: int = 1000, tol: float = 1e-10) -> Evidence:
    """ln Z by bridge sampling from the posterior draws of ``posterior``.

    Parameters
    ----------
    lik : Likelihood
        The likelihood the posterior was sampled with.
    posterior : PosteriorResult
        Draws on the scaled problem (``samples_scaled``), walker-major.
    seed : int
        Seeds the proposal draws and the support estimate.

    References
    ----------
    X.-L. Meng and W. H. Wong (1996), Statistica Sinica 6; Q. F. Gronau et al. (2017), J. Math.
    Psychol. 81; S. Frühwirth-Schnatter (2004), Econometrics Journal 7.
    """
    tr = Transform(lik)
    u = tr.to_u(posterior.samples_scaled)
    return _bridge(lik, u.reshape(posterior.n_walkers, -1, u.shape[1]), seed=seed,
                   max_iter=max_iter, tol=tol)


def _bridge(lik: Likelihood, draws: np.ndarray, *, seed: int, max_iter: int = 1000,
            tol: float = 1e-10, support: tuple[float, float] | None = None) -> Evidence:
    """Bridge sampling from posterior draws ``draws`` (chains × draws × parameters, in the
    sampling coordinates): every other draw of each chain fits the proposal, the rest enter
    the bridge with their effective size. ``support``: ln P(S) and its error where the caller
    has them (:func:`log_support_fraction`, else estimated here)."""
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    tr = Transform(lik)
    log_q = _log_prob_fn(lik, tr)
    n_walkers = draws.shape[0]
    fit_half = draws[:, 0::2].reshape(-1, draws.shape[2])
    bridge_half = draws[:, 1::2].reshape(-1, draws.shape[2])
    if bridge_half.shape[0] < 10 * draws.shape[2]:
        raise InputError("too few posterior draws for bridge sampling")
    mixture = _GaussianMixture.fit(fit_half, rng)
    n1 = bridge_half.shape[0]
    n2 = n1
    proposal = mixture.sample(n2, rng)
    log_g = mixture.log_pdf

    l1 = log_q(bridge_half) - log_g(bridge_half)
    l2 = log_q(proposal) - log_g(proposal)
    if not np.all(np.isfinite(l1)):
        raise InputError("posterior draws outside the support: the posterior result does not "
                         "belong to this likelihood")
    # The draws are autocorrelated: their effective number enters the weights and the error.
    ess = max(2.0, min(float(n1), _ess(l1.reshape(n_walkers, -1))))
    s1, s2 = ess / (ess + n2), n2 / (ess + n2)
    if not np.any(np.isfinite(l2)):
        raise InputError(
            f"bridge sampling for '{lik.structure.name}': none of {n2} proposal draws lies in "
            "the support (the posterior is far from Gaussian in the sampling coordinates)")
    # Meng & Wong's fixed-point iteration in log space: the ratios span hundreds of decades
    # when the posterior is far from the Gaussian proposal.
    l1c = l1 - float(np.median(l1))
    l2c = np.where(np.isfinite(l2), l2 - float(np.median(l1)), -np.inf)
    log_s1, log_s2 = math.log(s1), math.log(s2)
    log_r = 0.0
    for _ in range(max_iter):
        num = logsumexp(l2c - np.logaddexp(log_s1 + l2c, log_s2 + log_r)) - math.log(n2)
        den = logsumexp(-np.logaddexp(log_s1 + l1c, log_s2 + log_r)) - math.log(n1)
        log_r_new = float(num - den)
        if abs(log_r_new - log_r) < tol:
            log_r = log_r_new
            break
        log_r = log_r_new
    log_z_support = log_r + float(np.median(l1))
    # Relative mean-squared error (Frühwirth-Schnatter 2004), draws' autocorrelation via ESS;
    # both ratios are invariant to a common factor, so they are computed relative to r.
    f1 = np.exp(l2c - log_r - np.logaddexp(log_s1 + l2c - log_r, log_s2))  # proposal draws
    f2 = np.exp(-np.logaddexp(log_s1 + l1c - log_r, log_s2))                 # posterior draws
    re2 = np.var(f1) / np.mean(f1) ** 2 / n2 + np.var(f2) / np.mean(f2) ** 2 / ess
    log_s, log_s_err = log_support_fraction(lik, rng) if support is None else support
    return Evidence(
        log_z=log_z_support - log_s,
        log_z_err=math.sqrt(re2 + log_s_err**2),
        method="bridge",
        log_support=log_s,
        n_likelihood=int(n1 + n2),
        seconds=time.perf_counter() - t0,
    )


def ladder_evidence(lik: Likelihood, *, seed: int = 0, n_particles: int = 1000,
                    n_runs: int = 2, guide: PosteriorResult | None = None,
                    **ladder_kwargs) -> Evidence:
    """ln Z by bridge sampling from the particles of ``n_runs`` independent tempered ladders.

    Each run (:func:`bayesfo.inference.smc.ladder_run`) carries ``n_particles`` prior draws
    to the posterior; bridge sampling on its final particles gives one ln Z with its error. The
    result is their mean; its error combines the runs' stated errors with their spread, which
    also holds what the stated errors miss (how well each run weighted the posterior's modes).

    Unlike :func:`bridge_evidence` it needs no converged emcee run: the ladder reaches the
    posterior from the prior. ``guide`` (a posterior result, converged or not) lets the ladder
    propose from its draws as well (independence moves, see ``ladder_run``), so that a narrow
    mode found by the optimiser and the walkers is not lost on the way; the moves keep every
    rung exact, so a poor guide costs efficiency, never correctness.
    """
    return ladder_runs(lik, seed=seed, n_particles=n_particles, n_runs=n_runs, guide=guide,
                       **ladder_kwargs)[0]


def ladder_runs(lik: Likelihood, *, seed: int = 0, n_particles: int = 1000, n_runs: int = 2,
                guide: PosteriorResult | np.ndarray | None = None, earlier=(),
                **ladder_kwargs) -> tuple:
    """:func:`ladder_evidence` and the runs it came from (their final particles are
    independent sets of posterior draws: see
    :func:`~bayesfo.inference.posterior.posterior_from_particles`).

    ``guide`` is a posterior result (e.g. emcee's, converged or not) or draws in the sampling
    coordinates (e.g. the importance proposal's, which cover every optimum). Each run is guided
    by its own share of the draws (consecutive blocks: whole walkers of a walker-major emcee
    run; a resampled importance posterior can repeat a draw in both), so that the runs' moves
    share no random input: their agreement, which certifies the posterior, and the spread of
    their ln Z, which enters its error, then also show how much the result depends on the
    guide's draws. What they do share, the optima the guide was drawn around and the estimate
    of ln P(S), no agreement between them can check: the error of ln P(S) enters whole. Runs
    guided by the same draws can agree with each other and still miss a mode, and ln Z with it
    (BENCHMARKS.md, "Measurements behind design choices"; see
    :class:`~bayesfo.inference.smc._Guide` for the cause and the fix).

    ``earlier``: the runs of an earlier call with the same ``lik``, ``seed``, ``guide``,
    ``n_particles`` and other settings (``slabs`` among them), to which this call adds ``n_runs`` more: they continue the earlier runs'
    sequence of generators (children of the same seed), are guided by the same shares of the
    guide, and the evidence returned (with the list of runs) is that of all of them, the
    earlier ones first.

    Returns
    -------
    (Evidence, list of LadderRun)
    """
    t0 = time.perf_counter()
    earlier = list(earlier)
    if n_runs < 1 or n_runs + len(earlier) < 2:
        raise ValueError("n_runs must be at least 2, or 1 with earlier runs (their spread is "
                         "part of the error)")
    if any(r.bridge is None for r in earlier):
        raise ValueError("earlier runs must come from ladder_runs (their ln Z by bridge "
                         "sampling is part of the evidence)")
    first = len(earlier)
    children = np.random.SeedSequence(seed).spawn(first + n_runs)[first:]
    values = [r.bridge[0] for r in earlier]
    errors = [r.bridge[1] for r in earlier]
    calls, runs = sum(r.n_likelihood for r in earlier), list(earlier)
    reached = [float(np.max(r.log_likelihood)) for r in earlier]
    # ln P(S) once for all runs, from as many prior draws as the runs' separate estimates had:
    # its error is common to the runs, so it enters the error whole, not averaged down (the
    # same estimate as the earlier call's, where runs are added).
    shared = first or n_runs
    log_s, log_s_err = log_support_fraction(lik, np.random.default_rng([seed, shared]),
                                            n=20_000 * shared)
    if guide is None or isinstance(guide, np.ndarray):
        guide_u = guide
    else:
        guide_u = Transform(lik).to_u(guide.samples_scaled)
    shares = [None] * n_runs if guide_u is None else np.array_split(guide_u, n_runs)
    # The runs advance in lock-step (one batch of evaluations for all of them); each is the run
    # that ladder_run would give with its generator.
    together = ladder_runs_together(lik, [np.random.default_rng(c) for c in children],
                                    guides=shares, n_particles=n_particles, **ladder_kwargs)
    for i, run in enumerate(together, start=first):
        ev = _bridge(lik, run.particles[None], seed=seed + i, support=(log_s, 0.0))
        values.append(ev.log_z)
        errors.append(ev.log_z_err)
        calls += run.n_likelihood + ev.n_likelihood
        reached.append(float(np.max(run.log_likelihood)))
        runs.append(replace(run, bridge=(ev.log_z, ev.log_z_err)))
    values, errors = np.array(values), np.array(errors)
    err = math.sqrt((np.mean(errors**2) + np.var(values, ddof=1)) / values.size + log_s_err**2)
    return Evidence(
        log_z=float(values.mean()),
        log_z_err=err,
        method="ladder",
        log_support=ev.log_support,
        n_likelihood=int(calls),
        seconds=time.perf_counter() - t0,
        reached_log_likelihood=min(reached),
    ), runs


def other_noise_evidence(other: Likelihood, lik: Likelihood, posterior: PosteriorResult,
                         log_z: float) -> dict | None:
    """ln Z of the same structure under another noise model (``other``), from the posterior
    under ``lik``, whose ln Z is ``log_z``: both share the structure's prior and support, so

        Z_other = Z · E_p[m_other(θ) / m(θ)],

    m the likelihood with the noise scale integrated out
    (:meth:`~bayesfo.inference.likelihood.Likelihood.log_noise_marginal`) and p the posterior
    of the structure parameters θ (its draws). An importance-sampling estimate whose proposal
    is the posterior under ``lik``: uncertified, and reliable only where the Pareto k̂ of the
    ratios is small (their tail is heavy where the other noise model's posterior lies away from
    this one's). Returns ``{"log_z", "k_hat", "intervals", "method"}`` (the exponents' 94 %
    intervals under ``other`` from the smoothed ratios), as
    :func:`~bayesfo.inference.importance.screen_noise`; None where m is not available or no
    ratio is finite."""
    k = lik.structure.n_params
    theta = np.asarray(posterior.samples_scaled, dtype=float)[:, :k]
    mine, theirs = lik.log_noise_marginal(theta), other.log_noise_marginal(theta)
    if mine is None or theirs is None:
        return None
    with np.errstate(invalid="ignore"):
        log_r = theirs - mine
    finite = np.isfinite(log_r)
    if finite.sum() < 2:
        return None
    smoothed, k_hat = psis(log_r[finite])
    w = np.exp(smoothed - logsumexp(smoothed))
    return {"log_z": float(log_z + logsumexp(log_r[finite]) - math.log(log_r.size)),
            "k_hat": float(k_hat), "intervals": exponent_intervals(other, theta[finite], w),
            "method": OTHER_NOISE_METHOD}


#: How :func:`other_noise_evidence` names its estimate.
OTHER_NOISE_METHOD = "importance (from the other noise model's posterior)"


def nested_evidence(lik: Likelihood, *, seed: int = 0, nlive: int = 500, dlogz: float = 0.1,
                    sample: str = "unif", slices: int | None = None) -> Evidence:
    """ln Z by static nested sampling with dynesty on the same prior and likelihood.

    The prior transform maps the unit cube through each prior's quantile function; points
    outside the support get log-likelihood −inf.

    ``sample`` is dynesty's way of drawing a new live point: ``"unif"`` (the default) draws
    uniformly from the bounding ellipsoids, exactly from the constrained prior while they enclose
    it; on the thin curved ridges of over-parameterised structures (near pole–zero
    cancellations) it accepts almost nothing and may take hours. ``"rslice"`` (random-direction
    slice sampling) follows such ridges; it needs ``slices`` well above dynesty's default of
    3 + ndim, which gives ln Z too low, where more slices agree with uniform draws
    (BENCHMARKS.md, "Measurements behind design choices").
    """
    import dynesty

    t0 = time.perf_counter()
    priors = lik.prior_list

    def prior_transform(cube):
        return np.array([p.ppf(c) for p, c in zip(priors, cube, strict=True)])

    def loglike(theta):
        theta = theta[None, :]
        if not lik.in_support(theta)[0]:
            return -np.inf
        value = float(lik(theta)[0])
        return value if np.isfinite(value) else -np.inf

    rng = np.random.default_rng(seed)
    kwargs = {} if slices is None else {"slices": int(slices)}
    sampler = dynesty.NestedSampler(loglike, prior_transform, lik.ndim, nlive=nlive, sample=sample,
                                    rstate=rng, **kwargs)
    sampler.run_nested(dlogz=dlogz, print_progress=False)
    res = sampler.results
    log_s, log_s_err = log_support_fraction(lik, np.random.default_rng(seed + 1))
    return Evidence(
        log_z=float(res.logz[-1]) - log_s,
        log_z_err=math.sqrt(float(res.logzerr[-1]) ** 2 + log_s_err**2),
        method="nested",
        log_support=log_s,
        n_likelihood=int(np.sum(res.ncall)),
        seconds=time.perf_counter() - t0,
    )
