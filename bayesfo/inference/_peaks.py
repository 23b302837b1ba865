"""The log posterior's peaks as importance sampling and its ridge probe use them: the maximum
near a point within the prior box (:func:`_polish`, :func:`_polished`), the gradient and
Hessian by central differences in vectorised calls (:func:`_hessian`), the Laplace
approximation at a peak (:func:`_laplace`, with :func:`_inward` where the peak is on the edge
of the support), and the density of the Student-t mixtures built at the peaks
(:func:`_mixture_log_pdf`)."""

from __future__ import annotations

import math

import numpy as np
from scipy.special import gammaln, logsumexp

DF = 5.0  # Student-t degrees of freedom: heavier tails than the Laplace approximation


#: Rows of the stencil that :func:`_hessian` passes to ``f`` at once: a master curve of 200
#: isotherms has some 200 parameters and 83 000 stencil points, which ``f`` evaluated over
#: every data point in one piece (83 000 × 1000 complex, a MemoryError).
STENCIL_CHUNK = 1024


def _hessian(f, u0: np.ndarray, h: np.ndarray):
    """Gradient and Hessian of ``f`` (vectorised over rows) at ``u0`` by central differences,
    in calls of ``f`` on at most :data:`STENCIL_CHUNK` points; None if a point of the stencil
    leaves the support."""
    d = u0.size
    eye = np.eye(d) * h
    pairs = [(i, j) for i in range(d) for j in range(i + 1, d)]
    pts = np.empty((1 + 2 * d + 4 * len(pairs), d))
    pts[0] = u0
    for i in range(d):
        pts[1 + 2 * i], pts[2 + 2 * i] = u0 + eye[i], u0 - eye[i]
    base = 1 + 2 * d
    for k, (i, j) in enumerate(pairs):
        pts[base + 4 * k: base + 4 * k + 4] = (u0 + eye[i] + eye[j], u0 + eye[i] - eye[j],
                                               u0 - eye[i] + eye[j], u0 - eye[i] - eye[j])
    v = np.concatenate([np.asarray(f(pts[k:k + STENCIL_CHUNK]))
                        for k in range(0, pts.shape[0], STENCIL_CHUNK)])
    if not np.all(np.isfinite(v)):
        return None
    f0 = v[0]
    grad = np.empty(d)
    hess = np.empty((d, d))
    for i in range(d):
        fp, fm = v[1 + 2 * i], v[2 + 2 * i]
        grad[i] = (fp - fm) / (2 * h[i])
        hess[i, i] = (fp - 2 * f0 + fm) / h[i] ** 2
    base = 1 + 2 * d
    for k, (i, j) in enumerate(pairs):
        pp, pm, mp, mm = v[base + 4 * k: base + 4 * k + 4]
        hess[i, j] = hess[j, i] = (pp - pm - mp + mm) / (4 * h[i] * h[j])
    return f0, grad, hess


def _polish(f, u0: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The maximum of the log posterior ``f`` near ``u0`` within the box, by L-BFGS-B.

    The optima come from least squares weighted by the data's magnitude; under another noise
    model (a constant σ) the posterior's mode lies elsewhere, much higher (BENCHMARKS.md,
    "Measurements behind design choices"), beyond the reach of a few Newton steps that must
    stay inside the box where a coefficient sits on its prior bound."""
    from scipy.optimize import minimize

    f0 = f(u0[None, :])[0]
    if not np.isfinite(f0):
        return u0

    d = u0.size
    h = 1e-6 * np.where(np.isfinite(hi - lo), hi - lo, 1.0)
    stencil = np.vstack([np.zeros(d), np.diag(h), -np.diag(h)])

    def neg(u):
        # Value and central-difference gradient in one vectorised call.
        v = f(u[None, :] + stencil)
        if not np.all(np.isfinite(v)):
            v0 = v[0]
            return (-v0 if np.isfinite(v0) else 1e300), np.zeros(d)
        return -v[0], -(v[1:d + 1] - v[d + 1:]) / (2 * h)

    bounds = [(a if np.isfinite(a) else None, b if np.isfinite(b) else None)
              for a, b in zip(lo + h, hi - h, strict=True)]
    res = minimize(neg, np.clip(u0, lo + h, hi - h), jac=True, method="L-BFGS-B",
                   bounds=bounds, options={"maxiter": 200, "ftol": 1e-12})
    return res.x if np.isfinite(res.fun) and -res.fun > f0 else u0


def _mixture_log_pdf(factors, means, log_weights):
    """The log density of the Student-t mixture of :func:`_mvt` at any points."""
    d = means.shape[1]
    norm = log_weights - logsumexp(log_weights)
    const = gammaln((DF + d) / 2) - gammaln(DF / 2) - 0.5 * d * math.log(DF * math.pi)

    def log_pdf(y):
        terms = []
        for lw, mean, (w, v) in zip(norm, means, factors, strict=True):
            proj = (y - mean) @ v  # coordinates along the eigenvectors
            maha = np.sum(proj * proj * w, axis=1)
            log_det = -0.5 * np.sum(np.log(w))  # log sqrt(det covariance)
            terms.append(lw + const - log_det - 0.5 * (DF + d) * np.log1p(maha / DF))
        return logsumexp(np.array(terms), axis=0)

    return log_pdf


def _polished(f, u0: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """:func:`_polish` within the box: an optimum on a bound of the prior box (a coefficient at
    its smallest value) is moved just inside, so that the difference stencil of
    :func:`_laplace` stays in the box."""
    span = np.where(np.isfinite(hi - lo), hi - lo, 1.0 + np.abs(u0))
    h = 1e-4 * span
    return _polish(f, np.clip(u0, lo + 3 * h, hi - 3 * h), lo + 3 * h, hi - 3 * h)


def _laplace(f, u0: np.ndarray, lo: np.ndarray, hi: np.ndarray, newton_steps: int = 4,
             broad: float | None = None, polish: bool = True):
    """The mode near ``u0`` (a few Newton steps on the log posterior) and the Laplace
    approximation there, as the eigenvalues and eigenvectors ``(w, v)`` of its precision
    (directions without curvature floored at the variance ``broad``, by default one that
    spreads over the box, see below). Where the stencil at the optimum leaves the support (an
    optimum on its edge), it is taken a few steps inside (:func:`_inward`); the Newton steps
    stop where the Hessian is singular or a step's stencil leaves the support, keeping the last
    point that had one. None where no stencil fits or the Hessian is not finite."""
    span = np.where(np.isfinite(hi - lo), hi - lo, 1.0 + np.abs(u0))
    h = 1e-4 * span
    u = _polished(f, u0, lo, hi) if polish else np.clip(u0, lo + 3 * h, hi - 3 * h)
    best = None
    for _ in range(newton_steps + 1):
        out = _hessian(f, u, h)
        if out is None and best is None:
            # An optimum on the support's edge (a coefficient at 0 where an element vanishes,
            # two orders that meet): the stencil is taken a few steps inside.
            inside = _inward(f, u, h, lo, hi)
            if inside is not None:
                u, h = inside
                out = _hessian(f, u, h)
        if out is None:
            if best is None:
                return None
            break
        f0, grad, hess = out
        best = (f0, u, hess)
        try:
            step = np.linalg.solve(hess, -grad)
        except np.linalg.LinAlgError:
            break
        cand = u + step
        if not np.all(np.isfinite(cand)) or not np.all((cand > lo + 3 * h) & (cand < hi - 3 * h)):
            break
        value = f(cand[None, :])[0]
        if not value > f0:
            break
        u = cand
    f0, u, hess = best
    w, v = np.linalg.eigh(-hess)
    if not np.all(np.isfinite(w)):
        return None
    # Directions without curvature (a parameter the data leave to its prior, a peak cut by a
    # bound) get a variance that spreads the proposal over the prior box; the certificate of
    # the weights decides whether that describes the posterior.
    if broad is None:
        broad = (np.max(span[np.isfinite(span)]) / 4.0) ** 2
    w = np.where(w > 1.0 / broad, w, 1.0 / broad)
    return f0, u, (w, v)


#: Steps of :func:`_inward` along the axes that leave the support, relative to the stencil's
#: step: the first at which the stencil fits within :data:`INWARD_DROP` of the edge is taken.
INWARD_STEPS = (1.0, 0.1, 0.01, 0.001)
#: How far (in nats) the log posterior may fall between the optimum on the support's edge and
#: the stencil's centre moved inside: a larger fall means the step is coarse for the posterior's
#: width across the edge.
INWARD_DROP = 1.0


def _inward(f, u: np.ndarray, h: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """A point near ``u`` and a step, at which the difference stencil lies in the support: the
    centre moved two steps away from the support's edge along the axes where one side of the
    stencil leaves it, the step along those axes made smaller (:data:`INWARD_STEPS`) until the
    log posterior there is within :data:`INWARD_DROP` of its value at ``u``; None where an axis
    leaves on both sides or no step succeeds.

    The Laplace approximation there describes the posterior's curvature beside an optimum that
    the support cuts (a coefficient at 0 where its element vanishes, two springpot orders that
    meet): the proposal built from it spills part of its draws over the edge, which the
    weights count as outside the support, and the certificate of the weights decides as for
    any proposal."""
    d = u.size
    eye = np.eye(d) * h
    v = f(np.concatenate([u[None], u + eye, u - eye]))
    f0, up, down = v[0], np.isfinite(v[1:d + 1]), np.isfinite(v[d + 1:])
    if np.any(~up & ~down) or np.all(up & down):
        return None
    # +1 where only the step down leaves the support, −1 where only the step up does.
    direction = up.astype(float) - down.astype(float)
    for k in INWARD_STEPS:
        step = np.where(direction != 0, k * h, h)
        moved = u + 2 * direction * step
        if not np.all((moved >= lo + 3 * h) & (moved <= hi - 3 * h)):
            continue
        if f(moved[None])[0] >= f0 - INWARD_DROP and _hessian(f, moved, step) is not None:
            return moved, step
    return None
