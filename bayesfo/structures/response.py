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

from ..errors import InputError

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
    log_w = np.log(omega).reshape(-1)
    # Σ_t c_t e^{j e_t π/2} ω^{e_t} with real arithmetic, term by term from zero: a real
    # exponential for the modulus and a per-term phase factor (cheaper than a complex
    # exponential over (..., n_terms, n_freq), and than an einsum, which casts the moduli to a
    # complex temporary: BENCHMARKS.md, "Measurements behind design choices").
    out = np.zeros(coef.shape[:-1] + log_w.shape, dtype=complex)
    out_re, out_im = out.real, out.imag
    for t in range(coef.shape[-1]):
        e, c = exponent[..., t:t + 1], coef[..., t:t + 1]
        if not e.any():
            # (jω)^0 = 1 (a spring, the constant of a side): the term adds c to the real part
            # and c·0 to the imaginary part, the values of the products below (NaN for an
            # infinite c), without their exponentials.
            out_re += c
            out_im += c * 0.0 + 0.0
            continue
        phase = c * np.exp(1j * HALF_PI * e)
        modulus = np.exp(e * log_w)
        out_re += phase.real * modulus
        out_im += phase.imag * modulus
    return out


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
        # In place: the same products and sums without a temporary per step.
        out *= lam
        out += coef[..., k : k + 1]
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
    num = polyval_ascending(np.asarray(b, float), lam)
    den = polyval_ascending(np.asarray(a, float), lam)
    if num.shape != den.shape:
        return num / den
    num /= den
    return num


# ---------------------------------------------------------------------- stability
def _monic_reversed_roots(a: np.ndarray) -> np.ndarray:
    """Roots μ = 1/λ of A(λ) for a batch with a[..., 0] != 0; shape (batch, n).

    The reversed polynomial μ^n A(1/μ) = a_0 μ^n + a_1 μ^{n-1} + … + a_n is monic after dividing
    by a_0, so vanishing leading coefficients a_n (degree drops) show up as roots μ = 0 instead
    of roots at infinity, and the companion matrix stays finite. |arg λ| = |arg μ|.
    """
    return _reversed_roots(a[:, 1:] / a[:, :1])


def _reversed_roots(c: np.ndarray) -> np.ndarray:
    """:func:`_monic_reversed_roots` from the monic coefficients ``c = a[:, 1:] / a[:, :1]``."""
    n = c.shape[1]  # >= 2: first-degree denominators are handled in closed form by the caller
    if n == 2:
        disc = np.sqrt((c[:, 0] ** 2 - 4 * c[:, 1]).astype(complex))
        return np.stack([(-c[:, 0] + disc) / 2, (-c[:, 0] - disc) / 2], axis=1)
    comp = np.zeros((c.shape[0], n, n))
    comp[:, 0, :] = -c
    comp[:, np.arange(1, n), np.arange(n - 1)] = 1.0
    return np.linalg.eigvals(comp)


#: Batches with fewer rows than this take the eigenvalues directly: below it, the fixed cost of
#: the closed form (~70 array operations, with the eigenvalues of the rows it leaves open)
#: exceeds the per-row cost of the eigenvalues of 3×3 companion matrices (BENCHMARKS.md,
#: "Measurements behind design choices").
CLOSED_FORM_MIN_ROWS = 128

#: Relative perturbation of each coefficient (about 4500 machine epsilons) in the error bound
#: of the closed-form cubic roots (:func:`cubic_roots`).
ROOT_RTOL = 1e-12


def cubic_roots(c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Roots of the monic cubics x³ + c_0 x² + c_1 x + c_2 (rows of ``c``, shape (n, 3)) in
    closed form, with a bound of their error.

    One real root comes from Cardano's formula (three real roots: the trigonometric form) and
    two Newton steps; the other two from the deflated quadratic; then every root takes one
    Newton step on the cubic itself.

    Returns
    -------
    x : ndarray of complex, shape (n, 3)
    err : ndarray, shape (n, 3)
        A bound of the distance of ``x`` from the exact roots, and of the eigenvalues that LAPACK
        computes from the companion matrix: |f(x)|/|f′(x)| (the remaining Newton step), the
        first-order effect of relative perturbations :data:`ROOT_RTOL` of the coefficients,
        and of a perturbation of the companion matrix C by 2.2e-16·‖C‖_F (the backward error of
        the eigenvalue solver; ‖v‖ ‖y‖/|f′(x)| is the condition number of the eigenvalue x with
        right and left eigenvectors v = (x², x, 1) and y = (1, x + c_0, x² + c_0 x + c_1)).
        ``inf`` where the bound is not meaningful: non-finite values, or an error above 1 % of
        the distance to the nearest other root (nearly multiple roots).
    """
    # Common subexpressions are computed once (fixed cost: a call takes ~70 array operations,
    # whose overhead counts at the tens to hundreds of rows of a tempered ladder's checks:
    # BENCHMARKS.md, "Measurements behind design choices");
    # every value is the same floating-point expression as written out in the docstring's
    # steps.
    a, b, d = c[:, 0], c[:, 1], c[:, 2]
    with np.errstate(all="ignore"):
        third = a / 3.0
        two_a = 2.0 * a
        p = b - a * third
        p3 = p / 3.0
        r = (2.0 * third * third - b) * third + d
        half_r = -0.5 * r
        disc = 0.25 * r * r + p3 ** 3
        u = np.cbrt(half_r - np.copysign(np.sqrt(np.abs(disc)), r))
        nz = u != 0
        t_one = np.where(nz, u - p / (3.0 * np.where(nz, u, 1.0)), 0.0)
        m = np.sqrt(np.maximum(-p3, 0.0))
        cos3 = np.minimum(np.maximum(half_r / np.where(m > 0, m ** 3, 1.0), -1.0), 1.0)
        x1 = np.where(disc > 0, t_one, 2.0 * m * np.cos(np.arccos(cos3) / 3.0)) - third
        for _ in range(2):
            f = ((x1 + a) * x1 + b) * x1 + d
            df = (3.0 * x1 + two_a) * x1 + b
            x1 = x1 - np.where(df != 0, f / df, 0.0)
        # x² + s x + t = f(x)/(x − x1), with t from c_1 or from c_2, whichever leaves the
        # smaller remainder.
        s = a + x1
        xs = x1 * s
        t_fwd = b + xs
        t_bwd = -d / x1
        use_bwd = np.isfinite(t_bwd) & (np.abs(b - t_bwd + xs) * np.sqrt(np.abs(t_bwd))
                                        < np.abs(t_fwd * x1 + d))
        t = np.where(use_bwd, t_bwd, t_fwd)
        dq = s * s - 4.0 * t
        sq = np.sqrt(np.abs(dq))
        big = -0.5 * (s + np.copysign(sq, s))
        small = np.where(big != 0, t / big, 0.0)
        real = dq >= 0
        half_s, half_sq = -0.5 * s, 0.5j * sq
        x = np.stack([x1 + 0j, np.where(real, big, half_s + half_sq),
                      np.where(real, small, half_s - half_sq)], axis=1)
        a, b, d, two_a = a[:, None], b[:, None], d[:, None], two_a[:, None]
        df = (3.0 * x + two_a) * x + b
        x = x - np.where(df != 0, (((x + a) * x + b) * x + d) / df, 0.0)
        xa = x + a
        xab = xa * x + b
        f = xab * x + d
        df = np.abs((3.0 * x + two_a) * x + b)
        ax = np.abs(x)
        coefwise = ((ax + np.abs(a)) * ax + np.abs(b)) * ax + np.abs(d)
        norm_c = np.sqrt(a * a + b * b + d * d + 2.0)
        cond = (np.sqrt((ax * ax + 1.0) * ax * ax + 1.0)
                * np.sqrt(1.0 + np.abs(xa) ** 2 + np.abs(xab) ** 2))
        err = (np.abs(f) + ROOT_RTOL * coefwise + 2.2e-16 * norm_c * cond) / df
        d01, d02, d12 = (np.abs(x[:, 0] - x[:, 1]), np.abs(x[:, 0] - x[:, 2]),
                         np.abs(x[:, 1] - x[:, 2]))
        sep = np.stack([np.minimum(d01, d02), np.minimum(d01, d12), np.minimum(d02, d12)], axis=1)
        err = np.where(np.isfinite(err) & np.isfinite(ax) & (err < 0.01 * sep), err, np.inf)
    return x, err


def _cubic_matignon(c: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Matignon's test of cubics a_0 + a_1 λ + a_2 λ² + a_3 λ³ (a_0 ≠ 0, given as the finite
    monic coefficients ``c = a[:, 1:] / a[:, :1]`` of the reversed polynomial) from the
    closed-form roots μ = 1/λ: (stable, sure).

    ``sure`` marks the rows whose decision is the same for any roots within twice the error
    bound of :func:`cubic_roots`, which covers both these roots and the eigenvalues of the
    companion matrix (:func:`_monic_reversed_roots`): every root is clearly finite (|μ| above
    1e-9 of the largest, far above the 1e-13 that counts as a root at infinity) and its
    argument is clearly above or below qπ/2; or one such root is clearly unstable. The other
    rows are left to the eigenvalues."""
    mu, err = cubic_roots(c)
    absmu = np.abs(mu)
    with np.errstate(invalid="ignore", divide="ignore"):
        tol = 2.0 * err / absmu
        finite = (absmu > 1e-9 * np.maximum(1.0, absmu.max(axis=1, keepdims=True))) & (tol < 1e-3)
        margin = np.abs(np.arctan2(mu.imag, mu.real)) - q[:, None] * HALF_PI
        bound = 1.01 * tol + 1e-15
        good = finite & (margin > bound)
        bad = finite & (margin < -bound)
    stable = np.all(good, axis=1)
    return stable, np.any(bad, axis=1) | stable


def _same_sign_sector(c: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Rows that Matignon's condition certainly holds for, without the roots: the monic
    coefficients ``c`` (of 1 + c_1 λ + … + c_n λ^n) all ≥ 0 and q < 2/n.

    Such a polynomial has no root with |arg λ| < π/n: for λ = r e^{jθ}, 0 < |θ| < π/n, every
    sin kθ (k ≤ n) has the sign of θ, so Im A(λ) = Σ c_k r^k sin kθ ≠ 0, and A(r) ≥ 1 on the
    positive axis (a classical exclusion sector, e.g. A. Melman 2021). With qπ/2 < π/n every
    root then lies outside the sector. Exact for the
    floating-point coefficients (the roots of the other routes are of the same ``c``). It
    settles many rows of a tempered-ladder run without their roots, and so makes
    ``matignon_stable`` faster with the same decisions (BENCHMARKS.md, "Measurements behind
    design choices").
    """
    return np.all(c >= 0, axis=1) & (q < 2.0 / c.shape[1])


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

    Notes
    -----
    The roots are the eigenvalues of companion matrices, in closed form for degree 1 and 2;
    batches of cubics take the closed-form roots of :func:`cubic_roots` and the eigenvalues
    only for rows whose decision the roots' error bound leaves open (the same decisions).

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
    a = np.broadcast_to(a, batch + a.shape[-1:]).reshape(-1, a.shape[-1])
    q = np.broadcast_to(q, batch).reshape(-1)
    ok = a[:, 0] != 0
    if allow_integrator and not ok.all():
        # Factor out λ while the constant term vanishes.
        a = a.copy()
        for _ in range(a.shape[1] - 1):
            rows = a[:, 0] == 0
            if not rows.any():
                break
            a[rows] = np.concatenate([a[rows, 1:], np.zeros((rows.sum(), 1))], axis=1)
        ok = a[:, 0] != 0
    # ok is now false where A is identically zero, or an integrator that is not allowed.
    if a.shape[1] == 1 or not ok.any():
        return ok.reshape(batch)
    # Non-finite coefficients (an overflowed fit) or q have no roots to test: unstable.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        c = a[:, 1:] / a[:, :1]
    ok &= np.all(np.isfinite(c), axis=1) & np.isfinite(q)
    rows = np.flatnonzero(ok)
    if rows.size < ok.size:
        c, q = c[rows], q[rows]
    certain = _same_sign_sector(c, q)
    if certain.any():
        rows, c, q = rows[~certain], c[~certain], q[~certain]
    if a.shape[1] == 4 and rows.size >= CLOSED_FORM_MIN_ROWS:
        # Cubics: closed-form roots, with the eigenvalues only for rows too close to call.
        stable, sure = _cubic_matignon(c, q)
        ok[rows] = stable
        if sure.all():
            return ok.reshape(batch)
        rows, c, q = rows[~sure], c[~sure], q[~sure]
    if rows.size:
        mu = _reversed_roots(c)
        absmu = np.abs(mu)
        scale = np.maximum(1.0, absmu.max(axis=1, keepdims=True))
        finite_root = absmu > 1e-13 * scale  # μ ≈ 0 is a root at infinity: a dropped degree
        arg_ok = np.abs(np.arctan2(mu.imag, mu.real)) > q[:, None] * HALF_PI
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
