"""The letter of the measured quantity, and texts written in it.

A frequency response carries the symbol its file gives the measured quantity
(:attr:`~bayesfo.data.FrequencyResponse.symbol`): ``"G"`` a shear modulus, ``"E"`` a tensile
(Young's) modulus, as a dynamic mechanical analyser measures it, ``"J"`` a shear compliance and
``"D"`` a tensile compliance. What bayesfo shows follows it: a tensile modulus is E* = E′ + iE″
with |E*|, E′, E″ and E(t) in figures, reports and the terminal; its compliance D* = D′ − iD″
and D(t). The mode of deformation does not change the computation (every structure is fitted to
the complex response as it is), only its names.

Texts of bayesfo are written for shear (G*, G′, G″, |G|, G(t), J(s), J(t), moduli G_e, G_m);
:func:`in_symbol` rewrites them in the letters of the data, :func:`parameter_label` does so for
a parameter's name (``G_e`` → ``E_e``). Names stay keys: ``summary.json``, ``ranking.csv``,
``--prior`` and the NetCDF files use the names of the structure's card whatever the data.

Examples
--------
>>> response_symbol("E", "modulus"), response_symbol("E", "compliance")
('E', 'D')
>>> in_symbol("G*(s) = G_e + c_q s^q, sampled as the card's compliance J(s)", "E")
"E*(s) = E_e + c_q s^q, sampled as the card's compliance D(s)"
>>> parameter_label("G_m", "E"), parameter_label("c_q", "E"), parameter_label("G_m", "G")
('E_m', 'c_q', 'G_m')
"""

from __future__ import annotations

import re

#: The symbols a response may carry: shear modulus, tensile modulus, shear compliance,
#: tensile compliance.
SYMBOLS = ("G", "E", "J", "D")

_MODULUS = {"G": "G", "J": "G", "E": "E", "D": "E"}
_COMPLIANCE = {"G": "J", "J": "J", "E": "D", "D": "D"}
_MODE = {"G": "shear", "J": "shear", "E": "tensile", "D": "tensile"}
#: The symbol of the reciprocal response (a modulus' compliance and back).
RECIPROCAL = {"G": "J", "J": "G", "E": "D", "D": "E"}


def modulus_symbol(symbol: str) -> str:
    """``"G"`` for shear, ``"E"`` for tensile data (of either kind)."""
    return _MODULUS.get(symbol, "G")


def compliance_symbol(symbol: str) -> str:
    """``"J"`` for shear, ``"D"`` for tensile data (of either kind)."""
    return _COMPLIANCE.get(symbol, "J")


def mode(symbol: str) -> str:
    """``"shear"`` or ``"tensile"``."""
    return _MODE.get(symbol, "shear")


def response_symbol(symbol: str, kind: str) -> str:
    """The letter of the response of ``kind`` measured as ``symbol``: the modulus' letter for
    a modulus, the compliance's for a compliance, ``symbol`` itself for a generic response."""
    if kind == "modulus":
        return modulus_symbol(symbol)
    if kind == "compliance":
        return compliance_symbol(symbol)
    return symbol if symbol in SYMBOLS else "G"


def parts(symbol: str, kind: str) -> tuple[str, str]:
    """The storage and loss parts' symbols: ``("E′", "E″")`` for a tensile modulus."""
    letter = response_symbol(symbol, kind)
    return f"{letter}′", f"{letter}″"


_SHEAR_LETTER = re.compile(r"(?<![A-Za-z0-9_])([GJ])(?![A-Za-z0-9])")


def in_symbol(text: str, symbol: str) -> str:
    """``text``, written for shear data, in the letters of data measured as ``symbol``: for
    tensile data every G standing alone or starting a name (``G*``, ``G′``, ``|G|``, ``G(t)``,
    ``G_e``, ``[G]``) becomes E and every J (``J(s)``, ``J(t)``, ``J′``) D; other words and
    units (``GPa``, ``Gamma``) stay. Shear data leave the text as it is. Use it for bayesfo's
    own texts, not for names of the user's (a file or data set name)."""
    if mode(symbol) == "shear" or not text:
        return text
    return _SHEAR_LETTER.sub(lambda m: "E" if m.group(1) == "G" else "D", text)


def parameter_label(name: str, symbol: str) -> str:
    """A parameter's name as shown for data measured as ``symbol``: a modulus named by its
    shear letter (``G_e``, ``G_m``, ``G_k``) takes the tensile letter (``E_e``) for tensile
    data; the Maxwell modulus the thesis calls ``E`` takes the data's modulus letter (``G``
    for shear data); every other name stays.

    Examples
    --------
    >>> parameter_label("G_e", "E"), parameter_label("E", "G"), parameter_label("E", "E")
    ('E_e', 'G', 'E')
    """
    if mode(symbol) == "tensile" and re.fullmatch(r"G_[A-Za-z0-9_]+", name):
        return "E" + name[1:]
    if name == "E":
        return modulus_symbol(symbol)
    return name


def describe(symbol: str, kind: str) -> str:
    """A short phrase for the terminal and the report: ``"tensile modulus E* = E′ + iE″"``,
    ``"shear compliance J* = J′ − iJ″"``; ``""`` for a generic response."""
    if kind not in ("modulus", "compliance"):
        return ""
    letter = response_symbol(symbol, kind)
    sign = "+" if kind == "modulus" else "−"
    return f"{mode(symbol)} {kind} {letter}* = {letter}′ {sign} i{letter}″"
