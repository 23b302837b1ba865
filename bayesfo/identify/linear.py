"""Linear identification methods 1–5 of the thesis (Table 3.1), vectorised.

For a commensurate structure with given n, m and q, the model

    G̃(s) = (b_0 + b_1 λ + … + b_m λ^m) / (1 + a_1 λ + … + a_n λ^n),   λ = s^q,

is fitted by minimising a weighted *equation error* that is linear in p = [a_1..a_n, b_0..b_m]:

    E_k = A(λ_k) G_k − B(λ_k) = G_k − S_k p,   S_k = [−λ_k G_k, …, −λ_k^n G_k, 1, λ_k, …, λ_k^m]

(Levy's error, eq. (3.8); with U = 1 the output-error form of §3.2.1 is the same error). Real and
imaginary parts are stacked once (§3.2.1), and the weighted normal equations are solved for a
whole batch at once: every leading dimension of ``G`` (Monte Carlo realisations) and of ``q``
(a grid of orders) broadcasts.

The methods differ in the weights:

1. output error with Vinagre's weights entering the rows (Kronecker product of §3.2.3), i.e.
   cost Σ w_k² |E_k|² with w_k = φ_k/ω_k²;
2. Levy with Vinagre's weights, cost Σ w_k |E_k|² (eq. (3.14));
3. Levy with Sanathanan–Koerner iterations, cost Σ |E_k|²/|A_{L−1}(λ_k)|², A_0 = 1, 10
   iterations (§3.2.4);
4. Lawrence–Rogers recursion (eqs. (3.19)–(3.21)) with Vinagre's weights, H_0 = I/ε (ε relative
   to the scale of the data term, 1e-9), p_0 = 0, and a second pass started from the first
   estimate (§3.2.5), which removes the pull of H_0 towards p_0;
5. Lawrence–Rogers recursion (as in 4) with Sanathanan–Koerner weights, 10 iterations.

The recursion minimises Σ w_k² |E_k|², eq. (3.16); it equals the batch solution with weights
w_k² to about six digits (tested). Its estimate after the last frequency is that of regularised
least squares, which :func:`lawrence_rogers` computes in one batched solve (see there).

References
----------
Thesis §3.2 (eqs. (3.4)–(3.21)), Table 3.1; Levy (1959); Vinagre et al. (2000); Sanathanan and
Koerner (1963); Lawrence and Rogers (1979).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..structures.response import jw_power

METHODS = (1, 2, 3, 4, 5)
SK_ITERATIONS = 10
LR_EPSILON = 1e-9
LR_PASSES = 3


def vinagre_weights(omega) -> np.ndarray:
    """Vinagre's weights w_k = φ_k / ω_k² (eq. (3.13)), φ_k the half-width around ω_k."""
    omega = np.asarray(omega, dtype=float)
    if omega.size < 2:
        raise InputError("Vinagre's weights need at least two frequencies")
    phi = np.empty_like(omega)
    phi[0] = (omega[1] - omega[0]) / 2
    phi[-1] = (omega[-1] - omega[-2]) / 2
    phi[1:-1] = (omega[2:] - omega[:-2]) / 2
    return phi / omega**2


def regressors(omega, G, q, n: int, m: int):
    """Complex regressor matrix S (..., N, n+m+1), target G (..., N) and λ^k table.

    Columns are ordered as p = [a_1..a_n, b_0..b_m].
    """
    G = np.asarray(G, dtype=complex)
    q = np.asarray(q, dtype=float)
    lam = jw_power(np.asarray(omega, float), q[..., None])  # (..., N)
    kmax = max(n, m)
    powers = [np.ones_like(lam)]
    for _ in range(kmax):
        powers.append(powers[-1] * lam)
    batch = np.broadcast_shapes(G.shape, lam.shape)
    G = np.broadcast_to(G, batch)
    cols = [-powers[k] * G for k in range(1, n + 1)] + [
        np.broadcast_to(powers[k], batch) for k in range(m + 1)
    ]
    return np.stack(cols, axis=-1), G, powers


def weighted_solve(S, y, weights) -> np.ndarray:
    """Minimise Σ_k w_k |y_k − S_k p|² over real p: the weighted normal equations.

    Real and imaginary parts are stacked, M = [Re S; Im S], and (Mᵀ W M) p = Mᵀ W y is solved
    after equilibrating the columns (the powers of λ span many decades).
    """
    w = np.asarray(weights, dtype=float)
    Sr, Si = S.real, S.imag
    wk = w[..., :, None]
    A = np.einsum("...ki,...kj->...ij", Sr * wk, Sr) + np.einsum("...ki,...kj->...ij", Si * wk, Si)
    b = np.einsum("...ki,...k->...i", Sr * wk, y.real) + np.einsum("...ki,...k->...i", Si * wk, y.imag)
    d = np.sqrt(np.abs(np.diagonal(A, axis1=-2, axis2=-1)))
    d = np.where(d > 0, d, 1.0)
    As = A / d[..., :, None] / d[..., None, :]
    x = _solve_batch(As, b / d)
    return x / d


def _solve_batch(A, b) -> np.ndarray:
    """Solve A x = b for a batch of square systems; NaN for a system that is singular or holds
    a non-finite number (e.g. powers of λ that overflowed for an extreme q), instead of an
    exception that would discard the whole batch (a q grid)."""
    finite = np.all(np.isfinite(A), axis=(-2, -1)) & np.all(np.isfinite(b), axis=-1)
    P = A.shape[-1]
    A_ok = np.where(finite[..., None, None], A, np.eye(P))
    b_ok = np.where(finite[..., None], b, 0.0)
    try:
        x = np.linalg.solve(A_ok, b_ok[..., None])[..., 0]
    except np.linalg.LinAlgError:
        flat_A = A_ok.reshape(-1, P, P)
        flat_b = b_ok.reshape(-1, P)
        x = np.empty_like(flat_b)
        for i in range(flat_A.shape[0]):
            try:
                x[i] = np.linalg.solve(flat_A[i], flat_b[i])
            except np.linalg.LinAlgError:
                x[i] = np.nan
        x = x.reshape(b_ok.shape)
    return np.where(finite[..., None], x, np.nan)


def lawrence_rogers(S, y, weights, *, epsilon: float = LR_EPSILON, passes: int = LR_PASSES,
                    p0=None) -> np.ndarray:
    """The estimate of the recursion of Lawrence and Rogers, eqs. (3.19)–(3.21).

    The recursion adds each frequency's real and imaginary regressor as two rank-one updates
    of H = (H_0⁻¹ + Σ 2w_k² (Re r Re rᵀ + Im r Im rᵀ))⁻¹, starting from H_0 = I/(ε·s), s the
    mean diagonal of the final information matrix, and p_0 = 0; a further pass restarts from
    the previous estimate. Recursive least squares without forgetting ends, after the last
    frequency, exactly at the minimiser of Σ 2w_k² |E_k|² + ε·s·|p − p_0|² (the recursion is
    that minimiser updated one observation at a time), so each pass is computed here as that
    regularised least-squares solution, in one batched solve, without a Python loop over the
    frequencies. It matches an independent least-squares solution of that problem to 1e-9
    relative; the recursion itself (one frequency at a time, in the tests) matches it to about
    1e-7, the digits its start from H_0 = I/(ε·s) loses.
    """
    w2 = np.asarray(weights, dtype=float) ** 2
    batch = S.shape[:-2]
    P = S.shape[-1]
    p = np.zeros(batch + (P,)) if p0 is None else np.array(np.broadcast_to(p0, batch + (P,)))
    Sr, Si = S.real, S.imag
    wk = 2.0 * np.broadcast_to(w2, S.shape[:-1])[..., :, None]
    A = np.einsum("...ki,...kj->...ij", Sr * wk, Sr) + np.einsum("...ki,...kj->...ij", Si * wk, Si)
    b = np.einsum("...ki,...k->...i", Sr * wk, y.real) + np.einsum("...ki,...k->...i", Si * wk, y.imag)
    # ε is relative to the mean diagonal of the information matrix: an absolute ε is either a
    # bias (too large) or a loss of digits (too small), depending on the units of the data.
    reg = epsilon * np.trace(A, axis1=-2, axis2=-1) / P
    A = A + reg[..., None, None] * np.eye(P)
    d = np.sqrt(np.abs(np.diagonal(A, axis1=-2, axis2=-1)))
    d = np.where(d > 0, d, 1.0)
    As = A / d[..., :, None] / d[..., None, :]
    for _ in range(passes):
        p = _solve_batch(As, (b + reg[..., None] * p) / d) / d
    return p


def identify_linear(omega, G, q, n: int, m: int, method: int, *,
                    sk_iterations: int = SK_ITERATIONS, lr_epsilon: float = LR_EPSILON,
                    lr_passes: int = LR_PASSES):
    """Identify the coefficients with method 1–5 for a batch of data sets and orders.

    Parameters
    ----------
    omega : array_like, shape (N,)
        Angular frequencies [rad/s] (in the units in which the coefficients are wanted).
    G : array_like of complex, shape (..., N)
        Measured responses; leading dimensions are independent data sets.
    q : float or array_like, shape broadcastable to G.shape[:-1]
        Commensurate order(s).
    n, m : int
        Degrees of the denominator and numerator pseudo-polynomials (n ≥ 1 for methods 2–5,
        whose error needs a denominator; n ≥ 0 for method 1).
    method : {1, 2, 3, 4, 5}
        See the module docstring (thesis Table 3.1).

    Returns
    -------
    a : ndarray, shape (..., n+1)
        Denominator [1, a_1, …, a_n] (thesis convention).
    b : ndarray, shape (..., m+1)
        Numerator [b_0, …, b_m].

    Raises
    ------
    InputError
        For an unknown method, negative degrees, or fewer real equations than unknowns.
    """
    if method not in METHODS:
        raise InputError(f"argument 'method' must be one of 1, 2, 3, 4, 5, got {method!r}")
    if n < 0 or m < 0:
        raise InputError(f"degrees must be non-negative, got n = {n}, m = {m}")
    if n < 1 and method != 1:
        raise InputError(f"method {method} needs a denominator (n >= 1), got n = {n}")
    omega = np.asarray(omega, dtype=float)
    if 2 * omega.size < n + m + 1:
        raise InputError(
            f"{omega.size} frequencies give {2 * omega.size} real equations, fewer than the "
            f"{n + m + 1} coefficients"
        )
    # Powers of λ may overflow for extreme q over many decades: the solve then marks that
    # system NaN (see _solve_batch) instead of warning or raising.
    with np.errstate(all="ignore"):
        S, y, powers = regressors(omega, G, q, n, m)
        if method in (1, 2, 4):
            wv = vinagre_weights(omega)
            if method == 1:
                p = weighted_solve(S, y, wv**2)
            elif method == 2:
                p = weighted_solve(S, y, wv)
            else:
                p = lawrence_rogers(S, y, wv, epsilon=lr_epsilon, passes=lr_passes)
        else:
            w = np.ones(S.shape[:-1])
            p = None
            for _ in range(sk_iterations):
                if method == 3:
                    p = weighted_solve(S, y, w)
                else:
                    p = lawrence_rogers(S, y, np.sqrt(w), epsilon=lr_epsilon, passes=lr_passes)
                A = 1.0 + sum(p[..., k - 1 : k] * powers[k] for k in range(1, n + 1))
                w = 1.0 / np.abs(A) ** 2
    a = np.concatenate([np.ones(p.shape[:-1] + (1,)), p[..., :n]], axis=-1)
    return a, p[..., n:]
