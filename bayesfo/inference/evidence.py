"""Log-evidence ln Z of a structure, by two independent routes.

``bridge_evidence``
    Bridge sampling (Meng and Wong 1996, in the iterative form of Gronau et al. 2017) from the
    emcee posterior draws: a multivariate normal proposal fitted to half of the draws (in the
    sampling coordinates, log for log-uniform priors), the other half and as many proposal
    draws in the bridge, and the relative mean-squared error of Frühwirth-Schnatter (2004)
    with the autocorrelation of the draws taken into account through their effective size.
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
from dataclasses import dataclass

import numpy as np
from scipy.special import logsumexp

from ..errors import InputError
from .likelihood import Likelihood
from .posterior import PosteriorResult, _log_prob_fn, _Transform


@dataclass(frozen=True)
class Evidence:
    """ln Z with its standard error.

    Attributes
    ----------
    log_z, log_z_err : float
        Natural-log evidence (physical units of the data, like the log-likelihood) and its
        standard error.
    method : str
        ``"bridge"`` or ``"nested"``.
    log_support : float
        ln P(S), the log prior mass of the support (0 when the whole prior range is admissible).
    n_likelihood : int
        Likelihood evaluations spent by the estimator.
    seconds : float
        Wall time.
    """

    log_z: float
    log_z_err: float
    method: str
    log_support: float
    n_likelihood: int
    seconds: float

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def log_support_fraction(lik: Likelihood, rng: np.random.Generator, n: int = 20_000) -> tuple[float, float]:
    """ln P(S) and its standard error from ``n`` prior draws.

    Raises
    ------
    InputError
        If no prior draw lies in the support.
    """
    draws = np.column_stack([p.sample(rng, n) for p in lik.prior_list])
    k = int(lik.in_support(draws).sum())
    if k == 0:
        raise InputError(
            f"none of {n} prior draws of structure '{lik.structure.name}' is stable and "
            "dissipative: the prior has (almost) no admissible mass"
        )
    if k == n:
        return 0.0, 0.0
    p = k / n
    return math.log(p), math.sqrt((1 - p) / (n * p))


def _ess(x: np.ndarray) -> float:
    """Effective size of the draws (walker-major rows) of a scalar, by arviz."""
    from ._arviz import arviz

    return float(arviz().ess(x))


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
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    tr = _Transform(lik)
    log_q = _log_prob_fn(lik, tr)
    u = tr.to_u(posterior.samples_scaled)
    n_walkers = posterior.n_walkers
    draws = u.reshape(n_walkers, -1, u.shape[1])
    fit_half = draws[:, 0::2].reshape(-1, u.shape[1])
    bridge_half = draws[:, 1::2].reshape(-1, u.shape[1])
    if bridge_half.shape[0] < 10 * u.shape[1]:
        raise InputError("too few posterior draws for bridge sampling")
    mean = fit_half.mean(axis=0)
    cov = np.atleast_2d(np.cov(fit_half, rowvar=False))
    cov = cov + 1e-12 * np.diag(np.diag(cov) + 1e-300)
    chol = np.linalg.cholesky(cov)
    n1 = bridge_half.shape[0]
    n2 = n1
    proposal = mean + rng.standard_normal((n2, u.shape[1])) @ chol.T
    log_det = 2 * np.sum(np.log(np.diag(chol)))

    def log_g(x):
        z = np.linalg.solve(chol, (x - mean).T)
        return -0.5 * np.sum(z * z, axis=0) - 0.5 * log_det - 0.5 * x.shape[1] * math.log(2 * math.pi)

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
    log_s, log_s_err = log_support_fraction(lik, rng)
    return Evidence(
        log_z=log_z_support - log_s,
        log_z_err=math.sqrt(re2 + log_s_err**2),
        method="bridge",
        log_support=log_s,
        n_likelihood=int(n1 + n2),
        seconds=time.perf_counter() - t0,
    )


def nested_evidence(lik: Likelihood, *, seed: int = 0, nlive: int = 500, dlogz: float = 0.1,
                    sample: str = "rslice") -> Evidence:
    """ln Z by static nested sampling with dynesty on the same prior and likelihood.

    The prior transform maps the unit cube through each prior's quantile function; points
    outside the support get log-likelihood −inf.

    ``sample`` is dynesty's way of drawing a new live point. The default, random-direction
    slice sampling (``"rslice"``), follows the thin curved ridges of the over-parameterised
    max-order members (near pole–zero cancellations), where dynesty's default for few
    dimensions (uniform draws from bounding ellipsoids) accepts almost nothing.
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
    sampler = dynesty.NestedSampler(loglike, prior_transform, lik.ndim, nlive=nlive, sample=sample,
                                    rstate=rng)
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
