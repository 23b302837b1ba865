"""The ridge probe, the third part of the importance route's certificate: posterior mass that a
proposal built at the optima does not reach (see :mod:`bayesfo.inference.importance`)."""

from __future__ import annotations

import math

import numpy as np
from scipy.special import logsumexp

from ._peaks import _hessian, _mixture_log_pdf, _polish

#: The ridge probe (:func:`_ridge_probe`): profile steps of 2, 4, ..., 2^PROBE_STEPS marginal
#: proposal standard deviations along each coordinate, from each mode, and once on a ridge that
#: holds mass the proposal misses (a tenth of PROBE_MISSED at one point), up to PROBE_FINER
#: steps of a quarter of the distance reached; a profile
#: point deeper than PROBE_DEPTH nats below the mode ends a direction (no mass worth having lies
#: there).
PROBE_STEPS = 8
PROBE_FINER = 16
PROBE_DEPTH = 15.0
#: At most this many profile points per probe (a bound on its cost: a typical posterior of
#: four to six parameters takes 10-30, one with a long ridge about 50).
PROBE_POINTS = 200
#: Posteriors of more parameters are not probed: each profile point maximises over all the
#: other coordinates, so the cost grows with the square of the dimension (on the joint
#: posterior of a master structure and many shifts it outweighs the rest of the route). The
#: joint master-curve posteriors are such; their shifts' intervals are calibrated
#: (BENCHMARKS.md, "Calibration of the master-curve shifts"), and ``info["probe"]["skipped"]``
#: says why.
PROBE_MAX_DIM = 12
#: Newton steps of a profile point before it falls back to L-BFGS-B.
PROFILE_NEWTON = 8
#: The share of the posterior that the ridge probe may find beyond the proposal's reach for
#: the weights to certify it. The probe's estimate is from above (on the 74 certified posteriors
#: of the bundled isotherms, 2-3 times the share of an unguided ladder's draws outside the
#: reported draws' range); 3 % keeps every posterior that misses 5 % or more off the fast route
#: (BENCHMARKS.md, "The ridge probe").
PROBE_MISSED = 0.03


def _profile_point(f, start: np.ndarray, i: int, value: float, lo: np.ndarray,
                   hi: np.ndarray):
    """The maximum of ``f`` over every coordinate but ``i``, which is held at ``value``, near
    ``start`` within the box (``start``: a point, or rows of them tried in turn until one is in
    the support), and the curvature of the cross-section there (the precision of
    its Laplace approximation in the other coordinates; None where it is not peaked).

    Newton steps with a central-difference Hessian (each one vectorised call of ``f``, as
    :func:`_laplace`), halved until they improve; where the Hessian is not negative definite or
    the stencil leaves the support, L-BFGS-B (:func:`~._peaks._polish`) instead. Returns (point,
    value, the eigenvalues and eigenvectors of the cross-section's precision or None); the
    value is −inf where every start leaves the support."""
    start = np.atleast_2d(start)
    d = start.shape[1]
    rest = np.delete(np.arange(d), i)
    span = np.where(np.isfinite(hi - lo), hi - lo, 1.0 + np.abs(start[0]))[rest]
    lo_r, hi_r = lo[rest] + 3e-4 * span, hi[rest] - 3e-4 * span

    def full(r):
        u = np.empty((len(r), d))
        u[:, rest] = r
        u[:, i] = value
        return u

    def g(r):
        return f(full(r))

    # The first of the starts given that lies in the support (a start on the line the crest
    # led to can leave it where a card inequality, such as β ≤ α, cuts across).
    starts = np.clip(start[:, rest], lo_r, hi_r)
    values = g(starts)
    inside = np.flatnonzero(np.isfinite(values))
    if not inside.size:
        return full(starts[:1])[0], -math.inf, None
    r, here = starts[inside[0]], float(values[inside[0]])
    h = 1e-4 * span
    for _ in range(PROFILE_NEWTON):
        out = _hessian(g, r, h)
        if out is None:
            break
        _, grad, hess = out
        eig = np.linalg.eigvalsh(-hess)
        if not np.all(np.isfinite(eig)) or eig.min() <= 0:
            break
        step = np.linalg.solve(-hess, grad)
        gain = 0.5 * float(grad @ step)  # the rise the quadratic model promises
        if gain < 1e-6:
            return full(r[None, :])[0], here, np.linalg.eigh(-hess)
        for t in (1.0, 0.5, 0.25, 0.125):
            cand = np.clip(r + t * step, lo_r, hi_r)
            value_c = float(g(cand[None, :])[0])
            if value_c > here:
                r, here = cand, value_c
                break
        else:
            break
    # Newton did not settle: L-BFGS-B from where it got, and the curvature at its end.
    r = _polish(g, r, lo_r, hi_r)
    here = float(g(r[None, :])[0])
    out = _hessian(g, r, h)
    cross = None
    if out is not None:
        eig = np.linalg.eigh(-out[2])
        if np.all(np.isfinite(eig[0])) and eig[0].min() > 0:
            cross = eig
    return full(r[None, :])[0], here, cross


def _ridge_probe(out) -> dict:
    """Posterior mass that the proposal of a round does not reach, along a ridge.

    The weights certify the posterior only where the proposal's draws land. A ridge along which
    the posterior stays high while it curves away from the modes (a coefficient free up to its
    prior bound with the others following it, as where both elements of a Voigt grow together)
    holds mass that no draw visits, and k̂ cannot see it. From each mode of the proposal, each
    coordinate is stepped outwards, 2, 4, ... marginal standard deviations of the proposal (and
    in finer steps once on a ridge that holds mass the proposal misses), and the log posterior
    maximised over the other coordinates at each step (the profile, which follows the ridge's
    crest; the first step starts on the line of the mode's conditional means, each later one
    where the last two profile points lead). Where a profile point's importance weight exceeds
    the largest of the draws' (the proposal under-represents the posterior there), the mass
    that the draws do not represent around it is estimated from the
    profile's height less the proposal's density times that largest weight, the Laplace volume
    of the cross-section there and the step; the sum of those, over the evidence that the draws
    give, estimates the share of the posterior that the proposal misses (roughly, and from
    above where the cross-section is not peaked: the crest's height stands for all of it).

    Returns ``{"points": profile points evaluated, "missed": that share, "coordinate": the
    coordinate of the profile that holds most of it (None if none), "components": a normal
    for each such profile point, ``(mean, (w, v), ln mass)`` in the form of the proposal's
    factors (the cross-section's Laplace covariance, and the square of the step from the
    profile point before along the crest's direction)}``."""
    x, log_w, finite, _, prop = out
    log_target = prop["log_target"]
    d = prop["means"].shape[1]
    lo = prop.get("lo", np.full(d, -np.inf))
    hi = prop.get("hi", np.full(d, np.inf))
    log_q = _mixture_log_pdf(prop["factors"], prop["means"], prop["log_weights"])
    top = float(np.max(log_w[finite]))
    log_z = float(logsumexp(log_w[finite]) - math.log(len(log_w)))
    base = prop.get("base", prop)
    masses = {}  # coordinate -> ln of the mass found beyond the proposal's reach
    components = []
    points = 0
    for mean, (w, v) in zip(base["means"], base["factors"], strict=True):
        peak = float(log_target(mean[None, :])[0])
        if not np.isfinite(peak):
            continue
        cov = (v / w[None, :]) @ v.T
        sd = np.sqrt(np.diag(cov))  # marginal sd of each coordinate
        for i in range(d):
            rest = np.delete(np.arange(d), i)
            for sign in (1.0, -1.0):
                u, before = mean, mean - cov[:, i] / cov[i, i] * sd[i]
                reach, finer = 2.0, None  # in marginal sds; finer: the step once on a ridge
                for _ in range(PROBE_STEPS + PROBE_FINER):
                    value = mean[i] + sign * reach * sd[i]
                    if not lo[i] < value < hi[i] or points >= PROBE_POINTS:
                        break
                    start = u + (u - before) * (value - u[i]) / (u[i] - before[i])
                    before = u
                    u, lp, cross = _profile_point(log_target, np.array([start, u, mean]), i,
                                                  value, lo, hi)
                    step = abs(u[i] - before[i])
                    tangent = (u - before) / (u[i] - before[i])  # the crest's direction
                    points += 1
                    if not np.isfinite(lp) or lp < peak - PROBE_DEPTH:
                        break
                    covered = float(log_q(u[None, :])[0]) + top - lp
                    if covered >= 0 or cross is None:
                        reach = 2 * reach if finer is None else reach + finer
                        continue  # the draws weigh this region at least as much
                    # The density beyond what the draws' largest weight represents here.
                    eig, vec = cross
                    volume = 0.5 * (d - 1) * math.log(2 * math.pi) - 0.5 * float(np.sum(np.log(eig)))
                    mass = lp + math.log1p(-math.exp(covered)) + volume + math.log(step)
                    masses[i] = float(np.logaddexp(masses.get(i, -math.inf), mass))
                    if finer is None and mass - log_z > math.log(PROBE_MISSED / 10):
                        # On a ridge that holds mass the proposal misses: from here, steps of
                        # a quarter of the way so far, which follow its crest where it bends.
                        finer = reach / 4
                    reach = 2 * reach if finer is None else reach + finer
                    # The cross-section's covariance, and the step along the crest.
                    full = np.zeros((d, d))
                    full[np.ix_(rest, rest)] = (vec / eig[None, :]) @ vec.T
                    full += step**2 * np.outer(tangent, tangent)
                    e, V = np.linalg.eigh(full)
                    components.append((u.copy(), (1.0 / e, V), mass))
    if not masses:
        return {"points": points, "missed": 0.0, "coordinate": None, "components": []}
    where = max(masses, key=masses.get)
    missed = float(np.exp(logsumexp(list(masses.values())) - log_z))
    return {"points": points, "missed": missed, "coordinate": where, "components": components}
