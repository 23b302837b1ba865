"""The sampling coordinates u (log for log-uniform priors, where the prior is flat) and the log
posterior density in them, vectorised: the hot path of every sampler (emcee, the tempered
ladder, importance sampling, bridge sampling)."""

from __future__ import annotations

from contextlib import nullcontext

import numpy as np

from ..priors import LogUniform, Uniform
from .likelihood import Likelihood


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

    def in_box(self, u: np.ndarray) -> np.ndarray:
        """Rows of ``u`` (2-D) inside the prior box (column by column: 35 µs at 2 000 rows of
        seven, against 57 µs for the whole comparison at once)."""
        ok = np.ones(u.shape[0], dtype=bool)
        for j in range(u.shape[1]):
            column = u[:, j]
            ok &= (column >= self.lo_u[j]) & (column <= self.hi_u[j])
        return ok

    def to_theta(self, u):
        return np.where(self.log, np.exp(np.clip(u, -700, 700)), u)

    def to_u(self, theta):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.log, np.log(np.abs(theta)), theta)


def _log_parts_fn(lik: Likelihood, tr: _Transform, *, constraints: bool = True):
    """(log prior density in u, log-likelihood) of a batch of points in u, both −inf outside
    the support; the tempered ladder weighs the two parts differently. With
    ``constraints=False`` only the prior box bounds the support: the structure's constraints
    (stability, dissipation, inequalities) are left to the caller (the ladder checks them only
    where a move would be accepted), and a response that overflows outside them is −inf."""
    k = lik.structure.n_params
    kind, grid = lik.data.kind, lik.grid

    def log_parts(u):
        u = np.atleast_2d(u)
        log_prior = np.full(u.shape[0], -np.inf)
        log_lik = np.full(u.shape[0], -np.inf)
        rows = np.flatnonzero(tr.in_box(u))
        if not rows.size:
            return log_prior, log_lik
        # All rows in the box (most calls): the points as they are, without a copy.
        theta = tr.to_theta(u if rows.size == u.shape[0] else u[rows])
        if constraints:
            ok = lik.structure.constraints_hold(theta[:, :k], kind, grid)
            rows, theta = rows[ok], theta[ok]
        if rows.size:
            lp = np.full(rows.size, tr.flat_const)
            for i, prior in tr.other:
                lp = lp + prior.log_prob(theta[:, i])
            log_prior[rows] = lp
            with np.errstate(all="ignore") if not constraints else nullcontext():
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

