"""Units written in lab files, and their conversion to SI (rad/s, Hz, Pa, 1/Pa, Pa·s, degrees, °C).

A unit is recognised in the spellings rheometer and DMA software write (``Pa``, ``MPa``,
``1/MPa``, ``MPa-1``, ``Pa.s``, ``Pa·s``, ``mPa s``, ``rad/s``, ``1/s``, ``Hz``, ``°``, ``rad``,
``°C``, ``K``, ``dyn/cm²`` ...). :func:`parse_unit` returns None for anything else: a unit that is
not recognised is never guessed.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

#: SI unit of each quantity, as the reader reports it.
SI = {"angular_frequency": "rad/s", "frequency": "Hz", "modulus": "Pa", "compliance": "1/Pa",
      "viscosity": "Pa s", "angle": "deg", "temperature": "°C", "dimensionless": ""}


@dataclass(frozen=True)
class Unit:
    """A recognised unit: value_SI = value * factor + offset (offset for temperatures only)."""

    text: str
    quantity: str
    factor: float = 1.0
    offset: float = 0.0

    @property
    def si(self) -> str:
        return SI[self.quantity]

    @property
    def is_si(self) -> bool:
        return self.factor == 1.0 and self.offset == 0.0

    def to_si(self, values):
        if self.is_si:
            return values
        return values * self.factor + self.offset if self.offset else values * self.factor

    def describe(self) -> str:
        """How a value in this unit becomes SI, e.g. ``MPa → Pa (× 1e+06)``."""
        if self.offset:
            return f"{self.text} → {self.si} ({self._scale_text()}{self.offset:+g})"
        return f"{self.text} → {self.si} (× {self.factor:.6g})"

    def _scale_text(self) -> str:
        return "" if self.factor == 1.0 else f"× {self.factor:.6g} "


_PREFIX = {"": 1.0, "m": 1e-3, "h": 1e2, "k": 1e3, "M": 1e6, "G": 1e9}
_PRESSURE = {f"{p}Pa": f for p, f in _PREFIX.items()}
_PRESSURE.update({"dyn/cm2": 0.1, "dyne/cm2": 0.1, "N/m2": 1.0, "N/mm2": 1e6, "psi": 6894.757293168,
                  "kpsi": 6894757.293168, "bar": 1e5, "mbar": 1e2})


def _table() -> dict[str, tuple[str, float, float]]:
    t: dict[str, tuple[str, float, float]] = {}
    for name, f in _PRESSURE.items():
        t[name] = ("modulus", f, 0.0)
        for inv in (f"1/{name}", f"{name}-1", f"/{name}"):
            t[inv] = ("compliance", 1.0 / f, 0.0)
        for visc in (f"{name}.s", f"{name}s" if name.endswith("Pa") else None):
            if visc:
                t[visc] = ("viscosity", f, 0.0)
    t.update({"cm2/dyn": ("compliance", 10.0, 0.0), "m2/N": ("compliance", 1.0, 0.0),
              "P": ("viscosity", 0.1, 0.0), "cP": ("viscosity", 1e-3, 0.0),
              "poise": ("viscosity", 0.1, 0.0), "cPs": ("viscosity", 1e-3, 0.0)})
    for name in ("rad/s", "rad.s-1", "1/s", "s-1", "/s", "rads-1", "rad/sec", "1/sec"):
        t[name] = ("angular_frequency", 1.0, 0.0)
    t["rad/min"] = ("angular_frequency", 1.0 / 60.0, 0.0)
    for name, f in (("Hz", 1.0), ("mHz", 1e-3), ("kHz", 1e3), ("cps", 1.0), ("1/min", 1 / 60.0)):
        t[name] = ("frequency", f, 0.0)
    for name in ("°", "deg", "degree", "degrees", "grad"):
        t[name] = ("angle", 1.0, 0.0)
    t["rad"] = ("angle", 180.0 / math.pi, 0.0)
    t["mrad"] = ("angle", 0.18 / math.pi, 0.0)
    for name in ("°C", "C", "degC", "deg.C", "℃", "celsius", "Celsius"):
        t[name] = ("temperature", 1.0, 0.0)
    t["K"] = ("temperature", 1.0, -273.15)
    for name in ("°F", "F", "degF"):
        t[name] = ("temperature", 5.0 / 9.0, -32.0 * 5.0 / 9.0)
    for name in ("", "-", "1", "[]", "()"):
        t[name] = ("dimensionless", 1.0, 0.0)
    return t


_UNITS = _table()
_SUPERSCRIPT = str.maketrans({"⁻": "-", "¹": "1", "²": "2", "³": "3", "−": "-", "·": ".",
                              "⋅": ".", "*": ".", "µ": "u", "μ": "u", "’": "'", "º": "°"})


def _canonical(text: str) -> str:
    u = text.strip().translate(_SUPERSCRIPT)
    while len(u) >= 2 and u[0] + u[-1] in ("[]", "()", "{}"):
        u = u[1:-1].strip()
    u = u.replace("^", "")
    u = re.sub(r"\s*/\s*", "/", u)
    u = re.sub(r"\s*\.\s*", ".", u)
    u = re.sub(r"(?<=[A-Za-z°])\s+(?=[A-Za-z°/])", ".", u)  # "Pa s" -> "Pa.s", "deg C" -> "deg.C"
    u = re.sub(r"(?<=[A-Za-z])-(?=[A-Za-z])", ".", u)  # "Pa-s" -> "Pa.s"
    u = re.sub(r"\s+", "", u)
    u = re.sub(r"(?<=[A-Za-z])\.?-1$", "-1", u)  # "MPa^-1" -> "MPa-1", "rad.s.-1" -> "rad.s-1"
    u = u.replace("°.C", "°C").replace("°.F", "°F")
    return u


def parse_unit(text: str | None) -> Unit | None:
    """The :class:`Unit` written as ``text`` (brackets allowed), or None if not recognised.

    Examples
    --------
    >>> parse_unit("[MPa]").factor
    1000000.0
    >>> parse_unit("rad·s⁻¹").quantity
    'angular_frequency'
    >>> parse_unit("furlong") is None
    True
    """
    if text is None:
        return None
    key = _canonical(text)
    hit = _UNITS.get(key)
    if hit is None and key.lower() in ("pa.s", "pas"):
        hit = _UNITS["Pa.s"]
    if hit is None:
        return None
    quantity, factor, offset = hit
    return Unit(text.strip().strip("[]()").strip() or "-", quantity, factor, offset)


# Units that only show that a row is a row of units (they are never converted).
_OTHER_UNITS = {"s", "min", "h", "ms", "%", "N", "mN", "uN.m", "mN.m", "N.m", "Nm", "g.cm", "g",
                "mm", "um", "m", "cm", "rad", "1/K", "N.m/rad", "1/rad", "1/m", "Pa/N",
                "W", "J", "V", "A", "kg", "mg", "Pa/s", "1/Pa.s", "m/s", "mm/s", "%/s", "-", "rpm"}


def looks_like_unit(cell: str) -> bool:
    """Whether a cell of a units row looks like a unit (recognised, or one never converted such
    as ``%`` or ``N.m``), is empty or bracketed, or is the row's label ``Units``: used to tell a
    units row from a header."""
    c = cell.strip()
    if not c or (c[0] in "[(" and c[-1] in "])") or c.lower().rstrip(":") in ("units", "unit"):
        return True
    return parse_unit(c) is not None or _canonical(c) in _OTHER_UNITS


_HEADER_UNIT = re.compile(r"^(?P<name>.*?)\s*(?:\[(?P<sq>[^\[\]]*)\]|\((?P<rd>[^()]*)\)|"
                          r"\{(?P<cu>[^{}]*)\})\s*$")
_IN_UNIT = re.compile(r"^(?P<name>.+?)\s+in\s+(?P<unit>\S+(?:\s\S+)?)\s*$", re.IGNORECASE)
_SLASH_UNIT = re.compile(r"^(?P<name>.+?)\s*/\s*(?P<unit>[^/]+(?:/[^/]+)?)\s*$")
_UNDERSCORE = {"rad_s": "rad/s", "rads": "rad/s", "1_s": "1/s", "Hz": "Hz", "Pa_s": "Pa.s",
               "mPa_s": "mPa.s", "C": "°C", "degC": "°C", "K": "K", "deg": "deg", "rad": "rad",
               "percent": "%", "pct": "%", "1_Pa": "1/Pa", "1_MPa": "1/MPa", "1_GPa": "1/GPa",
               "1_kPa": "1/kPa", "per_Pa": "1/Pa", "per_MPa": "1/MPa"}


def split_header(cell: str) -> tuple[str, str | None]:
    """A header cell as (name, unit text or None): ``"E' [MPa]"``, ``"G' (kPa)"``,
    ``"G' in kPa"``, ``"omega / rad/s"``, ``"Gp_Pa"`` and ``"omega_rad_s"`` carry a unit;
    parentheses that hold no unit stay in the name (``"Raw phase (torque)"``).

    Examples
    --------
    >>> split_header("Storage modulus [MPa]")
    ('Storage modulus', 'MPa')
    >>> split_header("omega_rad_s")
    ('omega', 'rad/s')
    >>> split_header("Oscillation strain (cmd)")
    ('Oscillation strain (cmd)', None)
    """
    text = cell.strip()
    m = _HEADER_UNIT.match(text)
    if m and m.group("name"):
        unit = m.group("sq")
        if unit is not None:
            return m.group("name").strip(), unit.strip()
        unit = m.group("rd") if m.group("rd") is not None else m.group("cu")
        if parse_unit(unit) is not None or unit.strip() in ("%", "-"):
            return m.group("name").strip(), unit.strip()
    m = _IN_UNIT.match(text)
    if m and parse_unit(m.group("unit")) is not None:
        return m.group("name").strip(), m.group("unit").strip()
    m = _SLASH_UNIT.match(text)
    if m and parse_unit(m.group("unit")) is not None and len(m.group("name")) > 1:
        return m.group("name").strip(), m.group("unit").strip()
    if "_" in text:
        parts = text.split("_")
        for k in range(1, min(3, len(parts))):
            suffix = "_".join(parts[-k:])
            if not "_".join(parts[:-k]):
                continue
            if suffix in _UNDERSCORE:
                return "_".join(parts[:-k]), _UNDERSCORE[suffix]
            unit = parse_unit(suffix) if len(suffix) >= 2 else None
            if unit is not None and unit.quantity != "dimensionless":
                return "_".join(parts[:-k]), suffix
    return text, None
