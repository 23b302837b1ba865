"""The grammar of a structure's transfer function: terms ``coefficient · s^exponent``, exponents
``k*q``, and the inequality constraints of a card."""

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


_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _number(text: str) -> float | None:
    """The finite number written in plain decimal notation in ``text``, else None."""
    if not _NUMBER.fullmatch(text):
        return None
    value = float(text)
    return value if math.isfinite(value) else None


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

