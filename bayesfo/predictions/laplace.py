"""Numerical inversion of the Laplace transform on the fixed Talbot contour, vectorised over
parameter sets and times.

f(t) = (r/M) [ ½ F(r) e^{rt} + Σ_{k=1}^{M-1} Re( e^{t s_k} F(s_k) (1 + i σ_k) ) ],
s_k = r θ_k (cot θ_k + i), σ_k = θ_k + (θ_k cot θ_k − 1) cot θ_k, θ_k = kπ/M, r = 2M/(5t)
(Abate & Valkó 2004, "Multi-precision Laplace transform inversion", Int. J. Numer. Meth. Eng.
60, 979-993). The contour wraps the negative real axis, where the singularities of a
viscoelastic material function lie (poles of integer-order relaxations, branch cuts of
fractional ones), and F is evaluated on the principal branch of s^α. In double precision the
error falls as about 10^(-0.6 M) until rounding takes over, near M = 20.

mpmath's ``invertlaplace`` does the same in arbitrary precision, one time and one parameter set
at a time: far too slow for thousands of posterior draws (``benchmarks/bench_predict.py``).
"""

from __future__ import annotations

import numpy as np

#: Nodes of the contour: the error of double-precision inversion is smallest near 20.
NODES = 20


def talbot_nodes(t, n: int = NODES) -> tuple[np.ndarray, np.ndarray]:
    """The contour's points s (n_t, n) and weights w (n_t, n) for times ``t`` (> 0): then
    f(t) ≈ Re Σ_k w_k e^{t s_k} F(s_k)."""
    t = np.asarray(t, dtype=float)
    theta = np.pi * np.arange(1, n) / n
    cot = 1.0 / np.tan(theta)
    r = 2.0 * n / (5.0 * t)[:, None]
    s = np.concatenate([r + 0j, r * theta * (cot + 1j)], axis=1)
    sigma = theta + (theta * cot - 1.0) * cot
    w = np.concatenate([0.5 * np.ones_like(r) + 0j, (r / r) * (1.0 + 1j * sigma)], axis=1)
    return s, w * (r / n)


def invert(transform, t, n: int = NODES) -> np.ndarray:
    """f(t) from its Laplace transform.

    Parameters
    ----------
    transform : callable
        F(s) for complex s of shape (n_t, n): returns an array of shape (..., n_t, n) (e.g. one
        row per parameter set).
    t : array_like, shape (n_t,)
        Times > 0.
    n : int
        Nodes of the contour.

    Returns
    -------
    ndarray, shape (..., n_t)
    """
    t = np.asarray(t, dtype=float)
    s, w = talbot_nodes(t, n)
    with np.errstate(over="ignore", invalid="ignore"):
        values = transform(s)
        return np.real(np.sum(w * np.exp(t[:, None] * s) * values, axis=-1))


def invert_per_set(transform, t) -> np.ndarray:
    """f(t) from its Laplace transform where each parameter set has its own times.

    Parameters
    ----------
    transform : callable
        F(s) for complex s of shape (n_sets, n_t, n), row i belonging to parameter set i
        alone: returns an array of the same shape.
    t : array_like, shape (n_sets, n_t)
        Times > 0 of each set.

    Returns
    -------
    ndarray, shape (n_sets, n_t)
    """
    t = np.asarray(t, dtype=float)
    s, w = talbot_nodes(t.ravel(), NODES)
    s, w = s.reshape(*t.shape, -1), w.reshape(*t.shape, -1)
    with np.errstate(over="ignore", invalid="ignore"):
        values = transform(s)
        return np.real(np.sum(w * np.exp(t[..., None] * s) * values, axis=-1))
