"""The log posterior's peaks as importance sampling and its ridge probe use them: the maximum
near a point within the prior box (:func:`_polish`), the gradient and Hessian by central
differences in one vectorised call (:func:`_hessian`), and the density of the Student-t
mixtures built at the peaks (:func:`_mixture_log_pdf`)."""

from __future__ import annotations

import math

import numpy as np
from scipy.special import gammaln, logsumexp

DF = 5.0  # Student-t degrees of freedom: heavier tails than the Laplace approximation


def _hessian(f, u0: np.ndarray, h: np.ndarray):
    """Gradient and Hessian of ``f`` (vectorised over rows) at ``u0`` by central differences,
    in one call of ``f``; None if a point of the stencil leaves the support."""
    d = u0.size
    eye = np.eye(d) * h
    pts = [u0]
    for i in range(d):
        pts += [u0 + eye[i], u0 - eye[i]]
    pairs = [(i, j) for i in range(d) for j in range(i + 1, d)]
    for i, j in pairs:
        pts += [u0 + eye[i] + eye[j], u0 + eye[i] - eye[j], u0 - eye[i] + eye[j],
                u0 - eye[i] - eye[j]]
    v = f(np.array(pts))
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
