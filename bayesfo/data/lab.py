"""Reading lab files: :func:`read` (one data set) and :func:`read_isotherms` (every data set of a
file), for the bayesfo CSV and the exports of rheometer, DMA and rheology software.

A file of the bayesfo contract is read by :func:`~bayesfo.data.read_csv`, unchanged. Any other
text file (or Excel workbook) is split into tables (:mod:`~bayesfo.data.tables`), its columns are
recognised by name and unit (:mod:`~bayesfo.data.columns`), converted to SI (:mod:`~bayesfo.data.
units`), split into isotherms by steps, a block column or a temperature column, and each data
set passes the checks and limits of the contract reader. Every choice is recorded in a
:class:`~bayesfo.data.reading.Reading` and in the notes of the response.
"""

from __future__ import annotations

import os
import re
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from .._io import csv_cells, show, split_lines
from ..errors import DataWarning, InputError
from .assemble import assemble_table
from .columns import ROLES, Choice, Column, NotResponse, choose
from .csv_reader import (
    KNOWN_COLUMNS,
    MAX_FILE_BYTES,
    MAX_FREQUENCIES,
    MAX_ROWS,
    read_csv,
)
from .formats import (
    comment_meta,
    context_temperature,
    file_format,
    no_table,
    preamble,
    reptate_parameters,
    table_columns,
    table_label,
)
from .frequency_response import KINDS, FrequencyResponse
from .reading import Isotherm, Reading
from .tables import (
    DELIMITERS,
    Line,
    Table,
    classify_rows,
    decode,
    excel_sheets,
    find_tables,
    sniff_decimal,
    split_file,
)
from .temperature import looks_like_kelvin, temperature_in_text

DUPLICATES = ("error", "first", "mean")
_EXCEL = (".xlsx", ".xlsm", ".xls")


def read(path: str | os.PathLike, *, kind: str | None = None, columns: dict | None = None,
         block: int | str | None = None, delimiter: str | None = None,
         decimal: str | None = None, duplicates: str = "error", units: str | None = None,
         name: str | None = None) -> FrequencyResponse:
    """Read one frequency response from a data file: the bayesfo CSV or a lab export.

    Parameters
    ----------
    path : path-like
        A CSV of the bayesfo contract (read as :func:`read_csv` reads it), or a text export of
        a rheometer, DMA or rheology program (TA TRIOS, Anton Paar RheoCompass, TA ARES/
        Orchestrator, RepTate ``.tts``/``.osc``, pyvisco), any delimited text with recognisable
        headers, or an Excel workbook (needs openpyxl). See ``docs/lab_files.md``.
    kind : {"compliance", "modulus", "generic"}, optional
        What the response is; by default what the columns say (G', E', |G*|, η* a modulus;
        J', |J*| a compliance), else a ``# kind:`` line, else as :func:`read_csv`. With both
        moduli and compliances in the file, ``"compliance"`` reads the compliances.
    columns : dict, optional
        Role -> column, for columns the reader does not recognise or to choose between several:
        roles ``omega`` [rad/s], ``freq`` [Hz], ``storage``, ``loss``, ``real``, ``imag``,
        ``magnitude``, ``phase`` (loss angle δ), ``phase_deg`` (phase of G), ``tan_delta``,
        ``viscosity`` (|η*|), ``eta_dyn`` (η'), ``eta_out`` (η''), ``sigma``, ``series``,
        ``temperature``, ``block``. A column is its header cell (with or without its unit) or
        its number from 1; a unit in brackets replaces the file's (``"E_stor [Pa]"``); None
        means "no such column" (e.g. ``{"temperature": None}`` reads a master curve whose rows
        carry their original temperature as one data set).
    block : int or str, optional
        For a file of several data sets: which one (its number from 1, or its label as
        :func:`read_isotherms` gives it).
    delimiter : {",", ";", "\\t", " "}, optional
        The cell delimiter (``" "``: runs of spaces); sniffed by default.
    decimal : {".", ","}, optional
        The decimal mark; sniffed by default.
    duplicates : {"error", "first", "mean"}
        What to do with rows that repeat a frequency (no ``series`` column): refuse, keep the
        first, or average them (e.g. overlapping isotherms of a master curve).
    units, name : str, optional
        Labels of the response (as :func:`read_csv`).

    Returns
    -------
    FrequencyResponse
        ω in rad/s and the response in SI units (Pa, 1/Pa) where the file states its units; its
        ``notes`` record every choice (columns, units converted, kind and why, delimiter, rows
        skipped, columns ignored).

    Raises
    ------
    InputError
        Naming the file, line and column: anything :func:`read_csv` refuses, and a file where
        two readings are possible (two storage moduli, a unit that is not recognised, a file of
        several data sets without ``block``), with the option that resolves it.

    Examples
    --------
    >>> import bayesfo as bf
    >>> data = bf.read("oscillation.txt")  # doctest: +SKIP
    >>> data = bf.read("export.csv", columns={"omega": "Ang. Freq.", "storage": "G'"})  # doctest: +SKIP
    """
    sets = read_isotherms(path, kind=kind, columns=columns, delimiter=delimiter, decimal=decimal,
                          duplicates=duplicates, units=units, name=name)
    if block is not None:
        return select(sets, block, f"file '{path}'").data
    if len(sets) == 1:
        return sets[0].data
    head = f"file '{path}' holds {len(sets)} data sets ({_summary(sets)}); "
    tail = "; or, if the rows form one data set such as a master curve, ignore the grouping with "
    raise InputError(
        f"{head}read one with {_choice_example(sets, 'block={}', repr)}, every one with "
        f"bayesfo.data.read_isotherms{tail}columns={{'temperature': None, 'block': None}}",
        command_line=f"{head}choose one with {_choice_example(sets, '--block {}', _quoted)}, "
                     f"every one with bayesfo batch FILE{tail}--columns temperature=,block=")


def _choice_example(sets, form: str, quote) -> str:
    """How to choose one of ``sets``, ``form`` the option: by number from 1, and by temperature
    or label where the first one has one (``block=N (N from 1, e.g. block=1) or its
    temperature (block='20 °C')``)."""
    first = sets[0]
    by_name = (f"{first.temperature:g} °C" if first.temperature is not None
               else first.label if first.label and not first.label.isdigit() else None)
    text = f"{form.format('N')} (N from 1, e.g. {form.format(1)})"
    if by_name is not None and quote(by_name) is not None:
        kind = "temperature" if first.temperature is not None else "label"
        text += f" or its {kind} ({form.format(quote(by_name))})"
    return text


def _quoted(text: str) -> str | None:
    """``text`` as one shell word (in double quotes where needed: POSIX shells and Windows
    alike); None where no simple quoting serves (or where the option parser would take it
    for an option: a leading '-' without a space)."""
    if text.startswith("-") and " " not in text:
        return None
    if re.fullmatch(r"[A-Za-z0-9_.+-]+", text):
        return text
    if any(c in text for c in '"$`\\!%\n'):
        return None
    return f'"{text}"'


def select(sets: list[Isotherm], block: int | str, where: str) -> Isotherm:
    """The data set ``block`` (number from 1, or label) of :func:`read_isotherms`' result.

    A bare number given as text (``--block 20``) on a file whose data sets have temperatures
    is refused where a data set is at that temperature too: the number and the temperature
    would name different sets. ``"#20"`` is the 20th set, ``"20 °C"`` the one at 20 °C."""
    if isinstance(block, str) and re.fullmatch(r"#\s*[0-9]+", block.strip()):
        block = int(block.strip()[1:])
    if isinstance(block, str) and block.strip().isdigit() and not any(
            s.label == block for s in sets):
        at = [s for s in sets if s.temperature is not None
              and abs(s.temperature - float(block)) <= 0.5]
        k = int(block)
        if at and not (1 <= k <= len(sets) and sets[k - 1] is at[0]):
            number = (f"data set {k} is at {sets[k - 1].temperature:g} °C"
                      if 1 <= k <= len(sets) and sets[k - 1].temperature is not None
                      else f"there is no data set {k}" if not 1 <= k <= len(sets)
                      else f"data set {k} is {sets[k - 1].label}")
            text = (f"{where}: block {block.strip()} is ambiguous: {number}, and a data set "
                    f"is at {at[0].temperature:g} °C; give ")
            raise InputError(f"{text}block='{block.strip()} °C' for the temperature or "
                             f"block={k} (an int) for the number",
                             command_line=f'{text}--block "{block.strip()} °C" for the '
                                          f'temperature or --block "#{k}" for the number')
    if isinstance(block, (int, np.integer)) or (isinstance(block, str) and block.isdigit()
                                               and not any(s.label == block for s in sets)):
        k = int(block)
        if not 1 <= k <= len(sets):
            raise InputError(f"{where}: block {k} does not exist; the file holds {len(sets)} "
                             f"data set(s): {_summary(sets)}")
        return sets[k - 1]
    hits = [s for s in sets if s.label.lower() == str(block).strip().lower()]
    if not hits:
        # A temperature ("20 °C", "20C", "-40.0 °C") names the data set at that temperature.
        match = _TEMPERATURE.fullmatch(str(block).strip())
        if match:
            # Measured temperatures (a column's mean, 19.98) match within 0.5 °C.
            hits = [s for s in sets if s.temperature is not None
                    and abs(s.temperature - float(match[1])) <= 0.5]
            if len(hits) > 1:
                text = (f"{where}: {len(hits)} data sets are at "
                        f"{show(str(block), ascii_only=False)}; the file holds "
                        f"{_summary(sets)}; give the number")
                raise InputError(f"{text} (block=N, N from 1)",
                                 command_line=f"{text} (--block N, N from 1)")
    if not hits:
        text = (f"{where}: no data set {show(str(block), ascii_only=False)}; the file holds "
                f"{_summary(sets)}; give ")
        raise InputError(
            f"{text}the number (block=N, N from 1), the label or the temperature "
            "(e.g. block='20 °C')",
            command_line=f"{text}the number (--block N, N from 1), the label or the "
                         'temperature (e.g. --block "20 °C")')
    return hits[0]


#: A block given as a temperature in °C (:func:`select`).
_TEMPERATURE = re.compile(r"([+-]?[0-9]+(?:\.[0-9]*)?)\s*(?:°\s*)?C", re.IGNORECASE)


def _summary(sets) -> str:
    labels = [f"{k}: {s.label or 'data'}" + (f" ({s.temperature:g} °C)" if s.temperature is not
                                              None and "°C" not in s.label else "")
              for k, s in enumerate(sets, start=1)]
    return ", ".join(labels[:6]) + (f", … ({len(labels)} in all)" if len(labels) > 6 else "")


def read_isotherms(path: str | os.PathLike, *, kind: str | None = None,
                   columns: dict | None = None, delimiter: str | None = None,
                   decimal: str | None = None, duplicates: str = "error",
                   units: str | None = None, name: str | None = None) -> list[Isotherm]:
    """Read every data set of a file: the steps of a TRIOS export, the intervals of a
    RheoCompass export, the sets of a pyvisco file, the isotherms of a file with a temperature
    column, or the one data set of any other file.

    Parameters are those of :func:`read` (without ``block``).

    Returns
    -------
    list of Isotherm
        In file order, each with its ``data`` (a :class:`FrequencyResponse`), ``temperature``
        [°C] or None, ``label`` and ``reading`` (every choice made). Steps that are not
        frequency sweeps (flow curves, amplitude sweeps at one frequency) are skipped and named
        in each reading's ``rows_skipped``.

    Raises
    ------
    InputError
        As :func:`read`; also when no table of the file holds a frequency response.
    """
    path = Path(path)
    where = f"file '{path}'"
    _check_arguments(kind, delimiter, decimal, duplicates)
    mapping = _mapping(columns)
    if path.suffix.lower() in _EXCEL:
        per_sheet, refused = [], []
        for sheet, rows in excel_sheets(path):
            lines = classify_rows(rows)
            if any(ln.kind == "data" for ln in lines):
                try:
                    per_sheet.append((sheet, _read_lines(
                        path, f"{where}, sheet '{sheet}'", lines, "cells", "Excel workbook",
                        decimal, mapping, kind, duplicates, units, name,
                        fmt=f"Excel workbook (sheet '{sheet}')")))
                except InputError as exc:  # a header or log sheet of numbers beside the data
                    refused.append(exc)
        if not per_sheet:
            if refused:
                raise refused[0]
            raise InputError(f"{where}: no sheet holds a table of numbers")
        for exc in refused:
            warnings.warn(f"{exc}; the sheet is left out, the other sheets are read",
                          DataWarning, stacklevel=2)
        if len(per_sheet) == 1:
            return _renumber(per_sheet[0][1])
        return _renumber([_relabel(iso, ", ".join(x for x in (sheet, iso.label) if x), path)
                          for sheet, sets in per_sheet for iso in sets])
    text, encoding = decode(path, MAX_FILE_BYTES)
    lines_text = split_lines(text)
    # A bayesfo CSV is read by the contract's reader, which refuses repeated frequencies; asked
    # to keep the first or average them, the general reader takes it (it knows its columns).
    if (not mapping and delimiter is None and decimal is None and duplicates == "error"
            and _is_contract(lines_text, where)):
        return [_contract(path, kind, units, name, lines_text)]
    lines, delim = split_file(lines_text, where, delimiter=delimiter)
    return _renumber(_read_lines(path, where, lines, DELIMITERS[delim], encoding, decimal,
                                 mapping, kind, duplicates, units, name))


def is_contract_csv(path: str | os.PathLike) -> bool:
    """Whether the file's first row (after comments) is a header of the bayesfo CSV contract,
    so that :func:`read_csv` reads it; False for an unreadable file."""
    try:
        text, _ = decode(path, MAX_FILE_BYTES)
    except InputError:
        return False
    try:
        return _is_contract(split_lines(text), f"file '{path}'")
    except InputError:
        return False


def _is_contract(lines: list[str], where: str) -> bool:
    for lineno, line in enumerate(lines, start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        cells = [c.strip().lower() for c in csv_cells(line, where, lineno)]
        return all(c in KNOWN_COLUMNS for c in cells)
    return True  # empty or comments only: read_csv says so


def columns_from_text(text: str | None) -> dict:
    """The ``columns`` mapping of the text of a ``--columns`` option.

    For example ``omega="Ang. Freq.",storage="G'",temperature=`` (an empty column: no such
    column).

    Raises
    ------
    InputError
        If an item is not ``ROLE=COLUMN`` or names an unknown role.
    """
    if not text:
        return {}
    import csv

    try:
        items = next(csv.reader([text], skipinitialspace=True))
    except (csv.Error, StopIteration):
        raise InputError(f"--columns: cannot read {show(text)}; write ROLE=COLUMN pairs "
                         "separated by commas") from None
    out: dict = {}
    for item in items:
        role, sep, column = item.partition("=")
        role = role.strip()
        if not sep or not role:
            raise InputError(f"--columns: {show(item)} is not ROLE=COLUMN (roles: "
                             f"{', '.join(ROLES)})")
        if role not in ROLES:
            raise InputError(f"--columns: unknown role {show(role)}; roles are {', '.join(ROLES)}")
        if role in out:
            raise InputError(f"--columns: role {show(role)} given twice")
        column = column.strip()
        if len(column) > 1 and column[0] == column[-1] and column[0] in "\"'":
            column = column[1:-1]  # one pair of quotes: storage="G'" is G', loss="G''" G''
        out[role] = column or None
    return out


def _check_arguments(kind, delimiter, decimal, duplicates) -> None:
    if kind is not None and kind not in KINDS:
        raise InputError(f"argument 'kind' must be one of {', '.join(KINDS)}, got {kind!r}")
    if delimiter is not None and delimiter not in DELIMITERS:
        raise InputError(f"argument 'delimiter' must be one of ',', ';', '\\t' or ' ' (runs of "
                         f"spaces), got {delimiter!r}")
    if decimal is not None and decimal not in (".", ","):
        raise InputError(f"argument 'decimal' must be '.' or ',', got {decimal!r}")
    if duplicates not in DUPLICATES:
        raise InputError(f"argument 'duplicates' must be one of {', '.join(DUPLICATES)}, "
                         f"got {duplicates!r}")


def _mapping(columns) -> dict:
    if columns is None:
        return {}
    if not isinstance(columns, dict):
        raise InputError(f"argument 'columns' must be a dict of role -> column, got "
                         f"{type(columns).__name__}")
    for role in columns:
        if role not in ROLES:
            raise InputError(f"argument 'columns': unknown role {show(str(role))}; roles are "
                             f"{', '.join(ROLES)}")
    if "omega" in columns and "freq" in columns and columns["omega"] and columns["freq"]:
        raise InputError("argument 'columns': give 'omega' or 'freq', not both")
    return dict(columns)


def _relabel(iso: Isotherm, label: str, path: Path) -> Isotherm:
    """The data set under another label (the sheet of a workbook of several)."""
    reading = replace(iso.reading, block=label)
    core = iso.data.notes[len(iso.reading.notes()):]
    name = iso.data.name or path.stem
    name = name.rsplit(", " + iso.label, 1)[0] if iso.label else name
    data = replace(iso.data, name=f"{name}, {label}", notes=reading.notes() + core)
    return replace(iso, label=label, reading=reading, data=data)


def _renumber(sets: list[Isotherm]) -> list[Isotherm]:
    out = []
    for k, s in enumerate(sets, start=1):
        out.append(replace(s, reading=replace(s.reading, index=k)))
    return out


# ---------------------------------------------------------------------- the contract file
def _contract(path, kind, units, name, lines) -> Isotherm:
    data = read_csv(path, kind=kind, units=units, name=name)
    meta = {}
    header_line = None
    for lineno, line in enumerate(lines, start=1):
        stripped = line.strip()
        if stripped.startswith("#"):
            key, sep, value = stripped.lstrip("#").partition(":")
            if sep:
                meta.setdefault(key.strip().lower(), value.strip())
        elif stripped and header_line is None:
            header_line = lineno
            header = [c.strip().lower() for c in csv_cells(line, f"file '{path}'", lineno)]
    temperature = _plain_temperature(meta.get("temperature"), f"file '{path}'")
    reason = (data.notes[0] if data.notes and data.notes[0].startswith("kind modulus")
              else f"kind {data.kind} as asked" if kind is not None
              else f"kind {data.kind} from the file's '# kind:' line" if "kind" in meta
              else f"kind {data.kind}: the default for these columns")
    reading = Reading(str(path), "bayesfo CSV", header_line=header_line,
                      lines=(header_line + 1, len(lines)), columns=tuple((c, c) for c in header),
                      kind=data.kind, kind_reason=reason, temperature=temperature,
                      temperature_source="'# temperature:' line" if temperature is not None
                      else "")
    return Isotherm(data, temperature, "", reading)


def _plain_temperature(text: str | None, where: str = "") -> float | None:
    if not text:
        return None
    if looks_like_kelvin(text):
        value = float(text.replace("C", "").strip())
        warnings.warn(f"{where + ': ' if where else ''}'# temperature: {text}' has no unit and "
                      f"is read as {value:g} °C, yet it looks like kelvin "
                      f"({value - 273.15:g} °C); write '{text} K' or '{text} C'", DataWarning,
                      stacklevel=3)
    found = temperature_in_text(text)
    if found is not None:
        return found
    try:
        return float(text.replace("C", "").strip())
    except ValueError:
        return None


# ---------------------------------------------------------------------- other files
def _read_lines(path, where, lines: list[Line], delimiter, encoding, decimal, mapping, kind,
                duplicates, units, name, fmt=None) -> list[Isotherm]:
    meta = comment_meta(lines)
    tables = [t for t in find_tables(lines, " " if delimiter == "spaces" else delimiter, where)]
    if not tables:
        raise no_table(where, lines)
    n_rows = sum(len(t.rows) for t in tables)
    if n_rows > MAX_ROWS:
        raise InputError(f"{where}: more than {MAX_ROWS} data rows; a data set may have at most "
                         f"{MAX_FREQUENCIES} frequencies")
    fmt = fmt or file_format(path, lines)
    reptate = fmt.startswith("RepTate")
    if decimal is None:
        decimal = sniff_decimal([r.cells for t in tables for r in t.rows], delimiter, where)
    params = reptate_parameters(lines) if reptate else {}
    file_kind = meta.get("kind")
    if file_kind is not None and file_kind not in KINDS:
        raise InputError(f"{where}: kind must be one of {', '.join(KINDS)}, got "
                         f"{show(file_kind)}")
    found: list[tuple[Table, Choice, list[Column]]] = []
    skipped: list[str] = []
    refused: list[tuple[Table, InputError]] = []
    for table in tables:
        cols, convention = table_columns(table, reptate, mapping)
        if cols is not None:
            # a header name without data in any row (a ragged table) plays no part
            filled = {i for ln in table.rows for i, c in enumerate(ln.cells) if c}
            cols = [c if c.index in filled or c.role is None else replace(c, role=None)
                    for c in cols]
        at = f"{where}, line {table.header_line}" if table.header_line else where
        if cols is None:
            if len(table.rows) > 1:
                skipped.append(f"lines {table.first_line}–{table.last_line}: numbers without a "
                               "header row")
            refused.append((table, InputError(
                f"{where}, line {table.first_line}: numbers without a header row; name the "
                "columns by number, e.g. --columns omega=1,storage=2,loss=3 (columns= in "
                "the API)")))
            continue
        try:
            choice = choose(cols, mapping, kind, file_kind, at)
        except NotResponse as exc:
            if table.header_line is not None:
                reason = str(exc).split(": ", 1)[-1].split(": need", 1)[0]
                skipped.append(f"{table_label(table) or 'table'} (lines {table.header_line}–"
                               f"{table.last_line}): {reason}")
            refused.append((table, exc))
            continue
        if convention:
            choice = replace(choice, kind_reason=choice.kind_reason + "; " + convention)
        found.append((table, choice, cols))
    if not found:
        table, exc = max(refused, key=lambda r: (r[0].header is not None, len(r[0].rows)))
        raise exc
    context = {"path": path, "where": where, "format": fmt, "encoding": encoding,
               "delimiter": delimiter, "decimal": decimal, "duplicates": duplicates,
               "units": units, "name": name if name is not None else meta.get("name"),
               "meta": meta, "params": params, "skipped": skipped,
               "several_tables": len(found) > 1, "preamble": preamble(lines, tables[0])}
    if params:
        shown = "; ".join(f"{k}={v}" for k, v in params.items())
        context["preamble"] = (f"line {lines[0].number}: RepTate parameters ({shown}) are not "
                               "read (T is a temperature without a unit; for a .tts file the "
                               "reference temperature of the master curve)")
    out: list[Isotherm] = []
    word = "interval" if fmt.startswith("Anton Paar") else "table"
    for k, (table, choice, cols) in enumerate(found, start=1):
        label = table_label(table) or (f"{word} {k}" if len(found) > 1 else "")
        out.extend(assemble_table(table, choice, cols, context, label,
                                  context_temperature(table)))
    if not out:
        raise InputError(f"{where}: no frequency sweep in the file; skipped: "
                         + "; ".join(context["skipped"]))
    out = [_complete_skips(iso, context["skipped"]) for iso in out]
    if len(out) == 1:
        out = [_file_temperature(out[0], meta, params)]
    return out


def _complete_skips(iso: Isotherm, skipped: list[str]) -> Isotherm:
    """Add the steps skipped after this data set was built (a later amplitude sweep)."""
    missing = tuple(s for s in skipped if s not in iso.reading.rows_skipped)
    if not missing:
        return iso
    reading = replace(iso.reading, rows_skipped=iso.reading.rows_skipped + missing)
    core = iso.data.notes[len(iso.reading.notes()):]
    return replace(iso, reading=reading, data=replace(iso.data, notes=reading.notes() + core))


def _file_temperature(iso: Isotherm, meta: dict, params: dict) -> Isotherm:
    if iso.temperature is not None:
        return iso
    t = _plain_temperature(meta.get("temperature"), f"file '{iso.data.source}'")
    source = "the '# temperature:' line"
    if t is None:
        return iso
    reading = replace(iso.reading, temperature=t, temperature_source=source)
    core = iso.data.notes[len(iso.reading.notes()):]
    data = replace(iso.data, notes=reading.notes() + core)
    return replace(iso, temperature=t, reading=reading, data=data)


__all__ = ["DUPLICATES", "columns_from_text", "is_contract_csv", "read", "read_isotherms",
           "select"]
