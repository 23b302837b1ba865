"""The frequency response: measured complex G(jω) with optional σ, its kind (compliance, modulus\nor generic), and what derives from it (reciprocal, hold-out split, replicates)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .._io import atomic_write_text
from ..errors import InputError
from .kramers_kronig import kramers_kronig
from .symbols import RECIPROCAL, SYMBOLS, compliance_symbol, modulus_symbol, response_symbol

KINDS = ("compliance", "modulus", "generic")


#: Relative tolerance within which two frequencies count as the same one.
FREQUENCY_RTOL = 1e-9


#: σ may not be below this multiple of |G| on its line: G itself is stored and the structures
#: are evaluated with relative rounding errors of a few 1e-16, so a smaller σ claims a precision
#: the arithmetic cannot reach (and 1/σ² overflows for σ → 0).
SIGMA_MIN_RATIO = 1e-15



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
    distinct_frequencies : bool
        Refuse a frequency that appears twice (default). Joint data sets of several isotherms
        (:mod:`bayesfo.tts`) repeat the frequencies of the sweep.
    symbol : {"G", "E", "J", "D"}
        The letter of the measured quantity, for names only (:mod:`bayesfo.data.symbols`):
        ``"G"`` a shear modulus (the default), ``"E"`` a tensile (Young's) modulus as a DMA
        measures it, ``"J"`` a shear and ``"D"`` a tensile compliance. The readers take it from
        the columns (``E'``, ``E_stor``, ``"Tensile storage modulus"``, ``D'``) or a
        ``# symbol:`` line; figures, reports and the terminal then say E′, E″, |E*|, E_e
        instead of G′, G″, |G*|, G_e. It does not change a computation. Every copy keeps it
        (slices, :meth:`split`, :meth:`to_csv_text`, :meth:`to_dict`); :meth:`reciprocal` turns
        a modulus' letter into its compliance's (E → D).

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
    distinct_frequencies: bool = True
    symbol: str = "G"

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
        if self.distinct_frequencies:
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
        if self.symbol not in SYMBOLS:
            raise InputError(f"argument 'symbol' must be one of {', '.join(SYMBOLS)} (shear "
                             f"modulus, tensile modulus, shear compliance, tensile compliance), "
                             f"got {self.symbol!r}")
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
    def modulus_symbol(self) -> str:
        """``"G"`` for shear, ``"E"`` for tensile data (whatever the kind)."""
        return modulus_symbol(self.symbol)

    @property
    def compliance_symbol(self) -> str:
        """``"J"`` for shear, ``"D"`` for tensile data (whatever the kind)."""
        return compliance_symbol(self.symbol)

    @property
    def response_symbol(self) -> str:
        """The letter of the response as its kind says: E for a tensile modulus, D for a
        tensile compliance, G or J for shear (``symbol`` for a generic response)."""
        return response_symbol(self.symbol, self.kind)

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
        # 1/(1/Pa) is Pa; 1/Pa stays 1/Pa, and a compound unit is bracketed (1/(m/N)).
        u = self.units.strip() if self.units else ""
        inner = u[2:].strip() if u.startswith("1/") else None
        if inner is not None and inner.startswith("(") and inner.endswith(")"):
            inner = inner[1:-1]
        units = (inner if inner is not None else
                 "" if not u else f"1/{u}" if u.isidentifier() else f"1/({u})")
        symbol = RECIPROCAL[self.symbol] if kind != self.kind else self.symbol
        return replace(
            self,
            response=1.0 / self.response,
            sigma=None if self.sigma is None else self.sigma / mag2,
            kind=kind,
            units=units,
            symbol=symbol,
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
        train : FrequencyResponse
            The remaining points.
        test : FrequencyResponse
            The held-out points.

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
                # The two nearest on a logarithmic scale, closest first, with enough digits
                # to be given back as they are.
                near = self.omega[np.argsort(np.abs(np.log(self.omega / w)))[:2]] if w > 0 \
                    else np.sort(self.omega)[:1]
                raise InputError(
                    f"hold-out frequency {w:g} rad/s is not among the frequencies of {self.where()} "
                    f"({self.omega.min():g} … {self.omega.max():g} rad/s); the nearest measured: "
                    + ", ".join(f"{v:.6g}" for v in near) + " rad/s"
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
            n = self.n_frequencies
            raise InputError(
                f"{self.where()} has {n} {'frequency' if n == 1 else 'frequencies'}, fewer "
                f"than the {n_params} parameters of {what}: measure more frequencies, or "
                "choose structures of fewer parameters (--structures)"
            )

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_replicates(
        cls, omega, responses, *, kind: str = "generic", units: str = "", name: str = "",
        source: str = "", symbol: str = "G",
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
        return cls(omega, mean, sigma, kind=kind, units=units, name=name, source=source,
                   symbol=symbol)

    # ------------------------------------------------------------------ output
    def to_csv(self, path: str | os.PathLike) -> Path:
        """Write the response in the CSV contract (``omega,real,imag[,sigma]``), atomically."""
        return atomic_write_text(path, self.to_csv_text())

    def to_csv_text(self, comments=()) -> str:
        """The response as CSV text of the contract (numbers written exactly), with ``# name:``,
        ``# kind:``, ``# units:`` and, for a symbol other than the default G, ``# symbol:``
        lines, and then ``comments`` (e.g. ``"temperature: 20 °C"``), each as a ``#`` line."""
        lines = []
        if self.name:
            lines.append(f"# name: {self.name}")
        lines.append(f"# kind: {self.kind}")
        if self.units:
            lines.append(f"# units: {self.units}")
        if self.symbol != "G":
            lines.append(f"# symbol: {self.symbol}")
        lines.extend(f"# {c}" for c in comments)
        header = ["omega", "real", "imag"] + (["sigma"] if self.sigma is not None else [])
        lines.append(",".join(header))
        cols = [self.omega, self.response.real, self.response.imag]
        if self.sigma is not None:
            cols.append(self.sigma)
        for row in np.column_stack(cols):
            lines.append(",".join(repr(float(v)) for v in row))
        return "\n".join(lines) + "\n"

    def kramers_kronig(self):
        """The linear Kramers–Kronig test of the two parts
        (:func:`bayesfo.data.kramers_kronig.kramers_kronig`), or None with too few points."""
        try:
            return kramers_kronig(self)
        except InputError:
            return None

    def to_dict(self) -> dict:
        """Plain-Python summary for JSON output (no arrays of data); ``symbol`` is the letter
        of the measured quantity (:attr:`symbol`)."""
        return {
            "name": self.label,
            "path": self.source,
            "kind": self.kind,
            "units": self.units,
            "symbol": self.symbol,
            "n_frequencies": self.n_frequencies,
            "omega_min": float(self.omega.min()),
            "omega_max": float(self.omega.max()),
            "has_sigma": self.sigma is not None,
            "dissipation_violations": self.omega[self.dissipation_violations()].tolist(),
            "notes": list(self.notes),
            "kramers_kronig": None if (kk := self.kramers_kronig()) is None else kk.to_dict(),
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

