"""Stability and passivity of structures: the exact dissipation check of commensurate structures;
for the others, sums and series of springpots and general power sums.

A side of a transfer function is a power sum D(s) = Σ d_k s^(e_k) (a pseudo-polynomial in one
s^q when commensurate; Matignon's theorem then decides, :func:`bayesfo.structures.response.matignon_stable`).
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

For commensurate structures, G(s) = N(λ)/D(λ) with λ = s^q, passivity is decided exactly
(:func:`commensurate_passive`). With x = ω^q, λ = (jω)^q = x e^{jqπ/2} and

    Im[N(λ) conj D(λ)] = Σ_k Σ_l n_k d_l x^(k+l) sin((k − l) qπ/2) =: P(x),

a real polynomial in x (the *dissipation polynomial*, :func:`dissipation_polynomial`) whose sign
is that of Im G(jω) = P(x)/|D(λ)|². A compliance dissipates iff P(x) ≤ 0 for every x > 0, and so
does its reciprocal, a modulus (Im(1/G) = −P(x)/|N(λ)|²): the condition on the parameters is the
same for both kinds. Deciding the sign of a polynomial on the positive axis is exact
(:func:`nonnegative_on_positive_axis`): by the sign pattern of its coefficients, and otherwise
by its values at the positive real critical points (the roots of P′), up to a relative rounding
tolerance.
"""

from __future__ import annotations

import numpy as np

from .response import (
    HALF_PI,
    cubic_roots,
    matignon_stable,
    polyval_ascending,
)

#: Groups of rows with a cubic p′ at least this large take closed-form critical points
#: (:func:`_cubic_critical_check`); smaller ones the eigenvalues directly.
CLOSED_FORM_MIN_ROWS = 32

#: Exponents closer than this to an integer count as integers.
INTEGER_TOL = 1e-12

#: Relative rounding tolerance of the exact dissipation check: coefficients of the dissipation
#: polynomial within this fraction of their scale are zero, and values within this fraction of
#: Σ|n_k| x^k · Σ|d_l| x^l (a bound of |N(λ)| |D(λ)|) are of either sign.
DISSIPATION_RTOL = 1e-12

#: Use the exact dissipation check for commensurate structures (``Structure.passive``); False
#: restores the dense-grid check of the definition.
EXACT_COMMENSURATE = True

#: Grid density and largest span (decades) of the argument-principle check.
POINTS_PER_DECADE = 40
MAX_DECADES = 600.0


def positive_sum_zero_free(coef: np.ndarray, expo: np.ndarray) -> np.ndarray:
    """Rows of the power sums Σ coef·s^expo (shape (n, T)) that are positive springpot sums
    (condition 1 of the module docstring): no zero in Re s ≥ 0 except at s = 0."""
    with np.errstate(invalid="ignore"):
        finite = np.all(np.isfinite(coef) & np.isfinite(expo), axis=1)
        positive = coef > 0
        nonneg = np.all(coef >= 0, axis=1) & np.any(positive, axis=1)
        # The span of the exponents of the positive terms (rows with an exponent that is not
        # finite are not ``finite``, whatever their span).
        spread = (np.max(np.where(positive, expo, -np.inf), axis=1)
                  - np.min(np.where(positive, expo, np.inf), axis=1))
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


# ---------------------------------------------------------------------- exact passivity
def dissipation_polynomial(den, num, q) -> tuple[np.ndarray, np.ndarray]:
    """The dissipation polynomial of commensurate transfer functions N(λ)/D(λ), λ = s^q.

    Parameters
    ----------
    den : array_like, shape (n_sets, n+1)
        Ascending coefficients d_l of D(λ).
    num : array_like, shape (n_sets, m+1)
        Ascending coefficients n_k of N(λ).
    q : array_like, shape (n_sets,)

    Returns
    -------
    coef : ndarray, shape (n_sets, n+m+1)
        Ascending coefficients in x = ω^q of P(x) = Im[N(λ) conj D(λ)] at λ = (jω)^q,
        c_j = Σ_{k+l=j} n_k d_l sin((k − l) qπ/2); c_0 = 0 always. Exact up to rounding: Im G(jω)
        has the sign of P(x) at every ω > 0.
    scale : ndarray, shape (n_sets, n+m+1)
        s_j = Σ_{k+l=j} |n_k| |d_l|, the coefficients of Σ|n_k| x^k · Σ|d_l| x^l ≥ |N(λ)| |D(λ)|:
        the size against which rounding of ``coef`` and of P(x) is judged.
    """
    den = np.atleast_2d(np.asarray(den, dtype=float))
    num = np.atleast_2d(np.asarray(num, dtype=float))
    q = np.atleast_1d(np.asarray(q, dtype=float))
    n_sets = max(den.shape[0], num.shape[0], q.shape[0])
    n_den = den.shape[1]
    coef = np.zeros((n_sets, n_den + num.shape[1] - 1))
    scale = np.zeros_like(coef)
    with np.errstate(all="ignore"):
        # sin((k − l) qπ/2) for every difference k − l at once, column k − l + n_den − 1; each
        # coefficient then sums its products n_k d_l in the order k = 0, 1, … (one array
        # operation per k instead of per pair: the same sums, a third of the fixed cost).
        diff = np.arange(-(n_den - 1), num.shape[1], dtype=float)
        sines = np.sin(q[:, None] * diff * HALF_PI)
        for k in range(num.shape[1]):
            prod = num[:, k:k + 1] * den  # n_k d_l, l = 0 … n, into coefficients k … k + n
            scale[:, k:k + n_den] += np.abs(prod)
            # Differences k − l for l = 0 … n are columns k + n_den − 1 down to k; l = k
            # (sin 0) is left out.
            sin_k = sines[:, k + n_den - 1::-1] if k == 0 else sines[:, k + n_den - 1:k - 1:-1]
            below = min(k, n_den)  # l < k
            if below:
                coef[:, k:k + below] += prod[:, :below] * sin_k[:, :below]
            if k + 1 < n_den:  # l > k
                coef[:, 2 * k + 1:k + n_den] += prod[:, k + 1:] * sin_k[:, k + 1:]
    return coef, scale


def _evaluate_ratio(p: np.ndarray, s: np.ndarray, x: np.ndarray) -> np.ndarray:
    """p(x)/s(x) for rows of ascending coefficients and candidate points x (rows, c) > 0,
    without overflow: in powers of 1/x where x > 1 (p(x)/x^K = Σ p_j (1/x)^(K−j))."""
    k = np.arange(p.shape[1])
    big = x > 1.0
    with np.errstate(all="ignore"):
        t = np.where(big, 1.0 / x, x)[:, :, None]
        e = np.where(big[:, :, None], k[-1] - k, k)  # (rows, c, K)
        w = t ** e
        num = np.sum(p[:, None, :] * w, axis=2)
        den = np.sum(s[:, None, :] * w, axis=2)
        return np.where(den > 0, num / den, 0.0)


def _isolated_negatives_dominated(p: np.ndarray) -> np.ndarray:
    """Rows of ascending coefficients (shape (n, K)) that are ≥ 0 at every x > 0 by the
    arithmetic–geometric mean inequality: no two negative coefficients are adjacent, and
    every negative p_j satisfies p_j² ≤ 4 (w p_{j−1})(w′ p_{j+1}), where w, w′ are the shares of
    its neighbours (1, or 1/2 for a neighbour between two negative coefficients), so that
    w p_{j−1} x^{j−1} + p_j x^j + w′ p_{j+1} x^{j+1} ≥ 0 and the shares add up to at most p.
    A sufficient condition (a certificate), with a factor 1 − 1e-9 against rounding."""
    neg = p < 0
    if p.shape[1] < 3:
        return ~neg.any(axis=1)
    adjacent = np.any(neg[:, 1:] & neg[:, :-1], axis=1)
    count = np.zeros(p.shape)
    count[:, 1:] += neg[:, :-1]
    count[:, :-1] += neg[:, 1:]
    share = np.maximum(p, 0.0) / np.maximum(count, 1.0)
    inner = p[:, 1:-1]
    dominated = inner * inner <= 4.0 * share[:, :-2] * share[:, 2:] * (1.0 - 1e-9)
    ends = ~neg[:, 0] & ~neg[:, -1]
    return ends & ~adjacent & np.all(dominated | ~neg[:, 1:-1], axis=1)


def _cubic_critical_check(p: np.ndarray, s: np.ndarray, deriv: np.ndarray, rtol: float
                          ) -> tuple[np.ndarray, np.ndarray]:
    """The rule of :func:`nonnegative_on_positive_axis` for rows whose p′ (ascending
    ``deriv``, 4 coefficients) is a cubic, with its roots in closed form: (ok, sure).

    ``sure`` marks rows whose decision is the same at any candidate points within twice the
    error bound of :func:`~bayesfo.structures.response.cubic_roots` (which also bounds the eigenvalues
    of the companion matrix): every root is clearly off the imaginary axis and away from 0,
    and every ratio p/S at a candidate x is farther from −rtol than it can move there
    (|d(p/S)/dx| ≤ 2 S′/S ≤ 2K/x, as |p_j| ≤ s_j) plus 1e-14 of rounding."""
    roots, err = cubic_roots(deriv[:, -2::-1] / deriv[:, -1:])
    e = 2.0 * err
    with np.errstate(all="ignore"):
        absr = np.abs(roots)
        clear = np.all((absr > 2.0 * e) & (np.abs(roots.real) > e), axis=1)
        cand = np.concatenate([absr, np.where(roots.real > 0, roots.real, 1.0)], axis=1)
        move = np.concatenate([e, np.where(roots.real > 0, e, 0.0)], axis=1)
        ratio = _evaluate_ratio(p, s, np.where(cand > 0, cand, 1.0))
        slack = 2.0 * (p.shape[1] - 1) * move / (cand - move) + 1e-14
        above = ratio >= -rtol + slack
        below = ratio < -rtol - slack
    ok = np.all(above, axis=1)
    return ok, clear & np.isfinite(err).all(axis=1) & (ok | np.any(below, axis=1))


def nonnegative_on_positive_axis(coef, scale=None, *, rtol: float = DISSIPATION_RTOL
                                 ) -> np.ndarray:
    """Whether real polynomials are ≥ 0 at every x > 0 (exact up to a rounding tolerance).

    Parameters
    ----------
    coef : array_like, shape (n_sets, K)
        Ascending coefficients p_j.
    scale : array_like, shape (n_sets, K), optional
        Non-negative sizes s_j of the coefficients (default |p_j|): p_j with |p_j| ≤ rtol·s_j
        count as 0, and p(x) ≥ −rtol·Σ s_j x^j counts as ≥ 0.
    rtol : float

    Returns
    -------
    ndarray of bool, shape (n_sets,)
        False where a coefficient is not finite.

    Notes
    -----
    The decision is exact, in three steps: every coefficient ≥ 0 → true; the lowest or the
    highest non-zero coefficient < 0 → false (p takes its sign near 0 or near ∞); otherwise p is
    positive at both ends of (0, ∞) and its minimum there is at a positive real root of p′,
    found as the eigenvalues of the companion matrices of p′ (batched by degree). p is evaluated
    at the modulus and the real part of every root of p′ (all positive points, so extra points
    only add checks), in powers of 1/x beyond x = 1 to stay finite. Two shortcuts give the same
    decisions with less work: a certificate of p ≥ 0 (isolated negative coefficients dominated
    by their neighbours, :func:`_isolated_negatives_dominated`) settles rows without roots, and
    a cubic p′ takes closed-form roots (:func:`_cubic_critical_check`) wherever their error
    bound cannot change a decision; the other rows take the eigenvalues.
    """
    p = np.atleast_2d(np.asarray(coef, dtype=float))
    s = np.abs(p) if scale is None else np.atleast_2d(np.asarray(scale, dtype=float))
    n, k = p.shape
    with np.errstate(all="ignore"):
        finite = np.all(np.isfinite(p) & np.isfinite(s), axis=1)
        if finite.all():  # the common case, without masking
            top = np.max(s, axis=1)
        else:
            top = np.max(np.where(finite[:, None], s, 0.0), axis=1)
            p = np.where(finite[:, None], p, 0.0)
            s = np.where(finite[:, None], s, 0.0)
        norm = np.where(top > 0, top, 1.0)[:, None]
        p = p / norm
        s = s / norm
    p = np.where(np.abs(p) <= rtol * s, 0.0, p)
    # Rows without a negative coefficient are ≥ 0; the others are false where the lowest or
    # the highest non-zero coefficient is negative, and undecided otherwise.
    out = finite & ~np.any(p < 0, axis=1)
    rest = np.flatnonzero(finite & ~out)
    if rest.size == 0:
        return out
    nonzero = p[rest] != 0
    j0 = np.argmax(nonzero, axis=1)
    j1 = k - 1 - np.argmax(nonzero[:, ::-1], axis=1)
    inner = (p[rest, j0] >= 0) & (p[rest, j1] >= 0)
    rest, j0, j1 = rest[inner], j0[inner], j1[inner]
    if rest.size:
        # A certificate of p ≥ 0 settles most of the others without roots.
        certified = _isolated_negatives_dominated(p[rest])
        out[rest[certified]] = True
        rest, j0, j1 = rest[~certified], j0[~certified], j1[~certified]
    if rest.size == 0:
        return out
    # p'(x) = Σ_{j≥1} j p_j x^(j−1); trimmed to x^(j0−1) … x^(j1−1), a factor x^(j0−1) dropped.
    for lo, hi in set(zip(j0.tolist(), j1.tolist())):
        grp = rest[(j0 == lo) & (j1 == hi)]
        deriv = p[grp, lo:hi + 1] * np.arange(lo, hi + 1)  # ascending coefficients of p'/x^(lo-1)
        deg = hi - lo
        if deg == 3 and grp.size >= CLOSED_FORM_MIN_ROWS:
            ok, sure = _cubic_critical_check(p[grp], s[grp], deriv, rtol)
            out[grp[sure]] = ok[sure]
            grp, deriv = grp[~sure], deriv[~sure]
            if grp.size == 0:
                continue
        lead = deriv[:, -1:]
        comp = np.zeros((grp.size, deg, deg))
        comp[:, 0, :] = -(deriv[:, -2::-1] / lead)
        if deg > 1:
            comp[:, np.arange(1, deg), np.arange(deg - 1)] = 1.0
        roots = np.linalg.eigvals(comp)
        cand = np.concatenate([np.abs(roots), np.where(roots.real > 0, roots.real, 1.0)], axis=1)
        cand = np.where(cand > 0, cand, 1.0)
        ratio = _evaluate_ratio(p[grp], s[grp], cand)
        out[grp] = np.all(ratio >= -rtol, axis=1)
    return out


def commensurate_passive(den, num, q, *, rtol: float = DISSIPATION_RTOL) -> np.ndarray:
    """Exact dissipation of commensurate transfer functions N(λ)/D(λ), λ = s^q, at every ω > 0.

    True where the dissipation polynomial (:func:`dissipation_polynomial`) is ≤ 0 for every
    x = ω^q > 0: Im G(jω) ≤ 0 (a dissipating compliance), equivalently Im(1/G(jω)) ≥ 0 (a
    dissipating modulus). The decision is exact up to the relative rounding tolerance ``rtol``
    (:func:`nonnegative_on_positive_axis`); it holds for any real q (λ = ω^q e^{jqπ/2}).

    Parameters
    ----------
    den, num : array_like, shapes (n_sets, n+1) and (n_sets, m+1)
        Ascending coefficients of D(λ) and N(λ).
    q : array_like, shape (n_sets,)

    Returns
    -------
    ndarray of bool, shape (n_sets,)
        False where a coefficient or q is not finite.
    """
    coef, scale = dissipation_polynomial(den, num, q)
    ok = nonnegative_on_positive_axis(-coef, scale, rtol=rtol)
    return ok & np.isfinite(np.broadcast_to(np.atleast_1d(np.asarray(q, float)), ok.shape))


def passive_on_grid(den, num, q, x, *, rtol: float = DISSIPATION_RTOL,
                    chunk: int = 250) -> np.ndarray:
    """The definition on a grid, the reference of :func:`commensurate_passive` in the tests and
    ``benchmarks/bench_passivity.py``: Im[N(λ) conj D(λ)] ≤ 0 at λ = x e^{jqπ/2} for every x of
    the grid, evaluated through complex λ (not through the dissipation polynomial), with the
    same rounding tolerance relative to Σ|n_k| x^k · Σ|d_l| x^l. ``chunk`` parameter sets at a
    time keep the memory at chunk × len(x)."""
    den, num = np.atleast_2d(den), np.atleast_2d(num)
    q, x = np.atleast_1d(q), np.asarray(x, dtype=float)
    out = []
    for i in range(0, len(q), chunk):
        lam = x * np.exp(1j * q[i:i + chunk, None] * HALF_PI)
        with np.errstate(all="ignore"):
            n = polyval_ascending(num[i:i + chunk], lam)
            d = polyval_ascending(den[i:i + chunk], lam)
            size = (polyval_ascending(np.abs(num[i:i + chunk]), x[None]).real
                    * polyval_ascending(np.abs(den[i:i + chunk]), x[None]).real)
        out.append(np.all((n * d.conj()).imag <= rtol * size, axis=1))
    return np.concatenate(out)


def _live_indices(n_den: int, n_num: int) -> np.ndarray:
    """Indices j of the dissipation polynomial that have a pair k + l = j with k ≠ l (the
    others are 0 for every parameter set)."""
    live = np.zeros(n_den + n_num - 1, dtype=bool)
    for k in range(n_num):
        for j in range(n_den):
            live[k + j] |= k != j
    return np.flatnonzero(live)


def dissipation_shortfall(den, num, q, *, margin: float = 1e-8) -> np.ndarray:
    """How far commensurate transfer functions are from dissipating with a small margin:
    non-negative measures, all 0 inside the passive region (for the optimiser's penalty).

    With p = −P (the dissipation polynomial, :func:`dissipation_polynomial`, with the sign that
    must be ≥ 0) and S(x) = Σ s_j x^j its scale, the columns are

    0. max(0, margin − p_lo/S(1)), p_lo the lowest coefficient that is not identically 0;
    1. max(0, margin − p_hi/S(1)), p_hi the highest one;
    2. max(0, margin − min p(x*)/S(x*)) over the positive real critical points x* of p.

    They are continuous in the parameters (normalised by S(1) sin(qπ/2), not by each
    coefficient's own scale), so least squares can drive them to 0. Zero shortfall implies
    :func:`commensurate_passive` (the margin exceeds its rounding tolerance).

    Returns
    -------
    ndarray, shape (n_sets, 3)
    """
    den = np.atleast_2d(np.asarray(den, dtype=float))
    num = np.atleast_2d(np.asarray(num, dtype=float))
    coef, scale = dissipation_polynomial(den, num, q)
    live = _live_indices(den.shape[1], num.shape[1])
    n = coef.shape[0]
    out = np.zeros((n, 3))
    if live.size == 0:
        return out
    with np.errstate(all="ignore"):
        # Normalised by S(1) sin(qπ/2) (every coefficient has a factor sin(k qπ/2)), so that
        # q → 0, where P vanishes identically, is no way out of the margin.
        sin_q = np.abs(np.sin(np.atleast_1d(np.asarray(q, dtype=float)) * HALF_PI))
        s1 = scale.sum(axis=1) * np.broadcast_to(np.maximum(sin_q, 1e-3), (n,))
        s1 = np.where(np.isfinite(s1) & (s1 > 0), s1, 1.0)[:, None]
        p, s = -coef / s1, scale / s1
        finite = np.all(np.isfinite(p), axis=1)
        p[~finite], s[~finite] = 0.0, 0.0
        lo, hi = int(live[0]), int(live[-1])
        out[:, 0] = np.maximum(0.0, margin - p[:, lo])
        out[:, 1] = np.maximum(0.0, margin - p[:, hi])
        if hi > lo:
            deriv = p[:, lo:hi + 1] * np.arange(lo, hi + 1)
            deg = hi - lo
            lead = deriv[:, -1:]
            lead = np.where(np.abs(lead) > 1e-300, lead, 1e-300)
            comp = np.zeros((n, deg, deg))
            comp[:, 0, :] = -(deriv[:, -2::-1] / lead)
            if deg > 1:
                comp[:, np.arange(1, deg), np.arange(deg - 1)] = 1.0
            comp = np.where(np.isfinite(comp), comp, 0.0)
            roots = np.linalg.eigvals(comp)
            real = np.abs(roots.imag) <= 1e-6 * np.abs(roots)
            cand = np.where(real & (roots.real > 0), roots.real, np.nan)
            ratio = _evaluate_ratio(p, s, np.where(np.isnan(cand), 1.0, cand))
            ratio = np.where(np.isnan(cand), np.inf, ratio)
            out[:, 2] = np.maximum(0.0, margin - ratio.min(axis=1))
        out[~finite] = 1.0
    return out
