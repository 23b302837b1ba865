"""A comparison in a notebook: the ranking as ``bayesfo compare`` prints it, in HTML (what
:meth:`~bayesfo.comparison.results.Comparison._repr_html_` shows)."""

from __future__ import annotations

from .._text import block, table
from .table import TEXT_COLUMNS


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
    return block(f"Comparison on '{d.label}'", lines,
                  table([h for h, _, _ in TEXT_COLUMNS], cells))
