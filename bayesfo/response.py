"""Vectorised evaluation of fractional-order transfer functions, stability and passivity.

A transfer function here is a ratio of sums of power terms,

    G(s) = Σ_i b_i s^β_i / Σ_j a_j s^α_j ,   s = jω,

evaluated for many parameter sets at once: coefficient and exponent arrays carry leading batch
dimensions ``(...)``, frequencies the last one, and results have shape ``(..., n_freq)``.
Commensurate transfer functions (all exponents multiples of one order q, thesis eq. (2.6)) have a
faster path through the pseudo-polynomials B(λ)/A(λ), λ = s^q, and a stability test (thesis
Theorem 3, Matignon).

References
----------
Thesis §2.3 (definition, Theorems 2 and 3) and §2.4.2 (viscoelastic models).
"""

from __future__ import annotations

import numpy as np

from .errors import InputError

HALF_PI = 0.5 * np.pi


def jw_power(omega, exponent) -> np.ndarray:
    """(jω)^e for ω > 0 on the principal branch: ω^e · exp(j e π/2).

    ``exponent`` broadcasts against ``omega``; to get a table over parameter sets use
    ``exponent[..., None]`` with a 1-D ``omega``.
    """
    omega = np.asarray(omega, dtype=float)
    exponent = np.asarray(exponent, dtype=float)
    return np.exp(exponent * np.log(omega)) * np.exp(1j * HALF_PI * exponent)


def power_sum(omega, coef, exponent) -> np.ndarray:
    """Σ_i c_i (jω)^{e_i} for batches of coefficients and exponents.

    Parameters
    ----------
    omega : array_like, shape (n_freq,)
        Angular frequencies, positive.
    coef : array_like, shape (..., n_terms)
        Coefficients c_i.
    exponent : array_like, shape (..., n_terms)
        Exponents e_i (broadcast against ``coef``).

    Returns
    -------
    ndarray of complex, shape (..., n_freq)
    """
    omega = np.asarray(omega, dtype=float)
    coef, exponent = np.broadcast_arrays(np.asarray(coef, float), np.asarray(exponent, float))
    log_w = np.log(omega)
    # Real exponential for the modulus and a per-term phase factor: cheaper than a complex
    # exponential over (..., n_terms, n_freq).
    modulus = np.exp(exponent[..., None] * log_w)
    phase = coef * np.exp(1j * HALF_PI * exponent)
    return np.einsum("...t,...tf->...f", phase, modulus)


def power_ratio(omega, num_coef, num_exp, den_coef, den_exp) -> np.ndarray:
    """G(jω) = Σ b_i (jω)^β_i / Σ a_j (jω)^α_j for batches of parameter sets.

    Parameters
    ----------
    omega : array_like, shape (n_freq,)
    num_coef, num_exp : array_like, shape (..., n_num)
        Numerator coefficients b_i and exponents β_i.
    den_coef, den_exp : array_like, shape (..., n_den)
        Denominator coefficients a_j and exponents α_j.

    Returns
    -------
    ndarray of complex, shape (..., n_freq)

    Examples
    --------
    >>> import numpy as np
    >>> g = power_ratio([1.0], [1.0], [0.0], [1.0, 1.0], [0.0, 0.5])
    >>> bool(np.isclose(g[0], 1 / (1 + np.sqrt(1j))))
    True
    """
    return power_sum(omega, num_coef, num_exp) / power_sum(omega, den_coef, den_exp)


def lambda_powers(omega, q) -> np.ndarray:
    """λ = (jω)^q with shape ``q.shape + (n_freq,)``."""
    q = np.asarray(q, dtype=float)
    return jw_power(np.asarray(omega, dtype=float), q[..., None])


def polyval_ascending(coef, lam) -> np.ndarray:
    """Σ_k c_k λ^k by Horner's scheme; ``coef`` (..., K+1) ascending, ``lam`` (..., n_freq)."""
    coef = np.asarray(coef)
    out = coef[..., -1:] + np.zeros(np.broadcast_shapes(coef.shape[:-1] + (1,), lam.shape), complex)
    for k in range(coef.shape[-1] - 2, -1, -1):
        out = out * lam + coef[..., k : k + 1]
    return out


def commensurate_response(omega, a, b, q) -> np.ndarray:
    """G(jω) = B(λ)/A(λ), λ = (jω)^q, for batches of commensurate parameter sets.

    Parameters
    ----------
    omega : array_like, shape (n_freq,)
    a : array_like, shape (..., n+1)
        Denominator coefficients in ascending order, ``a[..., 0]`` the constant term (the thesis
        fixes it to 1, eq. (3.1)).
    b : array_like, shape (..., m+1)
        Numerator coefficients in ascending order.
    q : array_like, shape (...)
        Commensurate order.

    Returns
    -------
    ndarray of complex, shape (..., n_freq)

    References
    ----------
    Thesis eq. (2.6) and (3.1).
    """
    lam = lambda_powers(omega, q)
    return polyval_ascending(np.asarray(b, float), lam) / polyval_ascending(np.asarray(a, float), lam)


# ---------------------------------------------------------------------- stability
def _monic_reversed_roots(a: np.ndarray) -> np.ndarray:
    """Roots μ = 1/λ of A(λ) for a batch with a[..., 0] != 0; shape (batch, n).

    The reversed polynomial μ^n A(1/μ) = a_0 μ^n + a_1 μ^{n-1} + … + a_n is monic after dividing
    by a_0, so vanishing leading coefficients a_n (degree drops) show up as roots μ = 0 instead
    of roots at infinity, and the companion matrix stays finite. |arg λ| = |arg μ|.
    """
    c = a[:, 1:] / a[:, :1]
    n = c.shape[1]  # >= 2: first-degree denominators are handled in closed form by the caller
    if n == 2:
        disc = np.sqrt((c[:, 0] ** 2 - 4 * c[:, 1]).astype(complex))
        return np.stack([(-c[:, 0] + disc) / 2, (-c[:, 0] - disc) / 2], axis=1)
    comp = np.zeros((c.shape[0], n, n))
    comp[:, 0, :] = -c
    comp[:, np.arange(1, n), np.arange(n - 1)] = 1.0
    return np.linalg.eigvals(comp)


def matignon_stable(a, q, *, allow_integrator: bool = False) -> np.ndarray:
    """Stability of commensurate fractional systems by Matignon's theorem (thesis Theorem 3).

    The system B(λ)/A(λ), λ = s^q, is BIBO stable iff every root λ_i of A satisfies
    |arg λ_i| > qπ/2.

    Parameters
    ----------
    a : array_like, shape (..., n+1)
        Denominator coefficients in ascending order (``a[..., 0]`` the constant term).
    q : array_like, shape (...)
        Commensurate order, 0 < q.
    allow_integrator : bool
        If true, roots at λ = 0 (a zero constant term: a pole at s = 0, an integrator such as a
        dashpot or the Maxwell compliance) are accepted and the remaining roots are tested.
        Such structures are judged by passivity instead of BIBO stability.

    Returns
    -------
    ndarray of bool, shape (...)
        True where the system is stable. A root exactly on the boundary counts as unstable.
        An identically zero denominator is unstable.

    References
    ----------
    D. Matignon (1996); thesis §2.3, Theorem 3.
    """
    a = np.asarray(a, dtype=float)
    q = np.asarray(q, dtype=float)
    if a.ndim == 0:
        raise InputError("argument 'a' must hold at least the constant coefficient")
    if a.shape[-1] == 2:
        # a0 + a1 λ: the root -a0/a1 is negative real (arg π, stable for q < 2) iff a0 a1 > 0;
        # a1 = 0 leaves no root; a0 = 0 is a root at the origin (an integrator).
        a0, a1 = a[..., 0], a[..., 1]
        ok = ((a0 * a1 > 0) & (q < 2)) | ((a1 == 0) & (a0 != 0))
        if allow_integrator:
            ok |= (a0 == 0) & (a1 != 0)
        return ok
    batch = np.broadcast_shapes(a.shape[:-1], q.shape)
    a = np.broadcast_to(a, batch + a.shape[-1:]).reshape(-1, a.shape[-1]).copy()
    q = np.broadcast_to(q, batch).reshape(-1)
    ok = np.ones(a.shape[0], dtype=bool)
    zero_const = a[:, 0] == 0
    if allow_integrator:
        # Factor out λ while the constant term vanishes.
        for _ in range(a.shape[1] - 1):
            rows = a[:, 0] == 0
            if not rows.any():
                break
            a[rows] = np.concatenate([a[rows, 1:], np.zeros((rows.sum(), 1))], axis=1)
        zero_const = a[:, 0] == 0
    ok &= ~zero_const  # identically zero, or an integrator that is not allowed
    if a.shape[1] > 1 and ok.any():
        rows = np.flatnonzero(ok)
        # Non-finite coefficients (an overflowed fit) or q have no roots to test: unstable.
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            finite = np.all(np.isfinite(a[rows, 1:] / a[rows, :1]), axis=1) & np.isfinite(q[rows])
        ok[rows[~finite]] = False
        rows = rows[finite]
    if a.shape[1] > 1 and ok.any():
        rows = np.flatnonzero(ok)
        mu = _monic_reversed_roots(a[rows])
        absmu = np.abs(mu)
        scale = np.maximum(1.0, absmu.max(axis=1, keepdims=True))
        finite_root = absmu > 1e-13 * scale  # μ ≈ 0 is a root at infinity: a dropped degree
        arg_ok = np.abs(np.angle(mu)) > q[rows, None] * HALF_PI
        ok[rows] = np.all(arg_ok | ~finite_root, axis=1)
    return ok.reshape(batch)


# ---------------------------------------------------------------------- passivity
def dissipation_grid(omega_min: float, omega_max: float, *, decades_beyond: float = 3.0,
                     points_per_decade: int = 20) -> np.ndarray:
    """A log-spaced grid from ``decades_beyond`` decades below ω_min to as many above ω_max."""
    if not (0 < omega_min <= omega_max) or not np.isfinite(omega_max):
        raise InputError(
            f"arguments 'omega_min' and 'omega_max' must satisfy 0 < omega_min <= omega_max, "
            f"got {omega_min!r} and {omega_max!r}"
        )
    lo = np.log10(omega_min) - decades_beyond
    hi = np.log10(omega_max) + decades_beyond
    n = max(2, int(np.ceil((hi - lo) * points_per_decade)) + 1)
    return np.logspace(lo, hi, n)


DISSIPATION_SIGN = {"compliance": -1.0, "modulus": 1.0}


def is_dissipative(values, kind: str, *, rtol: float = 1e-9) -> np.ndarray:
    """Whether responses dissipate energy at every frequency given.

    A compliance J(jω) = J' − jJ'' must have Im J ≤ 0, a modulus G' + jG'' must have Im G ≥ 0
    (non-negative loss, second law of thermodynamics). A generic transfer function has no such
    constraint and is always accepted.

    Parameters
    ----------
    values : array_like of complex, shape (..., n_freq)
        Responses on a dense grid (see :func:`dissipation_grid`).
    kind : {"compliance", "modulus", "generic"}
    rtol : float
        Imaginary parts of the wrong sign smaller than ``rtol·|G|`` are rounding, not violations.

    Returns
    -------
    ndarray of bool, shape (...)
    """
    values = np.asarray(values)
    if kind == "generic":
        return np.ones(values.shape[:-1], dtype=bool)
    if kind not in DISSIPATION_SIGN:
        raise InputError(f"argument 'kind' must be compliance, modulus or generic, got {kind!r}")
    s = DISSIPATION_SIGN[kind]
    with np.errstate(invalid="ignore"):
        ok = s * values.imag >= -rtol * np.abs(values)
    return np.all(ok & np.isfinite(values), axis=-1)
