"""Units of a structure's coefficients: the scaling between physical units and the scaled
problem (ω/ω_ref, G/g_ref), and the unit of each coefficient that follows from it.

Every coefficient p of a card has a unit s^t · C^(-g), C the unit of the transfer function (a
compliance for material structures), with t = t0 + Σ_j t_j x_j linear in the exponent
parameters x_j. Scaling multiplies p by ω_ref^t · c_ref^g (c_ref the reference magnitude of the
transfer function). t and g follow from the terms: every term c_k s^(e_k) of a side must scale
like that side, so for each term Σ_i n_ki log φ_i = e_k log ω_ref + L − [numerator] log c_ref
with n_ki the power of parameter i in the coefficient and L a free constant common to both
sides. This linear system is solved once per structure; a card whose terms cannot be scaled
consistently (a coefficient with two different units) is rejected.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import StructureError


@dataclass(frozen=True)
class Scaling:
    """Reference values that make the fitted quantities of order one.

    Attributes
    ----------
    omega_ref : float
        ω_ref [rad/s], the geometric mean of the measured frequencies.
    g_ref : float
        g_ref, the median of |G| of the data.
    reciprocal : bool
        True when the structure's transfer function is compared with the reciprocal of the data
        (material structures against modulus data); then the transfer function scales with
        1/g_ref.
    """

    omega_ref: float = 1.0
    g_ref: float = 1.0
    reciprocal: bool = False

    @classmethod
    def from_data(cls, data) -> Scaling:
        """Scaling for a :class:`~bayesfo.data.FrequencyResponse` (its kind sets ``reciprocal``)."""
        return cls(data.omega_ref, data.g_ref, data.kind == "modulus")

    @property
    def tf_gain(self) -> float:
        """The reference magnitude of the structure's transfer function."""
        return 1.0 / self.g_ref if self.reciprocal else self.g_ref


@dataclass(frozen=True)
class ScalePlan:
    """Per free coefficient: its column in θ, its time exponent ``t0 + Σ t[j]·x_j`` (x_j the
    exponent parameters ``expo``) and its power ``g`` of the transfer function's gain."""

    columns: tuple[int, ...]
    names: tuple[str, ...]
    expo: tuple[str, ...]
    t0: np.ndarray
    t: np.ndarray  # (n_coef, n_expo)
    g: np.ndarray

    def factors(self, theta2: np.ndarray, vals: dict, scaling: Scaling) -> np.ndarray:
        """Multipliers physical → scaled, shape of ``theta2``."""
        out = np.ones_like(theta2)
        log_w = math.log(scaling.omega_ref)
        log_g = math.log(scaling.tf_gain)
        for i, col in enumerate(self.columns):
            time = self.t0[i] + sum(self.t[i, j] * vals[x] for j, x in enumerate(self.expo))
            out[:, col] = np.exp(time * log_w + self.g[i] * log_g)
        return out

    def time_exponent(self, name: str) -> tuple[float, dict[str, float]]:
        """``(t0, {x_j: t_j})`` of coefficient ``name``."""
        i = self.names.index(name)
        return float(self.t0[i]), {x: float(self.t[i, j]) for j, x in enumerate(self.expo)
                                   if abs(self.t[i, j]) > 1e-12}


def _clean(x: np.ndarray) -> np.ndarray:
    """Round the solution to the multiples of 1/1000 that exact arithmetic would give."""
    r = np.round(x * 1000.0) / 1000.0
    return np.where(np.abs(x - r) < 1e-9, r, x)


def scale_plan(structure) -> ScalePlan:
    """Solve the unit equations of ``structure`` (see the module docstring).

    Raises
    ------
    StructureError
        If the coefficients cannot be given units consistently, or not uniquely.
    """
    s = structure
    expo_names = set(s.exponent_params)
    coef_names = [n for n in s.param_names if n not in expo_names]
    expo = tuple(sorted(expo_names))
    terms = [(t, True) for t in s.numerator] + [(t, False) for t in s.denominator]
    n, m = len(coef_names), len(terms)
    a = np.zeros((m, n + 1))
    rhs = np.zeros((m, 2 + len(expo)))  # columns: constant, gain, one per exponent parameter
    for k, (t, in_num) in enumerate(terms):
        for f in t.factors:
            if f in coef_names:
                a[k, coef_names.index(f)] += 1.0
        a[k, n] = -1.0
        rhs[k, 0] = t.exponent.constant
        rhs[k, 1] = -1.0 if in_num else 0.0
        for p, mult in t.exponent.coefs:
            if p in expo:
                rhs[k, 2 + expo.index(p)] += mult
            # a fixed exponent parameter is a number: fold it into the constant
            elif p in s.fixed:
                rhs[k, 0] += mult * float(s.fixed[p])
    where = f"structure '{s.name}'" + (f" (card {s.card})" if s.card else "")
    num_free = all(t.is_free for t in s.numerator)
    den_free = all(t.is_free for t in s.denominator)
    if not (num_free or den_free or not s.parameters):
        raise StructureError(
            f"{where}: one side of the transfer function must have only free "
            "coefficients, so that the magnitude of the data can be scaled"
        )
    if n == 0:
        return ScalePlan((), (), expo, np.zeros(0), np.zeros((0, len(expo))), np.zeros(0))
    if np.linalg.matrix_rank(a) < n + 1:
        # The two sides can be multiplied by one factor: fix it as the thesis does, with the
        # gain on the side whose coefficients are all free.
        row = np.zeros((1, n + 1))
        row[0, n] = 1.0
        extra = np.zeros((1, rhs.shape[1]))
        extra[0, 1] = 0.0 if num_free else 1.0
        a, rhs = np.vstack([a, row]), np.vstack([rhs, extra])
        if np.linalg.matrix_rank(a) < n + 1:
            raise StructureError(
                f"{where}: the units of the coefficients are not determined by the terms; "
                "each coefficient must appear in a term of its own or in products that fix it"
            )
    x, *_ = np.linalg.lstsq(a, rhs, rcond=None)
    if not np.allclose(a @ x, rhs, atol=1e-9):
        raise StructureError(
            f"{where}: the coefficients cannot be given consistent units: every term of a side "
            "must have the unit of that side (check products and exponents of the terms)"
        )
    x = _clean(x)
    columns = tuple(s.param_names.index(c) for c in coef_names)
    return ScalePlan(columns, tuple(coef_names), expo, x[:n, 0], x[:n, 2:], x[:n, 1])
