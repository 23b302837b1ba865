"""Linear fits over a grid of q and over the max-order family (thesis §4.3.2, §4.3.4).

For a commensurate structure the linear methods need q; the scan solves every q of a grid at once
(0.01 steps in (0, 1] by default), rejects unstable results by Matignon's theorem and keeps the
stable one with the lowest RMSE (eq. (3.23)). The max-order loop runs the scan for every member
n = 1..n_max, m = 0..n (inverted: m = 1..n_max, n = 0..m).

The methods run on the scaled data (ω/ω_ref, G/g_ref) for conditioning; coefficients are
reported in physical units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..data import FrequencyResponse
from ..errors import InputError
from ..structures.response import commensurate_response, matignon_stable
from .linear import identify_linear

DEFAULT_Q_GRID = np.round(np.arange(1, 101) * 0.01, 2)


@dataclass(frozen=True)
class LinearFit:
    """One linear fit in the thesis convention.

    Attributes
    ----------
    n, m : int
        Degrees of A and B.
    method : int
    inverted : bool
        True if the fitted transfer function is A/B (the reciprocal form, thesis §4.3.4).
    q : float
    a : ndarray
        [1, a_1, …, a_n] in physical units.
    b : ndarray
        [b_0, …, b_m] in physical units.
    rmse : float
        (1/N)·sqrt(Σ|G_k − Ĝ_k|²) against the data as measured (thesis eq. (3.23)).
    stable : bool
        Matignon stability of the fitted denominator (B for inverted fits), and for compliance
        and modulus data of the numerator too; integrators accepted.
    """

    n: int
    m: int
    method: int
    inverted: bool
    q: float
    a: np.ndarray
    b: np.ndarray
    rmse: float
    stable: bool

    def response(self, omega) -> np.ndarray:
        """The fitted structure's transfer function (B/A, or A/B if inverted) at ``omega``."""
        g = commensurate_response(omega, self.a, self.b, self.q)
        return 1.0 / g if self.inverted else g

    def to_dict(self) -> dict:
        return {
            "n": self.n, "m": self.m, "method": self.method, "inverted": self.inverted,
            "q": self.q, "a": self.a.tolist(), "b": self.b.tolist(), "rmse": self.rmse,
            "stable": self.stable,
        }


@dataclass(frozen=True)
class QScan:
    """A q-grid scan: every q with its RMSE and stability, and the best stable fit."""

    q_grid: np.ndarray
    rmse: np.ndarray
    stable: np.ndarray
    best: LinearFit | None

    @property
    def rejected_unstable(self) -> np.ndarray:
        """The q values whose fit was unstable."""
        return self.q_grid[~self.stable]


def fit_linear(data: FrequencyResponse, n: int, m: int, method: int, q, *,
               inverted: bool = False) -> list[LinearFit]:
    """Linear fits of B/A (or A/B if ``inverted``) for one or several q at once.

    Parameters
    ----------
    data : FrequencyResponse
    n, m : int
        Degrees of A (1 + a_1 λ + …) and B (b_0 + …).
    method : {1, 2, 3, 4, 5}
        Thesis Table 3.1.
    q : float or array_like
        Commensurate order(s).
    inverted : bool
        The structure is A/B (thesis §4.3.4).

    Returns
    -------
    list of LinearFit, one per q.

    Notes
    -----
    The methods fit B/A to whatever the structure is compared with: the data for compliance
    and generic data, their reciprocal for modulus data (cards describe compliances), and the
    reciprocal again for inverted structures. The RMSE is always on the data as measured.
    Stability is tested on the structure's denominator, and for compliance and modulus data
    also on its numerator (see :meth:`bayesfo.structures.Structure.stable`).
    """
    q = np.atleast_1d(np.asarray(q, dtype=float))
    if np.any((q <= 0) | ~np.isfinite(q)):
        raise InputError(f"commensurate order q must be positive, got {q[(q <= 0) | ~np.isfinite(q)][0]}")
    n_coef = n + m + 1
    data.check_enough_points((n_coef + 2) // 2, f"the linear fit with n = {n}, m = {m}")
    reciprocal = inverted != (data.kind == "modulus")
    target = data.reciprocal() if reciprocal else data
    w_ref, g_ref = target.omega_ref, target.g_ref
    w = target.omega / w_ref
    # Overflow for extreme q (powers of λ over many decades) gives non-finite coefficients:
    # that q gets an infinite RMSE and counts as unstable, as the scan expects; no warnings.
    with np.errstate(all="ignore"):
        a_s, b_s = identify_linear(w, target.response / g_ref, q, n, m, method)
        k_a = np.arange(n + 1)
        k_b = np.arange(m + 1)
        a = a_s * w_ref ** (-k_a[None, :] * q[:, None])
        b = b_s * g_ref * w_ref ** (-k_b[None, :] * q[:, None])
        fitted = commensurate_response(data.omega, a, b, q)
        if reciprocal:
            fitted = 1.0 / fitted
        stable = matignon_stable(b if inverted else a, q, allow_integrator=True)
        if data.kind in ("compliance", "modulus"):
            stable &= matignon_stable(a if inverted else b, q, allow_integrator=True)
        err = np.abs(fitted - data.response[None, :]) ** 2
        rmse = np.sqrt(np.sum(err, axis=-1)) / data.n_frequencies
    rmse = np.where(np.isfinite(rmse), rmse, np.inf)
    return [
        LinearFit(n, m, method, inverted, float(q[i]), a[i], b[i], float(rmse[i]), bool(stable[i]))
        for i in range(q.size)
    ]


def q_grid_scan(data: FrequencyResponse, n: int, m: int, method: int, *, q_grid=None,
                inverted: bool = False) -> QScan:
    """Scan q (default 0.01, 0.02, …, 1.00; thesis §4.3.2) and keep the best stable fit.

    Returns
    -------
    QScan
        ``best`` is None when every q gives an unstable fit.
    """
    q_grid = DEFAULT_Q_GRID if q_grid is None else np.asarray(q_grid, dtype=float)
    fits = fit_linear(data, n, m, method, q_grid, inverted=inverted)
    rmse = np.array([f.rmse for f in fits])
    stable = np.array([f.stable for f in fits])
    best = None
    if stable.any():
        idx = np.flatnonzero(stable)
        best = fits[idx[np.argmin(rmse[idx])]]
    return QScan(q_grid, rmse, stable, best)


def max_order_members(n_max: int, inverted: bool = False) -> list[tuple[int, int]]:
    """(n, m) of the max-order loop: n = 1..n_max, m = 0..n; inverted m = 1..n_max, n = 0..m."""
    if n_max < 1:
        raise InputError(f"n_max must be at least 1, got {n_max}")
    if inverted:
        return [(n, m) for m in range(1, n_max + 1) for n in range(m + 1)]
    return [(n, m) for n in range(1, n_max + 1) for m in range(n + 1)]


def max_order_scan(data: FrequencyResponse, n_max: int, method: int, *, q_grid=None,
                   inverted: bool = False) -> dict[tuple[int, int], QScan]:
    """The q-grid scan for every member of the max-order loop (members a method cannot fit,
    n = 0 for methods 2–5, or with too few points, are left out)."""
    out = {}
    for n, m in max_order_members(n_max, inverted):
        if n == 0 and method != 1:
            continue
        if 2 * data.n_frequencies < n + m + 1:
            continue
        out[(n, m)] = q_grid_scan(data, n, m, method, q_grid=q_grid, inverted=inverted)
    return out
