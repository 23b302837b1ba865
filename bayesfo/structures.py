"""Model structures, declared as cards in ``models/*.toml`` and evaluated vectorised.

A :class:`Structure` is a transfer function written as a ratio of power terms,
``Σ c_i s^{e_i} / Σ d_j s^{f_j}``, whose coefficients and exponents are parameters or constants,
together with the priors of its free parameters and its constraints. It is something you
evaluate: ``structure.response(theta, omega, kind)`` returns complex values of shape
``(n_sets, n_freq)`` for ``theta`` of shape ``(n_sets, n_params)``, and the same function serves
least squares, MCMC and plotting.

Cards
-----
A card describes one structure (or a family of them) as the **compliance** of a material, as the
thesis does (§2.4.2); for modulus data the same material is compared through the reciprocal. A
single-structure card::

    name = "voigt"
    title = "Fractional Voigt model"
    numerator = [["b0", "0"]]                  # [coefficient, exponent] pairs
    denominator = [[1, "0"], ["a1", "q"]]      # exponents: "0", "q", "2*q", "alpha", 1, ...
    constraints = ["stable", "passive"]        # and inequalities such as "alpha <= beta"
    [parameters]                               # priors on the scaled data, in this order
    a1 = { prior = "log-uniform", low = 1e-4, high = 1e4 }
    b0 = { prior = "log-uniform", low = 1e-4, high = 1e4 }
    q  = { prior = "uniform", low = 0, high = 1 }

A family card has ``family = "max-order"`` and ``n_max``; its members are the commensurate
structures ``B(λ)/A(λ)`` with ``A = 1 + a1 λ + … + an λ^n`` and ``B = b0 + … + bm λ^m`` for
n = 1..n_max, m = 0..n, and parameter tables may use the patterns ``"a*"`` and ``"b*"``.

Variants are generated, never written by hand: ``NAME-int`` fixes every exponent parameter to 1
(the integer-order baseline) and ``NAME-inv`` is the reciprocal transfer function (for
integrator-like data such as a hydraulic dashpot, thesis §4.3.4). Inverted max-order members
run over m = 1..n_max, n = 0..m.

Constraints
-----------
``stable``
    Matignon's theorem (thesis Theorem 3) on the denominator, which must be a polynomial in
    λ = s^p for one exponent parameter p, and for compliance and modulus data also on the
    numerator (the reciprocal of a passive material response is a stable response too). A root
    at λ = 0 is an integrator (Maxwell compliance, dashpot), not an instability, and is accepted.
``passive``
    Dissipation ≥ 0 of the response compared with the data (Im J ≤ 0 for a compliance,
    Im G ≥ 0 for a modulus; nothing for generic data), on a dense grid reaching decades beyond
    the data.
inequalities
    ``lhs <= rhs`` (or ``<``, ``>=``, ``>``), each side a product of parameter names and numbers.
    They must be invariant under the internal scaling (compare exponents with exponents, or
    products with the same units); inverted variants keep only those between exponent
    parameters, because coefficient orderings are statements about the parent material.

Scaling
-------
Parameters are sampled and optimised on scaled data, ω̃ = ω/ω_ref and G̃ = G/g_ref (see
:class:`Scaling`), and reported in physical units through :meth:`Structure.to_physical`.
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from dataclasses import dataclass, field, replace
from functools import cached_property
from importlib import resources
from pathlib import Path

import numpy as np

from ._io import read_text_file, show
from .errors import InputError, StructureError
from .priors import Prior, prior_from_dict
from .response import (
    commensurate_response,
    dissipation_grid,
    is_dissipative,
    matignon_stable,
    power_ratio,
)

N_MAX_DEFAULT = 3
MODEL_PATH_ENV = "BAYESFO_MODEL_PATH"

#: Highest degree of a pseudo-polynomial in s^q: the largest ``n_max`` of a max-order family and
#: the largest multiplier k of an exponent ``k*q`` (and the largest |exponent| given as a number).
#: The thesis goes to n = 3; at degree 6 a max-order member already has up to 14 parameters,
#: more than frequency responses of tens of points determine, the library of the family holds
#: 100 structures, and the powers (ω/ω_ref)^(6q) of data within the reader's 30 decades stay
#: finite. Larger multipliers would only make the polynomial arrays huge (``99999999999*q``
#: asked for a polynomial of 10^11 coefficients).
MAX_DEGREE = 6

_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _number(text: str) -> float | None:
    """The finite number written in plain decimal notation in ``text``, else None."""
    if not _NUMBER.fullmatch(text):
        return None
    value = float(text)
    return value if math.isfinite(value) else None


# ---------------------------------------------------------------------- terms
@dataclass(frozen=True)
class Exponent:
    """An exponent ``multiple · param`` (or the constant ``multiple`` when ``param`` is None)."""

    multiple: float
    param: str | None = None

    @classmethod
    def parse(cls, spec, where: str) -> Exponent:
        """Read ``0``, ``0.5``, ``"q"`` or ``"2*q"``; numbers and multipliers are bounded by
        ±:data:`MAX_DEGREE`."""
        if isinstance(spec, bool) or not isinstance(spec, (int, float, str)):
            raise StructureError(f"{where}: exponent must be a number or text like '2*q', got {spec!r}")
        if isinstance(spec, str):
            text = spec.replace(" ", "")
            value = _number(text)
            if value is None:
                if text.lower().lstrip("+-") in ("inf", "infinity", "nan"):
                    raise StructureError(f"{where}: exponent must be a finite number, got {spec!r}")
                m = re.fullmatch(r"(?:([^*]+)\*)?([A-Za-z_][A-Za-z0-9_]*)", text)
                k = None if m is None else 1.0 if m.group(1) is None else _number(m.group(1))
                if k is None or k < 0:
                    raise StructureError(
                        f"{where}: cannot read exponent {spec!r}; write a finite number or a "
                        "parameter with an optional non-negative multiplier, e.g. 0.5, 'q', '2*q'"
                    )
                return cls._checked(k, m.group(2), spec, where)
        else:
            value = float(spec)
        if not math.isfinite(value):
            raise StructureError(f"{where}: exponent must be a finite number, got {spec!r}")
        return cls._checked(value, None, spec, where)

    @classmethod
    def _checked(cls, multiple: float, param: str | None, spec, where: str) -> Exponent:
        if abs(multiple) > MAX_DEGREE:
            what = "the multiplier of an exponent" if param else "a constant exponent"
            raise StructureError(
                f"{where}: exponent {spec!r}: {what} must be within ±{MAX_DEGREE} (a "
                f"pseudo-polynomial of degree at most {MAX_DEGREE}), got {multiple:g}"
            )
        return cls(float(multiple), param)

    def __str__(self) -> str:
        if self.param is None:
            return f"{self.multiple:g}"
        return self.param if self.multiple == 1 else f"{self.multiple:g}{self.param}"


@dataclass(frozen=True)
class Term:
    """One power term ``coef · s^exponent``; ``coef`` is a parameter name or a constant."""

    coef: str | float
    exponent: Exponent

    @property
    def is_free(self) -> bool:
        return isinstance(self.coef, str)

    def __str__(self) -> str:
        c = self.coef if self.is_free else f"{self.coef:g}"
        if self.exponent.param is None and self.exponent.multiple == 0:
            return str(c)
        e = str(self.exponent)
        if e == "1":
            power = "s"
        elif len(e) == 1 or e.replace(".", "").isdigit() or e.isidentifier():
            power = f"s^{e}"
        else:
            power = f"s^({e})"
        return power if c == "1" else f"{c} {power}"


@dataclass(frozen=True)
class Inequality:
    """``lhs op rhs`` with each side a product of parameter names and numbers."""

    lhs: tuple
    op: str
    rhs: tuple
    text: str

    @classmethod
    def parse(cls, text: str, where: str) -> Inequality:
        m = re.fullmatch(r"\s*(.+?)\s*(<=|>=|<|>)\s*(.+?)\s*", text)
        if not m:
            raise StructureError(
                f"{where}: unknown constraint {text!r}; use 'stable', 'passive' or an "
                "inequality such as 'alpha <= beta'"
            )
        return cls(_product(m.group(1), where, text), m.group(2), _product(m.group(3), where, text),
                   text.strip())

    @property
    def names(self) -> set[str]:
        return {f for f in self.lhs + self.rhs if isinstance(f, str)}

    def holds(self, values: dict[str, np.ndarray]) -> np.ndarray:
        lhs = _evaluate_product(self.lhs, values)
        rhs = _evaluate_product(self.rhs, values)
        return {"<=": np.less_equal, "<": np.less, ">=": np.greater_equal, ">": np.greater}[
            self.op
        ](lhs, rhs)


def _product(text: str, where: str, constraint: str = "") -> tuple:
    factors = []
    for tok in text.split("*"):
        tok = tok.strip()
        value = _number(tok)
        if value is not None:
            factors.append(value)
        elif _NAME.fullmatch(tok) and tok.lower() not in ("nan", "inf", "infinity"):
            factors.append(tok)
        else:
            raise StructureError(
                f"{where}: cannot read {tok!r} in the constraint {(constraint or text).strip()!r}; write "
                "parameter names and finite numbers joined by '*', e.g. 'b1 <= a1*b0'"
            )
    return tuple(factors)


def _evaluate_product(factors, values):
    out = 1.0
    for f in factors:
        out = out * (values[f] if isinstance(f, str) else f)
    return out


# ---------------------------------------------------------------------- scaling
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


# ---------------------------------------------------------------------- structure
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


# ---------------------------------------------------------------------- variants
def integer_variant(s: Structure) -> Structure:
    """The integer-order baseline: every exponent parameter fixed to 1."""
    expo = set(s.exponent_params)
    if not expo:
        raise StructureError(f"structure '{s.name}' has no exponent parameter to fix")
    params = tuple(p for p in s.parameters if p.name not in expo)
    fixed = dict(s.fixed) | {name: 1.0 for name in expo}
    constraints = tuple(
        c for c in s.constraints if not (isinstance(c, Inequality) and c.names <= expo)
    )
    return replace(
        s, name=f"{s.name}-int", parameters=params, fixed=fixed, constraints=constraints,
        integer=True, title=f"{s.title} (integer order)",
    )


def fix_parameters(s: Structure, values: dict[str, float]) -> Structure:
    """A copy of ``s`` with some exponent parameters fixed (e.g. ``{"q": 0.5}``)."""
    unknown = [k for k in values if k not in s.param_names]
    if unknown:
        raise StructureError(
            f"structure '{s.name}' has no free parameter {show(str(unknown[0]))}; "
            f"its free parameters are {', '.join(s.param_names)}"
        )
    # Coefficients change with the internal scaling of ω and G; only exponents are unit-free.
    coef = [k for k in values if k not in s.exponent_params]
    if coef:
        raise StructureError(
            f"only exponent parameters ({', '.join(s.exponent_params) or 'none'}) can be fixed "
            f"in structure '{s.name}', not {show(str(coef[0]))}"
        )
    for k, v in values.items():
        if not s.priors[k].contains(v):
            raise StructureError(
                f"{k} = {v:g} is outside the prior {s.priors[k].describe()} of structure '{s.name}'"
            )
    params = tuple(p for p in s.parameters if p.name not in values)
    fixed = dict(s.fixed) | {k: float(v) for k, v in values.items()}
    return replace(s, parameters=params, fixed=fixed)


def inverted_variant(s: Structure) -> Structure:
    """The reciprocal transfer function (numerator and denominator swapped)."""
    expo = set(s.exponent_params)
    constraints = tuple(
        c for c in s.constraints if not isinstance(c, Inequality) or c.names <= expo
    )
    return replace(
        s, name=f"{s.name}-inv", numerator=s.denominator, denominator=s.numerator,
        constraints=constraints, inverted=True,
        title=f"{s.title} (inverted)",
    )


# ---------------------------------------------------------------------- cards
def _parse_terms(spec, where: str) -> tuple[Term, ...]:
    if not isinstance(spec, list) or not spec:
        raise StructureError(f"{where}: expected a list of [coefficient, exponent] pairs")
    terms = []
    for i, item in enumerate(spec):
        if not isinstance(item, list) or len(item) != 2:
            raise StructureError(f"{where}, term {i + 1}: expected [coefficient, exponent], got {item!r}")
        coef, expo = item
        if isinstance(coef, bool) or not isinstance(coef, (str, int, float)):
            raise StructureError(f"{where}, term {i + 1}: coefficient must be a name or a number")
        if isinstance(coef, str):
            value = _number(coef.strip())
            if value is not None:
                coef = value
            elif not _NAME.fullmatch(coef) or coef.lower() in ("nan", "inf", "infinity"):
                raise StructureError(
                    f"{where}, term {i + 1}: bad coefficient {coef!r}; write a parameter name "
                    "(letters, digits, '_') or a finite number"
                )
        else:
            coef = float(coef)
            if not math.isfinite(coef):
                raise StructureError(f"{where}, term {i + 1}: a constant coefficient must be a "
                                     f"finite number, got {item[0]!r}")
        terms.append(Term(coef, Exponent.parse(expo, f"{where}, term {i + 1}")))
    return tuple(terms)


def _parameters(names, table: dict, where: str, exponent_names) -> tuple[Parameter, ...]:
    params = []
    for name in names:
        spec = table.get(name)
        if spec is None:
            for pattern, s in table.items():
                if pattern.endswith("*") and name.startswith(pattern[:-1]) and name[len(pattern) - 1:].isdigit():
                    spec = s
                    break
        if spec is None:
            raise StructureError(f"{where}: no prior for parameter '{name}'")
        role = "exponent" if name in exponent_names else "coefficient"
        params.append(Parameter(name, role, prior_from_dict(spec, f"{where}, parameter {show(name)}")))
    return tuple(params)


def _common(card: dict, where: str) -> dict:
    constraints = []
    raw = card.get("constraints", [])
    if not isinstance(raw, list):
        raise StructureError(
            f"{where}: 'constraints' must be a list of text, e.g. [\"stable\", \"passive\"], "
            f"got {raw!r}"
        )
    for c in raw:
        if not isinstance(c, str):
            raise StructureError(f"{where}: constraints must be text, got {c!r}")
        constraints.append(c if c in ("stable", "passive") else Inequality.parse(c, where))
    return {
        "title": str(card.get("title", "")),
        "description": str(card.get("description", "")),
        "reference": str(card.get("reference", "")),
        "constraints": tuple(constraints),
    }


CARD_KEYS = {"name", "title", "description", "reference", "numerator", "denominator",
             "constraints", "parameters", "family", "n_max", "order"}


def structures_from_card(card: dict, source: str = "", n_max: int | None = None) -> list[Structure]:
    """All structures a card declares, including the generated ``-int`` and ``-inv`` variants.

    Raises
    ------
    StructureError
        Naming the card and the entry that cannot be used.
    """
    if not isinstance(card, dict):
        raise StructureError(f"card '{source}': expected a table of keys, got {type(card).__name__}")
    name = card.get("name")
    where = f"card '{source or name}'"
    if not isinstance(name, str) or not re.fullmatch(r"[a-z][a-z0-9_]*", name):
        raise StructureError(f"{where}: 'name' must be lower-case letters, digits or '_', got {name!r}")
    unknown = set(card) - CARD_KEYS
    if unknown:
        raise StructureError(f"{where}: unknown key {show(sorted(unknown)[0])}")
    table = card.get("parameters", {})
    if not isinstance(table, dict):
        raise StructureError(f"{where}: 'parameters' must be a table")
    common = _common(card, where)
    family = card.get("family")
    out: list[Structure] = []
    if family is None:
        num = _parse_terms(card.get("numerator"), f"{where}, numerator")
        den = _parse_terms(card.get("denominator"), f"{where}, denominator")
        expo = {t.exponent.param for t in num + den if t.exponent.param}
        used = [n for n in table if not n.endswith("*")]
        params = _parameters(used, table, where, expo)
        base = Structure(name, num, den, params, family=name, card=source, **common)
        bases = [(base, True, True)]
    elif family == "max-order":
        if n_max is not None:
            nmax = _check_n_max(n_max, "argument 'n_max'")
        else:
            nmax = _check_n_max(card.get("n_max", N_MAX_DEFAULT), f"{where}: 'n_max'")
        bases = []
        pairs = {(n, m) for n in range(1, nmax + 1) for m in range(n + 1)}
        inv_pairs = {(n, m) for m in range(1, nmax + 1) for n in range(m + 1)}
        for n, m in sorted(pairs | inv_pairs, key=lambda p: (max(p), p[0], p[1])):
            num = tuple(Term(f"b{k}", Exponent(float(k), "q") if k else Exponent(0.0)) for k in range(m + 1))
            den = (Term(1.0, Exponent(0.0)),) + tuple(
                Term(f"a{k}", Exponent(float(k), "q")) for k in range(1, n + 1)
            )
            names = [f"a{k}" for k in range(1, n + 1)] + [f"b{k}" for k in range(m + 1)] + ["q"]
            params = _parameters(names, table, where, {"q"})
            s = Structure(
                f"{name}-n{n}m{m}", num, den, params, family=name, degrees=(n, m), card=source,
                **common,
            )
            bases.append((s, (n, m) in pairs, (n, m) in inv_pairs))
    else:
        raise StructureError(f"{where}: unknown family {family!r}; known: 'max-order'")
    for base, plain, inverse in bases:
        variants = []
        if plain:
            variants.append(base)
        if inverse:
            variants.append(inverted_variant(base))
        for v in variants:
            out.append(v)
            if v.exponent_params:
                out.append(integer_variant(v))
    return out


def _check_n_max(value, what: str) -> int:
    """``value`` as the highest degree of a max-order family: an integer 1..MAX_DEGREE."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise StructureError(
            f"{what} must be a whole number from 1 to {MAX_DEGREE}, got {value!r}"
        )
    if not 1 <= value <= MAX_DEGREE:
        raise StructureError(
            f"{what} must be from 1 to {MAX_DEGREE} (the highest degree of a max-order member; "
            f"the thesis uses 3), got {value}"
        )
    return int(value)


def card_paths(extra=()) -> list[Path]:
    """The card files: the packaged ``models/``, then ``$BAYESFO_MODEL_PATH``, then ``extra``.

    ``extra`` entries may be card files or directories of cards.
    """
    paths = sorted(
        Path(str(p)) for p in resources.files("bayesfo.models").iterdir() if p.name.endswith(".toml")
    )
    dirs = [d for d in os.environ.get(MODEL_PATH_ENV, "").split(os.pathsep) if d]
    for entry in [*dirs, *extra]:
        entry = Path(entry)
        if entry.is_dir():
            paths.extend(sorted(entry.glob("*.toml")))
        elif entry.is_file():
            paths.append(entry)
        elif entry.exists():
            raise StructureError(f"model card path '{entry}' is not a regular file or a directory")
        else:
            raise StructureError(f"model card path '{entry}' does not exist")
    return paths


#: Largest card file (bytes): a card is a few dozen lines.
MAX_CARD_BYTES = 1024 * 1024


def load_library(extra=(), n_max: int | None = None) -> dict[str, Structure]:
    """Every structure of every card, by name.

    Parameters
    ----------
    extra : sequence of path-like
        Additional card files or directories (a user's own structures).
    n_max : int, optional
        Highest order of the max-order family (default: the card's ``n_max``, 3).

    Raises
    ------
    StructureError
        For an unreadable card, or two cards declaring the same structure name.
    """
    if n_max is not None:
        _check_n_max(n_max, "argument 'n_max'")
    library: dict[str, Structure] = {}
    cards = []
    for i, path in enumerate(card_paths(extra)):
        try:
            text = read_text_file(path, "card", max_bytes=MAX_CARD_BYTES)
        except InputError as exc:
            raise StructureError(str(exc)) from None
        try:
            card = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise StructureError(f"card '{path}' is not valid TOML: {exc}") from None
        except RecursionError:
            raise StructureError(f"card '{path}' is not valid TOML: arrays or tables nested "
                                 "too deeply") from None
        order = card.get("order", 1000)
        if isinstance(order, bool) or not isinstance(order, (int, float)) or not math.isfinite(order):
            raise StructureError(f"card '{path}': 'order' must be a finite number, got {order!r}")
        cards.append((order, i, path, card))
    for _, _, path, card in sorted(cards, key=lambda c: c[:2]):
        for s in structures_from_card(card, source=str(path), n_max=n_max):
            if s.name in library:
                raise StructureError(
                    f"card '{path}' declares structure '{s.name}', already declared by "
                    f"card '{library[s.name].card}'"
                )
            library[s.name] = s
    return library


_DEFAULT_LIBRARY: dict[str, Structure] | None = None


def default_library() -> dict[str, Structure]:
    """The packaged structures (cached)."""
    global _DEFAULT_LIBRARY
    if _DEFAULT_LIBRARY is None:
        _DEFAULT_LIBRARY = load_library()
    return _DEFAULT_LIBRARY


def get_structure(name: str, library: dict[str, Structure] | None = None) -> Structure:
    """The structure called ``name`` (e.g. ``"zener"``, ``"max-n2m1"``, ``"zener-inv-int"``)."""
    library = default_library() if library is None else library
    try:
        return library[name]
    except KeyError:
        raise StructureError(
            f"unknown structure {show(str(name))}; known structures: "
            f"{', '.join(_short_list(library))}"
        ) from None


def _short_list(library) -> list[str]:
    bases = [n for n, s in library.items() if not (s.inverted or s.integer)]
    return bases + ["NAME-int", "NAME-inv", "maxN", "all"]


def resolve_structures(spec: str | list[str], library: dict[str, Structure] | None = None) -> list[Structure]:
    """Structures named by a comma list with the shortcuts ``maxN`` and ``all``.

    ``maxN`` is every max-order member with n ≤ N (``maxN-inv``: the inverted members with
    m ≤ N); ``all`` is every structure of the library with all its variants.
    """
    library = default_library() if library is None else library
    if isinstance(spec, str):
        names = spec.split(",")
    elif isinstance(spec, (list, tuple)) and all(isinstance(n, str) for n in spec):
        names = list(spec)
    else:
        raise StructureError(f"structures must be given as a comma list of names, got {spec!r}")
    out: list[Structure] = []
    for raw in names:
        name = raw.strip()
        if not name:
            raise StructureError(f"empty structure name in {spec!r}")
        m = re.fullmatch(r"max([0-9]+)(-inv)?(-int)?", name)
        if name == "all":
            chosen = list(library.values())
        elif m:
            limit, inv, integer = int(m.group(1)), bool(m.group(2)), bool(m.group(3))
            members = [s for s in library.values() if s.degrees is not None and s.family == "max"]
            if not members:
                raise StructureError(
                    f"'{name}': the library has no max-order family (a card with "
                    "name = \"max\" and family = \"max-order\")"
                )
            top = max(s.degrees[1] if s.inverted else s.degrees[0] for s in members)
            if not 1 <= limit <= top:
                raise StructureError(
                    f"'{name}' asks for the max-order members up to degree {limit}, but the "
                    f"library has them up to {top}: use max1 to max{top}, or raise n_max in "
                    f"the card '{members[0].card}' (at most {MAX_DEGREE})"
                )
            chosen = [
                s for s in members
                if s.inverted == inv and s.integer == integer
                and (s.degrees[1] if inv else s.degrees[0]) <= limit
            ]
        else:
            chosen = [get_structure(name, library)]
        for s in chosen:
            if s not in out:
                out.append(s)
    return out
