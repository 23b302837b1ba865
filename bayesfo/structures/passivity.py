"""Stability and passivity of structures that are not of commensurate order: sums and series of
springpots and general power sums.

A side of a transfer function is a power sum D(s) = Σ d_k s^(e_k) (a pseudo-polynomial in one
s^q when commensurate; Matignon's theorem then decides, :func:`bayesfo.response.matignon_stable`).
For the other sides these conditions are used, in this order:

1. **Positive springpot sum** (exact, sufficient): if every d_k ≥ 0 (not all 0) and the spread of
   the exponents max e − min e is below 2, D has no zero in Re s ≥ 0 except possibly s = 0. For
   s = r e^{jφ}, 0 < φ ≤ π/2, every term lies in the cone of arguments [min e·φ, max e·φ] of
   opening below π, so their sum is not 0 (φ < 0 by symmetry, φ = 0: all terms ≥ 0). A zero at
   s = 0 is an integrator (flow), accepted as in the thesis' Maxwell structure.
2. **Integer exponents** (exact): when every exponent is an integer (an ``-int`` variant), D
   is a polynomial in s and Matignon's theorem with q = 1 (Routh–Hurwitz) decides.
3. **Argument principle** (numerical): the number of zeros in Re s > 0 is
   [2 (arg D(j0⁺) − arg D(j∞)) + (max e − min e) π] / 2π, with the phase unwrapped on a log
   grid between the frequencies beyond which the lowest and the highest term dominate. A zero
   on or within rounding of the imaginary axis counts as unstable.

Passivity (dissipation ≥ 0: Im J ≤ 0 of a compliance, Im G ≥ 0 of a modulus, at every ω > 0)
has these exact sufficient conditions before the dense-grid check of the definition:

* **Springpots in series**: a denominator of one term a s^α makes the compliance a sum
  Σ (b_k/a) s^(β_k − α); with b_k/a ≥ 0 and α − β_k ∈ [0, 2] every term has Im ≤ 0.
* **Springpots in parallel**: a numerator of one term b s^β makes the modulus Σ (a_k/b)
  s^(α_k − β); with a_k/b ≥ 0 and α_k − β ∈ [0, 2] every term has Im ≥ 0.
* **Series–parallel networks** declared in the card (:mod:`bayesfo.structures.network`): all
  coefficients positive and all orders in [0, 1].
"""

from __future__ import annotations

import numpy as np

from ..response import HALF_PI, matignon_stable

#: Exponents closer than this to an integer count as integers.
INTEGER_TOL = 1e-12

#: Grid density and largest span (decades) of the argument-principle check.
POINTS_PER_DECADE = 40
MAX_DECADES = 600.0


def positive_sum_zero_free(coef: np.ndarray, expo: np.ndarray) -> np.ndarray:
    """Rows of the power sums Σ coef·s^expo (shape (n, T)) that are positive springpot sums
    (condition 1 of the module docstring): no zero in Re s ≥ 0 except at s = 0."""
    with np.errstate(invalid="ignore"):
        finite = np.all(np.isfinite(coef) & np.isfinite(expo), axis=1)
        nonneg = np.all(coef >= 0, axis=1) & np.any(coef > 0, axis=1)
        used = np.where(coef > 0, expo, np.nan)
        spread = np.nanmax(np.where(np.isnan(used), -np.inf, used), axis=1) - np.nanmin(
            np.where(np.isnan(used), np.inf, used), axis=1)
    return finite & nonneg & (spread < 2.0)


def _integer_polynomial_stable(coef: np.ndarray, expo: np.ndarray) -> np.ndarray | None:
    """Matignon with q = 1 when every row has the same integer exponents, else None."""
    if expo.shape[0] == 0 or not np.all(np.isfinite(expo)):
        return None
    if np.ptp(expo, axis=0).max(initial=0.0) > 0:
        return None
    e = expo[0] - expo[0].min()
    k = np.round(e)
    if np.any(np.abs(e - k) > INTEGER_TOL) or k.max() > 60:
        return None
    poly = np.zeros((coef.shape[0], int(k.max()) + 1))
    for j, kk in enumerate(k.astype(int)):
        poly[:, kk] += coef[:, j]
    ok = np.all(np.isfinite(poly), axis=1)
    out = np.zeros(coef.shape[0], dtype=bool)
    if ok.any():
        out[ok] = matignon_stable(poly[ok], np.ones(int(ok.sum())), allow_integrator=True)
    return out


def rhp_zero_count(coef: np.ndarray, expo: np.ndarray) -> np.ndarray:
    """Zeros of Σ coef·s^expo in Re s > 0 by the argument principle (condition 3); NaN where
    the check cannot decide (a zero within rounding of the imaginary axis, or exponents so
    close that the grid would span more than :data:`MAX_DECADES` decades)."""
    coef = np.atleast_2d(np.asarray(coef, dtype=float))
    expo = np.broadcast_to(np.asarray(expo, dtype=float), coef.shape)
    # Chunks of rows keep the (rows, terms, grid) array small.
    return np.concatenate([_rhp_chunk(coef[i:i + 32], expo[i:i + 32])
                           for i in range(0, coef.shape[0], 32)] or [np.zeros(0)])


def _rhp_chunk(coef: np.ndarray, expo: np.ndarray) -> np.ndarray:
    n = coef.shape[0]
    out = np.full(n, np.nan)
    with np.errstate(all="ignore"):
        live = (coef != 0) & np.isfinite(coef) & np.isfinite(expo)
        e_min = np.min(np.where(live, expo, np.inf), axis=1)
        e_max = np.max(np.where(live, expo, -np.inf), axis=1)
        at_min = live & (np.abs(expo - e_min[:, None]) <= INTEGER_TOL)
        at_max = live & (np.abs(expo - e_max[:, None]) <= INTEGER_TOL)
        d_min = np.sum(np.where(at_min, coef, 0.0), axis=1)
        d_max = np.sum(np.where(at_max, coef, 0.0), axis=1)
        ok = np.any(live, axis=1) & (d_min != 0) & (d_max != 0) & np.all(
            np.isfinite(coef), axis=1)
        single = ok & (e_max - e_min <= INTEGER_TOL)
        out[single] = 0.0
        rows = np.flatnonzero(ok & ~single)
        if rows.size == 0:
            return out
        c, e, live = coef[rows], expo[rows], live[rows]
        lo_e, hi_e = e_min[rows, None], e_max[rows, None]
        t = live.sum(axis=1, keepdims=True).astype(float)
        # Below ω_lo the lowest term, above ω_hi the highest term outweighs the others 4:1.
        r_lo = np.abs(c / d_min[rows, None])
        r_hi = np.abs(c / d_max[rows, None])
        log_lo = np.where(live & (e > lo_e + INTEGER_TOL),
                          np.log(0.25 / (t * r_lo)) / (e - lo_e), np.inf).min(axis=1)
        log_hi = np.where(live & (e < hi_e - INTEGER_TOL),
                          np.log(t * r_hi / 0.25) / (hi_e - e), -np.inf).max(axis=1)
        a, b = np.minimum(log_lo, log_hi) - 1.0, np.maximum(log_lo, log_hi) + 1.0
        decades = (b - a) / np.log(10.0)
        good = np.isfinite(decades) & (decades <= MAX_DECADES)
        m = int(min(max(decades[good].max(initial=1.0) * POINTS_PER_DECADE, 200), 24001))
        x = a[:, None] + (b - a)[:, None] * np.linspace(0.0, 1.0, m)  # log ω, (rows, m)
        logmag = np.where(live[:, :, None], np.log(np.abs(c))[:, :, None]
                          + e[:, :, None] * x[:, None, :], -np.inf)
        phase = e * HALF_PI + np.where(c < 0, np.pi, 0.0)
        top = logmag.max(axis=1, keepdims=True)
        z = np.sum(np.exp(logmag - top) * np.exp(1j * phase)[:, :, None], axis=1)
        axis_zero = np.min(np.abs(z), axis=1) < 1e-9
        arg = np.unwrap(np.angle(z), axis=1)
        jumpy = np.max(np.abs(np.diff(arg, axis=1)), axis=1) > 2.0
        asym_lo = lo_e[:, 0] * HALF_PI + np.where(d_min[rows] < 0, np.pi, 0.0)
        asym_hi = hi_e[:, 0] * HALF_PI + np.where(d_max[rows] < 0, np.pi, 0.0)
        a_lo = asym_lo + 2 * np.pi * np.round((arg[:, 0] - asym_lo) / (2 * np.pi))
        a_hi = asym_hi + 2 * np.pi * np.round((arg[:, -1] - asym_hi) / (2 * np.pi))
        count = (2 * (a_lo - a_hi) + (hi_e[:, 0] - lo_e[:, 0]) * np.pi) / (2 * np.pi)
        decided = good & ~axis_zero & ~jumpy & (np.abs(count - np.round(count)) < 0.05)
        out[rows[decided]] = np.round(count[decided])
    return out


def side_stable(coef: np.ndarray, expo: np.ndarray) -> np.ndarray:
    """No zero of the power sums (rows of ``coef``, ``expo``) in Re s ≥ 0 other than s = 0,
    by conditions 1–3 of the module docstring; undecided rows count as unstable."""
    coef = np.atleast_2d(np.asarray(coef, dtype=float))
    expo = np.broadcast_to(np.asarray(expo, dtype=float), coef.shape)
    ok = positive_sum_zero_free(coef, expo)
    rest = np.flatnonzero(~ok)
    if rest.size:
        poly = _integer_polynomial_stable(coef[rest], expo[rest])
        if poly is not None:
            ok[rest] = poly
        else:
            ok[rest] = rhp_zero_count(coef[rest], expo[rest]) == 0
    return ok


def springpot_sum_passive(num: tuple, den: tuple) -> np.ndarray | None:
    """Rows that are sums of springpots in series or in parallel with non-negative
    coefficients and orders in [0, 2] (passive); None if neither side has a single term.

    ``num`` and ``den`` are (coefficients, exponents) pairs of shape (n, T)."""
    (nc, ne), (dc, de) = num, den
    with np.errstate(all="ignore"):
        if dc.shape[1] == 1:
            ratio, diff = nc / dc, de - ne  # compliance Σ (b/a) s^(β−α): orders α − β
        elif nc.shape[1] == 1:
            ratio, diff = dc / nc, de - ne  # modulus Σ (a/b) s^(α−β)
        else:
            return None
        ok = np.isfinite(ratio) & (ratio >= 0) & (diff >= -INTEGER_TOL) & (diff <= 2 + INTEGER_TOL)
    return np.all(ok, axis=1) & np.any(ratio > 0, axis=1)
