"""What rheometer, DMA and rheology programs write around their tables: the format of a file
(TRIOS, RheoCompass, RepTate, pyvisco), step and interval names, temperatures in step names and
metadata lines, RepTate's parameter line and headerless columns, ``#`` comment lines."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

from .._io import show
from ..errors import InputError
from .columns import identify
from .tables import Line, Table, number_like
from .temperature import temperature_in_text

REPTATE_PARAMS = re.compile(r"^\s*(?:[A-Za-z][\w ]*=[^;=]*;)+\s*$")


def preamble(lines: list[Line], first: Table) -> str:
    start = first.header_line or first.first_line
    text = [ln.number for ln in lines if ln.number < start and ln.kind in ("text", "data")]
    if not text:
        return ""
    span = f"line {text[0]}" if len(text) == 1 else f"lines {text[0]}–{text[-1]}"
    return f"{span}: {len(text)} line(s) before the first table (metadata)"


def comment_meta(lines: list[Line]) -> dict[str, str]:
    meta: dict[str, str] = {}
    for ln in lines:
        if ln.kind == "comment":
            key, sep, value = ln.text.strip().lstrip("#").partition(":")
            key = key.strip().lower()
            if sep and key in ("kind", "units", "name", "temperature", "symbol"):
                meta.setdefault(key, value.strip())
    return meta


def file_format(path: Path, lines: list[Line]) -> str:
    texts = [ln.text.strip() for ln in lines[:400] if ln.kind in ("text", "data")]
    first = texts[0] if texts else ""
    suffix = path.suffix.lower()
    if first == "[Version]" or any("LIMS export" in t for t in texts[:5]):
        return "TA Instruments TRIOS (LIMS text export)"
    if any(t.lower().startswith(("[step]", "trios version", "procedure name")) for t in texts):
        return "TA Instruments TRIOS export"
    if any(t.startswith(("Interval data:", "Project:", "Interval and data points:"))
           for t in texts):
        return "Anton Paar RheoCompass export"
    if suffix in (".tts", ".osc") or REPTATE_PARAMS.match(first):
        return f"RepTate {suffix}" if suffix in (".tts", ".osc") else "RepTate file"
    if any("E_stor" in t for t in texts[:3]):
        return "pyvisco CSV"
    return "delimited text"


def reptate_parameters(lines: list[Line]) -> dict[str, str]:
    for ln in lines:
        if ln.kind == "blank":
            continue
        text = ln.text.strip()
        if REPTATE_PARAMS.match(text):
            return {k.strip(): v.strip() for k, v in
                    (p.split("=", 1) for p in text.split(";") if "=" in p)}
        return {}
    return {}


def table_columns(table: Table, reptate: bool, mapping: dict):
    """The columns of a table, and the convention that named them (RepTate's headerless files
    hold ω [rad/s], G' [Pa], G'' [Pa] in their first three columns)."""
    if table.header is not None:
        return identify(table.header, table.units), ""
    n = len(table.rows[0].cells)
    numbered = [f"column {i + 1}" for i in range(n)]
    if mapping and any(re.fullmatch(r"\d+", str(v).split("[")[0].strip())
                       for v in mapping.values() if v):
        return identify(numbered, None), ""
    if reptate and n >= 3 and not mapping:
        header = ["omega", "storage", "loss"] + numbered[3:]
        cols = identify(header, ["rad/s", "Pa", "Pa"] + [""] * (n - 3))
        cols = [replace(c, header=numbered[i], quantity="modulus" if i in (1, 2) else c.quantity)
                for i, c in enumerate(cols)]
        return cols, ("RepTate's convention: columns 1–3 are ω [rad/s], G' [Pa], G'' [Pa]")
    return None, ""


def table_label(table: Table) -> str:
    """The name of a step or interval from the lines before its header."""
    ctx = table.context
    start = max((k for k, ln in enumerate(ctx) if re.fullmatch(r"\[.*\]", ln.text.strip())),
                default=-1)
    label = ""
    for k, ln in enumerate(ctx[start + 1:], start=start + 1):
        cells = [c for c in ln.cells if c] or [ln.text.strip()]
        key = cells[0].lower().rstrip(":")
        if key in ("step name", "step", "segment", "interval", "test") and len(cells) > 1:
            label = cells[1]
        elif k == start + 1 and start >= 0 and len(cells) == 1 and \
                ctx[start].text.strip().lower() == "[step]":
            label = cells[0]
    return label


def context_temperature(table: Table) -> tuple[float | None, str]:
    label = table_label(table)
    t = temperature_in_text(label) if label else None
    if t is not None:
        return t, f"from the step name '{label}'"
    for ln in table.context[-6:]:
        cells = [c for c in ln.cells if c]
        if len(cells) >= 2 and cells[0].lower().rstrip(":") in ("temperature", "temp"):
            t = temperature_in_text(" ".join(cells[1:]))
            if t is not None:
                return t, f"from the line '{ln.text.strip()}' (line {ln.number})"
    return None, ""


def no_table(where: str, lines: list[Line]) -> InputError:
    content = [ln for ln in lines if ln.kind in ("text", "data")]
    if not content:
        return InputError(f"{where} is empty: expected a header row and rows of numbers")
    for ln in content:
        if len(ln.cells) == 1:
            for d, dname, cli in ((";", "semicolon", ";"), ("\t", "tab", "tab"),
                                  (",", "comma", ",")):
                # A row of numbers left whole: the delimiter (not a header row alone, which
                # has no numbers to split).
                if sum(number_like(c.strip()) for c in ln.cells[0].split(d)) >= 2:
                    return InputError(
                        f"{where}, line {ln.number}: found one column {show(ln.cells[0])}: the "
                        f"delimiter looks like {dname} ({d!r}); give delimiter={d!r} "
                        f"(--delimiter {cli}), or leave it out to have it sniffed")
    return InputError(f"{where}: no rows of numbers (at least two numbers per row) found"
                      + (" after its header: the file has no data rows" if content else "")
                      + "; is it a data file?")
