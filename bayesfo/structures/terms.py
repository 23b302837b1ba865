"""The grammar of a structure's transfer function: terms ``coefficient · s^exponent``, exponents
``c + k1*p1 + k2*p2 + …``, coefficients that are a parameter, a product of parameters or a
constant, and the inequality constraints of a card."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..errors import StructureError

#: Highest degree of a pseudo-polynomial in s^q: the largest ``n_max`` of a max-order family and
#: the largest multiplier k of an exponent ``k*q`` (and the largest |exponent| given as a number).
#: The thesis goes to n = 3; at degree 6 a max-order member already has up to 14 parameters,
#: more than frequency responses of tens of points determine, the library of the family holds
#: 100 structures, and the powers (ω/ω_ref)^(6q) of data within the reader's 30 decades stay
#: finite. Larger multipliers would only make the polynomial arrays huge (``99999999999*q``
#: asked for a polynomial of 10^11 coefficients).
MAX_DEGREE = 6

#: Most parameters multiplied in one coefficient (``G_m*eta*V`` in the fractional Burgers card
#: has three).
MAX_FACTORS = 6


_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")

# One signed summand of an exponent: a number, or a name with an optional multiplier.
_SUMMAND = re.compile(
    r"([+-]?)(?:((?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)(?:\*([A-Za-z_][A-Za-z0-9_]*))?"
    r"|([A-Za-z_][A-Za-z0-9_]*))"
)

_UNREADABLE = (
    "cannot read exponent {spec!r}; write a finite number or a parameter with an optional "
    "non-negative multiplier, e.g. 0.5, 'q', '2*q', or a sum of them such as 'alpha+1'"
)


def _number(text: str) -> float | None:
    """The finite number written in plain decimal notation in ``text``, else None."""
    if not _NUMBER.fullmatch(text):
        return None
    value = float(text)
    return value if math.isfinite(value) else None


def _is_bad_name(name: str) -> bool:
    return name.lower() in ("nan", "inf", "infinity")


@dataclass(frozen=True)
class Exponent:
    """An exponent ``constant + Σ k_i · p_i`` with exponent parameters p_i and multipliers
    k_i ≥ 0 (``"q"``, ``"2*q"``, ``"alpha+1"``, ``"kappa+alpha"`` or a number)."""

    constant: float = 0.0
    coefs: tuple[tuple[str, float], ...] = ()

    @classmethod
    def of(cls, param: str, multiple: float = 1.0) -> Exponent:
        """``multiple · param``."""
        return cls(0.0, ((param, float(multiple)),))

    @classmethod
    def parse(cls, spec, where: str) -> Exponent:
        """Read ``0``, ``0.5``, ``"q"``, ``"2*q"`` or a sum such as ``"alpha+1"``; numbers and
        multipliers are bounded by ±:data:`MAX_DEGREE`."""
        if isinstance(spec, bool) or not isinstance(spec, (int, float, str)):
            raise StructureError(f"{where}: exponent must be a number or text like '2*q', got {spec!r}")
        if not isinstance(spec, str):
            value = float(spec)
            if not math.isfinite(value):
                raise StructureError(f"{where}: exponent must be a finite number, got {spec!r}")
            return cls._checked(value, (), spec, where)
        text = spec.replace(" ", "")
        value = _number(text)
        if value is not None:
            return cls._checked(value, (), spec, where)
        if text.lower().lstrip("+-") in ("inf", "infinity", "nan"):
            raise StructureError(f"{where}: exponent must be a finite number, got {spec!r}")
        constant, coefs, pos = 0.0, {}, 0
        while pos < len(text):
            m = _SUMMAND.match(text, pos)
            if m is None or m.end() == pos or (pos > 0 and not m.group(1)):
                raise StructureError(f"{where}: " + _UNREADABLE.format(spec=spec))
            sign, number, name = m.group(1), m.group(2), m.group(3) or m.group(4)
            if name is not None and _is_bad_name(name):
                raise StructureError(f"{where}: exponent must be a finite number, got {spec!r}")
            k = 1.0 if number is None else _number(number)
            if k is None:
                raise StructureError(f"{where}: " + _UNREADABLE.format(spec=spec))
            if name is None:
                constant += -k if sign == "-" else k
            elif sign == "-":
                raise StructureError(f"{where}: " + _UNREADABLE.format(spec=spec))
            else:
                coefs[name] = coefs.get(name, 0.0) + k
            pos = m.end()
        if not coefs and pos == 0:
            raise StructureError(f"{where}: " + _UNREADABLE.format(spec=spec))
        return cls._checked(constant, tuple(coefs.items()), spec, where)

    @classmethod
    def _checked(cls, constant: float, coefs, spec, where: str) -> Exponent:
        for _, k in coefs:
            if abs(k) > MAX_DEGREE:
                raise StructureError(
                    f"{where}: exponent {spec!r}: the multiplier of an exponent must be within "
                    f"±{MAX_DEGREE} (a pseudo-polynomial of degree at most {MAX_DEGREE}), got {k:g}"
                )
        if abs(constant) > MAX_DEGREE:
            raise StructureError(
                f"{where}: exponent {spec!r}: a constant exponent must be within ±{MAX_DEGREE} "
                f"(a pseudo-polynomial of degree at most {MAX_DEGREE}), got {constant:g}"
            )
        return cls(float(constant), tuple((p, float(k)) for p, k in coefs))

    @property
    def params(self) -> tuple[str, ...]:
        """The exponent parameters named in the exponent."""
        return tuple(p for p, _ in self.coefs)

    @property
    def single(self) -> tuple[str, float] | None:
        """``(p, k)`` when the exponent is ``k·p`` for one parameter p, else None."""
        if len(self.coefs) == 1 and self.constant == 0:
            return self.coefs[0]
        return None

    def value(self, values: dict):
        """The exponent for parameter values ``{name: array}`` (fixed ones included)."""
        out = self.constant
        for p, k in self.coefs:
            out = out + k * values[p]
        return out

    def substitute(self, fixed: dict) -> Exponent:
        """The exponent with the parameters in ``fixed`` replaced by their values."""
        constant = self.constant + sum(k * float(fixed[p]) for p, k in self.coefs if p in fixed)
        return Exponent(constant, tuple((p, k) for p, k in self.coefs if p not in fixed))

    def __str__(self) -> str:
        parts = [p if k == 1 else f"{k:g}{p}" for p, k in self.coefs]
        if self.constant or not parts:
            parts.append(f"{self.constant:g}")
        return "+".join(parts).replace("+-", "-")


@dataclass(frozen=True)
class Term:
    """One power term ``coef · s^exponent``; ``coef`` is a parameter name, a product of names
    such as ``"G_e*V"``, or a constant."""

    coef: str | float
    exponent: Exponent

    @property
    def is_free(self) -> bool:
        return isinstance(self.coef, str)

    @property
    def factors(self) -> tuple[str, ...]:
        """The parameter names multiplied in the coefficient (empty for a constant)."""
        return tuple(self.coef.split("*")) if self.is_free else ()

    def coefficient(self, values: dict, n_sets: int) -> np.ndarray:
        """The coefficient for parameter values ``{name: array of n_sets}``."""
        if not self.is_free:
            return np.full(n_sets, float(self.coef))
        out = np.ones(n_sets)
        for f in self.factors:
            out = out * values[f]
        return out

    def __str__(self) -> str:
        c = self.coef if self.is_free else f"{self.coef:g}"
        e = self.exponent
        if not e.coefs and e.constant == 0:
            return str(c)
        text = str(e)
        if text == "1":
            power = "s"
        elif len(text) == 1 or text.replace(".", "").isdigit() or text.isidentifier():
            power = f"s^{text}"
        else:
            power = f"s^({text})"
        return power if c == "1" else f"{c} {power}"


def parse_coefficient(coef, where: str) -> str | float:
    """A term's coefficient: a finite number, a parameter name or a product of names."""
    if isinstance(coef, bool) or not isinstance(coef, (str, int, float)):
        raise StructureError(f"{where}: coefficient must be a name or a number")
    if not isinstance(coef, str):
        value = float(coef)
        if not math.isfinite(value):
            raise StructureError(f"{where}: a constant coefficient must be a finite number, "
                                 f"got {coef!r}")
        return value
    value = _number(coef.strip())
    if value is not None:
        return value
    factors = [f.strip() for f in coef.split("*")]
    if (not all(_NAME.fullmatch(f) and not _is_bad_name(f) for f in factors)
            or len(factors) > MAX_FACTORS):
        raise StructureError(
            f"{where}: bad coefficient {coef!r}; write a parameter name (letters, digits, '_'), "
            f"a product of at most {MAX_FACTORS} names such as 'G_e*V', or a finite number"
        )
    return "*".join(factors)


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
        elif _NAME.fullmatch(tok) and not _is_bad_name(tok):
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
