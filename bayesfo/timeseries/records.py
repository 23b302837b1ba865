"""Sine-record files and many records to one frequency response (thesis §4.3.1).

A record file holds ``time``, ``input``, ``output`` columns (and optionally ``series`` for
repeated runs) and its excitation frequency in a ``# omega:`` or ``# freq:`` comment line;
:func:`read_sine_record` reads and checks one, :func:`extract_frequency_response` analyses many
(:func:`bayesfo.timeseries.sine.analyze_sine`) into a :class:`~bayesfo.data.FrequencyResponse`, and
:func:`write_extraction` writes it as a CSV of the data contract with the harmonic content of
each record in its comments.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np

from bayesfo._io import atomic_write_text, csv_cells, parse_number, read_text_file, split_lines
from bayesfo.data import FrequencyResponse
from bayesfo.errors import InputError

from .sine import (
    GRID_TOLERANCE,
    MIN_SAMPLES,
    SAME_FREQUENCY_RTOL,
    HarmonicAnalysis,
    _check_and_analyze,
    _check_n_harmonics,
    _check_positive,
    _grid_violation,
)

__all__ = ["read_sine_record", "extract_frequency_response", "write_extraction"]

_RECORD_COLUMNS = ("time", "input", "output", "series")
_REQUIRED_COLUMNS = ("time", "input", "output")

# --------------------------------------------------------------------------------------------
# record files
# --------------------------------------------------------------------------------------------
_META = re.compile(r"^#\s*(omega|freq)\s*[:=]\s*(.*?)\s*$", re.IGNORECASE)
_META_UNITS = {"omega": ("", "rad/s"), "freq": ("", "hz")}


def _number(text: str) -> float:
    """A number of a record file: plain ASCII decimal notation (not ``1_0``), or ``nan``/``inf``
    returned as such for the caller to name as not finite.

    Raises
    ------
    ValueError
        With the reason, e.g. "'abc' is not a number".
    """
    try:
        return parse_number(text)
    except ValueError:
        if re.fullmatch(r"[+-]?(?:nan|inf|infinity)", text.strip(), re.I):
            value = float(text)
            if not math.isfinite(value):
                return value
        raise


def _parse_meta(path: Path, lineno: int, key: str, text: str) -> float:
    parts = text.split()
    units = _META_UNITS[key]
    if not parts or len(parts) > 2 or (len(parts) == 2 and parts[1].lower() not in units):
        raise InputError(
            f"{path}, line {lineno}: '# {key}:' must be followed by a number"
            f"{' and optionally rad/s' if key == 'omega' else ' and optionally Hz'}, got {text!r}"
        )
    try:
        value = _number(parts[0])
    except ValueError:
        raise InputError(
            f"{path}, line {lineno}: '# {key}:' value {parts[0]!r} is not a number"
        ) from None
    if not math.isfinite(value) or value <= 0:
        raise InputError(
            f"{path}, line {lineno}: '# {key}:' value must be finite and > 0, got {parts[0]!r}"
        )
    return value if key == "omega" else 2.0 * np.pi * value


def read_sine_record(path):
    """Read one sine record file.

    Format: comma-separated text with a header row; lines starting with ``#`` are comments and
    blank lines are ignored. Columns (any order, case-insensitive): ``time`` [s], ``input``,
    ``output``, and optionally ``series``, an integer id of a repeated series; all series must
    share the same time vector. A comment ``# omega: <rad/s>`` or ``# freq: <Hz>`` gives the
    excitation frequency (both may be given if they agree to 1e-6).

    Parameters
    ----------
    path : str or os.PathLike
        Record file.

    Returns
    -------
    t : numpy.ndarray, shape (n,)
        Sample times in seconds.
    u, y : numpy.ndarray, shape (n_series, n)
        Input and output, one row per series in order of first appearance (one row when there
        is no ``series`` column).
    omega : float or None
        Excitation frequency in rad/s from the ``# omega:`` or ``# freq:`` comment, else None.

    Raises
    ------
    InputError
        Naming the file and, where it applies, the line and column: file missing or unreadable;
        no header; unknown, duplicated or missing columns; a row with the wrong number of cells;
        an empty, non-numeric, NaN or infinite cell; a non-integer series id; times not
        increasing within a series or not uniformly spaced; series of different lengths or time
        vectors; fewer than ``MIN_SAMPLES`` samples per series; malformed or contradictory
        frequency comments.

    References
    ----------
    Thesis §4.2 (measurement procedure: repeated series per frequency), §4.3.1.
    """
    path = Path(path)
    text = read_text_file(path, "record file")

    header: list[str] | None = None
    header_line = 0
    omega_meta: dict[str, tuple[float, int]] = {}
    rows: list[tuple[int, list[str]]] = []
    for lineno, raw in enumerate(split_lines(text), start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            match = _META.match(line)
            if match:
                key = match.group(1).lower()
                if key in omega_meta:
                    raise InputError(
                        f"{path}, line {lineno}: second '# {key}:' comment "
                        f"(first on line {omega_meta[key][1]})"
                    )
                omega_meta[key] = (_parse_meta(path, lineno, key, match.group(2)), lineno)
            continue
        cells = csv_cells(line, str(path), lineno)
        if header is None:
            header, header_line = [c.strip().lower() for c in cells], lineno
            continue
        rows.append((lineno, cells))

    if header is None:
        raise InputError(f"{path}: no header row (expected columns time,input,output[,series])")
    for j, name in enumerate(header):
        if name not in _RECORD_COLUMNS:
            raise InputError(
                f"{path}, line {header_line}: unknown column {name!r} (column {j + 1}); "
                f"allowed: {', '.join(_RECORD_COLUMNS)}"
            )
        if header.index(name) != j:
            raise InputError(f"{path}, line {header_line}: column {name!r} appears twice")
    missing = [c for c in _REQUIRED_COLUMNS if c not in header]
    if missing:
        raise InputError(f"{path}, line {header_line}: missing column(s) {', '.join(missing)}")
    if not rows:
        raise InputError(f"{path}: no data rows after the header on line {header_line}")

    col = {name: j for j, name in enumerate(header)}
    values = np.empty((len(rows), 3))
    series_ids: list[int] = []
    for r, (lineno, cells) in enumerate(rows):
        if len(cells) != len(header):
            raise InputError(
                f"{path}, line {lineno}: {len(cells)} cells, but the header has "
                f"{len(header)} columns"
            )
        for c, name in enumerate(_REQUIRED_COLUMNS):
            text = cells[col[name]].strip()
            if not text:
                raise InputError(f"{path}, line {lineno}, column {name!r}: empty cell")
            try:
                v = _number(text)
            except ValueError as exc:
                raise InputError(f"{path}, line {lineno}, column {name!r}: {exc}") from None
            if not math.isfinite(v):
                raise InputError(f"{path}, line {lineno}, column {name!r}: {text!r} is not finite")
            values[r, c] = v
        if "series" in col:
            text = cells[col["series"]].strip()
            try:
                sid = _number(text)
            except ValueError:
                sid = math.nan
            if not math.isfinite(sid) or sid != round(sid):
                raise InputError(
                    f"{path}, line {lineno}, column 'series': {text!r} is not an integer series id"
                )
            series_ids.append(int(round(sid)))
        else:
            series_ids.append(0)

    linenos = np.array([ln for ln, _ in rows])
    ids = np.array(series_ids)
    order = list(dict.fromkeys(series_ids))
    groups = {sid: np.flatnonzero(ids == sid) for sid in order}
    first = order[0]
    n = groups[first].size
    for sid, idx in groups.items():
        label = f"series {sid}" if "series" in col else "the record"
        if idx.size < MIN_SAMPLES:
            raise InputError(
                f"{path}: {label} has {idx.size} samples; at least {MIN_SAMPLES} are needed"
            )
        ts = values[idx, 0]
        step = np.diff(ts)
        if np.any(step <= 0):
            k = int(np.flatnonzero(step <= 0)[0]) + 1
            raise InputError(
                f"{path}, line {linenos[idx[k]]}, column 'time': time {ts[k]:g} does not increase "
                f"within {label} (previous {ts[k - 1]:g})"
            )
        if idx.size != n:
            raise InputError(
                f"{path}: series {sid} has {idx.size} samples but series {first} has {n}; "
                "all series must share the same time vector"
            )
    t = values[groups[first], 0]
    dt = (t[-1] - t[0]) / (n - 1)
    bad = _grid_violation(t)
    if bad is not None:
        raise InputError(
            f"{path}, line {linenos[groups[first][bad[0]]]}, column 'time': time {t[bad[0]]:g} is "
            f"{bad[1]:.3g} steps off the uniform grid of step {dt:g} s "
            f"(tolerance {GRID_TOLERANCE:g} of a step)"
        )
    for sid in order[1:]:
        ts = values[groups[sid], 0]
        off = np.abs(ts - t) > GRID_TOLERANCE * dt
        if np.any(off):
            k = int(np.flatnonzero(off)[0])
            raise InputError(
                f"{path}, line {linenos[groups[sid][k]]}, column 'time': series {sid} has time "
                f"{ts[k]:g} where series {first} has {t[k]:g}; all series must share the same "
                "time vector"
            )
    u = np.vstack([values[groups[sid], 1] for sid in order])
    y = np.vstack([values[groups[sid], 2] for sid in order])

    omega = None
    if "omega" in omega_meta:
        omega = omega_meta["omega"][0]
    if "freq" in omega_meta:
        from_freq, line_f = omega_meta["freq"]
        if omega is not None and abs(from_freq - omega) > 1e-6 * omega:
            raise InputError(
                f"{path}, line {line_f}: '# freq:' gives {from_freq:g} rad/s but '# omega:' on "
                f"line {omega_meta['omega'][1]} gives {omega:g} rad/s"
            )
        if omega is None:
            omega = from_freq
    return t, u, y, omega


# --------------------------------------------------------------------------------------------
# many records -> FrequencyResponse
# --------------------------------------------------------------------------------------------
def extract_frequency_response(
    paths, *, kind="generic", n_harmonics=5, nonlinearity_threshold=0.05
):
    """Frequency response from sine records, one record file per excitation frequency.

    Parameters
    ----------
    paths : str, os.PathLike or sequence of them
        Record files (format of :func:`read_sine_record`).
    kind : str, optional
        Kind of the response, passed to :class:`bayesfo.data.FrequencyResponse`
        (``"compliance"``, ``"modulus"`` or ``"generic"``).
    n_harmonics, nonlinearity_threshold
        As in :func:`analyze_sine`.

    Returns
    -------
    response : bayesfo.data.FrequencyResponse
        Points sorted by omega. ``sigma`` is set when every record has two or more series
        (and a nonzero spread), otherwise it is None and a note says why; ``notes`` also list
        the records flagged as nonlinear, and ``source`` is the records' common directory.
    analyses : list of HarmonicAnalysis
        One per record, in the order of ``response``.

    Raises
    ------
    InputError
        If ``paths`` is empty, a record is invalid (the message names the file), or two records
        give the same frequency (within ``SAME_FREQUENCY_RTOL``).

    Warns
    -----
    NonlinearityWarning
        For every record whose output harmonics exceed the threshold, naming the file.

    References
    ----------
    Thesis §3.1 (one frequency-response point per excitation frequency), §4.3.1.
    """
    if isinstance(paths, (str, bytes, os.PathLike)):
        paths = [paths]
    try:
        paths = [Path(p) for p in paths]
    except TypeError:
        raise InputError("argument 'paths' must be a path or a sequence of paths") from None
    if not paths:
        raise InputError("argument 'paths' is empty; give at least one record file")
    k = _check_n_harmonics(n_harmonics)
    thr = _check_positive("nonlinearity_threshold", nonlinearity_threshold)

    results = []
    for path in paths:
        t, u, y, omega = read_sine_record(path)
        try:
            res = _check_and_analyze(t, u, y, omega, k, thr, where=f"{path}: ")
        except InputError as exc:
            raise InputError(f"{path}: {exc}") from None
        results.append((res, path))
    results.sort(key=lambda item: item[0].omega)
    for (a, pa), (b, pb) in zip(results, results[1:]):
        if b.omega - a.omega <= SAME_FREQUENCY_RTOL * b.omega:
            raise InputError(
                f"{pa} and {pb} both give omega = {a.omega:.6g} rad/s "
                f"(within {SAME_FREQUENCY_RTOL:g}); give one record per frequency"
            )
    analyses = [r for r, _ in results]
    omega = np.array([r.omega for r in analyses])
    response = np.array([r.response for r in analyses])
    lacking = [r for r in analyses if r.sigma is None or not r.sigma > 0]
    sigma = None if lacking else np.array([r.sigma for r in analyses])
    notes = [f"extracted from {len(analyses)} sine records"]
    if lacking and len(lacking) < len(analyses):
        notes.append("sigma unknown: some record has a single series or identical series")
    for r, path in results:
        if r.nonlinear:
            notes.append(
                f"nonlinear at omega = {r.omega:.6g} rad/s (output THD {r.thd_output:.3g})"
            )
        if r.omega_estimated:
            notes.append(f"{path}: no '# omega:' or '# freq:' line; omega = {r.omega:.6g} rad/s "
                         "estimated from the input's spectrum")
    try:
        source = os.path.commonpath([str(p.resolve().parent) for p in paths])
    except ValueError:  # records on different drives
        source = ""


    fr = FrequencyResponse(
        omega, response, sigma=sigma, kind=kind, source=source, notes=tuple(notes)
    )
    return fr, analyses


def write_extraction(path, fr, analyses):
    """Write an extracted frequency response and its harmonic analysis.

    ``path`` receives the contract CSV (``omega,real,imag[,sigma]``) through
    ``fr.to_csv(path)``; ``<stem>_harmonics.csv`` beside it receives one row per point with
    columns ``omega, gain, phase_deg, n_periods, n_series, h2 .. hK`` (output harmonic ratios,
    ``nan`` where not measurable), ``thd, nonlinear`` (``true``/``false``).

    Parameters
    ----------
    path : str or os.PathLike
        Output CSV file.
    fr : bayesfo.data.FrequencyResponse
        Response returned by :func:`extract_frequency_response`.
    analyses : sequence of HarmonicAnalysis
        The matching analyses, in the order of ``fr.omega``.

    Returns
    -------
    tuple of pathlib.Path
        The response file and the harmonics file.

    Raises
    ------
    InputError
        If ``analyses`` does not match ``fr`` point by point or mixes different numbers of
        harmonics.

    References
    ----------
    Thesis §3.1, §4.3.4.
    """
    path = Path(path)
    analyses = list(analyses)
    omega = np.asarray(fr.omega, dtype=float)
    if len(analyses) != omega.size:
        raise InputError(
            f"argument 'analyses' has {len(analyses)} entries but 'fr' has {omega.size} points"
        )
    for i, a in enumerate(analyses):
        if not isinstance(a, HarmonicAnalysis):
            raise InputError(f"argument 'analyses'[{i}] is not a HarmonicAnalysis")
        if abs(a.omega - omega[i]) > 1e-12 * omega[i]:
            raise InputError(
                f"argument 'analyses'[{i}] is for omega = {a.omega:g} rad/s but point {i} of 'fr' "
                f"is at {omega[i]:g} rad/s"
            )
    n_h = {a.n_harmonics for a in analyses}
    if len(n_h) > 1:
        raise InputError(
            f"argument 'analyses' mixes numbers of harmonics {sorted(n_h)}; analyse all records "
            "with the same n_harmonics"
        )
    k_max = n_h.pop() if n_h else 1
    sidecar = path.with_name(f"{path.stem}_harmonics.csv")

    def fmt(x) -> str:
        return repr(float(x))

    head = ["omega", "gain", "phase_deg", "n_periods", "n_series"]
    head += [f"h{k}" for k in range(2, k_max + 1)] + ["thd", "nonlinear"]
    lines = [",".join(head)]
    for a in analyses:
        cells = [fmt(a.omega), fmt(a.gain), fmt(a.phase_deg), str(a.n_periods), str(a.n_series)]
        cells += [fmt(v) for v in a.harmonic_ratio_output]
        cells += [fmt(a.thd_output), "true" if a.nonlinear else "false"]
        lines.append(",".join(cells))
    fr.to_csv(path)
    atomic_write_text(sidecar, "\n".join(lines) + "\n")
    return path, sidecar
