"""Measured frequency responses: the :class:`FrequencyResponse` container and its CSV reader.

A frequency response is a set of angular frequencies ω [rad/s] with the complex value G(jω) of a
transfer function at each, and optionally the standard deviation σ of each complex value. The
CSV contract (see DESIGN.md) is:

* a header row, comma separated, ``#`` comment lines allowed anywhere;
* a frequency column ``omega`` [rad/s] or ``freq`` [Hz];
* the response as ``real``, ``imag`` or ``magnitude``, ``phase_deg`` or ``storage``, ``loss``;
* optionally ``sigma`` (standard deviation of the complex value) and ``series`` (an identifier of
  a replicate series: replicates are averaged per frequency, and σ is estimated from their spread).

Comment lines of the form ``# kind: modulus``, ``# units: MPa`` or ``# name: PP sample 3`` set the
metadata of the response.

Limits
------
The reader refuses, naming the file, line and column, what cannot be computed in double
precision or in reasonable time (see :func:`read_csv` for the reasons):

* ω from 1e-30 to 1e30 rad/s and |G| from 1e-30 to 1e30 (never exactly 0), each spanning at
  most 30 decades within one data set (:data:`VALUE_RANGE`, :data:`MAX_SPAN`);
* σ at most 100 times the largest |G| and at least 1e-15 times |G| on its line
  (:data:`SIGMA_MAX_RATIO`, :data:`SIGMA_MIN_RATIO`);
* phases within ±360 degrees (:data:`MAX_PHASE_DEG`);
* at most 1000 frequencies (:data:`MAX_FREQUENCIES`), 100 000 data rows and 32 MiB;
* numbers in plain ASCII decimal notation (no ``1_0``, no ``inf``/``nan``), no invisible
  control characters, and only regular files (not a FIFO).
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ._io import atomic_write_text, csv_cells, parse_number, read_text_file, show, split_lines
from .errors import InputError

KINDS = ("compliance", "modulus", "generic")

FREQUENCY_COLUMNS = ("omega", "freq")
RESPONSE_FORMS = (("real", "imag"), ("magnitude", "phase_deg"), ("storage", "loss"))
OPTIONAL_COLUMNS = ("sigma", "series")
KNOWN_COLUMNS = FREQUENCY_COLUMNS + tuple(c for form in RESPONSE_FORMS for c in form) + OPTIONAL_COLUMNS

#: Relative tolerance within which two frequencies count as the same one.
FREQUENCY_RTOL = 1e-9

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

#: σ may not be below this multiple of |G| on its line: G itself is stored and the structures
#: are evaluated with relative rounding errors of a few 1e-16, so a smaller σ claims a precision
#: the arithmetic cannot reach (and 1/σ² overflows for σ → 0).
SIGMA_MIN_RATIO = 1e-15

#: Largest |phase| in degrees. A phase is an angle, and instruments report it wrapped into
#: (−180°, 180°] or [0°, 360°); the unwrapped phase of a material (compliance −90…0°, modulus
#: 0…90°) or of a max-order member up to n = 3 (at most 270° in magnitude for q ≤ 1) also lies
#: within one turn. A larger value is a corrupted cell or a unit error, and loses digits: exp(i·φ)
#: keeps none once |φ| reaches about 1e16 degrees.
MAX_PHASE_DEG = 360.0

#: Most frequencies (after averaging replicates) a data set may have. A likelihood evaluation
#: costs time and memory proportional to the number of frequencies, and a comparison runs some
#: 10⁵–10⁶ of them per structure (emcee up to 10 000 steps of 32+ walkers, the tempered ladder,
#: PSIS-LOO over up to 2000 stored draws × frequencies). Measured in one process: zener and
#: max-n2m2 together take 74 s at 200 frequencies and 315 s (0.8 GB) at 2000; voigt alone 11 s
#: at 200 and 56 s (1.1 GB) at 5000, about 0.2 MB per frequency in every worker process. At
#: 100 000 frequencies a comparison would run for hours and need tens of GB per worker.
#: Rheometers and dynamic mechanical analysers give tens to a few hundred points (5–10 per
#: decade), and a smooth response is determined by far fewer than 1000.
MAX_FREQUENCIES = 1000

#: Most data rows (replicates included) and bytes of a data file.
MAX_ROWS = 100_000
MAX_FILE_BYTES = 32 * 1024 * 1024


def _as_1d(values, name: str, dtype) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise InputError(f"argument '{name}' must be an array of numbers: {exc}") from None
    if arr.ndim != 1:
        raise InputError(f"argument '{name}' must be one-dimensional, got shape {arr.shape}")
    return arr


@dataclass(frozen=True, eq=False)
class FrequencyResponse:
    """A measured complex frequency response G(jω).

    Parameters
    ----------
    omega : array_like, shape (n,)
        Angular frequencies [rad/s], positive and distinct (any order; see :meth:`sorted`).
    response : array_like of complex, shape (n,)
        G(jω) at each frequency.
    sigma : array_like, shape (n,), optional
        Standard deviation of each complex value, σ_k² = E|G_k − E G_k|². Real and imaginary
        parts are taken as independent with variance σ_k²/2 each (circular complex noise).
    kind : {"compliance", "modulus", "generic"}
        What G is: a compliance (strain/stress), a modulus (stress/strain), or any
        input→output transfer function. The kind decides how material structures are compared
        with the data and the sign of the dissipation condition.
    units : str
        Units of G, for labels only.
    name : str
        A label for reports and plots.
    source : str
        Where the data came from (a path), for reports.

    Raises
    ------
    InputError
        If an array is not one-dimensional, lengths differ, a value is NaN or infinite, a
        frequency is not positive or appears twice, the response is 0 everywhere, a σ is not
        positive, or ``kind`` is unknown. (:func:`read_csv` checks more: the ranges a
        computation in double precision needs.)

    Examples
    --------
    >>> import numpy as np
    >>> w = np.logspace(-1, 2, 4)
    >>> fr = FrequencyResponse(w, 1 / (1 + (1j * w) ** 0.5), kind="compliance")
    >>> fr.n_frequencies
    4
    """

    omega: np.ndarray
    response: np.ndarray
    sigma: np.ndarray | None = None
    kind: str = "generic"
    units: str = ""
    name: str = ""
    source: str = ""
    notes: tuple[str, ...] = field(default=())

    def __post_init__(self):
        omega = _as_1d(self.omega, "omega", float)
        response = _as_1d(self.response, "response", complex)
        if omega.shape != response.shape:
            raise InputError(
                f"arguments 'omega' and 'response' must have the same length, "
                f"got {omega.size} and {response.size}"
            )
        if omega.size == 0:
            raise InputError("argument 'omega' is empty: a frequency response needs at least one point")
        _check_finite(omega, "omega")
        _check_finite(response, "response")
        if not np.any(response):
            raise InputError("argument 'response' is 0 at every frequency: there is nothing to fit")
        bad = np.flatnonzero(omega <= 0)
        if bad.size:
            raise InputError(
                f"argument 'omega' must be positive: omega[{bad[0]}] = {omega[bad[0]]:g} rad/s"
            )
        _check_distinct(omega, "omega")
        sigma = None
        if self.sigma is not None:
            sigma = _as_1d(self.sigma, "sigma", float)
            if sigma.shape != omega.shape:
                raise InputError(
                    f"argument 'sigma' must have the same length as 'omega', "
                    f"got {sigma.size} and {omega.size}"
                )
            _check_finite(sigma, "sigma")
            bad = np.flatnonzero(sigma <= 0)
            if bad.size:
                raise InputError(
                    f"argument 'sigma' must be positive: sigma[{bad[0]}] = {sigma[bad[0]]:g}"
                )
        if self.kind not in KINDS:
            raise InputError(f"argument 'kind' must be one of {', '.join(KINDS)}, got {self.kind!r}")
        for name, arr in (("omega", omega), ("response", response), ("sigma", sigma)):
            if arr is not None:
                arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "notes", tuple(self.notes))

    # ------------------------------------------------------------------ properties
    @property
    def n_frequencies(self) -> int:
        """Number of frequencies."""
        return int(self.omega.size)

    @property
    def freq(self) -> np.ndarray:
        """Frequencies in Hz."""
        return self.omega / (2 * np.pi)

    @property
    def magnitude(self) -> np.ndarray:
        """|G(jω)|."""
        return np.abs(self.response)

    @property
    def phase_deg(self) -> np.ndarray:
        """arg G(jω) in degrees, in (−180, 180]."""
        return np.degrees(np.angle(self.response))

    @property
    def omega_ref(self) -> float:
        """Reference frequency for scaling: the geometric mean of ω."""
        return float(np.exp(np.mean(np.log(self.omega))))

    @property
    def g_ref(self) -> float:
        """Reference magnitude for scaling: the median of |G|."""
        g = float(np.median(self.magnitude))
        return g if g > 0 else 1.0

    @property
    def label(self) -> str:
        """A human-readable name: ``name``, else the source file name, else ``"data"``."""
        return self.name or (Path(self.source).stem if self.source else "data")

    def where(self) -> str:
        """Text naming the data for error messages ("file 'x.csv'" or "data 'name'")."""
        return f"file '{self.source}'" if self.source else f"data '{self.label}'"

    def dissipation_violations(self) -> np.ndarray:
        """Indices of points whose loss has the wrong sign for the kind (none for generic).

        A compliance must have Im J ≤ 0 and a modulus Im G ≥ 0; a measured point that violates
        this is an instrument artefact or noise that no passive structure can fit.
        """
        sign = {"compliance": -1.0, "modulus": 1.0}.get(self.kind)
        if sign is None:
            return np.array([], dtype=int)
        return np.flatnonzero(sign * self.response.imag < 0)

    # ------------------------------------------------------------------ derived responses
    def sorted(self) -> FrequencyResponse:
        """The same response with frequencies in increasing order."""
        order = np.argsort(self.omega, kind="stable")
        return self._take(order)

    def _take(self, index, notes: tuple[str, ...] | None = None) -> FrequencyResponse:
        return replace(
            self,
            omega=self.omega[index],
            response=self.response[index],
            sigma=None if self.sigma is None else self.sigma[index],
            notes=self.notes if notes is None else notes,
        )

    def with_kind(self, kind: str) -> FrequencyResponse:
        """The same values declared as another kind."""
        return replace(self, kind=kind)

    def reciprocal(self) -> FrequencyResponse:
        """The reciprocal response 1/G, with σ propagated to first order (σ/|G|²).

        A compliance becomes a modulus and vice versa; a generic response stays generic.

        Raises
        ------
        InputError
            If G is zero at some frequency (the row is named).
        """
        zero = np.flatnonzero(self.response == 0)
        if zero.size:
            k = zero[0]
            raise InputError(
                f"{self.where()}: cannot take the reciprocal, the response is zero at "
                f"omega = {self.omega[k]:g} rad/s (point {k + 1} of {self.n_frequencies})"
            )
        mag2 = np.abs(self.response) ** 2
        kind = {"compliance": "modulus", "modulus": "compliance"}.get(self.kind, self.kind)
        units = f"1/({self.units})" if self.units else ""
        return replace(
            self,
            response=1.0 / self.response,
            sigma=None if self.sigma is None else self.sigma / mag2,
            kind=kind,
            units=units,
            notes=self.notes + ("reciprocal of the measured response",),
        )

    def select(self, mask) -> FrequencyResponse:
        """The points where the boolean ``mask`` is true."""
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != self.omega.shape:
            raise InputError(f"argument 'mask' must have shape {self.omega.shape}, got {mask.shape}")
        if not mask.any():
            raise InputError("argument 'mask' selects no frequency")
        return self._take(np.flatnonzero(mask))

    def split(self, holdout) -> tuple[FrequencyResponse, FrequencyResponse]:
        """Split off the frequencies in ``holdout`` for validation (thesis §4.3.3).

        Parameters
        ----------
        holdout : sequence of float
            Angular frequencies [rad/s] to hold out. Each must match a frequency of the data to
            a relative tolerance of 1e-6.

        Returns
        -------
        train, test : FrequencyResponse
            The remaining points and the held-out points.

        Raises
        ------
        InputError
            If a frequency is not in the data, or nothing would remain for fitting.
        """
        holdout = np.atleast_1d(np.asarray(holdout, dtype=float))
        mask = np.zeros(self.n_frequencies, dtype=bool)
        for w in holdout:
            match = np.flatnonzero(np.isclose(self.omega, w, rtol=1e-6, atol=0.0))
            if not match.size:
                raise InputError(
                    f"hold-out frequency {w:g} rad/s is not among the frequencies of {self.where()} "
                    f"({self.omega.min():g} … {self.omega.max():g} rad/s)"
                )
            mask[match] = True
        if mask.all():
            raise InputError("the hold-out set contains every frequency: nothing is left to fit")
        return self.select(~mask), self.select(mask)

    def check_enough_points(self, n_params: int, what: str) -> None:
        """Raise :class:`InputError` unless there are at least ``n_params`` frequencies.

        Each frequency carries two real numbers, but a structure with more parameters than
        frequencies cannot be told apart from its own overfit, so this is the floor.
        """
        if self.n_frequencies < n_params:
            raise InputError(
                f"{self.where()} has {self.n_frequencies} frequencies, fewer than the "
                f"{n_params} parameters of {what}"
            )

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_replicates(
        cls, omega, responses, *, kind: str = "generic", units: str = "", name: str = "",
        source: str = "",
    ) -> FrequencyResponse:
        """Average replicate series measured at the same frequencies.

        Parameters
        ----------
        omega : array_like, shape (n,)
            Angular frequencies [rad/s].
        responses : array_like of complex, shape (r, n)
            ``r`` ≥ 2 replicate measurements of G at each frequency.

        Returns
        -------
        FrequencyResponse
            The mean of the replicates, with σ the standard error of that mean,
            ``sqrt(sum |G_i − mean|² / (r − 1)) / sqrt(r)``.
        """
        responses = np.asarray(responses, dtype=complex)
        omega = _as_1d(omega, "omega", float)
        if responses.ndim != 2 or responses.shape[1] != omega.size:
            raise InputError(
                f"argument 'responses' must have shape (r, {omega.size}), got {responses.shape}"
            )
        if responses.shape[0] < 2:
            raise InputError("argument 'responses' needs at least 2 replicate series")
        mean, sigma = _mean_and_standard_error([responses[:, k] for k in range(omega.size)])
        return cls(omega, mean, sigma, kind=kind, units=units, name=name, source=source)

    # ------------------------------------------------------------------ output
    def to_csv(self, path: str | os.PathLike) -> Path:
        """Write the response in the CSV contract (``omega,real,imag[,sigma]``), atomically."""
        lines = []
        if self.name:
            lines.append(f"# name: {self.name}")
        lines.append(f"# kind: {self.kind}")
        if self.units:
            lines.append(f"# units: {self.units}")
        header = ["omega", "real", "imag"] + (["sigma"] if self.sigma is not None else [])
        lines.append(",".join(header))
        for k in range(self.n_frequencies):
            row = [self.omega[k], self.response[k].real, self.response[k].imag]
            if self.sigma is not None:
                row.append(self.sigma[k])
            lines.append(",".join(repr(float(v)) for v in row))
        return atomic_write_text(path, "\n".join(lines) + "\n")

    def to_dict(self) -> dict:
        """Plain-Python summary for JSON output (no arrays of data)."""
        return {
            "name": self.label,
            "path": self.source,
            "kind": self.kind,
            "units": self.units,
            "n_frequencies": self.n_frequencies,
            "omega_min": float(self.omega.min()),
            "omega_max": float(self.omega.max()),
            "has_sigma": self.sigma is not None,
            "dissipation_violations": self.omega[self.dissipation_violations()].tolist(),
            "notes": list(self.notes),
        }


def _check_finite(arr: np.ndarray, name: str) -> None:
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise InputError(f"argument '{name}' contains NaN or infinity at index {bad[0]}")


def _check_distinct(omega: np.ndarray, name: str) -> None:
    order = np.argsort(omega)
    w = omega[order]
    dup = np.flatnonzero(np.isclose(w[1:], w[:-1], rtol=FREQUENCY_RTOL, atol=0.0))
    if dup.size:
        i, j = sorted((order[dup[0]], order[dup[0] + 1]))
        raise InputError(
            f"argument '{name}' has the frequency {w[dup[0]]:g} rad/s twice "
            f"(indices {i} and {j})"
        )


def _mean_and_standard_error(groups) -> tuple[np.ndarray, np.ndarray | None]:
    """Mean of each group of complex values, and the standard error of that mean.

    The standard error is None unless every group has at least two members whose spread is
    resolved in double precision (a standard error above 1e-15 of the mean's magnitude,
    :data:`SIGMA_MIN_RATIO`): replicates identical to rounding give no σ.
    """
    mean = np.array([np.mean(g) for g in groups], dtype=complex)
    if min(len(g) for g in groups) < 2:
        return mean, None
    se = np.array(
        [math.sqrt(np.sum(np.abs(g - m) ** 2) / (len(g) - 1) / len(g)) for g, m in zip(groups, mean)]
    )
    if np.any(se <= SIGMA_MIN_RATIO * np.abs(mean)) or not np.all(np.isfinite(se)):
        return mean, None
    return mean, se


# ---------------------------------------------------------------------- CSV reader
def read_csv(
    path: str | os.PathLike, *, kind: str | None = None, units: str | None = None,
    name: str | None = None,
) -> FrequencyResponse:
    """Read a frequency response from a CSV file in the bayesfo contract.

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
                if key.strip().lower() in ("kind", "units", "name"):
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

    notes: list[str] = []
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

    if "omega" in values:
        omega, fcol = values["omega"], "omega"
    else:
        fcol = "freq"
        with np.errstate(over="ignore"):
            omega = 2 * np.pi * values["freq"]
    _check_rows(omega <= 0, where, linenos, fcol, "frequency must be positive")
    _check_frequency_range(omega, values.get("freq"), where, linenos, fcol)

    if "real" in values:
        form = ("real", "imag")
        response = values["real"] + 1j * values["imag"]
    elif "magnitude" in values:
        form = ("magnitude",)
        _check_rows(values["magnitude"] < 0, where, linenos, "magnitude", "magnitude is negative")
        phase = values["phase_deg"]
        _check_rows(np.abs(phase) > MAX_PHASE_DEG, where, linenos, "phase_deg",
                    f"a phase of {{value:g}} degrees is outside ±{MAX_PHASE_DEG:g}; a phase is an "
                    "angle within one turn: wrap it into (-180, 180] by adding or subtracting "
                    "multiples of 360", phase)
        response = values["magnitude"] * np.exp(1j * np.radians(phase))
    else:
        form = ("storage", "loss")
        sign = -1.0 if kind == "compliance" else 1.0
        response = values["storage"] + sign * 1j * values["loss"]
    magnitude = _check_magnitudes(values, form, where, linenos)
    sigma = values.get("sigma")
    if sigma is not None:
        _check_rows(sigma <= 0, where, linenos, "sigma", "sigma must be positive")
        _check_sigma(sigma, magnitude, where, linenos)

    if "series" in values:
        omega, response, sigma, n_rep, linenos = _average_series(
            omega, response, sigma, values["series"], linenos, where, fcol
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
        _check_duplicates(omega, linenos, where, fcol)
    _check_span(omega, linenos, where, f"column '{fcol}'", "the frequencies span", "rad/s")
    _check_span(np.abs(response), linenos, where, _columns(form), "|G| spans", "")

    fr = FrequencyResponse(
        omega,
        response,
        sigma,
        kind=kind,
        units=units if units is not None else meta.get("units", ""),
        name=name if name is not None else meta.get("name", ""),
        source=str(path),
        notes=tuple(notes),
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


def _columns(form) -> str:
    if len(form) == 1:
        return f"column '{form[0]}'"
    return f"columns '{form[0]}' and '{form[1]}'"


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


def _check_magnitudes(values, form, where, linenos) -> np.ndarray:
    """|G| per row, after checking it is nonzero and within :data:`VALUE_RANGE`."""
    if len(form) == 1:
        magnitude = values[form[0]]
    else:
        magnitude = np.hypot(values[form[0]], values[form[1]])
    cols = _columns(form)
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
            cols = f"column '{col}'"
            what = f"{values[col][k]:g}"
        else:
            what = f"|G| = {magnitude[k]:g}"
        raise InputError(
            f"{where}, line {linenos[k]}, {cols}: {what} is outside the magnitudes {lo:g} … "
            f"{hi:g} bayesfo computes with in double precision (their squares must stay "
            "finite and nonzero); check the units of the response"
        )
    return magnitude


def _check_sigma(sigma, magnitude, where, linenos) -> None:
    g_max = float(magnitude.max())
    big = np.flatnonzero(sigma > SIGMA_MAX_RATIO * g_max)
    if big.size:
        k = big[0]
        raise InputError(
            f"{where}, line {linenos[k]}, column 'sigma': sigma = {sigma[k]:g} is more than "
            f"{SIGMA_MAX_RATIO:g} times the largest |G| of the data ({g_max:g}); no measurement is "
            "that noisy: check that sigma is the standard deviation of G, in the units of G"
        )
    small = np.flatnonzero(sigma < SIGMA_MIN_RATIO * magnitude)
    if small.size:
        k = small[0]
        raise InputError(
            f"{where}, line {linenos[k]}, column 'sigma': sigma = {sigma[k]:g} is less than "
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


def _check_duplicates(omega, linenos, where: str, col: str) -> None:
    order = np.argsort(omega, kind="stable")
    w = omega[order]
    dup = np.flatnonzero(np.isclose(w[1:], w[:-1], rtol=FREQUENCY_RTOL, atol=0.0))
    if dup.size:
        a, b = sorted((linenos[order[dup[0]]], linenos[order[dup[0] + 1]]))
        raise InputError(
            f"{where}, line {b}, column '{col}': duplicate frequency (same as line {a}); "
            "mark replicate measurements with a 'series' column"
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
