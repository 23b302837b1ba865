"""Results in a notebook: one HTML rendering per result type, which the results'
``_repr_html_`` call (Jupyter shows a :class:`~bayesfo.comparison.results.Comparison`,
:class:`~bayesfo.tts.result.MasterCurve`, :class:`~bayesfo.predictions.functions.Prediction`
or :class:`~bayesfo.predictions.prony.Prony` as a short table, the way lmfit shows its
``ModelResult``). The results stay plain data: they import this module only when a notebook
asks for the HTML, and it reads them without computing anything new.

Examples
--------
>>> from bayesfo.output.notebook import table
>>> table(["x", "y"], [["1", "<2"]])
'<table><tr><th>x</th><th>y</th></tr><tr><td>1</td><td>&lt;2</td></tr></table>'
"""

from __future__ import annotations

import html

from ..comparison.table import TEXT_COLUMNS, number

#: Rows of x shown for a prediction or terms for a Prony series before the middle is elided.
MAX_ROWS = 12


def table(headers, rows) -> str:
    """A plain HTML table, every cell escaped."""
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _block(title: str, lines: list[str], *tables: str) -> str:
    text = "".join(f"<p>{html.escape(x)}</p>" for x in lines if x)
    return (f"<div class='bayesfo'><strong>{html.escape(title)}</strong>{text}"
            + "".join(tables) + "</div>")


def _elided(n: int) -> list[int | None]:
    """Row indices to show: all of up to :data:`MAX_ROWS`, else the first and last halves
    with None for the rows left out."""
    if n <= MAX_ROWS:
        return list(range(n))
    half = MAX_ROWS // 2
    return [*range(half), None, *range(n - half, n)]


def comparison_html(result) -> str:
    """The ranking as ``bayesfo compare`` prints it, as an HTML table, with the data."""
    d = result.data
    rows = result.table()
    ranked = [r for r in rows if not r.get("error")]
    cells = [[cell(r) for _, _, cell in TEXT_COLUMNS] for r in ranked]
    cells += [["-", r["structure"], r["n_params"], f"failed: {r['error']}",
               *[""] * (len(TEXT_COLUMNS) - 4)] for r in rows if r.get("error")]
    lines = [f"{d.n_frequencies} frequencies ({d.omega.min():.4g} to {d.omega.max():.4g} "
             f"rad/s), {d.kind}" + (f" in {d.units}" if d.units else "")
             + f"; seed {result.seed}; ranked by ln Z", *result.data_warnings]
    return _block(f"Comparison on '{d.label}'", lines,
                  table([h for h, _, _ in TEXT_COLUMNS], cells))


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
    return _block(f"Master curve of {mc.structure} at {mc.reference_temperature:g} °C", lines,
                  table(["T [°C]", "log10 a_T", "sd", "94 % HDI"], rows))


def prediction_html(p) -> str:
    """The values with their band, the middle rows elided where there are many."""
    from ..structures.physical import in_brackets

    who = p.structure if p.weights is None else f"{p.average} average"
    rows = []
    for i in _elided(len(p.x)):
        if i is None:
            rows.append(["…"] * 4)
            continue
        rows.append([f"{p.x[i]:.5g}", f"{p.median[i]:.5g}",
                     f"[{p.hdi_low[i]:.5g}, {p.hdi_high[i]:.5g}]",
                     "extrapolated" if p.extrapolated[i] else ""])
    title = f"{p.symbol or p.quantity}{in_brackets(p.unit)} of {who}" + (
        f" at {p.temperature:g} °C" if p.temperature is not None else "")
    return _block(title, list(p.notes),
                  table([f"x [{p.x_unit}]", "median", "94 % HDI", ""], rows))


def prony_html(prony) -> str:
    """The series' terms, moduli and stated errors."""
    from ..data.symbols import modulus_symbol
    from ..predictions.prony import _unit_suffix
    from ..structures.physical import in_brackets

    e = modulus_symbol(prony.symbol)
    unit, suffix = in_brackets(prony.unit), _unit_suffix(prony.unit)
    rows = []
    for i in _elided(prony.tau.size):
        rows.append(["…", "…"] if i is None else [f"{prony.tau[i]:.6g}", f"{prony.g[i]:.6g}"])
    lines = [f"{e}0 = {prony.g_0:.6g}, {e}_inf = {prony.g_inf:.6g}{suffix}; fitted over t = "
             f"{prony.window[0]:.4g} to {prony.window[1]:.4g} s", *prony.terms_text(),
             *prony.error_text(), prony.shift_note]
    if prony.shift_law is not None:
        lines.append(prony._law_text())
    return _block(f"Prony series of {prony.source}: {prony.tau.size} terms", lines,
                  table(["tau [s]", f"g_i{unit}"], rows))
