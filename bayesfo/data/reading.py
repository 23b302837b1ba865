"""What the tolerant reader returns besides the data: :class:`Reading`, the record of every
choice it made for one data set, and :class:`Isotherm`, one data set of a file with its
temperature."""

from __future__ import annotations

from dataclasses import dataclass, field

from .frequency_response import FrequencyResponse


@dataclass(frozen=True, eq=False)
class Reading:
    """How one data set was read from a file: every choice the reader made.

    Attributes
    ----------
    path : str
        The file.
    format : str
        What the file was read as (``"bayesfo CSV"``, ``"TA Instruments TRIOS export"``,
        ``"Anton Paar RheoCompass export"``, ``"RepTate .tts"``, ``"pyvisco CSV"``,
        ``"delimited text"``, ``"Excel workbook"``...).
    encoding, delimiter, decimal : str
        Text encoding; ``"comma"``, ``"semicolon"``, ``"tab"`` or ``"spaces"``; ``"."`` or ``","``.
    block : str
        The data set within the file (a step name, ``"Set 3"``, ``"20 °C"``), or ``""``.
    index : int
        Its position among the file's data sets, from 1.
    lines : tuple of int
        First and last line (row of a sheet) of its data.
    header_line, units_line : int or None
        Lines of the header and of the units row.
    columns : tuple of (str, str)
        (role, column as written) for every column used: ``omega`` or ``freq``, the response
        columns, and ``sigma``, ``series``, ``temperature``, ``block`` where present.
    units_converted : tuple of str
        Each conversion to SI, e.g. ``"'E_stor': MPa → Pa (× 1e+06)"``.
    units_assumed : tuple of str
        Units taken without a label in the file, e.g. ``"'Angular Frequency': rad/s (no unit
        given; an angular frequency)"``.
    kind, kind_reason : str
        The kind of the response and why.
    temperature : float or None
        Temperature [°C] of the data set, and ``temperature_source``: where it came from.
    rows_skipped : tuple of str
        Lines not read as data of this set, and why (file header, other steps, empty rows,
        rows that repeat a frequency).
    columns_ignored, columns_kept : tuple of str
        Other columns: ignored (text, or not numeric throughout), or kept as numbers in
        ``extra``.
    not_used : tuple of str
        Other complete response forms in the file that were not used (e.g. the compliance
        columns of a TRIOS export when the moduli are read).
    extra : dict
        Column -> values of the kept columns, in the order of the data (sorted by frequency).
    """

    path: str
    format: str
    encoding: str = "UTF-8"
    delimiter: str = "comma"
    decimal: str = "."
    block: str = ""
    index: int = 1
    lines: tuple[int, int] = (0, 0)
    header_line: int | None = None
    units_line: int | None = None
    columns: tuple[tuple[str, str], ...] = ()
    units_converted: tuple[str, ...] = ()
    units_assumed: tuple[str, ...] = ()
    kind: str = "generic"
    kind_reason: str = ""
    temperature: float | None = None
    temperature_source: str = ""
    rows_skipped: tuple[str, ...] = ()
    columns_ignored: tuple[str, ...] = ()
    columns_kept: tuple[str, ...] = ()
    not_used: tuple[str, ...] = ()
    extra: dict = field(default_factory=dict)

    def notes(self) -> tuple[str, ...]:
        """The record as one-line notes (what ``bayesfo inspect`` prints and
        ``summary.json["data"]["notes"]`` holds)."""
        where = f"lines {self.lines[0]}–{self.lines[1]}" if self.lines[0] else ""
        head = f"read as {self.format}" + (f", {self.block}" if self.block else "")
        sep = ("spreadsheet cells" if self.delimiter == "cells"
               else f"{self.delimiter}-separated")
        out = [f"{head}: {where}; {sep}, decimal '{self.decimal}', "
               f"{self.encoding}" + (f"; header on line {self.header_line}" if self.header_line
                                     else "; no header row")
               + (f", units on line {self.units_line}" if self.units_line else "")]
        out.append("columns used: " + "; ".join(f"{role} ← '{col}'" for role, col in self.columns))
        out.append("units converted to SI: " + ("; ".join(self.units_converted)
                                                if self.units_converted else "none"))
        if self.units_assumed:
            out.append("units not in the file: " + "; ".join(self.units_assumed))
        out.append(self.kind_reason or f"kind {self.kind}")
        if self.temperature is not None:
            out.append(f"temperature {self.temperature:g} °C ({self.temperature_source})")
        if self.not_used:
            out.append("also in the file, not used: " + "; ".join(self.not_used))
        if self.columns_kept:
            out.append(f"other columns kept as metadata ({len(self.columns_kept)}): "
                       + _first(self.columns_kept))
        if self.columns_ignored:
            out.append(f"columns ignored ({len(self.columns_ignored)}): "
                       + _first(self.columns_ignored))
        out.extend(f"skipped: {s}" for s in self.rows_skipped)
        return tuple(out)

    def to_dict(self) -> dict:
        """Plain-Python record for JSON (without the values of the kept columns)."""
        return {
            "path": self.path, "format": self.format, "encoding": self.encoding,
            "delimiter": self.delimiter, "decimal": self.decimal, "block": self.block,
            "index": self.index, "lines": list(self.lines), "header_line": self.header_line,
            "units_line": self.units_line, "columns": {r: c for r, c in self.columns},
            "units_converted": list(self.units_converted),
            "units_assumed": list(self.units_assumed), "kind": self.kind,
            "kind_reason": self.kind_reason, "temperature_C": self.temperature,
            "temperature_source": self.temperature_source,
            "rows_skipped": list(self.rows_skipped), "columns_ignored": list(self.columns_ignored),
            "columns_kept": list(self.columns_kept), "not_used": list(self.not_used),
        }


@dataclass(frozen=True, eq=False)
class Isotherm:
    """One data set of a file: an isotherm, a step or an interval.

    Attributes
    ----------
    data : FrequencyResponse
        ω [rad/s] and the response in SI units (Pa, 1/Pa) where the file states its units; its
        ``notes`` hold :meth:`Reading.notes`.
    temperature : float or None
        Temperature [°C], if the file gives one (step name, temperature column, header).
    label : str
        The data set within the file (``Reading.block``), or ``""`` for a file of one data set.
    reading : Reading
        Every choice the reader made.
    """

    data: FrequencyResponse
    temperature: float | None
    label: str
    reading: Reading

    def to_dict(self) -> dict:
        """What ``bayesfo inspect --json`` prints for this data set."""
        d = self.data
        info = d.to_dict()
        info.update(block=self.label, temperature_C=self.temperature,
                    omega_ref=d.omega_ref, g_ref=d.g_ref,
                    magnitude_min=float(d.magnitude.min()), magnitude_max=float(d.magnitude.max()),
                    reading=self.reading.to_dict())
        return info


def contract_text(data: FrequencyResponse, temperature: float | None = None) -> str:
    """``data`` as a CSV of the bayesfo contract (``omega,real,imag[,sigma]``, numbers written
    exactly), with ``# name:``, ``# kind:``, ``# units:``, ``# temperature:``, ``# source:`` and
    ``# note:`` lines (:meth:`FrequencyResponse.to_csv_text`)."""
    comments = []
    if temperature is not None:
        comments.append(f"temperature: {temperature!r} °C")
    if data.source:
        comments.append(f"source: {data.source}")
    comments.extend(f"note: {note}" for note in data.notes)
    return data.to_csv_text(comments)


#: Column names a note lists before "and N more" (a file may have thousands).
SHOWN_COLUMNS = 20


def _first(names) -> str:
    """``'a', 'b', 'c'``, or the first :data:`SHOWN_COLUMNS` and how many more."""
    shown = ", ".join(f"'{c}'" for c in names[:SHOWN_COLUMNS])
    rest = len(names) - SHOWN_COLUMNS
    return shown + (f" and {rest} more" if rest > 0 else "")
