"""A structure: the transfer function of a card with its parameters and priors, evaluated
vectorised over parameter sets, with its constraints (stability, dissipation, inequalities)
and the scaling between physical units and the scaled problem."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from .._io import show
from ..errors import StructureError
from ..priors import Prior
from ..response import (
    commensurate_response,
    dissipation_grid,
    is_dissipative,
    matignon_stable,
    power_ratio,
)
from .terms import Exponent, Inequality, Term


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
class Parameter:
    """A free parameter: its name, its role (``coefficient`` or ``exponent``) and its prior."""

    name: str
    role: str
    prior: Prior


@dataclass(frozen=True, eq=False)
class Structure:
    """A transfer-function structure with priors and constraints.

    Build structures from cards (:func:`load_library`, :func:`get_structure`) rather than by
    hand. Arrays of parameters have shape ``(n_params,)`` or ``(n_sets, n_params)`` with the
    columns in the order of :attr:`param_names`; the results then have shape ``(n_freq,)`` or
    ``(n_sets, n_freq)``.

    Examples
    --------
    >>> import numpy as np
    >>> voigt = get_structure("voigt")
    >>> voigt.param_names
    ('a1', 'b0', 'q')
    >>> g = voigt.transfer([1.0, 2.0, 0.5], np.array([1.0]))
    >>> bool(np.isclose(g[0], 2.0 / (1 + np.sqrt(1j))))
    True
    """

    name: str
    numerator: tuple[Term, ...]
    denominator: tuple[Term, ...]
    parameters: tuple[Parameter, ...]
    fixed: dict = field(default_factory=dict)
    constraints: tuple = ()
    title: str = ""
    description: str = ""
    reference: str = ""
    family: str = ""
    inverted: bool = False
    integer: bool = False
    degrees: tuple[int, int] | None = None  # (n, m) of A and B before any inversion
    card: str = ""

    def __post_init__(self):
        self._validate()

    # ------------------------------------------------------------------ introspection
    @property
    def param_names(self) -> tuple[str, ...]:
        """Names of the free parameters, in the column order of ``theta``."""
        return tuple(p.name for p in self.parameters)

    @property
    def n_params(self) -> int:
        """Number of free parameters (without noise parameters)."""
        return len(self.parameters)

    @property
    def priors(self) -> dict[str, Prior]:
        return {p.name: p.prior for p in self.parameters}

    @property
    def exponent_params(self) -> tuple[str, ...]:
        names = {t.exponent.param for t in self.numerator + self.denominator if t.exponent.param}
        return tuple(sorted(names))

    @property
    def commensurate_order(self) -> str | None:
        """The name of q when numerator and denominator are polynomials in λ = s^q, else None."""
        p = _polynomial_order(self.numerator + self.denominator)
        return p if p != "" else None

    @property
    def formula(self) -> str:
        """The transfer function as text, e.g. ``b0 / (1 + a1 s^q)``."""

        def fix(t):
            e = t.exponent
            if e.param in self.fixed:
                return Term(t.coef, Exponent(e.multiple * float(self.fixed[e.param])))
            return t

        def side(terms):
            text = " + ".join(str(fix(t)) for t in terms)
            return f"({text})" if len(terms) > 1 else text

        return f"{side(self.numerator)} / {side(self.denominator)}"

    def describe(self) -> dict:
        """Plain-Python description (name, formula, priors, constraints) for reports."""
        return {
            "name": self.name,
            "family": self.family,
            "formula": self.formula,
            "inverted": self.inverted,
            "integer": self.integer,
            "n_params": self.n_params,
            "parameters": {p.name: p.prior.to_dict() for p in self.parameters},
            "fixed": dict(self.fixed),
            "constraints": [c if isinstance(c, str) else c.text for c in self.constraints],
            "title": self.title,
            "reference": self.reference,
        }

    def with_priors(self, priors: dict[str, Prior]) -> Structure:
        """A copy with some priors replaced (``{name: Prior}``)."""
        unknown = [k for k in priors if k not in self.param_names]
        if unknown:
            raise StructureError(
                f"structure '{self.name}' has no parameter {show(str(unknown[0]))}; "
                f"its parameters are {', '.join(self.param_names)}"
            )
        params = tuple(
            replace(p, prior=priors[p.name]) if p.name in priors else p for p in self.parameters
        )
        return replace(self, parameters=params)

    def check_data(self, data) -> None:
        """Raise :class:`~bayesfo.errors.InputError` if ``data`` has fewer points than parameters."""
        data.check_enough_points(self.n_params, f"structure '{self.name}'")

    # ------------------------------------------------------------------ evaluation
    def values(self, theta) -> tuple[dict[str, np.ndarray], bool]:
        """Map ``theta`` to ``{name: column}`` including fixed parameters; flag a single set."""
        theta = np.asarray(theta, dtype=float)
        single = theta.ndim == 1
        theta2 = np.atleast_2d(theta)
        if theta2.ndim != 2 or theta2.shape[1] != self.n_params:
            raise StructureError(
                f"structure '{self.name}' takes {self.n_params} parameters "
                f"({', '.join(self.param_names)}); got an array of shape {theta.shape}"
            )
        vals = {name: theta2[:, i] for i, name in enumerate(self.param_names)}
        for name, v in self.fixed.items():
            vals[name] = np.full(theta2.shape[0], float(v))
        return vals, single

    def _side_arrays(self, terms, vals, n_sets):
        coef = np.empty((n_sets, len(terms)))
        expo = np.empty((n_sets, len(terms)))
        for i, t in enumerate(terms):
            coef[:, i] = vals[t.coef] if t.is_free else t.coef
            e = t.exponent
            expo[:, i] = e.multiple * vals[e.param] if e.param else e.multiple
        return coef, expo

    def _polynomial(self, terms, vals, n_sets):
        """Ascending coefficients of a side that is a polynomial in λ = s^q."""
        degree = max(int(round(t.exponent.multiple)) if t.exponent.param else 0 for t in terms)
        out = np.zeros((n_sets, degree + 1))
        for t in terms:
            k = int(round(t.exponent.multiple)) if t.exponent.param else 0
            out[:, k] += vals[t.coef] if t.is_free else t.coef
        return out

    def polynomials(self, theta):
        """Pseudo-polynomial coefficients of a commensurate structure.

        Returns
        -------
        den, num : ndarray, shapes (n_sets, n+1) and (n_sets, m+1)
            Ascending coefficients of A(λ) (denominator) and B(λ) (numerator), λ = s^q.
        q : ndarray, shape (n_sets,)
        """
        p = self.commensurate_order
        if p is None:
            raise StructureError(f"structure '{self.name}' is not of commensurate order")
        vals, _ = self.values(theta)
        n_sets = next(iter(vals.values())).shape[0] if vals else 1
        return (
            self._polynomial(self.denominator, vals, n_sets),
            self._polynomial(self.numerator, vals, n_sets),
            vals[p],
        )

    def transfer(self, theta, omega) -> np.ndarray:
        """The transfer function as written in the card (with inversion for ``-inv``).

        Parameters
        ----------
        theta : array_like, shape (n_params,) or (n_sets, n_params)
        omega : array_like, shape (n_freq,)
            Angular frequencies, in the units matching ``theta`` (scaled or physical).

        Returns
        -------
        ndarray of complex, shape (n_freq,) or (n_sets, n_freq)
        """
        omega = np.asarray(omega, dtype=float)
        vals, single = self.values(theta)
        n_sets = np.atleast_2d(np.asarray(theta, float)).shape[0]
        p = self.commensurate_order
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            if p is not None:
                out = commensurate_response(
                    omega,
                    self._polynomial(self.denominator, vals, n_sets),
                    self._polynomial(self.numerator, vals, n_sets),
                    vals[p],
                )
            else:
                nc, ne = self._side_arrays(self.numerator, vals, n_sets)
                dc, de = self._side_arrays(self.denominator, vals, n_sets)
                out = power_ratio(omega, nc, ne, dc, de)
        return out[0] if single else out

    def power_terms(self, theta) -> tuple[list[tuple[float, float]], list[tuple[float, float]]]:
        """(coefficient, exponent) pairs of numerator and denominator for one parameter set,
        as :func:`bayesfo.timedomain.simulate` takes them."""
        theta = np.asarray(theta, dtype=float)
        if theta.ndim != 1:
            raise StructureError(f"power_terms takes one parameter set, got shape {theta.shape}")
        vals, _ = self.values(theta)
        sides = []
        for terms in (self.numerator, self.denominator):
            coef, expo = self._side_arrays(terms, vals, 1)
            sides.append([(float(c), float(e)) for c, e in zip(coef[0], expo[0])])
        return sides[0], sides[1]

    def response(self, theta, omega, kind: str = "compliance") -> np.ndarray:
        """The response compared with data of ``kind``: the transfer function, or its reciprocal
        for modulus data (cards describe compliances)."""
        g = self.transfer(theta, omega)
        if kind == "modulus":
            with np.errstate(divide="ignore", invalid="ignore"):
                return 1.0 / g
        return g

    # ------------------------------------------------------------------ constraints
    def in_support(self, theta) -> np.ndarray:
        """True where every free parameter lies within the support of its prior."""
        theta2 = np.atleast_2d(np.asarray(theta, float))
        ok = np.ones(theta2.shape[0], dtype=bool)
        for i, p in enumerate(self.parameters):
            ok &= p.prior.contains(theta2[:, i])
        return ok if np.ndim(theta) == 2 else ok[0]

    def stable(self, theta, kind: str = "generic") -> np.ndarray:
        """Matignon stability (thesis Theorem 3) of the poles, and for materials of the zeros.

        The poles (roots of the denominator) are always tested. For compliance and modulus data
        the zeros are tested too: a passive material has a compliance whose reciprocal, the
        modulus, is again a stable response, so a root of the numerator in the unstable region
        is as unphysical as a pole there. Roots at λ = 0 (integrators) are accepted. A side
        that is not a polynomial in one s^p is not tested.
        """
        vals, single = self.values(theta)
        n_sets = np.atleast_2d(np.asarray(theta, float)).shape[0]
        ok = np.ones(n_sets, dtype=bool)
        sides = [self.denominator] + ([self.numerator] if kind in ("compliance", "modulus") else [])
        for terms in sides:
            p = _polynomial_order(terms)
            if p:  # None: not a polynomial; "": a constant, without roots
                poly = self._polynomial(terms, vals, n_sets)
                ok &= matignon_stable(poly, vals[p], allow_integrator=True)
        return ok[0] if single else ok

    def passive(self, theta, kind: str, omega_grid) -> np.ndarray:
        """Dissipation ≥ 0 of the response compared with ``kind`` data on ``omega_grid``.

        Commensurate structures of degree ≤ 1 on both sides use the exact condition instead of
        the grid: Im[(b0 + b1 λ)/(a0 + a1 λ)] = (b1 a0 − b0 a1) Im λ / |A|², and Im λ > 0 for
        0 < q < 2, so a compliance (and its reciprocal, a modulus) dissipates iff
        b1 a0 ≤ b0 a1, at every frequency.
        """
        theta2 = np.atleast_2d(np.asarray(theta, float))
        single = np.ndim(theta) != 2
        if kind == "generic":
            ok = np.ones(theta2.shape[0], dtype=bool)
        elif self._first_degree:
            den, num, q = self.polynomials(theta2)
            d1 = den[:, 1] if den.shape[1] > 1 else 0.0
            n1 = num[:, 1] if num.shape[1] > 1 else 0.0
            lhs, rhs = n1 * den[:, 0], num[:, 0] * d1
            scale = np.abs(lhs) + np.abs(rhs)
            ok = (lhs <= rhs + 1e-12 * scale) | ~((q > 0) & (q < 2))
            ok &= np.all(np.isfinite(theta2), axis=1)
        else:
            ok = is_dissipative(self.response(theta2, omega_grid, kind), kind)
        return ok[0] if single else ok

    @cached_property
    def _first_degree(self) -> bool:
        """Commensurate with numerator and denominator of degree ≤ 1 in λ = s^q."""
        if self.commensurate_order is None:
            return False
        return all(
            (t.exponent.multiple if t.exponent.param else 0) <= 1
            for t in self.numerator + self.denominator
        )

    def admissible(self, theta, kind: str, omega_grid=None) -> np.ndarray:
        """All declared constraints and prior supports at once: the support of the posterior.

        Parameters
        ----------
        theta : array_like, shape (n_params,) or (n_sets, n_params)
        kind : {"compliance", "modulus", "generic"}
        omega_grid : array_like, optional
            The dense grid of the dissipation check, in the units of ``theta``
            (default :func:`~bayesfo.response.dissipation_grid` around ω = 1).
        """
        theta = np.asarray(theta, dtype=float)
        ok = np.atleast_1d(self.in_support(theta)).copy()
        ok &= self.constraints_hold(theta, kind, omega_grid, where=ok)
        return ok[0] if theta.ndim == 1 else ok

    def constraints_hold(self, theta, kind: str, omega_grid=None, where=None) -> np.ndarray:
        """The card's constraints (inequalities, ``stable``, ``passive``) without the prior
        ranges; rows where ``where`` is false are skipped (returned false)."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        ok = np.ones(theta.shape[0], dtype=bool) if where is None else np.array(where, dtype=bool)
        vals, _ = self.values(theta)
        for c in self.constraints:
            if isinstance(c, Inequality):
                ok &= c.holds(vals)
        names = {c for c in self.constraints if isinstance(c, str)}
        if "stable" in names and ok.any():
            ok &= self.stable(theta, kind)
        if "passive" in names and kind != "generic" and ok.any():
            grid = dissipation_grid(1.0, 1.0) if omega_grid is None else omega_grid
            rows = np.flatnonzero(ok)
            ok[rows] = self.passive(theta[rows], kind, grid)
        return ok

    # ------------------------------------------------------------------ units
    @cached_property
    def _scale_plan(self):
        """For each free coefficient: (column, term, side sign of the gain)."""
        gain_side = _gain_side(self)
        plan = []
        for side, terms in (("numerator", self.numerator), ("denominator", self.denominator)):
            g = -1.0 if side == "numerator" else 1.0
            g = g if side == gain_side else 0.0
            for t in terms:
                if t.is_free and t.coef in self.param_names:
                    plan.append((self.param_names.index(t.coef), t.exponent, g))
        return plan

    def _scale_factors(self, theta, scaling: Scaling) -> np.ndarray:
        theta2 = np.atleast_2d(np.asarray(theta, float))
        vals, _ = self.values(theta2)
        factors = np.ones_like(theta2)
        log_w = math.log(scaling.omega_ref)
        log_g = math.log(scaling.tf_gain)
        for col, e, g in self._scale_plan:
            expo = e.multiple * vals[e.param] if e.param else e.multiple
            factors[:, col] = np.exp(expo * log_w + g * log_g)
        return factors

    def to_scaled(self, theta, scaling: Scaling) -> np.ndarray:
        """Physical parameters → parameters of the scaled problem (ω/ω_ref, G/g_ref)."""
        theta = np.asarray(theta, float)
        out = np.atleast_2d(theta) * self._scale_factors(theta, scaling)
        return out[0] if theta.ndim == 1 else out

    def to_physical(self, theta, scaling: Scaling) -> np.ndarray:
        """Parameters of the scaled problem → physical parameters (exponents are unchanged)."""
        theta = np.asarray(theta, float)
        out = np.atleast_2d(theta) / self._scale_factors(theta, scaling)
        return out[0] if theta.ndim == 1 else out

    # ------------------------------------------------------------------ checks
    def _validate(self):
        where = f"structure '{self.name}'" + (f" (card {self.card})" if self.card else "")
        if not self.numerator or not self.denominator:
            raise StructureError(f"{where}: numerator and denominator need at least one term")
        coef_names = [t.coef for t in self.numerator + self.denominator if t.is_free]
        dup = {n for n in coef_names if coef_names.count(n) > 1}
        if dup:
            raise StructureError(f"{where}: coefficient '{sorted(dup)[0]}' appears in two terms")
        used = set(coef_names) | set(self.exponent_params)
        declared = set(self.param_names) | set(self.fixed)
        missing = used - declared
        if missing:
            raise StructureError(f"{where}: parameter '{sorted(missing)[0]}' has no prior")
        unused = set(self.param_names) - used
        if unused:
            raise StructureError(f"{where}: parameter {show(sorted(unused)[0])} does not appear in the formula")
        for t in self.numerator + self.denominator:
            if not t.is_free and (t.exponent.param or t.exponent.multiple != 0):
                raise StructureError(
                    f"{where}: a constant coefficient is only allowed on s^0, got term '{t}'"
                )
        for c in self.constraints:
            if isinstance(c, Inequality):
                unknown = c.names - declared
                if unknown:
                    raise StructureError(
                        f"{where}: constraint '{c.text}' names unknown parameter '{sorted(unknown)[0]}'"
                    )
            elif c not in ("stable", "passive"):
                raise StructureError(
                    f"{where}: unknown constraint {c!r}; use 'stable', 'passive' or an inequality"
                )
            elif c == "stable" and _polynomial_order(self.denominator) is None:
                raise StructureError(
                    f"{where}: 'stable' needs a denominator that is a polynomial in s^q for one "
                    "exponent parameter q (Matignon's theorem)"
                )
        _gain_side(self)


def _polynomial_order(terms) -> str | None:
    """The exponent parameter p if all terms are c·s^{k p} (k integer ≥ 0) or constants.

    Returns "" for constant-only sides and None if the terms are not a polynomial in s^p.
    """
    params = {t.exponent.param for t in terms if t.exponent.param}
    if len(params) > 1:
        return None
    for t in terms:
        e = t.exponent
        if e.param is None and e.multiple != 0:
            return None
        if e.param is not None and (e.multiple < 0 or e.multiple != round(e.multiple)):
            return None
    return params.pop() if params else ""


def _gain_side(s: Structure) -> str:
    """The side whose coefficients are all free: it absorbs the magnitude scale g_ref."""
    for side in ("numerator", "denominator"):
        terms = getattr(s, side)
        if all(t.is_free and t.coef in s.param_names for t in terms):
            return side
    if not s.parameters:
        return "numerator"
    # With every coefficient of both sides fixed or constant the gain cannot be scaled.
    raise StructureError(
        f"structure '{s.name}': one side of the transfer function must have only free "
        "coefficients, so that the magnitude of the data can be scaled"
    )

