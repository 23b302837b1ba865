"""Temperatures, the one place they are parsed: a cell or option (:func:`parse_temperature`),
a temperature written with its unit inside a label (:func:`temperature_in_text`), and an
isotherm file's temperature from a ``# temperature:`` line, the file stem (``Tm010C``) or a
``# name:`` line (:func:`temperature_of_file`)."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

from .._io import read_text_file
from ..errors import DataWarning, InputError
from .units import parse_unit

_NUMBER = r"[+\-\u2212]?\d+(?:\.\d*)?(?:[eE][+\-]?\d+)?"


_TEMPERATURE_VALUE = re.compile(rf"^\s*({_NUMBER})\s*(°\s*C|deg\s*C|C|K)?\s*$", re.IGNORECASE)


_TEMPERATURE_IN_NAME = re.compile(rf"({_NUMBER})\s*°\s*C")


_TEMPERATURE_IN_STEM = re.compile(r"(?:^|[_\-\s.])T([mp+\-])?(\d+)(?:[.p](\d+))?C(?=$|[_\-\s.])",
                                  re.IGNORECASE)
#: Other common ways to name a temperature in a file name: ``_-10C``, ``_25C``, ``25degC``,
#: ``25°C`` (a number with its unit, standing alone), and ``T25``, ``T-35`` (a T and a number).
_OTHER_TEMPERATURES_IN_STEM = (
    re.compile(r"(?:^|(?<=[_\s.]))([+\-])?(\d+)(?:[.p](\d+))?\s*(?:°\s*C|deg\s*C|C)"
               r"(?=$|[_\-\s.])", re.IGNORECASE),
    re.compile(r"(?:^|(?<=[\-]))()(\d+)(?:[.p](\d+))?\s*(?:°\s*C|deg\s*C|C)(?=$|[_\-\s.])",
               re.IGNORECASE),
    re.compile(r"(?:^|(?<=[_\-\s.]))T([+\-])?(\d+)(?:[.p](\d+))?(?=$|[_\-\s.])"),
)


def parse_temperature(text: str) -> float | None:
    """A temperature in °C from text such as ``"20"``, ``"-10 °C"``, ``"20 C"`` or ``"293.15 K"``.

    Returns None when the text is not a temperature.

    Examples
    --------
    >>> parse_temperature("293.15 K")
    20.0
    >>> parse_temperature("-10 °C")
    -10.0
    """
    m = _TEMPERATURE_VALUE.match(text)
    if not m:
        return None
    value = float(m.group(1).replace("\u2212", "-"))
    if (m.group(2) or "").upper() == "K":
        value = round(value - 273.15, 10)
    return value


def looks_like_kelvin(text: str) -> bool:
    """Whether a temperature written without a unit reads as kelvin: 173.15 or more (−100 °C
    in kelvin) and a whole number of degrees (or a half) above 273.15, as 293.15 or 423.15 are
    (a number of degrees Celsius ending in .15 is rare)."""
    m = _TEMPERATURE_VALUE.match(text)
    if not m or m.group(2):
        return False
    value = float(m.group(1).replace("\u2212", "-"))
    return value >= 173.15 and abs(2 * (value - 273.15) - round(2 * (value - 273.15))) < 1e-6 \
        and abs(value - round(value)) > 1e-6


def temperature_from_stem(stem: str) -> float | None:
    """A temperature in °C from a file stem such as ``T020C``, ``Tp020C``, ``Tm010C`` (−10 °C).

    ``m`` or ``-`` before the digits is a minus sign, ``p`` or ``+`` a plus sign; ``T20p5C`` is
    20.5 °C. The pattern must stand alone in the stem (at its start or end, or between ``_``,
    ``-``, ``.`` or spaces). Also a number with its unit (``foam_dma_-10C``, ``sample_25C``,
    ``x_25degC``; a ``-`` after ``_`` or a space is a minus sign, after a letter a separator)
    and a ``T`` with a number (``T25``, ``run_T-35``).

    Examples
    --------
    >>> temperature_from_stem("Tm010C"), temperature_from_stem("run3_T20p5C")
    (-10.0, 20.5)
    >>> temperature_from_stem("foam_dma_-10C"), temperature_from_stem("x_25degC")
    (-10.0, 25.0)
    >>> temperature_from_stem("run_T-35"), temperature_from_stem("PI-130C")
    (-35.0, 130.0)
    """
    m = _TEMPERATURE_IN_STEM.search(stem)
    for other in _OTHER_TEMPERATURES_IN_STEM:
        if m:
            break
        m = other.search(stem)
    if not m:
        return None
    value = float(m.group(2) + ("." + m.group(3) if m.group(3) else ""))
    return -value if (m.group(1) or "").lower() in ("m", "-") else value


def temperature_of_file(path) -> float | None:
    """The temperature [°C] of a data file: a ``# temperature:`` comment (``20``, ``20 C``,
    ``293.15 K``), else the file stem (:func:`temperature_from_stem`), else a ``# name:`` comment
    holding ``<number> °C``; None if none of these gives one or the file cannot be read (the
    comparison reports that).

    Raises
    ------
    InputError
        If a ``# temperature:`` comment is not a temperature (naming the file and line).
    """
    try:
        text = read_text_file(path)
    except InputError:
        return None
    meta = {}
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped.startswith("#"):
            continue
        key, sep, value = stripped.lstrip("#").partition(":")
        key = key.strip().lower()
        if sep and key == "temperature" and key not in meta:
            meta[key] = parse_temperature(value)
            if meta[key] is None:
                raise InputError(f"file '{path}', line {lineno}: '# temperature:' expects a "
                                 f"temperature such as 20, 20 C or 293.15 K, got {value.strip()!r}")
            if looks_like_kelvin(value):
                warnings.warn(f"file '{path}', line {lineno}: '# temperature: {value.strip()}' "
                              f"has no unit and is read as {meta[key]:g} °C, yet it looks like "
                              f"kelvin ({meta[key] - 273.15:g} °C); write '{value.strip()} K' "
                              f"or '{value.strip()} C'", DataWarning, stacklevel=2)
        elif sep and key == "name":
            meta.setdefault(key, value.strip())
    if meta.get("temperature") is not None:
        return meta["temperature"]
    value = temperature_from_stem(Path(path).stem)
    if value is not None:
        return value
    found = _TEMPERATURE_IN_NAME.findall(meta.get("name", ""))
    return float(found[-1].replace("\u2212", "-")) if found else None


_TEMPERATURE_TEXT = re.compile(r"([+\-−]?\d+(?:[.,]\d+)?)\s*(°\s*C|℃|deg\s*C|K|°\s*F)\b"
                               r"|([+\-−]?\d+(?:[.,]\d+)?)\s*(°\s*C|℃)")


def temperature_in_text(text: str) -> float | None:
    """The temperature [°C] written with its unit in ``text`` (``"Frequency sweep (150.0 °C)"``,
    ``"Temperature: 25 °C"``, ``"293.15 K"``), or None; the last one if several."""
    found = None
    for m in _TEMPERATURE_TEXT.finditer(text):
        number, unit = (m.group(1), m.group(2)) if m.group(1) else (m.group(3), m.group(4))
        u = parse_unit(unit.replace(" ", ""))
        if u is None:
            continue
        value = float(number.replace("−", "-").replace(",", "."))
        found = round(value * u.factor + u.offset, 10)
    return found
