"""Finite-element decks of a Prony series (:class:`~bayesfo.predictions.prony.Prony`): the
comment lines every format carries, and the cards of Abaqus (``*VISCOELASTIC, TIME=PRONY`` and
``*TRS``), ANSYS (``TB,PRONY`` and ``TB,SHIFT``, ``TBDATA`` three values a command), LS-DYNA
(``*MAT_GENERAL_VISCOELASTIC`` with TREF, A, B from the shift law) and the csv. What each deck
holds, and why, is in :mod:`bayesfo.predictions.prony` and the export page of the docs."""

from __future__ import annotations

import math

from ..data.symbols import mode as mode_of
from ..data.symbols import modulus_symbol
from ..errors import InputError

#: Gas constant [J/(mol K)] and the kelvin of 0 °C, for the Arrhenius shift law.
GAS_CONSTANT = 8.314462618
KELVIN = 273.15
#: The formats of a series: a table and the decks of three finite-element codes.
FORMATS = ("csv", "abaqus", "ansys", "lsdyna")
#: Terms *MAT_GENERAL_VISCOELASTIC takes (the long-term modulus is one of them, with β = 0).
LSDYNA_MAX_TERMS = 18
#: Significant digits of the moduli, ratios and times written.
DIGITS = 10


def _has_unit(unit: str) -> bool:
    """Whether ``unit`` names a unit: not empty, not the arbitrary unit of data without one
    (``a.u.``: :func:`~bayesfo.structures.physical.stress_unit`, ``[G]`` of earlier versions)."""
    return bool(unit) and "[" not in unit and "a.u." not in unit


def deck_text(prony, fmt: str) -> str:
    """The series ``prony`` in ``fmt`` (one of :data:`~bayesfo.predictions.prony.FORMATS`)."""
    if fmt not in FORMATS:
        raise InputError(f"export: format must be one of {', '.join(FORMATS)}, got {fmt!r}",
                         where="export")
    e, mode = modulus_symbol(prony.symbol), mode_of(prony.symbol)
    head = [f"Prony series of {prony.source} (bayesfo), {mode} modulus {e}"
            + (f" in {prony.unit}" if _has_unit(prony.unit) else " (the data give no unit)")
            + ", as measured",
            f"fitted over t = {prony.window[0]:.4g} to {prony.window[1]:.4g} s (the data window)",
            *prony.terms_text(),
            *prony._reach_text(),
            f"g_inf = {prony.g_inf:.10g}", f"g_0 = {prony.g_0:.10g}",
            *prony.long_time_text(),
            *prony.error_text()]
    head += prony.extrapolation_text()
    if mode == "tensile" and fmt in ("abaqus", "ansys"):
        head.append("a tensile series: its ratios g_i/g_0 stand for the shear ratios the "
                    "code takes under a constant Poisson's ratio")
    if fmt in ("abaqus", "ansys"):
        head += prony._ratio_text()
    law = prony.shift_law
    if law is not None:
        head.append(prony._law_text())
    elif prony.shift_note:
        head.append(prony.shift_note)
        head += [f"  T = {t:.6g} °C: log10 a_T = {a:.6g}" for t, a in prony.shift_table]
    if fmt == "csv":
        lines = [f"# {h}" for h in head] + ["tau_s,g_i"]
        lines += [f"{t:.10g},{g:.10g}" for t, g in zip(prony.tau, prony.g, strict=True)]
    elif fmt == "abaqus":
        lines = [f"** {h}" for h in head]
        # *ELASTIC takes Young's modulus and Poisson's ratio: a shear series' G0 is
        # E0 = 2 (1 + nu) G0 there; a tensile series' own G0 is E0.
        lines.append(f"** instantaneous modulus {e}0 = {prony.g_0:.10g}: give "
                     + ("it" if mode == "tensile" else f"E0 = 2 (1 + nu) {e}0")
                     + " with Poisson's ratio nu in *ELASTIC, MODULI=INSTANTANEOUS")
        lines.append("*VISCOELASTIC, TIME=PRONY")
        lines += [f"{r:.{DIGITS}g}, 0., {t:.{DIGITS}g}"
                  for t, r in zip(prony.tau, prony.ratios(), strict=True)]
        if law is not None:
            p, t_ref = law["parameters"], law["reference_temperature"]
            if law["name"] == "wlf":
                lines += ["*TRS, DEFINITION=WLF", f"{t_ref:.10g}, {p['C1']:.10g}, "
                                                  f"{p['C2']:.10g}"]
            else:
                lines += ["*TRS, DEFINITION=ARRHENIUS",
                          f"{t_ref:.10g}, {p['Ea']:.10g}, {GAS_CONSTANT:.10g}, {-KELVIN:.10g}"]
    elif fmt == "lsdyna":
        lines = _lsdyna(prony, head)
    else:  # ansys
        lines = _ansys(prony, head)
    return "\n".join(lines) + "\n"


def _ansys(prony, head: list[str]) -> list[str]:
    """TB,PRONY with TBDATA three values a command, as ANSYS's own curve fitting (TBFT)
    writes them, and TB,SHIFT for a master curve's law."""
    e, mode = modulus_symbol(prony.symbol), mode_of(prony.symbol)
    lines = [f"! {h}" for h in head]
    lines.append(f"! instantaneous modulus {e}0 = {prony.g_0:.10g}"
                 + (": the ratios alpha_i = g_i/E0 serve as the shear ratios (constant "
                    "Poisson's ratio)" if mode == "tensile" else ""))
    lines.append(f"TB,PRONY,1,,{prony.tau.size},SHEAR")
    pairs = [v for t, r in zip(prony.tau, prony.ratios(), strict=True) for v in (r, t)]
    for start in range(0, len(pairs), 3):
        chunk = ",".join(f"{v:.{DIGITS}g}" for v in pairs[start:start + 3])
        lines.append(f"TBDATA,{start + 1},{chunk}")
    law = prony.shift_law
    if law is not None:
        p, t_ref = law["parameters"], law["reference_temperature"]
        if law["name"] == "wlf":
            lines += ["TB,SHIFT,1,,3,WLF",
                      f"TBDATA,1,{t_ref:.10g},{p['C1']:.10g},{p['C2']:.10g}"]
        else:
            lines += ["! Arrhenius as Tool-Narayanaswamy: ln A = (Ea/R) (1/T_r - 1/T), "
                      "T in kelvin", "TB,SHIFT,1,,2,TN",
                      f"TBDATA,1,{t_ref + KELVIN:.10g},{p['Ea'] / GAS_CONSTANT:.10g}"]
    return lines


def lsdyna_shift(prony) -> tuple[float, float, float] | None:
    """TREF [K], A and B of *MAT_GENERAL_VISCOELASTIC for the shift law, None without one.

    LS-DYNA scales time by its shift function, t' = ∫ Φ(T) dt, so Φ = 1/a_T, and its
    manual (*MAT_076 remarks) writes Φ = exp(−A (T − TREF)/(B + T − TREF)) for WLF and
    Φ = exp(−A (1/T − 1/TREF)) for Arrhenius (B = 0). With log10 a_T = −C1 (T − T_r)/(C2
    + T − T_r): A = −C1 ln 10, B = C2; with ln a_T = (E_a/R)(1/T − 1/T_r): A = E_a/R.
    TREF in kelvin (the card asks TREF > 0; for WLF only T − TREF counts)."""
    law = prony.shift_law
    if law is None:
        return None
    p, t_ref = law["parameters"], law["reference_temperature"] + KELVIN
    if law["name"] == "wlf":
        return t_ref, -p["C1"] * math.log(10.0), p["C2"]
    return t_ref, p["Ea"] / GAS_CONSTANT, 0.0


def _lsdyna(prony, head: list[str]) -> list[str]:
    """*MAT_GENERAL_VISCOELASTIC in LS-DYNA's fixed 10-character fields."""
    tensile = mode_of(prony.symbol) == "tensile"
    rows = [(g, 1.0 / t) for t, g in zip(prony.tau, prony.g, strict=True)]
    if prony.g_inf > 0:
        rows.append((prony.g_inf, 0.0))
    if len(rows) > LSDYNA_MAX_TERMS:
        said = (f"LS-DYNA's *MAT_GENERAL_VISCOELASTIC takes at most {LSDYNA_MAX_TERMS} terms "
                f"(G_inf counts as one), this series has {len(rows)}; ask for fewer")
        raise InputError(f"export: {said} (terms {LSDYNA_MAX_TERMS - 1} or 1 per decade), or for "
                         "the automatic number of terms",
                         command_line=f"{said} (--terms {LSDYNA_MAX_TERMS - 1} or --per-decade 1), "
                         "or for the automatic number of terms")

    def field(v: float) -> str:  # 4 significant digits: a blank keeps the fields apart
        return f"{v:10.3E}" if v != 0 else f"{0.0:10.1f}"

    lines = [f"$ {h}" for h in head]
    lines += [("$ GI: the tensile moduli E_i in the data's unit: the card takes shear "
               "moduli, divide each by 2(1+nu)" if tensile else
               "$ GI: shear moduli in the data's unit")
              + "; BETAI = 1/tau_i [1/s]; the row with BETAI = 0 is the long-time modulus",
              "$ RO (density) and BULK (bulk modulus) are not measured in "
              + ("a tensile DMA" if tensile else "shear")
              + ": give them in the units of your model"]
    shift = lsdyna_shift(prony)
    if shift is not None:
        tref, a, b = shift
        if b:
            lines.append(f"$ TREF, A, B: the WLF law in LS-DYNA's form, time scaled by "
                         f"Phi(T) = exp(-A (T - TREF)/(B + T - TREF)) = 1/a_T: A = -C1 ln 10 "
                         f"= {a:.6g}, B = C2 = {b:.6g}, TREF = T_ref in kelvin = "
                         f"{tref:.6g} (temperatures in kelvin)")
        else:
            lines.append(f"$ TREF, A, B: the Arrhenius law in LS-DYNA's form, time scaled "
                         f"by Phi(T) = exp(-A (1/T - 1/TREF)) = 1/a_T: A = Ea/R = {a:.6g} K, "
                         f"B = 0, TREF = T_ref in kelvin = {tref:.6g}")
    else:
        tref = a = b = 0.0
    lines += ["*KEYWORD", "*MAT_GENERAL_VISCOELASTIC",
              "$      MID        RO      BULK       PCF        EF      TREF         A"
              "         B",
              f"{1:>10d}" + " " * 20 + field(0.0) * 2 + field(tref) + field(a) + field(b),
              "$     LCID        NT    BSTART     TRAMP     LCIDK       NTK   BSTARTK"
              "    TRAMPK",
              f"{0:>10d}{0:>10d}" + field(0.0) * 2 + f"{0:>10d}{0:>10d}" + field(0.0) * 2,
              "$       GI     BETAI        KI    BETAKI"]
    lines += [field(g) + field(b) + field(0.0) * 2 for g, b in rows]
    lines.append("*END")
    return lines
