"""Reading a frequency response from a CSV file of the bayesfo contract, with the limits of what\ncan be computed (see the package docstring)."""

from __future__ import annotations

import math
import os
import warnings
from pathlib import Path

import numpy as np

from .._io import csv_cells, parse_number, read_text_file, show, split_lines
from ..errors import InputError
from .frequency_response import (
    FREQUENCY_RTOL,
    KINDS,
    SIGMA_MIN_RATIO,
    FrequencyResponse,
    _mean_and_standard_error,
)
from .symbols import SYMBOLS

FREQUENCY_COLUMNS = ("omega", "freq")
RESPONSE_FORMS = (("real", "imag"), ("magnitude", "phase_deg"), ("storage", "loss"))
OPTIONAL_COLUMNS = ("sigma", "series")
KNOWN_COLUMNS = FREQUENCY_COLUMNS + tuple(c for form in RESPONSE_FORMS for c in form) + OPTIONAL_COLUMNS


#: Smallest and largest ω [rad/s] and nonzero |G| a data file may hold. Every measurable
#: frequency response lies many decades inside (master curves of mechanical and dielectric spectra
#: reach 1e-12 … 1e15 rad/s; moduli, compliances and other transfer functions in any common unit
#: 1e-15 … 1e15), and within these bounds the squares and the products the fits form in physical
#: units (|G|², σ², ω_ref^(n q)·g_ref for degrees n ≤ 6) stay far inside the normal range of
#: float64 (2.2e-308 … 1.8e308), instead of overflowing to inf or underflowing to 0.
VALUE_RANGE = (1e-30, 1e30)

#: Largest ratio max/min of ω, and of |G|, within one data set: 30 decades, more than
#: time-temperature master curves span (the bundled NREL DMA master curve spans 26). The fits
#: work on ω̃ = ω/ω_ref and G̃ = G/g_ref (geometric mean and median), which then lie within 1e±30
#: even for lopsided data; the linear methods form rows (λ^n·G̃)² with λ = (jω̃)^q that stay
#: below 1e240 for the thesis' degrees n ≤ 3 and q ≤ 1, and the likelihood squares residuals
#: weighted by 1/|G̃| (≤ 1e60). Beyond, scaling no longer keeps these finite.
MAX_SPAN = 1e30

#: σ may not exceed this multiple of the largest |G|: a point whose noise is a hundred times
#: the largest response measured carries no information, and is a unit error (σ in other units
#: than G) or the wrong column.
SIGMA_MAX_RATIO = 100.0


#: Largest |phase| in degrees. A phase is an angle, and instruments report it wrapped into
#: (−180°, 180°] or [0°, 360°); the unwrapped phase of a material (compliance −90…0°, modulus
#: 0…90°) or of a max-order member up to n = 3 (at most 270° in magnitude for q ≤ 1) also lies
#: within one turn. A larger value is a corrupted cell or a unit error, and loses digits: exp(i·φ)
#: keeps none once |φ| reaches about 1e16 degrees.
MAX_PHASE_DEG = 360.0

#: Most frequencies (after averaging replicates) a data set may have. A likelihood evaluation
#: costs time and memory proportional to the number of frequencies, and a comparison runs some
#: 10⁵–10⁶ of them per structure (emcee up to 10 000 steps of 32+ walkers, the tempered ladder,
#: PSIS-LOO over up to 2000 stored draws × frequencies): with thousands of frequencies a
#: comparison grows slow and needs much memory in every worker process (BENCHMARKS.md,
#: "Measurements behind design choices").
#: Rheometers and dynamic mechanical analysers give tens to a few hundred points (5–10 per
#: decade), and a smooth response is determined by far fewer than 1000.
MAX_FREQUENCIES = 1000

#: Most data rows (replicates included) and bytes of a data file.
MAX_ROWS = 100_000
MAX_FILE_BYTES = 32 * 1024 * 1024


# ---------------------------------------------------------------------- CSV reader
def read_csv(
    path: str | os.PathLike, *, kind: str | None = None, units: str | None = None,
    name: str | None = None,
) -> FrequencyResponse:
    """Read a frequency response from a CSV file in the bayesfo contract.

    A ``# symbol:`` comment (``G``, ``E``, ``J`` or ``D``) names the measured quantity:
    ``# symbol: E`` for a tensile modulus E′, E″ of a DMA (:attr:`FrequencyResponse.symbol`;
    default G).

    Parameters
    ----------
    path : path-like
        The CSV file (see the module docstring for the columns).
    kind : {"compliance", "modulus", "generic"}, optional
        Overrides a ``# kind:`` comment in the file; without either, ``storage``/``loss``
        columns mean a modulus (stated in ``notes``) and other columns ``"generic"``.
    units, name : str, optional
        Override the ``# units:`` and ``# name:`` comments.

    Returns
    -------
    FrequencyResponse
        Sorted by frequency. With a ``series`` column the replicates are averaged per frequency
        and, when no ``sigma`` column is given and every frequency has at least two replicates,
        σ is the standard error of the mean. ``storage``/``loss`` give G = G' + jG'' for a modulus
        or generic response and J = J' − jJ'' for a compliance (loss compliance J'' ≥ 0).

    Raises
    ------
    InputError
        Naming the file, and the column and line where it applies, for: a missing or unreadable
        file, or one that is not a regular file (a FIFO would block), not UTF-8, holds an
        invisible control character (a NUL byte) or is larger than 32 MiB; a missing, unknown,
        duplicated or conflicting column; a cell that is not a plain decimal number (empty,
        ``1_0``, Unicode digits, NaN, infinite, longer than 1000 characters); ω ≤ 0; a frequency
        given twice in a series; a negative magnitude or a non-positive σ; an unknown kind; and
        values that cannot be computed with:

        * ω outside 1e-30 … 1e30 rad/s, or |G| outside 1e-30 … 1e30 (:data:`VALUE_RANGE`):
          their squares and the products the fits form must stay finite and normal in float64;
        * a response that is exactly 0 at some frequency, or everywhere: a measured value is
          never exactly 0, and 1/|G| weights, proportional noise and reciprocals need |G| > 0;
        * ω, or |G|, spanning more than 30 decades (:data:`MAX_SPAN`): the fits scale the data
          by its geometric-mean frequency and median magnitude, and powers of the scaled values
          (λ^n·G, squared) must stay finite;
        * σ above 100·max|G| (:data:`SIGMA_MAX_RATIO`, a unit error) or below 1e-15·|G| of its
          line (:data:`SIGMA_MIN_RATIO`, below double precision);
        * a phase outside ±360 degrees (:data:`MAX_PHASE_DEG`);
        * more than 1000 frequencies (:data:`MAX_FREQUENCIES`: the samplers' cost grows in
          proportion; thin or average the data) or more than 100 000 data rows.

    Examples
    --------
    >>> fr = read_csv("examples/data/voigt_compliance.csv")  # doctest: +SKIP
    """
    path = Path(path)
    where = f"file '{path}'"
    text = read_text_file(path, max_bytes=MAX_FILE_BYTES)

    meta: dict[str, str] = {}
    rows: list[tuple[int, list[str]]] = []
    header: list[str] | None = None
    header_line = 0
    for lineno, line in enumerate(split_lines(text), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            body = stripped.lstrip("#").strip()
            if ":" in body:
                key, value = body.split(":", 1)
                if key.strip().lower() in ("kind", "units", "name", "symbol"):
                    meta[key.strip().lower()] = value.strip()
            continue
        cells = csv_cells(line, where, lineno)
        if header is None:
            header, header_line = [c.strip().lower() for c in cells], lineno
        else:
            rows.append((lineno, cells))
            if len(rows) > MAX_ROWS:
                raise InputError(
                    f"{where}, line {lineno}: more than {MAX_ROWS} data rows; a data set may "
                    f"have at most {MAX_FREQUENCIES} frequencies: {_THIN_HINT}"
                )
    if header is None:
        raise InputError(f"{where} is empty: expected a header row such as 'omega,real,imag'")
    if not rows:
        raise InputError(f"{where} has a header but no data rows")

    columns = _check_header(header, where, header_line)
    if "series" not in columns and len(rows) > MAX_FREQUENCIES:
        _too_many(where, len(rows))
    values: dict[str, np.ndarray] = {}
    for lineno, cells in rows:
        if len(cells) != len(header):
            raise InputError(
                f"{where}, line {lineno}: expected {len(header)} cells as in the header, "
                f"got {len(cells)}"
            )
    for col in columns:
        idx = header.index(col)
        out = np.empty(len(rows))
        for r, (lineno, cells) in enumerate(rows):
            try:
                out[r] = parse_number(cells[idx])
            except ValueError as exc:
                raise InputError(f"{where}, line {lineno}, column '{col}': {exc}") from None
        values[col] = out
    linenos = np.array([ln for ln, _ in rows])

    return _from_columns(values, linenos, where, kind=kind, meta=meta, units=units, name=name,
                         source=str(path))


def _from_columns(
    values: dict[str, np.ndarray], linenos: np.ndarray, where: str, *, kind: str | None,
    meta: dict[str, str], units: str | None, name: str | None, source: str,
    notes: tuple[str, ...] = (), labels: dict[str, str] | None = None,
    symbol: str | None = None,
) -> FrequencyResponse:
    """The checked, sorted response from parsed columns named as in the contract.

    ``values`` maps contract column names (``omega`` or ``freq``, one response form, optionally
    ``sigma`` and ``series``) to numbers, one per data row, and ``linenos`` gives each row's line
    in the file; every check of :func:`read_csv` after parsing the cells happens here, so that
    other readers that normalise a file to these columns keep the same limits. ``labels`` maps a
    contract name to the name shown in messages (a column of the original file); ``notes`` start
    the notes of the response; ``symbol`` (the letter the columns give the response) else a
    ``# symbol:`` line of ``meta`` else G names the measured quantity.
    """
    labels = labels or {}

    def lab(col: str) -> str:
        return labels.get(col, col)

    notes = list(notes)
    if kind is None and "kind" not in meta and "storage" in values:
        # G' and G'' (storage and loss) are by definition the parts of a modulus; fitting them
        # as a generic transfer function loses the sign convention and the dissipation check.
        kind = "modulus"
        notes.append("kind modulus: storage and loss columns are the parts of a modulus "
                     "(G', G''); for a compliance J', J'' give '# kind: compliance' or "
                     "--kind compliance")
    kind = kind if kind is not None else meta.get("kind", "generic")
    if kind not in KINDS:
        raise InputError(f"{where}: kind must be one of {', '.join(KINDS)}, got {show(str(kind))}")
    if symbol is None:
        symbol = meta.get("symbol", "G").strip()
        if symbol not in SYMBOLS:
            raise InputError(f"{where}: the '# symbol:' line must say G (shear modulus), E "
                             "(tensile modulus), J (shear compliance) or D (tensile compliance), "
                             f"got {show(symbol)}")

    if "omega" in values:
        omega, fcol = values["omega"], "omega"
    else:
        fcol = "freq"
        with np.errstate(over="ignore"):
            omega = 2 * np.pi * values["freq"]
    _check_rows(omega <= 0, where, linenos, lab(fcol), "frequency must be positive")
    _check_frequency_range(omega, values.get("freq"), where, linenos, lab(fcol))

    if "real" in values:
        form = ("real", "imag")
        response = values["real"] + 1j * values["imag"]
    elif "magnitude" in values:
        form = ("magnitude",)
        _check_rows(values["magnitude"] < 0, where, linenos, lab("magnitude"),
                    "magnitude is negative")
        phase = values["phase_deg"]
        _check_rows(np.abs(phase) > MAX_PHASE_DEG, where, linenos, lab("phase_deg"),
                    f"a phase of {{value:g}} degrees is outside ±{MAX_PHASE_DEG:g}; a phase is an "
                    "angle within one turn: wrap it into (-180, 180] by adding or subtracting "
                    "multiples of 360", phase)
        response = values["magnitude"] * np.exp(1j * np.radians(phase))
    else:
        form = ("storage", "loss")
        sign = -1.0 if kind == "compliance" else 1.0
        response = values["storage"] + sign * 1j * values["loss"]
    magnitude = _check_magnitudes(values, form, where, linenos, labels)
    sigma = values.get("sigma")
    if sigma is not None:
        _check_rows(sigma <= 0, where, linenos, lab("sigma"), "sigma must be positive")
        _check_sigma(sigma, magnitude, where, linenos, lab("sigma"))

    if "series" in values:
        omega, response, sigma, n_rep, linenos = _average_series(
            omega, response, sigma, values["series"], linenos, where, lab(fcol)
        )
        notes.append(f"mean of {n_rep} replicate series")
        if sigma is None:
            notes.append("sigma unknown: some frequency has a single replicate")
        zero = np.flatnonzero(response == 0)
        if zero.size:
            raise InputError(
                f"{where}, line {linenos[zero[0]]}: the mean of the replicates at omega = "
                f"{omega[zero[0]]:g} rad/s is exactly 0, which cannot be scaled or weighted; "
                "check the replicates of this frequency"
            )
        if omega.size > MAX_FREQUENCIES:
            _too_many(where, omega.size)
    else:
        _check_duplicates(omega, linenos, where, lab(fcol))
    _check_span(omega, linenos, where, f"column '{lab(fcol)}'", "the frequencies span", "rad/s")
    _check_span(np.abs(response), linenos, where, _columns(form, labels), "|G| spans", "")

    fr = FrequencyResponse(
        omega,
        response,
        sigma,
        kind=kind,
        units=units if units is not None else meta.get("units", ""),
        name=name if name is not None else meta.get("name", ""),
        source=source,
        notes=tuple(notes),
        symbol=symbol,
    )
    return fr.sorted()


_THIN_HINT = (
    "thin the data (e.g. 10 to 50 log-spaced frequencies per decade), or average neighbouring "
    "frequencies, before the comparison"
)


def _too_many(where: str, n: int) -> None:
    raise InputError(
        f"{where} has {n} frequencies, more than the {MAX_FREQUENCIES} a comparison handles in "
        f"reasonable time (the samplers' cost grows with the number of frequencies): {_THIN_HINT}"
    )


def _columns(form, labels=None) -> str:
    labels = labels or {}
    names = [labels.get(c, c) for c in form]
    if len(names) == 1:
        return f"column '{names[0]}'"
    return f"columns '{names[0]}' and '{names[1]}'"


def _check_frequency_range(omega, freq, where, linenos, col) -> None:
    lo, hi = VALUE_RANGE
    bad = np.flatnonzero((omega < lo) | (omega > hi))
    if bad.size:
        k = bad[0]
        if freq is not None:
            value = f"{freq[k]:g} Hz is outside {lo / (2 * np.pi):.3g} … {hi / (2 * np.pi):.3g} Hz"
        else:
            value = f"{omega[k]:g} rad/s is outside {lo:g} … {hi:g} rad/s"
        raise InputError(
            f"{where}, line {linenos[k]}, column '{col}': {value}, the range bayesfo computes "
            "with in double precision; check the units of the column"
        )


def _check_magnitudes(values, form, where, linenos, labels=None) -> np.ndarray:
    """|G| per row, after checking it is nonzero and within :data:`VALUE_RANGE`."""
    if len(form) == 1:
        magnitude = values[form[0]]
    else:
        magnitude = np.hypot(values[form[0]], values[form[1]])
    cols = _columns(form, labels)
    if np.all(magnitude == 0):
        raise InputError(
            f"{where}: the response is 0 at every frequency ({cols}): there is nothing to fit; "
            "check that these columns hold the measured response"
        )
    zero = np.flatnonzero(magnitude == 0)
    if zero.size:
        raise InputError(
            f"{where}, line {linenos[zero[0]]}, {cols}: the response is exactly 0; a measured "
            "response never is (a placeholder for a missing value?), and a zero cannot be "
            "scaled, weighted by 1/|G| or inverted: remove the row"
        )
    lo, hi = VALUE_RANGE
    bad = np.flatnonzero((magnitude < lo) | (magnitude > hi))
    if bad.size:
        k = bad[0]
        if len(form) == 2 and magnitude[k] > hi:
            # Name the cell that is too large.
            col = form[0] if abs(values[form[0]][k]) >= abs(values[form[1]][k]) else form[1]
            cols = _columns((col,), labels)
            what = f"{values[col][k]:g}"
        else:
            what = f"|G| = {magnitude[k]:g}"
        raise InputError(
            f"{where}, line {linenos[k]}, {cols}: {what} is outside the magnitudes {lo:g} … "
            f"{hi:g} bayesfo computes with in double precision (their squares must stay "
            "finite and nonzero); check the units of the response"
        )
    return magnitude


def _check_sigma(sigma, magnitude, where, linenos, col: str = "sigma") -> None:
    g_max = float(magnitude.max())
    big = np.flatnonzero(sigma > SIGMA_MAX_RATIO * g_max)
    if big.size:
        k = big[0]
        raise InputError(
            f"{where}, line {linenos[k]}, column '{col}': sigma = {sigma[k]:g} is more than "
            f"{SIGMA_MAX_RATIO:g} times the largest |G| of the data ({g_max:g}); no measurement is "
            "that noisy: check that sigma is the standard deviation of G, in the units of G"
        )
    small = np.flatnonzero(sigma < SIGMA_MIN_RATIO * magnitude)
    if small.size:
        k = small[0]
        raise InputError(
            f"{where}, line {linenos[k]}, column '{col}': sigma = {sigma[k]:g} is less than "
            f"{SIGMA_MIN_RATIO:g} times |G| = {magnitude[k]:g} on this line, below the precision "
            "of a double; give the measurement's real standard deviation"
        )


def _check_span(values, linenos, where, cols: str, what: str, unit: str) -> None:
    """At most :data:`MAX_SPAN` between the smallest and the largest of ``values`` (> 0)."""
    i, j = int(np.argmin(values)), int(np.argmax(values))
    if values[j] > MAX_SPAN * values[i]:
        unit = f" {unit}" if unit else ""
        decades = math.log10(values[j]) - math.log10(values[i])
        raise InputError(
            f"{where}, {cols}: {what} {decades:.1f} decades (from {values[i]:g}{unit} on "
            f"line {linenos[i]} to {values[j]:g}{unit} on line {linenos[j]}), more than the "
            f"{math.log10(MAX_SPAN):.0f} decades the scaled fits handle in double precision; "
            "remove the outlying rows or check their units"
        )


def _check_header(header: list[str], where: str, lineno: int) -> list[str]:
    seen = set()
    for col in header:
        if col == "":
            raise InputError(f"{where}, line {lineno}: the header has an empty column name")
        if col in seen:
            raise InputError(f"{where}, line {lineno}: column {show(col)} appears twice in the header")
        seen.add(col)
        if col not in KNOWN_COLUMNS:
            raise InputError(
                f"{where}, line {lineno}: unknown column {show(col)}; known columns are "
                f"{', '.join(KNOWN_COLUMNS)}"
            )
    freq = [c for c in FREQUENCY_COLUMNS if c in seen]
    if not freq:
        raise InputError(f"{where}: missing frequency column: need 'omega' [rad/s] or 'freq' [Hz]")
    if len(freq) > 1:
        raise InputError(f"{where}: give either 'omega' or 'freq', not both")
    forms = [form for form in RESPONSE_FORMS if any(c in seen for c in form)]
    if not forms:
        raise InputError(
            f"{where}: missing response columns: need 'real','imag' or 'magnitude','phase_deg' "
            "or 'storage','loss'"
        )
    if len(forms) > 1:
        raise InputError(
            f"{where}: columns {', '.join(c for f in forms for c in f if c in seen)} mix two "
            "response forms; use one of 'real','imag' / 'magnitude','phase_deg' / 'storage','loss'"
        )
    missing = [c for c in forms[0] if c not in seen]
    if missing:
        raise InputError(
            f"{where}: missing column '{missing[0]}' (needed with '{[c for c in forms[0] if c in seen][0]}')"
        )
    return [freq[0], *forms[0], *[c for c in OPTIONAL_COLUMNS if c in seen]]


def _check_rows(bad: np.ndarray, where: str, linenos, col: str, message: str, values=None) -> None:
    """Raise naming the first row where ``bad``; ``message`` may hold ``{value}`` (of ``values``)."""
    idx = np.flatnonzero(bad)
    if idx.size:
        if values is not None:
            message = message.format(value=values[idx[0]])
        raise InputError(f"{where}, line {linenos[idx[0]]}, column '{col}': {message}")


#: What to do about rows that repeat a frequency: the one piece of advice of every reader.
DUPLICATE_ADVICE = (
    "several sweeps in one table, replicate measurements, or overlapping isotherms of a "
    "master curve? Split them with a block or temperature column (--columns block=NAME; "
    "replicates in a bayesfo CSV: a 'series' column, averaged per frequency), or keep the "
    "first row of each frequency with duplicates='first' (--duplicates first) or average them "
    "with duplicates='mean'")


def _check_duplicates(omega, linenos, where: str, col: str) -> None:
    order = np.argsort(omega, kind="stable")
    w = omega[order]
    dup = np.flatnonzero(np.isclose(w[1:], w[:-1], rtol=FREQUENCY_RTOL, atol=0.0))
    if dup.size:
        a, b = sorted((linenos[order[dup[0]]], linenos[order[dup[0] + 1]]))
        raise InputError(
            f"{where}, line {b}, column '{col}': the frequency {w[dup[0]]:g} rad/s repeats "
            f"line {a} ({dup.size} repeated row(s) in all); {DUPLICATE_ADVICE}"
        )


def _average_series(omega, response, sigma, series, linenos, where, col):
    """Average replicate series per frequency; check each series has distinct frequencies.

    Returns the frequencies, mean responses, their σ (or None), the number of series and, per
    frequency, the first line of the file that holds it.
    """
    for s in np.unique(series):
        sel = series == s
        _check_duplicates(omega[sel], linenos[sel], where, col)
    # Group frequencies that agree to FREQUENCY_RTOL across series: each with the previous
    # one, so that the means of neighbouring groups differ by more than FREQUENCY_RTOL too.
    order = np.argsort(omega, kind="stable")
    groups: list[list[int]] = []
    for i in order:
        if groups and math.isclose(omega[i], omega[groups[-1][-1]], rel_tol=FREQUENCY_RTOL):
            groups[-1].append(i)
        else:
            groups.append([i])
    w = np.array([np.mean(omega[g]) for g in groups])
    lines = np.array([min(linenos[g]) for g in groups])
    if sigma is not None:
        # Known σ per replicate: inverse-variance weighted mean and its standard error.
        mean = np.empty(len(groups), dtype=complex)
        se = np.empty(len(groups))
        for k, g in enumerate(groups):
            wts = 1.0 / sigma[g] ** 2
            mean[k] = np.sum(wts * response[g]) / np.sum(wts)
            se[k] = 1.0 / math.sqrt(np.sum(wts))
        return w, mean, se, len(np.unique(series)), lines
    mean, se = _mean_and_standard_error([response[g] for g in groups])
    if se is None:
        warnings.warn(
            f"{where}: some frequency has a single replicate, so no sigma is estimated",
            UserWarning,
            stacklevel=3,
        )
    return w, mean, se, len(np.unique(series)), lines
