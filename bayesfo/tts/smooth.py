"""A model-free master function for the shifts: smooth curves of ln G′ and ln G″ against
log10(a_T ω), integrated out in closed form, so that the posterior is over the shifts and a
few hyperparameters only.

Each part p of the response (storage and loss; a compliance's J′ and J″) of isotherm i at
frequency ω is modelled in logs as

    ln|G_p(ω)| = f_p(log10 ω + log10 a_T,i) − s·ln(10)·log10 b_T,i + ε,   ε ~ N(0, σ_p²),

with s = 1 for a modulus (G_i = G_master(a_T ω)/b_T) and −1 for a compliance. A relative
error of each part, the usual error model of a rheometer or DMA (``relative_parts``), is a
constant error of its logarithm. Complex noise proportional to |G| (``proportional``) gives a
part's log the variance σ_p²κ, κ = |G|²/(2G_p²), and a mean σ_p²κ/2 below the log of the
part's mean (to second order), which the model adds back. The master function f_p is a cubic B-spline on equally spaced
knots (:data:`KNOT_STEP` decades apart, spanning every reduced frequency the shifts' prior
allows) whose coefficients have a Gaussian smoothness prior: second differences with sd ρ_p
(a P-spline, Eilers & Marx 1996; Lang & Brezger 2004 for the Bayesian form) and a weak ridge
(sd :data:`LEVEL_SD` around the mean of the data's logs) that makes the prior proper. Given
the shifts the model is linear-Gaussian in the coefficients, which integrate out exactly:

    ln p(y | shifts, ρ, σ) = −½ n ln(2πσ²) + ½ ln|P| − ½ ln|A| − ½ (r·r/σ² − c·A⁻¹c),

with P the prior precision, A = P + BᵀB/σ², r the centred data and c = Bᵀr/σ². A and P are
banded (half-bandwidth 3), so each evaluation is a banded Cholesky factorisation
(``scipy.linalg.cholesky_banded``) per part: the shifts' posterior costs milliseconds per
thousand parameter sets, whatever the master curve looks like. The parameters are the shifts
(one free log10 a_T per isotherm other than the reference, or a law's constants), free
log10 b_T where asked, and ρ_p, σ_p of each part (log-uniform).

Its posterior is :mod:`bayesfo.tts.smooth_posterior`. The shifts so found do not depend on a
structure describing the data; the structures are fitted afterwards to the isotherms so shifted
(:mod:`bayesfo.tts.conditional`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.linalg import cho_solve_banded, cholesky_banded, eigvals_banded

from ..errors import InputError
from ..priors import LogUniform, Uniform
from .laws import arrhenius
from .model import (
    EA_MAX,
    EA_MIN,
    VERTICAL_RANGE,
    WLF_C1_MAX,
    WLF_C2_MAX,
    log_shifts,
    log_vertical,
    shift_name,
)

#: The name of the model-free master in rankings, summaries and messages.
NAME = "smooth"
#: Knot spacing of the B-splines [decades of reduced frequency].
KNOT_STEP = 0.25
#: Prior sd of each spline coefficient around the mean of the data's logs (natural log): a
#: weak ridge that makes the prior proper (ln G spans ±10 over nine decades).
LEVEL_SD = 20.0
#: Prior ranges of the smoothness (sd of the coefficients' second differences, natural log
#: per knot step) and of the noise (sd of ln|G_p|, about the relative error of each part).
SMOOTHNESS_RANGE = (1e-4, 3.0)
NOISE_RANGE = (1e-4, 1.0)
#: Noise models of the logs: the relative error of each part constant (``relative_parts``),
#: or complex noise proportional to |G| (``proportional``: a part's relative error grows as
#: the part is small against |G|).
NOISE = ("relative_parts", "proportional")
#: The parts of the response, in the order of the hyperparameters.
PARTS = ("storage", "loss")
#: Parameter sets evaluated at once (bounds the memory of a batch); up to FEW sets are
#: factorised one by one by LAPACK, more by the vectorised factorisation.
CHUNK = 2000
FEW = 64


def _basis(x: np.ndarray, lo: float, n_basis: int):
    """Cubic B-splines on knots lo + k·KNOT_STEP at ``x`` (any shape): the index of the first
    of the four non-zero basis functions at each point and their values (shape x.shape + (4,)).
    """
    u = (x - lo) / KNOT_STEP
    k = np.clip(np.floor(u).astype(np.int64), 0, n_basis - 4)
    t = np.clip(u - k, 0.0, 1.0)
    t2, t3 = t * t, t * t * t
    values = np.stack([(1 - t) ** 3, 3 * t3 - 6 * t2 + 4, -3 * t3 + 3 * t2 + 3 * t + 1, t3],
                      axis=-1) / 6.0
    return k, values


def _banded_solve(band: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """ln|A| and c·A⁻¹c of many symmetric positive definite banded matrices at once:
    ``band`` (n_sets, n_diagonals, n) in lower banded form (``band[:, d, j]`` = A[j + d, j]),
    ``c`` (n_sets, n). Cholesky factorisation column by column, vectorised over the sets
    (``scipy.linalg.cholesky_banded`` takes one matrix a call: a Python loop over thousands of
    sets costs a hundred times more); NaN where a matrix is not positive definite."""
    n_sets, nd, n = band.shape
    low = np.zeros_like(band)
    z = np.zeros((n_sets, n))
    with np.errstate(invalid="ignore", divide="ignore"):
        for j in range(n):
            diag = band[:, 0, j].copy()
            for k in range(1, min(nd, j + 1)):
                diag -= low[:, k, j - k] ** 2
            root = np.sqrt(diag)
            low[:, 0, j] = root
            for d in range(1, min(nd, n - j)):
                acc = band[:, d, j].copy()
                for k in range(1, nd - d):
                    if j - k < 0:
                        break
                    acc -= low[:, k + d, j - k] * low[:, k, j - k]
                low[:, d, j] = acc / root
            acc = c[:, j].copy()
            for k in range(1, min(nd, j + 1)):
                acc -= low[:, k, j - k] * z[:, j - k]
            z[:, j] = acc / root
        log_det = 2.0 * np.sum(np.log(low[:, 0, :]), axis=1)
    return log_det, np.sum(z * z, axis=1)


def _banded_solve_each(band: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_banded_solve` one matrix at a time by LAPACK (faster for a few sets)."""
    log_det = np.full(band.shape[0], np.nan)
    quad = np.full(band.shape[0], np.nan)
    for s in range(band.shape[0]):
        try:
            chol = cholesky_banded(band[s], lower=True, check_finite=False)
        except np.linalg.LinAlgError:
            continue
        log_det[s] = 2.0 * float(np.sum(np.log(chol[0])))
        quad[s] = float(c[s] @ cho_solve_banded((chol, True), c[s], check_finite=False))
    return log_det, quad


def _second_difference_band(n: int) -> np.ndarray:
    """DᵀD of the second-difference matrix D ((n − 2) × n), in lower banded form (3, n)."""
    d = np.zeros((n - 2, n))
    idx = np.arange(n - 2)
    d[idx, idx], d[idx, idx + 1], d[idx, idx + 2] = 1.0, -2.0, 1.0
    full = d.T @ d
    band = np.zeros((3, n))
    for j in range(3):
        band[j, :n - j] = np.diagonal(full, -j)
    return band


@dataclass(frozen=True, eq=False)
class SmoothMaster:
    """The shifts' likelihood under a smooth master function integrated out (see the module).

    Attributes
    ----------
    log_omega : ndarray
        log10 ω of every point of the joint data.
    point_isotherm : ndarray of int
        The isotherm of each point.
    y : ndarray, shape (2, n_points)
        ln of the storage and loss part of each point (NaN where a part is not positive, which
        then leaves that part of the point out).
    temperatures : tuple of float
        [°C], ascending.
    reference : int
        The isotherm whose shifts are 0.
    kind : {"modulus", "compliance"}
    vertical : {"none", "density", "free"}
    law : {"free", "wlf", "arrhenius"}
    reach : float
        Each free log10 a_T is uniform over ± this many decades.
    """

    log_omega: np.ndarray
    point_isotherm: np.ndarray
    y: np.ndarray
    temperatures: tuple[float, ...]
    reference: int
    kind: str = "modulus"
    vertical: str = "none"
    law: str = "free"
    reach: float = 15.0
    noise: str = "relative_parts"
    magnitude: np.ndarray | None = None

    @classmethod
    def of(cls, iso, vertical: str = "none", law: str = "free", reach: float = 15.0,
           noise: str = "relative_parts") -> SmoothMaster:
        """The model of checked isotherms (:class:`~bayesfo.tts.isotherms._Isotherms`)."""
        j = iso.joint
        sign = -1.0 if j.kind == "compliance" else 1.0  # J* = J′ − iJ″
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.log(np.vstack([j.response.real, sign * j.response.imag]))
        y[~np.isfinite(y)] = np.nan
        if noise not in NOISE:
            raise InputError(f"noise of the model-free master must be one of "
                             f"{', '.join(NOISE)}, got {noise!r}")
        return cls(np.log10(j.omega), iso.point_isotherm, y, iso.temperatures, iso.reference,
                   j.kind, vertical, law, reach, noise, np.log(np.abs(j.response)))

    # ------------------------------------------------------------------ parameters
    @property
    def shifted(self) -> tuple[int, ...]:
        return tuple(i for i in range(len(self.temperatures)) if i != self.reference)

    @cached_property
    def parameters(self) -> tuple[tuple[str, object], ...]:
        """(name, prior) of every parameter, in order: the horizontal shifts (or the law's
        constants), the free vertical shifts, then ρ and σ of each part."""
        temps = np.asarray(self.temperatures, float)
        t_ref = temps[self.reference]
        if self.law == "wlf":
            out = [("wlf_C1", Uniform(0.0, WLF_C1_MAX)),
                   ("wlf_C2", Uniform(max(t_ref - temps.min(), 0.0) + 1.0, WLF_C2_MAX))]
        elif self.law == "arrhenius":
            out = [("Ea", LogUniform(EA_MIN, EA_MAX))]
        elif self.law == "free":
            out = [(shift_name(self.temperatures[i]), Uniform(-self.reach, self.reach))
                   for i in self.shifted]
        else:
            raise InputError(f"law must be one of free, wlf, arrhenius, got {self.law!r}")
        if self.vertical == "free":
            out += [(shift_name(self.temperatures[i], "bT"),
                     Uniform(-VERTICAL_RANGE, VERTICAL_RANGE)) for i in self.shifted]
        out += [(f"smoothness_{p}", LogUniform(*SMOOTHNESS_RANGE)) for p in PARTS]
        out += [(f"sigma_{p}", LogUniform(*NOISE_RANGE)) for p in PARTS]
        return tuple(out)

    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(n for n, _ in self.parameters)

    @property
    def n_horizontal(self) -> int:
        return {"wlf": 2, "arrhenius": 1}.get(self.law, len(self.shifted))

    @cached_property
    def log_scale(self) -> np.ndarray:
        """Which parameters are sampled as logs (the log-uniform ones)."""
        return np.array([isinstance(p, LogUniform) for _, p in self.parameters])

    @cached_property
    def bounds(self) -> np.ndarray:
        """(n_params, 2) bounds in the sampling coordinates (logs of the log-uniform ones), in
        which every prior is uniform."""
        b = np.array([p.bounds for _, p in self.parameters], float)
        b[self.log_scale] = np.log(b[self.log_scale])
        return b

    @property
    def log_prior_volume(self) -> float:
        """ln of the prior support's volume in the sampling coordinates: the box, where free
        shifts are ordered (the a isotherms colder than the reference in (0, reach), the b
        warmer in (−reach, 0), each group in order: reach^a/a! · reach^b/b!)."""
        box = float(np.sum(np.log(np.diff(self.bounds, axis=1))))
        if self.law != "free":
            return box
        a = sum(1 for i in self.shifted if i < self.reference)
        b = len(self.shifted) - a
        return box - len(self.shifted) * math.log(2.0) - math.lgamma(a + 1) - math.lgamma(b + 1)

    def ordered(self, theta) -> np.ndarray:
        """Whether each set's shifts fall as the temperature rises (relaxation is slower the
        colder: log10 a_T strictly decreasing), part of the prior's support; always true of
        the laws (C1 > 0 and C2 above T_ref − T_min; E_a > 0)."""
        theta = np.atleast_2d(np.asarray(theta, float))
        if self.law != "free":
            return np.ones(theta.shape[0], bool)
        return np.all(np.diff(self.log_shifts(theta), axis=1) < 0, axis=1)

    def to_params(self, u) -> np.ndarray:
        u = np.asarray(u, float)
        return np.where(self.log_scale, np.exp(u), u)

    def to_u(self, theta) -> np.ndarray:
        theta = np.asarray(theta, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.log_scale, np.log(np.abs(theta)), theta)

    # ------------------------------------------------------------------ shifts
    def log_shifts(self, theta) -> np.ndarray:
        """log10 a_T of every isotherm (0 at the reference), shape (n_sets, n_isotherms)."""
        return log_shifts(theta, self.temperatures, self.reference, self.law, 0)

    def log_vertical(self, theta) -> np.ndarray:
        """log10 b_T of every isotherm (0 at the reference), shape (n_sets, n_isotherms)."""
        return log_vertical(theta, self.temperatures, self.reference, self.vertical,
                            self.n_horizontal)

    # ------------------------------------------------------------------ the spline
    @cached_property
    def _grid(self) -> tuple[float, int]:
        """(lowest knot, number of basis functions): knots over every reduced frequency that
        shifts within the prior reach, with three knot steps to spare at each end (where
        the cubic B-splines sum to one)."""
        lo = float(self.log_omega.min()) - self.reach - 1.0
        hi = float(self.log_omega.max()) + self.reach + 1.0
        return lo, int(math.ceil((hi - lo) / KNOT_STEP)) + 4

    @cached_property
    def _penalty(self) -> tuple[np.ndarray, np.ndarray]:
        """DᵀD in lower banded form and its eigenvalues (for ln|P|)."""
        band = _second_difference_band(self._grid[1])
        return band, np.clip(eigvals_banded(band, lower=True), 0.0, None)

    @cached_property
    def _penalty_dense(self) -> np.ndarray:
        """DᵀD as a dense matrix (for the gradient's traces)."""
        band = self._penalty[0]
        n = band.shape[1]
        out = np.zeros((n, n))
        for d in range(3):
            idx = np.arange(n - d)
            out[idx + d, idx] = out[idx, idx + d] = band[d, :n - d]
        return out

    @cached_property
    def _centred(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(the weight 1/κ of each part of each point, 0 where the part is left out; centred
        logs, 0 where left out; the level of each part; Σ ln κ of each part): the variance of
        a log is σ_p² κ, κ = 1 under ``relative_parts`` and |G|²/(2 G_p²) under
        ``proportional`` (complex noise of sd σ|G|, half on each part)."""
        ok = np.isfinite(self.y)
        level = np.array([np.mean(self.y[p, ok[p]]) for p in range(2)])
        r = np.where(ok, self.y - level[:, None], 0.0)
        if self.noise == "proportional":
            log_kappa = np.where(ok, 2.0 * (self.magnitude[None, :] - self.y) - math.log(2.0),
                                 0.0)
        else:
            log_kappa = np.zeros_like(r)
        weight = np.where(ok, np.exp(-log_kappa), 0.0)
        return weight, r, level, log_kappa.sum(axis=1)

    @cached_property
    def _kappa(self) -> np.ndarray:
        """κ of each part of each point (0 where the part is left out): the weights' inverse."""
        weight = self._centred[0]
        return np.where(weight > 0, 1.0 / np.where(weight > 0, weight, 1.0), 0.0)

    def _positions(self, theta):
        """Each point's reduced log10 ω and the vertical shift of its log (natural log), for
        parameter sets ``theta`` (n_sets, n_params)."""
        x = self.log_omega[None, :] + self.log_shifts(theta)[:, self.point_isotherm]
        v = self.log_vertical(theta)[:, self.point_isotherm] * math.log(10.0)
        return x, (v if self.kind == "modulus" else -v)

    def _normal_equations(self, x, v, p: int, rho, sigma):
        """For part ``p``: the lower band of A = P + BᵀB/σ² (n_sets, 4, n_basis), c = Bᵀr/σ²,
        r·r, the basis (first index and values at each point) and the centred data r."""
        lo, n_basis = self._grid
        weight, r0, *_ = self._centred
        n_sets = x.shape[0]
        k0, b = _basis(x, lo, n_basis)
        w = weight[p][None, :]
        r = r0[p][None, :] + v
        if self.noise == "proportional":
            # A part's relative error σ√κ is not small where the part is small against |G|:
            # the mean of its log lies σ²κ/2 below the log of its mean (to second order).
            r = r + 0.5 * (sigma ** 2)[:, None] * self._kappa[p][None, :]
        r = np.where(w > 0, r, 0.0)
        bw = b * w[..., None]
        flat = np.arange(n_sets)[:, None] * n_basis + k0
        size = n_sets * n_basis
        btb = np.zeros((4, size))
        btr = np.zeros(size)
        for a in range(4):
            idx = (flat + a).ravel()
            btr += np.bincount(idx, (bw[..., a] * r).ravel(), size)
            for d in range(4 - a):
                btb[d] += np.bincount(idx, (bw[..., a] * b[..., a + d]).ravel(), size)
        s2 = (sigma ** 2)[:, None, None]
        band = np.moveaxis(btb.reshape(4, n_sets, n_basis), 0, 1) / s2
        dtd, _ = self._penalty
        band[:, :3] += dtd[None] / (rho ** 2)[:, None, None]
        band[:, 0] += 1.0 / LEVEL_SD ** 2
        c = btr.reshape(n_sets, n_basis) / s2[:, :, 0]
        return band, c, np.sum(w * r * r, axis=1), k0, b, r

    def log_likelihood(self, theta) -> np.ndarray:
        """ln p(data | θ) with the master function integrated out, for parameter sets
        ``theta`` (n_sets, n_params) in natural units; −inf where a set is not finite, lies
        outside the prior's support (:meth:`ordered`) or shifts a point beyond the knots."""
        theta = np.atleast_2d(np.asarray(theta, float))
        out = np.full(theta.shape[0], -np.inf)
        rows = np.flatnonzero(np.all(np.isfinite(theta), axis=1) & self.ordered(theta))
        for chunk in np.array_split(rows, max(1, -(-rows.size // CHUNK))):
            if chunk.size:
                out[chunk] = self._log_likelihood(theta[chunk])
        return out

    def _log_likelihood(self, th) -> np.ndarray:
        lo, n_basis = self._grid
        x, v = self._positions(th)
        inside = np.all((x > lo + 3 * KNOT_STEP) & (x < lo + (n_basis - 3) * KNOT_STEP), axis=1)
        weight, _, _, log_kappa = self._centred
        _, eig = self._penalty
        m = th.shape[1]
        total = np.zeros(th.shape[0])
        for p in range(2):
            rho, sigma = th[:, m - 4 + p], th[:, m - 2 + p]
            band, c, rr, *_ = self._normal_equations(x, v, p, rho, sigma)
            log_det_a, quad = _banded_solve(band, c) if band.shape[0] > FEW else \
                _banded_solve_each(band, c)
            log_det_p = np.sum(np.log(eig[None, :] / (rho ** 2)[:, None]
                                      + 1.0 / LEVEL_SD ** 2), axis=1)
            n = int((weight[p] > 0).sum())
            total += (-0.5 * n * np.log(2.0 * math.pi * sigma ** 2) - 0.5 * log_kappa[p]
                      + 0.5 * log_det_p
                      - 0.5 * log_det_a - 0.5 * (rr / sigma ** 2 - quad))
        return np.where(inside & np.isfinite(total), total, -np.inf)

    def shift_information(self, theta) -> np.ndarray:
        """The information each isotherm's own points carry on its log10 a_T, with the noise
        of ``theta`` (one parameter set, natural units): Σ (∂ ln G_p/∂ log10 ω)² / (σ_p² κ)
        over its points and both parts, the slopes those of a quadratic in log10 ω fitted to
        the isotherm's own logs, less what the fit's noise adds on average (tr(C·DᵀWD), C the
        coefficients' covariance, D the slope's design); with free vertical shifts, what is
        left after its log10 b_T is fitted too (the Schur complement). Near 0 where the
        isotherm lies on a featureless stretch: its shift then rests on the smoothness prior's
        reach across the gap to its neighbours, not on its data."""
        th = np.atleast_2d(np.asarray(theta, float))[0]
        m = th.size
        weight, r, *_ = self._centred
        n_iso = len(self.temperatures)
        dv = math.log(10.0) * (1.0 if self.kind == "modulus" else -1.0)
        i_aa, i_ab, i_bb = np.zeros(n_iso), np.zeros(n_iso), np.zeros(n_iso)
        for i in range(n_iso):
            at = self.point_isotherm == i
            x = self.log_omega[at] - self.log_omega[at].mean()
            for p in range(2):
                w = weight[p][at] / th[m - 2 + p] ** 2
                if np.count_nonzero(w) < 4:
                    continue
                design = np.column_stack([np.ones_like(x), x, x * x])
                slope_design = np.column_stack([np.zeros_like(x), np.ones_like(x), 2 * x])
                precision = design.T @ (w[:, None] * design)
                try:
                    cov = np.linalg.inv(precision)
                except np.linalg.LinAlgError:
                    continue
                coef = cov @ (design.T @ (w * r[p][at]))
                slope = slope_design @ coef
                noise = float(np.trace(cov @ (slope_design.T @ (w[:, None] * slope_design))))
                i_aa[i] += max(float(w @ slope ** 2) - noise, 0.0)
                i_ab[i] += float(w @ slope) * dv
                i_bb[i] += float(w.sum()) * dv ** 2
        if self.vertical == "free":
            with np.errstate(divide="ignore", invalid="ignore"):
                return np.maximum(np.where(i_bb > 0, i_aa - i_ab ** 2 / i_bb, i_aa), 0.0)
        return i_aa

    def gradient(self, theta) -> tuple[float, np.ndarray]:
        """ln p(data | θ) and its gradient in the sampling coordinates (logs of the
        log-uniform parameters) at one parameter set, in closed form: the envelope theorem
        for the fitted coefficients β̂ = A⁻¹c and tr(A⁻¹ ∂A) for the determinant."""
        th = np.atleast_2d(np.asarray(theta, float))[:1]
        m = th.shape[1]
        grad = np.zeros(m)
        lo, n_basis = self._grid
        if not (np.all(np.isfinite(th)) and self.ordered(th)[0]):
            return -math.inf, grad
        x, v = self._positions(th)
        if not np.all((x > lo + 3 * KNOT_STEP) & (x < lo + (n_basis - 3) * KNOT_STEP)):
            return -math.inf, grad
        weight, _, _, log_kappa = self._centred
        dtd, eig = self._penalty
        pen = self._penalty_dense
        value = 0.0
        d_x = np.zeros(x.shape[1])   # ∂ ln p/∂x of each point
        d_v = np.zeros(x.shape[1])   # ∂ ln p/∂(vertical offset of its log)
        u = (x[0] - lo) / KNOT_STEP
        k0, b = _basis(x, lo, n_basis)
        k0, b = k0[0], b[0]
        t = np.clip(u - k0, 0.0, 1.0)
        db = np.stack([-3 * (1 - t) ** 2, 9 * t * t - 12 * t, -9 * t * t + 6 * t + 3,
                       3 * t * t], axis=-1) / (6.0 * KNOT_STEP)
        cols = k0[:, None] + np.arange(4)
        for p in range(2):
            rho, sigma = th[0, m - 4 + p], th[0, m - 2 + p]
            s2 = sigma ** 2
            band, c, rr, _, _, r = self._normal_equations(x, v, p, np.array([rho]),
                                                          np.array([sigma]))
            try:
                chol = cholesky_banded(band[0], lower=True, check_finite=False)
            except np.linalg.LinAlgError:
                return -math.inf, np.zeros(m)
            inv = cho_solve_banded((chol, True), np.eye(n_basis), check_finite=False)
            beta = inv @ c[0]
            w = weight[p]
            n = int((w > 0).sum())
            log_det_p = float(np.sum(np.log(eig / rho ** 2 + 1.0 / LEVEL_SD ** 2)))
            value += (-0.5 * n * math.log(2.0 * math.pi * s2) - 0.5 * log_kappa[p]
                      + 0.5 * log_det_p - float(np.sum(np.log(chol[0])))
                      - 0.5 * (float(rr[0]) / s2 - float(c[0] @ beta)))
            fitted = np.sum(b * beta[cols], axis=1)
            e = np.where(w > 0, r[0] - fitted, 0.0)
            slope = np.sum(db * beta[cols], axis=1)
            # B_n A⁻¹ B′_nᵀ of each point, from the 4 × 4 block of A⁻¹ at its knots.
            block = inv[cols[:, :, None], cols[:, None, :]]
            lever = np.einsum("na,nab,nb->n", b, block, db)
            d_x += w * (e * slope - lever) / s2
            d_v -= w * e / s2
            # Hyperparameters (derivatives in ln ρ and ln σ); tr(A⁻¹ BᵀB/σ²) from
            # tr(A⁻¹ A) = n_basis less the prior's share.
            tr_pen = float(np.sum(inv * pen))
            tr_data = n_basis - tr_pen / rho ** 2 - float(np.trace(inv)) / LEVEL_SD ** 2
            grad[m - 4 + p] = (-np.sum((eig / rho ** 2) / (eig / rho ** 2 + 1 / LEVEL_SD ** 2))
                               + (tr_pen + beta @ pen @ beta) / rho ** 2)
            grad[m - 2 + p] = -n + float(e @ (w * e)) / s2 + tr_data
            if self.noise == "proportional":  # the offset σ²κ/2 of each log moves with σ
                grad[m - 2 + p] -= float(e.sum())
        # Shifts: each point's x moves with its isotherm's log10 a_T; its log with log10 b_T.
        n_iso = len(self.temperatures)
        per_iso_x = np.bincount(self.point_isotherm, d_x, n_iso)
        per_iso_v = np.bincount(self.point_isotherm, d_v, n_iso) * math.log(10.0) \
            * (1.0 if self.kind == "modulus" else -1.0)
        temps = np.asarray(self.temperatures, float)
        t_ref = temps[self.reference]
        if self.law == "wlf":
            c1, c2 = th[0, 0], th[0, 1]
            dt = temps - t_ref
            grad[0] = per_iso_x @ (-dt / (c2 + dt))
            grad[1] = per_iso_x @ (c1 * dt / (c2 + dt) ** 2)
        elif self.law == "arrhenius":
            grad[0] = per_iso_x @ arrhenius(temps, t_ref, 1.0) * th[0, 0]
        else:
            grad[:len(self.shifted)] = per_iso_x[list(self.shifted)]
        if self.vertical == "free":
            k = self.n_horizontal
            grad[k:k + len(self.shifted)] = per_iso_v[list(self.shifted)]
        return value, grad
