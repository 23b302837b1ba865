"""Are the measured real and imaginary parts consistent with each other? A linear
Kramers–Kronig test, before any model is fitted.

A causal linear response is fixed by either of its parts (the Kramers–Kronig relations): one
set of coefficients of a causal basis must describe both. The basis is a Maxwell one for a
modulus, G_e + Σ g_k iωτ_k/(1 + iωτ_k) + iω η, and a Voigt one for a compliance or any other
transfer function, J_g + Σ j_k/(1 + iωτ_k) + 1/(iω η), with the τ_k two per decade (fewer
where the data have few points, but one per decade where they allow: :func:`kramers_kronig`)
from a decade beyond the highest frequency to a decade beyond the lowest (Boukamp 1995; Schönleber, Klotz & Ivers-Tiffée 2014, whose linear test on a Voigt
basis this follows).

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


def kramers_kronig(data, *, per_decade: int = 2) -> KramersKronig:
    """The linear Kramers–Kronig test of a :class:`~bayesfo.data.FrequencyResponse`.

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
    n_tau = int(round((hi - lo + 2) * per_decade)) + 1
    # The separate fits of the two parts (2·n_tau + 3 coefficients) must leave at least half
    # of the 2n numbers as degrees of freedom, or they interpolate the data and the test
    # compares the tied fit with nothing; but on sparse data that leaves fewer elements than
    # decades of τ, too few for a continuous spectrum, and the tied fit misses consistent data
    # (12 points over 3.5 decades: 4 elements over 5.5 decades, F = 8.6). So at least one
    # element per decade where 5 degrees of freedom remain (n − 4 elements at most): false
    # alarms on sparse fractional data 2.3 % at most, from 4.7 %, with twice the power
    # (BENCHMARKS.md, "Kramers–Kronig basis on sparse data").
    per_decade_floor = min(n - 4, math.ceil(hi - lo + 2) + 1)
    n_tau = min(n_tau, max((n - 3) // 2, per_decade_floor))
    if n_tau < 2:
        raise InputError(f"{data.where()}: {n} frequencies; the Kramers–Kronig test needs 5 "
                         "or more")
    tau = np.logspace(-hi - 1, -lo + 1, n_tau)
    a = _basis(omega, tau, data.kind)
    noise = "given" if data.sigma is not None else "estimated"
    w = 1.0 / (np.asarray(data.sigma, float)[order] if data.sigma is not None else np.abs(g))
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
    d1, d2 = p_free - p_tied, max(2 * n - p_free, 1)
    rss_tied, rss_free = float(r_tied @ r_tied), float(r_free @ r_free)
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
