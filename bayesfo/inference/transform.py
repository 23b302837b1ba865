"""The sampling coordinates u (log for log-uniform priors, where the prior is flat) and the log
posterior density in them, vectorised: the hot path of every sampler (emcee, the tempered
ladder, importance sampling, bridge sampling); and the unbounded coordinates z (the logit of u
within its prior range) in which importance sampling builds its proposal where one in u would
leave the box."""

from __future__ import annotations

import math
from contextlib import nullcontext

import numpy as np
from scipy.special import expit

from ..priors import LogUniform, Uniform
from .likelihood import Likelihood

#: Batches of at most this many rows are checked against the prior box in one comparison
#: (:meth:`Transform.in_box`).
BOX_ROWS = 256


class Transform:
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
        """Rows of ``u`` (2-D) inside the prior box: the whole comparison at once for the
        small batches of the optimisers and certificates (fewer calls), column by column for
        a sampler's thousands of rows (fewer temporaries); the same decisions (BENCHMARKS.md,
        "The constraint checks of small batches")."""
        if u.shape[0] <= BOX_ROWS:
            return ((u >= self.lo_u) & (u <= self.hi_u)).all(axis=1)
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


#: The grid along z on which a coordinate that the optimum leaves on a bound is moved inside:
#: ±30 reaches within 1e-13 of either bound.
GRID_Z = 30.0


class _Unbounded:
    """The proposal's coordinates z: the logit of each sampling coordinate u that the prior
    bounds on both sides (uniform and log-uniform priors, the latter already log in u), the
    others (normal priors) as they are.

    A proposal in z never leaves the prior box: an optimum on a bound (an order at 0, a
    coefficient at its smallest value) lies at a finite z where the log target has curvature,
    while a Student-t in u centred there spills half its draws over the bound. The target in z
    is the posterior density in u times |du/dz|, so that the weights, target over proposal in
    the same coordinates, keep their mean equal to the evidence: ∫ p(u) du = ∫ p(u(z)) |du/dz|
    dz."""

    #: Directions without curvature get at least the variance of the logistic distribution,
    #: π²/3: the image in z of a density flat over the box.
    BROAD = math.pi**2 / 3

    def __init__(self, lo: np.ndarray, hi: np.ndarray):
        self.bounded = np.isfinite(lo) & np.isfinite(hi)
        self.lo = np.where(self.bounded, lo, 0.0)
        self.hi = np.where(self.bounded, hi, 1.0)
        self.width = self.hi - self.lo

    def to_u(self, z: np.ndarray) -> np.ndarray:
        # From the nearer bound, so that a point close to either keeps its precision.
        below = self.lo + self.width * expit(z)
        above = self.hi - self.width * expit(-z)
        return np.where(self.bounded, np.where(z < 0, below, above), z)

    def to_z(self, u: np.ndarray) -> np.ndarray:
        """z of points in the box (a point on a bound is moved just inside it)."""
        p = np.clip((u - self.lo) / self.width, 1e-12, 1.0 - 1e-12)
        return np.where(self.bounded, np.log(p) - np.log1p(-p), u)

    def log_jacobian(self, z: np.ndarray) -> np.ndarray:
        """ln |du/dz| of each row of ``z`` (2-D)."""
        terms = np.log(self.width) - np.logaddexp(0.0, z) - np.logaddexp(0.0, -z)
        return np.sum(np.where(self.bounded, terms, 0.0), axis=1)

    def broad(self, z0: np.ndarray) -> float:
        """The variance floor of the Laplace approximation in z
        (:func:`~bayesfo.inference._peaks._laplace`): :attr:`BROAD`, or where a coordinate
        is left as it is, the rule in u over those coordinates, if wider."""
        free = ~self.bounded
        if not free.any():
            return self.BROAD
        return max(self.BROAD, float(np.max(1.0 + np.abs(z0[free])) / 4.0) ** 2)

    def start(self, log_target, u: np.ndarray) -> np.ndarray:
        """Where the Newton steps towards the mode in z begin, from an optimum ``u`` polished
        in u within the box (:func:`~bayesfo.inference._peaks._polished`, where the bounds
        hold a coordinate that leans on one).

        Such a coordinate maps to the far tail in z, where the target's slope is that of the
        Jacobian and its curvature nil, so that neither Newton steps nor L-BFGS-B (which stops
        there among the posterior's sharp directions) reach the mode. It is moved along z, the
        others held, to the best point of a grid over the whole box: the target in z has its
        maximum inside, since the Jacobian vanishes at the bounds."""
        span = np.where(self.bounded, self.width, 1.0 + np.abs(u))
        z = self.to_z(u)
        pinned = self.bounded & ((u - self.lo < 1e-3 * span) | (self.hi - u < 1e-3 * span))
        grid = np.linspace(-GRID_Z, GRID_Z, 241)
        for j in np.flatnonzero(pinned):
            rows = np.repeat(z[None, :], grid.size + 1, axis=0)
            rows[1:, j] = grid
            values = log_target(rows)
            if np.any(np.isfinite(values)):
                z = rows[int(np.argmax(np.where(np.isfinite(values), values, -np.inf)))]
        return z

    def target(self, log_prob):
        """The log target density in z, vectorised over rows: log_prob(u(z)) + ln |du/dz|."""
        def log_target(z):
            z = np.atleast_2d(z)
            return log_prob(self.to_u(z)) + self.log_jacobian(z)

        return log_target


def _log_parts_fn(lik: Likelihood, tr: Transform, *, constraints: bool = True):
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


def _log_prob_fn(lik: Likelihood, tr: Transform):
    """Log posterior density in u (the hot path: one vectorised call per half-ensemble)."""
    log_parts = _log_parts_fn(lik, tr)

    def log_prob(u):
        log_prior, log_lik = log_parts(u)
        return log_prior + log_lik

    return log_prob

