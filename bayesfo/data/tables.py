"""The tables of a lab file: text decoding, delimiter and decimal-mark sniffing, and the blocks of
header, units row and data rows that rheometer and DMA software write (TRIOS steps, RheoCompass
intervals, pyvisco's units row, RepTate's headerless columns), with the lines around each.

Nothing here knows what a column means (see :mod:`bayesfo.data.columns`).
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from .._io import INVISIBLE, csv_cells, parse_number, read_text_file, show, text_position
from ..errors import DataWarning, InputError
from .units import looks_like_unit

#: Delimiters the reader recognises, with the names it reports.
DELIMITERS = {",": "comma", ";": "semicolon", "\t": "tab", " ": "spaces"}

_NUMLIKE = re.compile(r"[+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?")
_GROUPED = re.compile(r"[+-]?\d{1,3}(?:([.,'])\d{3})(?:\1\d{3})*(?:[.,]\d*)?(?:[eE][+-]?\d+)?")


def number_like(cell: str) -> bool:
    """Whether a cell is a number in either decimal mark (``1.5``, ``1,5``, ``1.234,5``)."""
    c = cell.strip()
    return bool(c) and (_NUMLIKE.fullmatch(c) is not None or _GROUPED.fullmatch(c) is not None)


def to_number(cell: str, decimal: str) -> float:
    """The number in a cell written with the decimal mark ``decimal`` ('.' or ','), thousands
    separators allowed where they group digits by three (``1,234.5``; ``1.234,5``).

    Raises
    ------
    ValueError
        As :func:`bayesfo._io.parse_number`, for the caller to name file, line and column.
    """
    text = cell.strip()
    m = _GROUPED.fullmatch(text)
    if m and m.group(1) != decimal:
        text = text.replace(m.group(1), "")
    if decimal == ",":
        if "." in text and "," not in text and _NUMLIKE.fullmatch(text):
            raise ValueError(f"{show(text)} has a decimal point, but this file writes decimal "
                             "commas; give decimal='.' (--decimal .) if that is wrong")
        text = text.replace(",", ".")
    return parse_number(text)


# ---------------------------------------------------------------------- decoding
def decode(path, max_bytes: int) -> tuple[str, str]:
    """The text of a file and the name of its encoding: UTF-8 (with or without a byte-order
    mark), UTF-16 (as Anton Paar RheoCompass writes) or Windows-1252/Latin-1 (RepTate, older
    instrument software).

    Raises
    ------
    InputError
        As :func:`bayesfo._io.read_text_file` (missing, not a regular file, too large, invisible
        control characters), or if the bytes are not text in any of these encodings.
    """
    try:
        return read_text_file(path, max_bytes=max_bytes), "UTF-8"
    except InputError as exc:
        message = str(exc)
        if "is not a UTF-8 text file" not in message and "a NUL byte" not in message:
            raise
        first_error = exc
    with open(path, "rb") as fh:  # read_text_file has checked it is a regular file, not too big
        raw = fh.read(max_bytes + 1)
    half = len(raw) // 2
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        encoding, codec = "UTF-16", "utf-16"
    elif half and raw[1::2].count(0) > 0.9 * half:
        encoding, codec = "UTF-16 (little-endian, no byte-order mark)", "utf-16-le"
    elif half and raw[0::2].count(0) > 0.9 * half:
        encoding, codec = "UTF-16 (big-endian, no byte-order mark)", "utf-16-be"
    elif b"\x00" in raw:
        raise first_error
    else:
        encoding, codec = "Windows-1252 (Latin-1)", "cp1252"
    try:
        text = raw.decode(codec)
    except UnicodeDecodeError:
        if codec != "cp1252":
            raise InputError(f"file '{path}' is neither UTF-8 nor UTF-16 text; save it as UTF-8 "
                             "text") from None
        encoding, text = "Latin-1", raw.decode("latin-1")
    text = text.removeprefix("\ufeff")
    bad = INVISIBLE.search(text)
    if bad:
        line, char = text_position(text, bad.start())
        raise InputError(f"file '{path}', line {line}, character {char}: a control character "
                         f"(U+{ord(bad.group()):04X}, invisible) in {encoding} text; is it a text "
                         "file? save it as UTF-8 text")
    return text, encoding


# ---------------------------------------------------------------------- lines and tables
@dataclass
class Line:
    """A line of the file: its number, the cells and what it is."""

    number: int
    text: str
    cells: list[str]
    kind: str  # "blank", "comment", "text", "data"


@dataclass
class Table:
    """A header (or none), an optional units row and the data rows under them, with the text
    lines between the previous table and this one (step names, interval and temperature lines)."""

    header: list[str] | None
    header_line: int | None
    units: list[str] | None
    units_line: int | None
    rows: list[Line]
    context: list[Line] = field(default_factory=list)

    @property
    def first_line(self) -> int:
        return self.rows[0].number

    @property
    def last_line(self) -> int:
        return self.rows[-1].number


def _split(line: str, delimiter: str, where: str, lineno: int) -> list[str]:
    if delimiter == " ":
        if "\t" in line:
            return [c.strip() for c in line.split("\t")]
        return line.split()
    return [c.strip() for c in csv_cells(line, where, lineno, delimiter, DELIMITERS[delimiter])]


def _kind_of(cells: list[str]) -> str:
    nonempty = [c for c in cells if c]
    if not nonempty:
        return "blank"
    numeric = sum(number_like(c) for c in nonempty)
    return "data" if numeric >= 2 and numeric * 2 >= len(nonempty) else "text"


def sniff_delimiter(lines: list[str], where: str) -> str:
    """The delimiter that splits most lines into the same number of numeric cells.

    Ties go to tab, then semicolon, then comma, then runs of spaces.
    """
    sample = [(i, s) for i, s in lines if s.strip() and not s.lstrip().startswith("#")][:2000]
    best, best_score = ",", -1
    for delim in ("\t", ";", ",", " "):
        if delim != " " and not any(delim in s for _, s in sample):
            continue
        counts: Counter = Counter()
        nums: dict[int, int] = {}
        for i, s in sample:
            cells = _split(s, delim, where, i)
            n = sum(number_like(c) for c in cells)
            if n >= 2:
                counts[len(cells)] += 1
                nums[len(cells)] = nums.get(len(cells), 0) + n
        if not counts:
            continue
        modal = counts.most_common(1)[0][0]
        score = nums[modal]
        if score > best_score:
            best, best_score = delim, score
    return best


def sniff_decimal(rows: list[list[str]], delimiter: str, where: str) -> str:
    """'.' or ',' from the numbers of the data rows; raises where only thousands-grouped commas
    (``1,234``) are seen, which could be either."""
    dot = comma = grouped_comma = 0
    for cells in rows:
        for c in cells:
            if not number_like(c):
                continue
            has_dot, has_comma = "." in c, "," in c
            if has_dot and has_comma:
                return "," if c.rfind(",") > c.rfind(".") else "."
            if has_comma:
                comma += 1
                grouped_comma += bool(_GROUPED.fullmatch(c))
            elif has_dot:
                dot += 1
    if comma and dot:
        if grouped_comma == comma:
            return "."
        raise InputError(f"{where}: some numbers have a decimal point and others a decimal "
                         "comma; give decimal='.' or decimal=',' (--decimal)")
    if comma:
        if grouped_comma == comma:
            raise InputError(f"{where}: numbers such as '1,234' could have a decimal comma or "
                             "a thousands separator; give decimal=',' or decimal='.' (--decimal)")
        return ","
    return "."


def split_file(text_lines: list[str], where: str, *, delimiter: str | None = None,
               first_line: int = 1) -> tuple[list[Line], str]:
    """Split every line into cells and classify it; returns the lines and the delimiter."""
    numbered = [(first_line + k, s) for k, s in enumerate(text_lines)]
    delim = delimiter if delimiter is not None else sniff_delimiter(numbered, where)
    out = []
    for i, s in numbered:
        stripped = s.strip()
        if not stripped:
            out.append(Line(i, s, [], "blank"))
        elif stripped.startswith("#"):
            out.append(Line(i, s, [], "comment"))
        else:
            cells = _split(s, delim, where, i)
            while cells and not cells[-1]:
                cells.pop()
            out.append(Line(i, s, cells, _kind_of(cells)))
    return out, delim


def _is_units_row(cells: list[str]) -> bool:
    nonempty = [c for c in cells if c.strip()]
    if not nonempty or any(number_like(c) for c in nonempty):
        return False
    return sum(looks_like_unit(c) for c in cells) >= 0.7 * len(cells)


_ROW_LABELS = ("variables", "interval data:", "units", "data point", "")


def _fit_header(cells: list[str], n: int) -> list[str] | None:
    """The header cells aligned with data rows of ``n`` cells, or None if they cannot be."""
    if len(cells) < 2 or all(number_like(c) for c in cells if c):
        return None
    if len(cells) == n + 1 and cells[0].lower() in _ROW_LABELS + ("interval data",):
        return cells[1:]  # a row label that the data rows do not repeat
    # A header names every data cell; it may name more (columns without data at the end).
    return cells if len(cells) >= n else None


def find_tables(lines: list[Line], delimiter: str, where: str = "the file") -> list[Table]:
    """The tables of a classified file, in order.

    A table is a run of data lines with the same number of cells (blank and comment lines
    inside are skipped; a blank line followed by comment or text lines ends it), under a header
    line whose cells align with the data, optionally with a units row in between. A run without
    a header right after a table of as many columns, separated by blank and comment lines only,
    takes that table's header (blocks such as gnuplot's).

    Raises
    ------
    InputError
        Naming ``where`` and the line, where up to :data:`ODD_ROWS` data lines with another
        number of cells sit directly between the rows of a table (a stray delimiter, such as a
        thousands separator, or a missing cell): read as they are, they would end the table
        there and leave the rows after them without a header, unread.
    """
    tables: list[Table] = []
    k, n_lines = 0, len(lines)
    last_end = -1
    while k < n_lines:
        if lines[k].kind != "data":
            k += 1
            continue
        ncell = len(lines[k].cells)
        rows, j, broke = [], k, False
        while j < n_lines:
            ln = lines[j]
            if ln.kind == "data" and len(ln.cells) == ncell:
                rows.append(ln)
                j += 1
            elif ln.kind == "data" and rows and not broke and _resumes(lines, j, ncell):
                raise InputError(
                    f"{where}, line {ln.number}: {len(ln.cells)} cells where the rows above "
                    f"and below it have {ncell}: a stray delimiter (a thousands separator?) "
                    "or a missing cell; correct or remove the line")
            elif ln.kind == "comment" and not broke:
                j += 1
            elif ln.kind == "blank":
                broke = True
                j += 1
            else:
                break
            if broke and j < n_lines and lines[j].kind == "comment":
                break
        # back up over trailing blanks/comments so they belong to the context of the next table
        end = j
        while end > k and lines[end - 1].kind in ("blank", "comment"):
            end -= 1
        before = [ln for ln in lines[last_end + 1:k] if ln.kind in ("text", "comment", "data")]
        header = units = None
        header_line = units_line = None
        texts = [ln for ln in before if ln.kind != "comment"]
        if texts and texts[-1].kind == "text":
            cand = texts[-1]
            if _is_units_row(cand.cells) and len(texts) >= 2 and texts[-2].kind == "text":
                head = _fit_header(_realign(texts[-2], delimiter, ncell), ncell)
                if head is not None:
                    unit_cells = _realign(cand, delimiter, ncell)
                    if len(unit_cells) == len(head) + 1:
                        unit_cells = unit_cells[1:]
                    header, header_line = head, texts[-2].number
                    units, units_line = unit_cells, cand.number
            if header is None:
                head = _fit_header(_realign(cand, delimiter, ncell), ncell)
                if head is not None:
                    header, header_line = head, cand.number
        context = [ln for ln in before if header_line is None or ln.number < header_line]
        if (header is None and tables and not [ln for ln in context if ln.kind == "text"]
                and len(tables[-1].rows[0].cells) == ncell and tables[-1].header is not None):
            prev = tables[-1]
            header, header_line, units, units_line = (prev.header, prev.header_line,
                                                      prev.units, prev.units_line)
        tables.append(Table(header, header_line, units, units_line, rows, context))
        last_end = end - 1
        k = end if end > k else j
    return tables


#: Consecutive data lines with another number of cells that :func:`find_tables` takes for
#: damaged rows of the table around them (more are a table of their own).
ODD_ROWS = 3


def _resumes(lines: list[Line], j: int, ncell: int) -> bool:
    """Whether the data line ``j`` with another number of cells than ``ncell``, and at most
    :data:`ODD_ROWS` − 1 more such data lines after it, are followed directly by a data line
    with ``ncell`` cells."""
    for following in lines[j + 1:j + 1 + ODD_ROWS]:
        if following.kind != "data":
            return False
        if len(following.cells) == ncell:
            return True
    return False


def _realign(line: Line, delimiter: str, n: int) -> list[str]:
    """The cells of a header or units line; between data split at runs of spaces, a header
    without tabs is split at runs of two or more spaces when that matches the data."""
    if delimiter != " " or "\t" in line.text:
        return line.cells
    wide = [c for c in re.split(r"\s{2,}", line.text.strip()) if c]
    return wide if len(wide) == n and len(line.cells) != n else line.cells


#: Lines of a sheet read at most: the rows a data set may have (:data:`MAX_ROWS` of the CSV
#: reader) and room for headers, comments and a few tables beside them.
EXCEL_MAX_LINES = 110_000
#: Cells a sheet may span (rows × columns of its declared extent): a workbook with a stray cell
#: far out (``XFD200000``) is refused before any row is read, instead of being padded to
#: billions of empty cells.
EXCEL_MAX_CELLS = 5_000_000


def _cell_text(v) -> str:
    """The text of one cell value (numbers written exactly)."""
    import math

    if v is None or (isinstance(v, float) and math.isnan(v)):
        return ""
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, float):
        return repr(v)
    return str(v).strip()


class _TooLarge(InputError):
    """A sheet beyond the caps of :func:`_openpyxl_sheets`."""


def _too_large(path: Path, sheet: str, rows: int, cols: int) -> _TooLarge:
    from openpyxl.utils import get_column_letter

    return _TooLarge(
        f"file '{path}', sheet '{sheet}': the sheet spans {rows} rows × {cols} columns (to cell "
        f"{get_column_letter(cols)}{rows}), more than a data set needs (at most "
        f"{EXCEL_MAX_LINES} rows and {EXCEL_MAX_CELLS} cells); delete the cells beyond the "
        "data (Ctrl+End shows the last one) or save the table as CSV")


def _openpyxl_sheets(path: Path) -> list[tuple[str, list[list[str]]]]:
    """The sheets of an ``.xlsx`` workbook, streamed row by row (openpyxl's read-only mode)
    within :data:`EXCEL_MAX_LINES` and :data:`EXCEL_MAX_CELLS`. A sheet beyond them is left
    out with a :class:`~bayesfo.errors.DataWarning` (an instrument's log beside the data), and
    refused only when no other sheet is left; error cells (``#N/A``) read as empty."""
    import warnings

    import openpyxl


    try:
        book = openpyxl.load_workbook(path, read_only=True, data_only=True)
    except Exception as exc:  # noqa: BLE001 - any failure of the workbook library is bad input
        raise InputError(f"file '{path}' cannot be read as an Excel workbook: {exc}") from None
    out, refused = [], []
    try:
        for ws in book.worksheets:
            try:
                out.append((str(ws.title), _sheet_rows(path, ws)))
            except _TooLarge as exc:
                refused.append(str(exc))
    finally:
        book.close()
    if refused and not out:
        raise InputError(refused[0])
    for why in refused:
        warnings.warn(f"{why}; the sheet is left out", DataWarning, stacklevel=3)
    return out


_EXCEL_ERRORS = {"#N/A", "#DIV/0!", "#VALUE!", "#REF!", "#NAME?", "#NUM!", "#NULL!"}


def _sheet_rows(path: Path, ws) -> list[list[str]]:
    declared = (ws.max_row or 0, ws.max_column or 0)  # the sheet's dimension, if given
    if declared[0] > EXCEL_MAX_LINES or declared[0] * declared[1] > EXCEL_MAX_CELLS:
        raise _too_large(path, ws.title, *declared)
    # Some writers declare a wrong dimension (A1:A1); within the caps, read every row there is.
    ws.reset_dimensions()
    rows, cells_read = [], 0
    try:
        for values in ws.iter_rows(values_only=True):
            cells = ["" if isinstance(v, str) and v in _EXCEL_ERRORS else _cell_text(v)
                     for v in values]
            while cells and not cells[-1]:
                cells.pop()
            rows.append(cells)
            cells_read += len(values)
            if len(rows) > EXCEL_MAX_LINES or cells_read > EXCEL_MAX_CELLS:
                raise _TooLarge(
                    f"file '{path}', sheet '{ws.title}': more than "
                    + (f"{EXCEL_MAX_LINES} rows" if len(rows) > EXCEL_MAX_LINES
                       else f"{EXCEL_MAX_CELLS} cells")
                    + f" (row {len(rows)} read), more than a data set needs; delete the rows "
                    "beyond the data or save the table as CSV")
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 - a damaged sheet is bad input
        raise InputError(f"file '{path}', sheet '{ws.title}' cannot be read: {exc}") from None
    while rows and not rows[-1]:
        rows.pop()
    return rows


def excel_sheets(path: Path) -> list[tuple[str, list[list[str]]]]:
    """The sheets of an Excel workbook as rows of cell texts (numbers written exactly).

    ``.xlsx`` workbooks are streamed (at most :data:`EXCEL_MAX_LINES` rows and
    :data:`EXCEL_MAX_CELLS` cells per sheet); ``.xls`` workbooks (at most 65 536 × 256 cells
    by their format) are read with xlrd.

    Raises
    ------
    InputError
        If openpyxl (``.xlsx``) or xlrd (``.xls``) is not installed, the workbook cannot be
        read, or a sheet spans more cells than a data set needs.
    """
    engine = "xlrd" if path.suffix.lower() == ".xls" else "openpyxl"
    try:
        __import__(engine)
    except ImportError:
        raise InputError(f"file '{path}': reading Excel workbooks needs the package {engine} "
                         f"(pip install {engine}"
                         + ", or pip install 'bayesfo[excel]'"
                         + "); or save the sheet as CSV or text") from None
    if engine == "openpyxl":
        return _openpyxl_sheets(path)
    import xlrd

    # xlrd itself rather than pandas' read_excel, whose xlrd engine pandas deprecates.
    try:
        book = xlrd.open_workbook(str(path), on_demand=True)
        try:
            return [(sheet.name, [[_cell_text(v) for v in sheet.row_values(i)]
                                  for i in range(sheet.nrows)])
                    for sheet in book.sheets()]
        finally:
            book.release_resources()
    except Exception as exc:  # noqa: BLE001 - any failure of the workbook library is bad input
        raise InputError(f"file '{path}' cannot be read as an Excel workbook: {exc}") from None


def classify_rows(rows: list[list[str]]) -> list[Line]:
    """Excel rows (cells already split) as classified lines, numbered from 1 as the sheet."""
    out = []
    for i, cells in enumerate(rows, start=1):
        cells = list(cells)
        while cells and not cells[-1]:
            cells.pop()
        first = cells[0] if cells else ""
        kind = "comment" if first.startswith("#") else _kind_of(cells)
        out.append(Line(i, "\t".join(cells), cells, kind))
    return out
