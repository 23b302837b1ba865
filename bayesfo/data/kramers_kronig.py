"""Are the measured real and imaginary parts consistent with each other? A linear
Kramers–Kronig test, before any model is fitted.

A causal linear response is fixed by either of its parts (the Kramers–Kronig relations): one
set of coefficients of a causal basis must describe both. The basis is a Maxwell one for a
modulus, G_e + Σ g_k iωτ_k/(1 + iωτ_k) + iω η, and a Voigt one for a compliance or any other
transfer function, J_g + Σ j_k/(1 + iωτ_k) + 1/(iω η), with the τ_k log-spaced from a decade
beyond the highest frequency to a decade beyond the lowest (Boukamp 1995; Schönleber, Klotz &
Ivers-Tiffée 2014, whose linear test on a Voigt basis this follows). Their number is two per
decade where the data have points enough, and more where lin-KK's over-fitting criterion allows
(as many as the tied fit takes before its masses begin to alternate in sign: :func:`sign_balance`,
:func:`kramers_kronig`).

The test compares two fits of the same basis: tied (one set of coefficients for both parts,
what causality demands) and free (each part its own), by the F statistic of the extra sum of
squares, (ΔRSS/Δp)/(RSS_free/ν), weighted by 1/σ where the data give σ, else by 1/|G|
(proportional noise, whose level cancels in the ratio). For consistent data F follows the F
distribution (about 1); ``consistent`` is F below its 1 − :data:`FALSE_ALARM` quantile. The
false-alarm rate and the power against parts of different responses are measured by
simulation in ``benchmarks/bench_kramers_kronig.py`` (figures in BENCHMARKS.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

#: The test's false-alarm rate on consistent data where the basis represents them.
FALSE_ALARM = 0.01
#: lin-KK's over-fitting bound on μ (Schönleber et al. 2014): more elements are added while
#: the tied fit's masses keep μ at or above it (:func:`sign_balance`).
MU_OVERFIT = 0.85
#: The frequencies reported as the worst.
N_WORST = 3


@dataclass(frozen=True)
class KramersKronig:
    """The result of :func:`kramers_kronig`.

    Attributes
    ----------
    consistent : bool
    chi2_per_dof : float
        The F statistic of the tied fit against the free one (about 1 for consistent data).
    worst_frequencies : tuple of float
        Angular frequencies [rad/s] of the largest residuals of the tied fit.
    residuals : ndarray of complex
        The tied fit's residuals of the real and imaginary parts, in units of the free fit's
        scatter.
    noise : str
        ``"given"`` (σ of the data) or ``"estimated"`` (from a fit of both parts).
    n_elements : int
    misfit_rms, misfit_max : float
        How far the tied (causal) fit lies from the data: the root mean square and the largest
        of |G_fit − G|/|G| over the frequencies. The test says whether an inconsistency is
        beyond the data's scatter; these say how large it is (a structure that misfits by less
        may be limited by the data, not by its form).
    """

    consistent: bool
    chi2_per_dof: float
    worst_frequencies: tuple[float, ...]
    residuals: np.ndarray
    noise: str
    n_elements: int
    misfit_rms: float = math.nan
    misfit_max: float = math.nan

    def to_dict(self) -> dict:
        """The ``kramers_kronig`` block of ``summary.json`` and ``bayesfo inspect --json``."""
        return {"consistent": bool(self.consistent),
                "chi2_per_dof": float(self.chi2_per_dof),
                "worst_frequencies": [float(w) for w in self.worst_frequencies],
                "noise": self.noise, "n_elements": int(self.n_elements),
                "misfit_rms": float(self.misfit_rms), "misfit_max": float(self.misfit_max)}

    def describe(self) -> str:
        """The result in words (the verdict's sentence where the parts are not consistent)."""
        worst = ", ".join(f"{w:.4g}" for w in self.worst_frequencies)
        if self.consistent:
            return (f"the real and imaginary parts are consistent by the Kramers–Kronig "
                    f"relations (F = {self.chi2_per_dof:.2f})")
        return (f"the real and imaginary parts are not consistent by the Kramers–Kronig "
                f"relations beyond their scatter (F = {self.chi2_per_dof:.3g}, most at omega = "
                f"{worst} rad/s): the best causal description misses them by "
                f"{100 * self.misfit_rms:.2g} % rms ({100 * self.misfit_max:.2g} % at most), so "
                "a structure's misfit of that size may be the data's (an instrument artefact "
                "such as inertia or compliance, parts from different measurements, or isotherms "
                "that do not superpose)")


def _basis(omega: np.ndarray, tau: np.ndarray, kind: str) -> np.ndarray:
    """Columns of the causal basis (complex), constant first, the viscous term last."""
    s = 1j * omega[:, None] * tau[None, :]
    if kind == "modulus":
        cols = [np.ones(omega.size), *(s / (1 + s)).T, 1j * omega]
    else:
        cols = [np.ones(omega.size), *(1 / (1 + s)).T, 1 / (1j * omega)]
    return np.column_stack(cols)


def _fit(omega, g, w, kind, tau):
    """The tied and free fits on the basis of time constants ``tau``, weighted by ``w``.

    Returns the tied fit's coefficients and residuals, the two residual sums of squares and
    the F statistic's degrees of freedom.
    """
    n = omega.size
    a = _basis(omega, tau, kind)
    y = np.r_[g.real * w, g.imag * w]
    # Tied: one set of coefficients for both parts (what causality demands).
    tied = np.vstack([a.real * w[:, None], a.imag * w[:, None]])
    c_tied, *_ = np.linalg.lstsq(tied, y, rcond=None)
    r_tied = tied @ c_tied - y
    # Free: each part its own coefficients (the constant only in the real part).
    re_cols, im_cols = a.real * w[:, None], a.imag[:, 1:] * w[:, None]
    c_re, *_ = np.linalg.lstsq(re_cols, g.real * w, rcond=None)
    c_im, *_ = np.linalg.lstsq(im_cols, g.imag * w, rcond=None)
    r_free = np.r_[re_cols @ c_re - g.real * w, im_cols @ c_im - g.imag * w]
    p_tied, p_free = a.shape[1], 2 * a.shape[1] - 1
    return (a, c_tied, r_tied, float(r_tied @ r_tied), float(r_free @ r_free),
            p_free - p_tied, max(2 * n - p_free, 1))


def sign_balance(masses: np.ndarray) -> float:
    """Schönleber's μ for a spectrum of either sign: 1 − (mass of the minority sign)/(mass of
    the majority sign).

    lin-KK's μ = 1 − Σ|negative masses|/Σ positive masses is near 1 while the basis follows the
    data and falls as the elements begin to fit the noise with alternating signs (Schönleber,
    Klotz & Ivers-Tiffée 2014, who take the first number of elements with μ < 0.85). Taking
    the majority's sign instead of the positive one keeps μ near 1 for a spectrum that is
    negative throughout (an integrator with a lag, 1/(s(1 + Ts)) = 1/s − T/(1 + Ts), whose
    one relaxation has a negative mass), where lin-KK's μ would call every basis over-fitted.
    """
    pos, neg = float(masses[masses > 0].sum()), float(-masses[masses < 0].sum())
    big = max(pos, neg)
    return 1.0 - min(pos, neg) / big if big > 0 else 1.0


def kramers_kronig(data) -> KramersKronig:
    """The linear Kramers–Kronig test of a :class:`~bayesfo.data.FrequencyResponse`.

    The number of elements is the larger of two counts: two per decade of τ, capped at
    (n − 3)//2 but at least one per decade where n − 4 allow; and lin-KK's, by its
    over-fitting criterion (Schönleber et al. 2014) with the sign taken from the spectrum
    (:func:`sign_balance`): from one element per decade, more while the tied fit's masses keep
    μ ≥ :data:`MU_OVERFIT`, at most n − 4 (5 degrees of freedom left to the free fit); where
    μ is below the bound already at one per decade, that count.

    Raises
    ------
    InputError
        With too few frequencies for the basis.
    """
    from scipy.special import fdtri  # scipy.stats.f.ppf itself, without importing scipy.stats

    omega = np.asarray(data.omega, float)
    g = np.asarray(data.response, complex)
    n = omega.size
    order = np.argsort(omega)
    omega, g = omega[order], g[order]
    lo, hi = math.log10(omega[0]), math.log10(omega[-1])
    # The count: two per decade of τ, capped at (n − 3)//2 (half the 2n numbers left to the
    # free fit) but at least one per decade where n − 4 allow, raised to lin-KK's count where
    # that is larger. The cap alone left 12 points over 3.5 decades 4 elements over 5.5
    # decades of τ (a consistent fractional Voigt, F = 8.6); one per decade still misses a
    # single discrete relaxation between two elements (the dashpot's 1/(s(1 + 0.19 s)): 6
    # elements over 4.5 decades leave a 3 % approximation error beside 3 % noise, F = 12.6);
    # two per decade everywhere flagged 16 of the 20 adhesive isotherms, and lin-KK's count
    # alone stops early on dense data (μ dips at 7 elements on a Zener, false alarms 13 %).
    # Together: false alarms on sparse consistent data, fractional and discrete, 0.5 % and 0 %
    # (from 1.2 % and 7 %) at the same power; dense data and the isotherms as before
    # (BENCHMARKS.md, "Kramers–Kronig basis on sparse data").
    first = min(n - 4, math.ceil(hi - lo + 2) + 1)
    if first < 2:
        raise InputError(f"{data.where()}: {n} frequencies; the Kramers–Kronig test needs 6 "
                         "or more")
    capped = min(int(round((hi - lo + 2) * 2)) + 1, max((n - 3) // 2, first))
    noise = "given" if data.sigma is not None else "estimated"
    w = 1.0 / (np.asarray(data.sigma, float)[order] if data.sigma is not None else np.abs(g))
    fits = {}
    for n_tau in range(first, n - 3):
        fits[n_tau] = _fit(omega, g, w, data.kind, np.logspace(-hi - 1, -lo + 1, n_tau))
        if sign_balance(fits[n_tau][1][1:-1]) < MU_OVERFIT:
            if n_tau > first:  # over-fitted: the count before (one per decade at least)
                del fits[n_tau]
            break
    n_tau = max(max(fits), capped)
    tau = np.logspace(-hi - 1, -lo + 1, n_tau)
    a, c_tied, r_tied, rss_tied, rss_free, d1, d2 = (
        fits[n_tau] if n_tau in fits else _fit(omega, g, w, data.kind, tau))
    f = ((rss_tied - rss_free) / d1) / max(rss_free / d2, 1e-300)
    threshold = float(fdtri(d1, d2, 1 - FALSE_ALARM))
    per_point = r_tied[:n] ** 2 + r_tied[n:] ** 2
    worst = np.argsort(-per_point)[:N_WORST]
    residuals = np.empty(n, complex)
    scale = math.sqrt(rss_free / d2) if rss_free > 0 else 1.0
    residuals[order] = (r_tied[:n] + 1j * r_tied[n:]) / scale
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.abs(a @ c_tied - g) / np.abs(g)
    return KramersKronig(consistent=bool(f < threshold), chi2_per_dof=float(f),
                         worst_frequencies=tuple(float(omega[k]) for k in sorted(worst)),
                         residuals=residuals, noise=noise, n_elements=int(tau.size),
                         misfit_rms=float(np.sqrt(np.mean(rel**2))), misfit_max=float(rel.max()))
