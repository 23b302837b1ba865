"""Configurations of a posterior that no optimum seeds: an element that vanishes.

Where the data leave an element invisible, its coefficient is free from where it stops mattering
down to its prior bound: the posterior holds a region (a *plateau* along that coefficient, in
the sampling coordinates where the prior is flat) in which the other parameters take the values
that describe the data without the element, often far from the optimum's (a Zener whose spring
vanishes makes do with a springpot of small order and a large viscosity; two springpots of
nearly equal order, one vanishing while the other takes over). The optimiser ends at one
configuration; the importance proposal and the guide of the tempered ladder are built there;
and a ladder whose particles leave the plateau at one rung does not regain it: the
differential-evolution moves cannot reach a region that no particle occupies, and the
independence moves propose from mixtures fitted to where the particles already are. Two runs
that agree can then both miss a tenth of the posterior (BENCHMARKS.md, "A region of the
posterior that no optimum seeds").

:func:`vanishing_slabs` looks for each such configuration from the highest optima: the
coefficient held near its lower prior bound, the others maximised (a profile point, as the
ridge probe's), kept where the log posterior there is within :data:`DEPTH` nats of the highest
optimum and the guide's draws do not already reach the plateau. Each becomes a :class:`_Slab`,
a proposal component with an exact density: uniform along the coefficient from its bound to
where the plateau ends, normal in the other coordinates (the cross-section's Laplace covariance,
widened), and a *way*, normal components at profile points from the plateau's end back to the
optimum, where the other parameters change from one configuration's values to the other's. The
ladder proposes from them at every rung (:func:`~bayesfo.inference.smc.ladder_run`), so that
particles move between the plateau and the rest as each tempered posterior requires; the
importance route's certificate estimates the mass they hold beyond its draws
(:func:`missed_share`). Only configurations that this search finds are covered: posteriors of
more than :data:`~._ridge.PROBE_MAX_DIM` parameters are not searched, and a configuration whose
profile point the optimisers do not reach is not found.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ._mixture import _GaussianMixture
from ._peaks import _hessian
from ._ridge import PROBE_MAX_DIM, _profile_point
from .transform import Transform, _log_prob_fn

#: Where a coefficient is held to find the configuration in which its element vanishes: this
#: share of its prior range (in the sampling coordinates) above its lower bound.
VANISH = 0.02
#: Configurations whose profile point lies more than this many nats below the highest optimum
#: are left out (their mass is negligible unless the plateau is very long: e^-10 of the peak's
#: height over a plateau a hundred times the peak's width is 0.5 % of the posterior).
DEPTH = 10.0
#: The plateau ends where the log posterior along the coefficient (the others held at the
#: configuration) falls this many nats below the configuration's value.
PLATEAU_DROP = 3.0
#: A configuration whose plateau already holds this share of the guide's draws is covered.
COVERED = 0.05
#: Scale of a slab's normal part relative to the cross-section's Laplace covariance (the
#: importance proposal's).
SLAB_SCALE = 1.5
#: Points of the grid along the coefficient on which the plateau's end is found.
PLATEAU_GRID = 101
#: The configurations are searched from this many of the highest optima: a bound on the cost
#: (each start is a profile optimisation per coefficient; the optimiser can return many optima
#: along one ridge, eight on a fractional_kelvin_voigt data set of the certificate study).
MODES = 3
#: A configuration whose profile point ends between :data:`DEPTH` and this many nats below the
#: highest optimum is searched again by Nelder-Mead (:func:`_retried`); one further below is
#: taken as an element that cannot vanish.
RETRY = 1000.0
#: Function evaluations of that search, per coordinate.
RETRY_EVALUATIONS = 300
#: Profile points from the plateau's end to the optimum: the way between the two regions,
#: where the other parameters move from the configuration's values to the optimum's.
CHAIN_POINTS = 8


@dataclass(frozen=True)
class _Slab:
    """A proposal component for the configuration where coordinate ``index`` has vanished:
    uniform on [``lo``, ``hi``] along it, normal with mean ``mean`` (that coordinate's entry
    unused) and Cholesky factor ``chol`` in the others."""

    index: int
    lo: float
    hi: float
    mean: np.ndarray
    chol: np.ndarray

    @property
    def _rest(self) -> np.ndarray:
        return np.delete(np.arange(self.mean.size), self.index)

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        rest = self._rest
        x = np.empty((n, self.mean.size))
        x[:, self.index] = rng.uniform(self.lo, self.hi, size=n)
        x[:, rest] = self.mean[rest] + rng.standard_normal((n, rest.size)) @ self.chol.T
        return x

    @cached_property
    def _whitening(self) -> tuple[np.ndarray, float]:
        inverse = np.linalg.inv(self.chol)
        const = (-float(np.sum(np.log(np.diag(self.chol))))
                 - 0.5 * (self.mean.size - 1) * math.log(2 * math.pi)
                 - math.log(self.hi - self.lo))
        return inverse, const

    def log_pdf(self, x: np.ndarray) -> np.ndarray:
        rest = self._rest
        inverse, const = self._whitening
        z = (x[:, rest] - self.mean[rest]) @ inverse.T
        column = x[:, self.index]
        inside = (column >= self.lo) & (column <= self.hi)
        return np.where(inside, const - 0.5 * np.einsum("ij,ij->i", z, z), -np.inf)


def vanishing_slabs(lik, modes_u: np.ndarray, guide_u: np.ndarray | None = None) -> list[_Slab]:
    """The configurations where one coefficient's element vanishes, as :class:`_Slab`\\ s (see
    the module's docstring); ``modes_u``: the optima in the sampling coordinates (rows, with the
    noise parameter where ``lik`` has one); ``guide_u``: draws that already cover the posterior
    as far as they reach (a configuration whose plateau holds :data:`COVERED` of them gives no
    slab). Deterministic: no random step."""
    tr = Transform(lik)
    log_prob = _log_prob_fn(lik, tr)
    modes_u = np.atleast_2d(np.asarray(modes_u, dtype=float))
    heights = log_prob(modes_u)
    keep = np.isfinite(heights)
    if not np.any(keep):
        return []
    modes_u, heights = modes_u[keep], heights[keep]
    top = float(np.max(heights))
    modes_u = modes_u[np.argsort(-heights, kind="stable")[:MODES]]
    lo, hi = tr.lo_u, tr.hi_u
    slabs: list[_Slab] = []
    for j, p in enumerate(lik.structure.parameters):
        if p.role == "exponent" or not tr.log[j] or not np.isfinite(hi[j] - lo[j]):
            continue
        value = lo[j] + VANISH * (hi[j] - lo[j])
        best = None
        for mode in modes_u:
            if mode[j] <= value:
                continue  # the optimum is this configuration: the proposal is built there
            u, height, cross = _profile_point(log_prob, mode[None, :], j, value, lo, hi)
            if best is None or height > best[1]:
                best = (u, height, cross, mode)
        if best is None:
            continue
        u, height, cross, mode = best
        if top - RETRY >= height or height >= top - DEPTH:
            pass  # far below (the element cannot vanish), or found
        else:
            # Where two springpots exchange roles (one vanishes, the other takes over with
            # nearly the same order), the profile's Newton and L-BFGS-B steps can stall in a
            # narrow curved valley, far below the valley's highest point: Nelder-Mead from where
            # they ended (BENCHMARKS.md, "A region of the posterior that no optimum seeds").
            u, height, cross = _retried(log_prob, u, j, value, lo, hi)
        cross = _kept(log_prob, u, height, cross, j, lo, hi, top)
        if cross is None:
            continue
        grid = np.linspace(lo[j], hi[j], PLATEAU_GRID)
        along = np.repeat(u[None, :], grid.size, axis=0)
        along[:, j] = grid
        fallen = np.flatnonzero(~(log_prob(along) >= height - PLATEAU_DROP) & (grid > value))
        end = float(grid[fallen[0]]) if fallen.size else float(hi[j])
        if guide_u is not None and len(guide_u) and np.mean(guide_u[:, j] <= end) >= COVERED:
            continue
        eig, vec = cross
        cov = SLAB_SCALE**2 * (vec / eig[None, :]) @ vec.T
        try:
            chol = np.linalg.cholesky(cov)
        except np.linalg.LinAlgError:
            continue
        slabs.append(_Slab(index=j, lo=float(lo[j]), hi=end, mean=u, chol=chol))
        way = _way(log_prob, u, mode, j, end, lo, hi, top)
        if way is not None:
            slabs.append(way)
    return slabs


def _kept(log_prob, u: np.ndarray, height: float, cross, j: int, lo, hi, top: float):
    """The floored precision of the cross-section at a profile point (its own where it was
    peaked, else :func:`_cross_section`'s), or None where the point lies more than
    :data:`DEPTH` below ``top`` or has no cross-section."""
    if not height >= top - DEPTH:
        return None
    return _floored(cross, lo, hi) if cross is not None else _cross_section(log_prob, u, j, lo, hi)


def _cross_section(log_prob, u: np.ndarray, j: int, lo, hi):
    """The precision of the cross-section at ``u`` (coordinate ``j`` held) as eigenvalues and
    eigenvectors, where :func:`~._ridge._profile_point` found it not peaked: directions without
    curvature (the order of the element that vanished, which the data no longer see) get a
    variance that spreads over the prior box, as in the importance route's Laplace
    approximations. None where the difference stencil leaves the support."""
    rest = np.delete(np.arange(u.size), j)
    span = np.where(np.isfinite(hi - lo), hi - lo, 1.0 + np.abs(u))[rest]
    h = 1e-4 * span
    point = np.clip(u[rest], lo[rest] + 3 * h, hi[rest] - 3 * h)

    def g(r):
        x = np.repeat(u[None, :], len(r), axis=0)
        x[:, rest] = r
        return log_prob(x)

    out = _hessian(g, point, h)
    if out is None:
        return None
    eig, vec = np.linalg.eigh(-out[2])
    if not np.all(np.isfinite(eig)):
        return None
    return _floored((eig, vec), lo, hi)


def _floored(cross, lo, hi):
    """A cross-section's precision ``(eigenvalues, eigenvectors)`` with each eigenvalue at
    least that of a variance spreading over the prior box (a quarter of its widest finite
    range, as the importance route's Laplace approximations): a direction of little curvature
    does not send the normal part's draws far outside the box."""
    eig, vec = cross
    span = hi - lo
    span = span[np.isfinite(span)]
    widest = float(np.max(span)) if span.size else 1.0
    floor = 1.0 / (widest / 4.0) ** 2
    return np.maximum(eig, floor), vec


def _retried(log_prob, u: np.ndarray, j: int, value: float, lo, hi):
    """The profile point at ``value`` of coordinate ``j`` again: Nelder-Mead over the other
    coordinates from ``u`` (the box's outside is the worst value), then the profile's Newton
    steps from its end for the cross-section's curvature. Returns (point, value, cross)."""
    from scipy.optimize import minimize

    rest = np.delete(np.arange(u.size), j)

    def negative(r):
        x = u.copy()
        x[rest] = r
        v = float(log_prob(x[None, :])[0])
        return -v if np.isfinite(v) else 1e300

    found = minimize(negative, u[rest], method="Nelder-Mead",
                     options={"maxfev": RETRY_EVALUATIONS * rest.size, "xatol": 1e-9,
                              "fatol": 1e-9, "adaptive": True})
    start = u.copy()
    start[rest] = found.x
    return _profile_point(log_prob, start[None, :], j, value, lo, hi)


def _way(log_prob, start: np.ndarray, mode: np.ndarray, j: int, end: float, lo, hi,
         top: float):
    """Normal components on the way from a plateau's end (``end`` along coordinate ``j``) to
    the optimum ``mode``: :data:`CHAIN_POINTS` profile points at equal steps of the coordinate,
    each started from the one before, with the cross-section's Laplace covariance (widened by
    :data:`SLAB_SCALE`) and the step along the crest; weighted by their Laplace masses. A
    :class:`~bayesfo.inference._mixture._GaussianMixture`, or None where no point is within
    :data:`DEPTH` of ``top`` or the way is empty."""
    if not mode[j] > end:
        return None
    d = start.size
    rest = np.delete(np.arange(d), j)
    values = np.linspace(end, mode[j], CHAIN_POINTS + 2)[1:-1]
    step = float(values[1] - values[0]) if values.size > 1 else float(mode[j] - end)
    means, chols, log_masses = [], [], []
    here, before = start, start
    for value in values:
        guess = here + (here - before) * (value - here[j]) / (here[j] - before[j]) \
            if here[j] != before[j] else here
        point, height, cross = _profile_point(log_prob, np.array([guess, here, mode]), j, value,
                                              lo, hi)
        before, here = here, point
        cross = _kept(log_prob, point, height, cross, j, lo, hi, top)
        if cross is None:
            continue
        eig, vec = cross
        cov = np.zeros((d, d))
        cov[np.ix_(rest, rest)] = SLAB_SCALE**2 * (vec / eig[None, :]) @ vec.T
        tangent = (here - before) / (here[j] - before[j])
        cov += step**2 * np.outer(tangent, tangent)
        try:
            chols.append(np.linalg.cholesky(cov))
        except np.linalg.LinAlgError:
            continue
        means.append(point)
        log_masses.append(height + float(np.sum(np.log(np.diag(chols[-1])))))
    if not means:
        return None
    weights = np.exp(np.array(log_masses) - max(log_masses))
    kept = weights > 0  # a component whose mass underflows has no log weight
    return _GaussianMixture(weights[kept] / weights[kept].sum(), np.array(means)[kept],
                            np.array(chols)[kept])


def configurations(lik, modes_scaled, guide_u=None) -> list:
    """:func:`vanishing_slabs` from the optima as ``certified_posterior`` receives them
    (scaled coordinates without the noise parameter, whose estimate at each optimum is added
    where ``lik`` has one); [] where the search fails numerically, and for posteriors of more
    than :data:`~._ridge.PROBE_MAX_DIM` parameters (each profile point maximises over all the
    others, as the ridge probe's: the joint master-curve posteriors are not searched)."""
    modes = np.atleast_2d(np.asarray(modes_scaled, dtype=float))
    if modes.size == 0 or lik.ndim > PROBE_MAX_DIM:
        return []
    if lik.noise_param:
        modes = np.column_stack([modes, lik.noise_estimate(modes)])
    try:
        with np.errstate(all="ignore"):
            return vanishing_slabs(lik, Transform(lik).to_u(modes), guide_u)
    except (np.linalg.LinAlgError, FloatingPointError, ValueError):
        return []


def vanished(lik, slabs) -> list[str]:
    """The names of the coefficients whose vanishing the slabs describe, each once."""
    names = lik.param_names
    return list(dict.fromkeys(names[s.index] for s in slabs if isinstance(s, _Slab)))


#: Draws of the configurations' slabs and ways with which the importance route's certificate
#: estimates the posterior mass they hold beyond the importance draws' reach
#: (:func:`missed_share`).
MISSED_DRAWS = 4000


def missed_share(lik, slabs, draws_u: np.ndarray, log_z_support: float, seed: int) -> float:
    """The share of the posterior in the configurations ``slabs`` that lies outside the range of
    ``draws_u`` (the importance route's draws) on some parameter: importance sampling from the
    slabs and ways, equally weighted (:data:`MISSED_DRAWS` draws, exact densities), against
    ``log_z_support``, the posterior's ln Z on the support by the importance weights. An
    estimate from below where the configuration reaches into the draws' range, which is where
    they represent it."""
    from scipy.special import logsumexp


    rng = np.random.default_rng([seed, 19])
    log_prob = _log_prob_fn(lik, Transform(lik))
    n = len(slabs)
    which = rng.integers(n, size=MISSED_DRAWS)
    x = np.empty((MISSED_DRAWS, draws_u.shape[1]))
    for i, part in enumerate(slabs):
        rows = np.flatnonzero(which == i)
        if rows.size:
            x[rows] = part.sample(rows.size, rng)
    log_q = logsumexp([part.log_pdf(x) for part in slabs], axis=0) - math.log(n)
    with np.errstate(all="ignore"):
        log_w = log_prob(x) - log_q
    lo, hi = draws_u.min(axis=0), draws_u.max(axis=0)
    outside = np.any((x < lo) | (x > hi), axis=1) & np.isfinite(log_w)
    if not outside.any():
        return 0.0
    return float(np.exp(logsumexp(log_w[outside]) - math.log(MISSED_DRAWS) - log_z_support))
