"""A master function without a chosen structure: a discrete relaxation spectrum with a
smoothness prior.

G*(s) = G_e + Σ_k g_k sτ_k/(1 + sτ_k), with the relaxation times τ_k fixed, one per decade
(:data:`PER_DECADE`) from a decade below 1/ω_max to a decade above 1/ω_min of the reduced
window, and g_k, G_e ≥ 0: every such modulus is passive and stable. The parameters are
``G_e`` (log-uniform), ``ln_g_1`` (the log of the shortest mode's modulus, uniform) and the
steps ``dln_g_k`` = ln g_k − ln g_(k−1), each normal with sd :data:`SMOOTHING` (a random-walk
prior on ln g over the τ grid): the spectrum may rise or fall by about a decade per decade
of τ, as polymer spectra do through the transition zone, while wiggles from mode to mode are
penalised. It gives a master curve whose shifts do not hang on choosing a structure, and an
evidence beside the structures' (``bayesfo mastercurve --structures spectrum,...``).

The same object serves the sampler (in the likelihood's scaled units: τ_k ω_ref, moduli times
the transfer function's gain) and the predictions (physical units): :meth:`Spectrum.physical`
gives the latter from the former.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..errors import InputError
from ..priors import LogUniform, Normal, Uniform
from ..structures.parameters import Parameter, Parametrised

#: The structure name that stands for the spectrum in ``--structures``.
NAME = "spectrum"
#: Relaxation times per decade.
PER_DECADE = 1
#: Decades of relaxation times beyond the reduced window on each side.
MARGIN = 1
#: Prior sd of a step ln g_k − ln g_(k−1) between neighbouring modes (one decade per decade
#: of τ at one sd).
SMOOTHING = math.log(10.0)
#: Prior ranges (in the likelihood's scaled units, where the data's |G| is about 1).
G_E_RANGE = (1e-10, 1e4)
LN_G1_RANGE = (math.log(1e-10), math.log(1e6))


@dataclass(frozen=True, eq=False)
class Spectrum(Parametrised):
    """A discrete relaxation spectrum on fixed relaxation times (see the module).

    Attributes
    ----------
    tau : tuple of float
        The relaxation times, ascending (scaled or physical, as the object is used).
    """

    tau: tuple[float, ...]
    name: str = field(default=NAME)

    @classmethod
    def over(cls, omega_min: float, omega_max: float) -> Spectrum:
        """The spectrum for a (scaled) window of angular frequencies."""
        lo = math.log10(1.0 / omega_max) - MARGIN
        hi = math.log10(1.0 / omega_min) + MARGIN
        n = max(2, int(math.ceil((hi - lo) * PER_DECADE)) + 1)
        return cls(tuple(float(t) for t in np.logspace(lo, hi, n)))

    def physical(self, scaling) -> Spectrum:
        """The same spectrum in physical units (τ in s, moduli in the data's unit)."""
        return Spectrum(tuple(t / scaling.omega_ref for t in self.tau))

    def to_dict(self) -> dict:
        return {"tau_s": list(self.tau), "smoothing": SMOOTHING, "per_decade": PER_DECADE}

    # ------------------------------------------------------------------ the structure's face
    @cached_property
    def parameters(self) -> tuple:
        steps = tuple(Parameter(f"dln_g_{k + 1}", "coefficient", Normal(0.0, SMOOTHING))
                      for k in range(1, len(self.tau)))
        return (Parameter("G_e", "coefficient", LogUniform(*G_E_RANGE)),
                Parameter("ln_g_1", "coefficient", Uniform(*LN_G1_RANGE))) + steps

    fixed: dict = field(default_factory=dict, repr=False)
    inverted: bool = False
    commensurate_order = None
    integer = False

    def check_data(self, data) -> None:
        if data.kind not in ("modulus", "compliance"):
            raise InputError("a relaxation spectrum describes modulus or compliance data")
        if data.n_frequencies < self.n_params + 1:
            raise InputError(f"{data.n_frequencies} points for the {self.n_params} parameters "
                             "of the relaxation spectrum: too few")

    def with_priors(self, priors: dict) -> Spectrum:
        if priors:
            raise InputError("the relaxation spectrum's priors cannot be overridden")
        return self

    def equilibrium_modulus(self, theta) -> np.ndarray:
        """G_e = lim G(t) as t → ∞ of each parameter set (physical units): the spectrum's
        equilibrium modulus, every mode having relaxed."""
        return self.moduli(np.atleast_2d(np.asarray(theta, float)))[0]

    def moduli(self, theta) -> tuple[np.ndarray, np.ndarray]:
        """(G_e, g) of each parameter set: shapes (n_sets,) and (n_sets, n_tau)."""
        theta = np.atleast_2d(np.asarray(theta, float))
        with np.errstate(over="ignore"):
            g = np.exp(theta[:, 1:2] + np.cumsum(
                np.column_stack([np.zeros(theta.shape[0]), theta[:, 2:]]), axis=1))
        return theta[:, 0], g

    def laplace(self, theta, s, *, per_set: bool = False) -> np.ndarray:
        """The compliance 1/G*(s) at complex ``s`` (any shape), as a card's transfer function
        (with ``per_set``, row i of ``s`` belongs to parameter set i)."""
        single = np.ndim(theta) == 1
        g_e, g = self.moduli(theta)
        s = np.asarray(s, dtype=complex)
        tau = np.asarray(self.tau)
        if per_set and not np.any(s.real):
            # On the imaginary axis (the likelihood's path) in real arithmetic:
            # iy/(1 + iy) = 1 − d + i y d with y = ωτ and d = 1/(1 + y²), summed over the
            # modes by einsum.
            y = s.imag.reshape(s.shape[0], -1)[..., None] * tau
            d = 1.0 / (1.0 + y * y)
            real = np.sum(g, axis=1)[:, None] - np.einsum("npk,nk->np", d, g)
            imag = np.einsum("npk,nk->np", y * d, g)
            modulus = (g_e[:, None] + real + 1j * imag).reshape(s.shape)
        elif per_set:
            extra = (1,) * (s.ndim - 1)
            st = s[..., None] * tau
            modes = np.sum(g.reshape(g.shape[0], *extra, -1) * st / (1.0 + st), axis=-1)
            modulus = g_e.reshape(-1, *extra) + modes
        else:
            st = s[..., None] * tau
            modes = np.tensordot(g, np.moveaxis(st / (1.0 + st), -1, 0), axes=(1, 0))
            modulus = g_e.reshape(-1, *(1,) * s.ndim) + modes
        with np.errstate(divide="ignore", invalid="ignore"):
            out = 1.0 / modulus
        return out[0] if single and not per_set else out

    def response(self, theta, omega, kind: str = "compliance") -> np.ndarray:
        c = self.laplace(theta, 1j * np.asarray(omega, float))
        if kind == "modulus":
            with np.errstate(divide="ignore", invalid="ignore"):
                return 1.0 / c
        return c

    def constraints_hold(self, theta, kind: str, omega_grid=None, where=None) -> np.ndarray:
        """Always: non-negative moduli on real relaxation times are passive and stable."""
        n = np.atleast_2d(np.asarray(theta, float)).shape[0]
        return np.ones(n, dtype=bool)

    def admissible(self, theta, kind: str, omega_grid=None) -> np.ndarray:
        return self.in_support(theta)

    def _convert(self, theta, scaling, to_physical: bool) -> np.ndarray:
        theta2 = np.atleast_2d(np.asarray(theta, float)).copy()
        # Scaled moduli are the physical ones times the transfer function's gain (the
        # reciprocal of the data's reference magnitude for modulus data).
        gain = scaling.tf_gain if to_physical else 1.0 / scaling.tf_gain
        theta2[:, 0] = theta2[:, 0] / gain
        theta2[:, 1] = theta2[:, 1] - math.log(gain)
        return theta2 if np.ndim(theta) == 2 else theta2[0]

    def to_physical(self, theta, scaling) -> np.ndarray:
        return self._convert(theta, scaling, True)

    def to_scaled(self, theta, scaling) -> np.ndarray:
        return self._convert(theta, scaling, False)

    def seed(self, data) -> np.ndarray:
        """Parameters from non-negative least squares of G′, G″ (relative residuals) on the
        τ grid: a start for the joint fit, in the units of ``data`` and the grid."""
        from scipy.optimize import nnls

        g = data.response if data.kind == "modulus" else 1.0 / data.response
        st = 1j * data.omega[:, None] * np.asarray(self.tau)
        basis = np.column_stack([np.ones(data.n_frequencies), st / (1.0 + st)])
        w = 1.0 / np.abs(g)
        a = np.vstack([basis.real * w[:, None], basis.imag * w[:, None]])
        x, _ = nnls(a, np.r_[g.real * w, g.imag * w], maxiter=50 * a.shape[1])
        top = max(float(x[1:].max()), 1e-300)
        g_k = np.maximum(x[1:], 1e-4 * top)  # a mode fitted to 0 is a small one, not ln 0
        lo, hi = G_E_RANGE
        g_e = float(np.clip(max(x[0], 1e-6 * top), lo * 1.001, hi / 1.001))
        ln_g = np.log(g_k)
        steps = np.clip(np.diff(ln_g), -4 * SMOOTHING, 4 * SMOOTHING)
        first = float(np.clip(ln_g[0], LN_G1_RANGE[0] + 1e-3, LN_G1_RANGE[1] - 1e-3))
        return np.r_[g_e, first, steps]
