"""Text of results for people: numbers in tables (:func:`number`) and the plain HTML that a
result's ``_repr_html_`` shows in a notebook (:func:`table`, :func:`block`), for every layer
that renders one of its results.

Examples
--------
>>> from bayesfo._text import table
>>> table(["x", "y"], [["1", "<2"]])
'<table><tr><th>x</th><th>y</th></tr><tr><td>1</td><td>&lt;2</td></tr></table>'
"""

from __future__ import annotations

import html
import math


def number(value, spec: str = ".2f", missing: str = "-") -> str:
    """One number of a table in text: ``value`` formatted by ``spec``, or ``missing`` where it
    is undefined (None, NaN or infinite; the reason is among the warnings).

    Examples
    --------
    A value that rounds to zero is written without a sign ("0.000", not "-0.000").

    >>> number(-12.3456), number(float("nan")), number(None, missing="–")
    ('-12.35', '-', '–')
    >>> number(-1e-17, ".3f"), number(-0.0004, ".3f"), number(-0.0, "g")
    ('0.000', '0.000', '0')
    """
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return missing
    text = format(value, spec)
    if text.startswith("-") and not any(c in "123456789" for c in text.split("e")[0]):
        return text[1:]
    return text


#: Rows of x shown for a prediction or terms for a Prony series before the middle is elided.
MAX_ROWS = 12


def table(headers, rows) -> str:
    """A plain HTML table, every cell escaped."""
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def block(title: str, lines: list[str], *tables: str) -> str:
    text = "".join(f"<p>{html.escape(x)}</p>" for x in lines if x)
    return (f"<div class='bayesfo'><strong>{html.escape(title)}</strong>{text}"
            + "".join(tables) + "</div>")


def elided(n: int) -> list[int | None]:
    """Row indices to show: all of up to :data:`MAX_ROWS`, else the first and last halves
    with None for the rows left out."""
    if n <= MAX_ROWS:
        return list(range(n))
    half = MAX_ROWS // 2
    return [*range(half), None, *range(n - half, n)]
