"""A master curve in a notebook: the structure, the reference temperature, the shift law and
the shifts, in HTML (what :meth:`~bayesfo.tts.result.MasterCurve._repr_html_` shows)."""

from __future__ import annotations

from .._text import block, number, table


def mastercurve_html(mc) -> str:
    """The master structure, the reference temperature, the shift law and the shifts."""
    law = mc.shift_law()
    probabilities = ", ".join(f"{k} {number(v, '.3f')}" for k, v in law["probabilities"].items())
    valid = {True: "superposition holds by the model-free tests",
             False: "superposition not established", None: ""}[mc.tts_valid]
    lines = [f"{len(mc.temperatures)} isotherms, {min(mc.temperatures):g} to "
             f"{max(mc.temperatures):g} °C; shifts: "
             + ("free (each isotherm its own)" if mc.law == "free" else f"the {mc.law} law")
             + f"; preferred law {law['name']} ({probabilities})", valid, mc.misfit()]
    rows = [[f"{f['temperature']:g}", number(f["log10_aT"]["mean"], ".3f"),
             number(f["log10_aT"]["sd"], ".3f"),
             f"[{number(f['log10_aT']['hdi_low'], '.3f')}, "
             f"{number(f['log10_aT']['hdi_high'], '.3f')}]"] for f in mc.shift_factors()]
    return block(f"Master curve of {mc.structure} at {mc.reference_temperature:g} °C", lines,
                  table(["T [°C]", "log10 a_T", "sd", "94 % HDI"], rows))
