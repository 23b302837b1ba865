"""Predictions and Prony series in a notebook: values with their band, a series' terms and
errors, in HTML (what their ``_repr_html_`` shows)."""

from __future__ import annotations

from .._text import block, elided, table
from ..data.symbols import modulus_symbol


def prediction_html(p) -> str:
    """The values with their band, the middle rows elided where there are many."""
    from ..structures.physical import in_brackets

    who = p.structure if p.weights is None else f"{p.average} average"
    rows = []
    for i in elided(len(p.x)):
        if i is None:
            rows.append(["…"] * 4)
            continue
        rows.append([f"{p.x[i]:.5g}", f"{p.median[i]:.5g}",
                     f"[{p.hdi_low[i]:.5g}, {p.hdi_high[i]:.5g}]",
                     "extrapolated" if p.extrapolated[i] else ""])
    title = f"{p.symbol or p.quantity}{in_brackets(p.unit)} of {who}" + (
        f" at {p.temperature:g} °C" if p.temperature is not None else "")
    return block(title, list(p.notes),
                  table([f"x [{p.x_unit}]", "median", "94 % HDI", ""], rows))


def prony_html(prony, suffix: str = "") -> str:
    """The series' terms, moduli and stated errors (``suffix``: the unit after a modulus,
    " Pa", or nothing for data without one)."""
    from ..structures.physical import in_brackets

    e = modulus_symbol(prony.symbol)
    unit = in_brackets(prony.unit)
    rows = []
    for i in elided(prony.tau.size):
        rows.append(["…", "…"] if i is None else [f"{prony.tau[i]:.6g}", f"{prony.g[i]:.6g}"])
    lines = [f"{e}0 = {prony.g_0:.6g}, {e}_inf = {prony.g_inf:.6g}{suffix}; fitted over t = "
             f"{prony.window[0]:.4g} to {prony.window[1]:.4g} s", *prony.terms_text(),
             *prony.error_text(), prony.shift_note]
    if prony.shift_law is not None:
        lines.append(prony._law_text())
    return block(f"Prony series of {prony.source}: {prony.tau.size} terms", lines,
                  table(["tau [s]", f"g_i{unit}"], rows))
