"""One sine record to one frequency-response point (thesis §3.1, §4.3.1): the numerical core.

Reading record files and turning many records into a data set is :mod:`bayesfo.timeseries.records`.

For every excitation frequency omega the system input ``u(t) = u0 sin(omega t)`` and the output
``y(t)`` are recorded, possibly several times. One record gives one point ``G(j omega)`` of the
frequency response:

1. the repeated series are averaged;
2. the record is cut to the largest whole number of periods that fits, keeping its end, where
   the transient after switching the excitation on has died away;
3. offset and linear trend are removed;
4. the fundamental is read from the FFT bin of the excitation frequency (with whole periods it
   falls on a bin) and ``G = Y(omega) / U(omega)``;
5. the output's amplitudes at ``2 omega .. K omega`` relative to the fundamental reveal a
   nonlinearity such as the servo valve's dead zone of thesis §4.3.4;
6. with several series, ``G`` of every series gives the standard error of the mean.

Offset and trend are estimated by least squares *together with* sines and cosines at
``omega .. K omega`` and only the offset and trend are subtracted. A plain linear detrend
(:func:`scipy.signal.detrend`) fits part of the sine itself, because ``t`` and ``sin(omega t)``
are correlated over whole periods: it shrinks the sine component of each signal by
``24 / (2 pi m)**2 = 0.61 / m**2`` for ``m`` periods (15 % for two periods, 0.6 % for ten).
For an output lagging by 46 degrees this biased the gain by 10 %, 1.4 % and 0.3 % and the phase
by 4.3, 0.66 and 0.16 degrees with 2, 5 and 10 periods; the joint fit is exact to rounding.

References
----------
Thesis §3.1 (extraction of magnitude and phase with the FFT), §4.3.1 (preprocessing: averaging,
whole periods, offsets and linear trends), §4.3.4 (dead zone ``f(x) = 372 x**5`` and its
harmonics at 3 omega and 5 omega).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize

from bayesfo.errors import InputError, NonlinearityWarning

__all__ = ["HarmonicAnalysis", "analyze_sine", "check_time_grid"]

# A sample time may deviate from the ideal uniform grid by this fraction of a step. The FFT
# treats samples as equally spaced; 1 % of a step is a timing error below omega*dt/100 rad.
GRID_TOLERANCE = 0.01

# Fewest samples per series a record may hold.
MIN_SAMPLES = 8

# Two records whose frequencies agree to this relative tolerance measure the same point.
SAME_FREQUENCY_RTOL = 1e-4

# An input amplitude at omega below this fraction of the input's largest value is treated as
# zero (no excitation at that frequency).
_ZERO_AMPLITUDE_RTOL = 1e-10

# With a declared omega, some other input bin larger than this multiple of the fundamental
# means the declared frequency is not the one that excited the system.
_FOREIGN_PEAK_FACTOR = 2.0



# --------------------------------------------------------------------------------------------
# result
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class HarmonicAnalysis:
    """Frequency-response point and harmonic content of one sine record.

    Attributes
    ----------
    omega : float
        Excitation frequency in rad/s (declared, or estimated from the input spectrum).
    response : complex
        ``G(j omega) = Y(omega) / U(omega)`` of the averaged series.
    sigma : float or None
        Standard error of ``response``, ``sqrt(E|dG|**2)``, from the spread of the series'
        individual ``G``; None for a single series.
    gain : float
        ``abs(response)``.
    phase_deg : float
        ``angle(response)`` in degrees, in (-180, 180]; positive means the output leads.
    n_periods : int
        Whole periods of the excitation used.
    n_series : int
        Number of repeated series averaged.
    harmonic_ratio_output : numpy.ndarray
        ``|Y(k omega)| / |Y(omega)|`` for ``k = 2 .. K``; NaN where ``k omega`` is at or above
        the Nyquist frequency (not measurable), or where the output has no fundamental.
    harmonic_ratio_input : numpy.ndarray
        The same for the input.
    thd_output : float
        Total harmonic distortion of the output, ``sqrt(sum_k |Y(k omega)|**2) / |Y(omega)|``
        over the measurable harmonics ``k = 2 .. K``.
    nonlinear : bool
        True when some output harmonic ratio exceeds the threshold; a
        :class:`~bayesfo.errors.NonlinearityWarning` was issued. False where the input itself
        has a harmonic over the threshold (its own warning says so): the output's harmonics
        may then be the input's, and linearity is not tested.
    n_samples : int
        Samples per series used (the whole periods at the end of the record).
    omega_estimated : bool
        True when ``omega`` was estimated from the input spectrum rather than given.

    References
    ----------
    Thesis §3.1, §4.3.4.
    """

    omega: float
    response: complex
    sigma: float | None
    gain: float
    phase_deg: float
    n_periods: int
    n_series: int
    harmonic_ratio_output: np.ndarray = field(repr=False)
    harmonic_ratio_input: np.ndarray = field(repr=False)
    thd_output: float
    nonlinear: bool
    n_samples: int
    omega_estimated: bool

    @property
    def n_harmonics(self) -> int:
        """Highest harmonic ``K`` analysed (the ratio arrays hold ``k = 2 .. K``)."""
        return int(self.harmonic_ratio_output.size + 1)

    def to_dict(self) -> dict:
        """Plain-Python dictionary, JSON-serialisable (NaN becomes None, complex a pair).

        Returns
        -------
        dict
            Keys ``omega, response_real, response_imag, sigma, gain, phase_deg, n_periods,
            n_series, n_samples, omega_estimated, harmonic_ratio_output,
            harmonic_ratio_input, thd_output, nonlinear``; the ratio lists start at ``k = 2``.
        """

        def num(x):
            x = float(x)
            return x if math.isfinite(x) else None

        return {
            "omega": float(self.omega),
            "response_real": float(self.response.real),
            "response_imag": float(self.response.imag),
            "sigma": None if self.sigma is None else float(self.sigma),
            "gain": float(self.gain),
            "phase_deg": float(self.phase_deg),
            "n_periods": int(self.n_periods),
            "n_series": int(self.n_series),
            "n_samples": int(self.n_samples),
            "omega_estimated": bool(self.omega_estimated),
            "harmonic_ratio_output": [num(v) for v in self.harmonic_ratio_output],
            "harmonic_ratio_input": [num(v) for v in self.harmonic_ratio_input],
            "thd_output": num(self.thd_output),
            "nonlinear": bool(self.nonlinear),
        }


# --------------------------------------------------------------------------------------------
# argument checks
# --------------------------------------------------------------------------------------------
def _grid_violation(t: np.ndarray) -> tuple[int, float] | None:
    """First index whose time departs from the uniform grid by more than the tolerance."""
    n = t.size
    dt = (t[-1] - t[0]) / (n - 1)
    dev = np.abs(t - (t[0] + dt * np.arange(n))) / dt
    bad = np.flatnonzero(dev > GRID_TOLERANCE)
    if bad.size:
        return int(bad[0]), float(dev[bad[0]])
    return None


def check_time_grid(t, min_samples: int = MIN_SAMPLES) -> np.ndarray:
    """A uniformly sampled, strictly increasing 1-D time vector, or :class:`InputError`."""
    try:
        t = np.asarray(t, dtype=float)
    except (TypeError, ValueError):
        raise InputError("argument 't' must be a 1-D array of real sample times") from None
    if t.ndim != 1:
        raise InputError(f"argument 't' must be 1-D, got shape {t.shape}")
    if t.size < min_samples:
        raise InputError(f"argument 't' has {t.size} samples; at least {min_samples} are needed")
    if not np.all(np.isfinite(t)):
        i = int(np.flatnonzero(~np.isfinite(t))[0])
        raise InputError(f"argument 't' has a non-finite value at index {i}")
    d = np.diff(t)
    if np.any(d <= 0):
        i = int(np.flatnonzero(d <= 0)[0])
        raise InputError(f"argument 't' must be strictly increasing; t[{i + 1}] <= t[{i}]")
    bad = _grid_violation(t)
    if bad is not None:
        raise InputError(
            f"argument 't' is not uniformly sampled: t[{bad[0]}] is {bad[1]:.3g} steps off the "
            f"uniform grid (tolerance {GRID_TOLERANCE:g} of a step)"
        )
    return t


def _check_signal(name: str, x, n: int) -> np.ndarray:
    try:
        x = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"argument {name!r} must be a real array") from None
    if x.ndim == 1:
        x = x[None, :]
    if x.ndim != 2 or x.shape[1] != n or x.shape[0] < 1:
        raise InputError(
            f"argument {name!r} must have shape ({n},) or (n_series, {n}) to match 't', "
            f"got {np.shape(x)}"
        )
    if not np.all(np.isfinite(x)):
        i, j = (int(v[0]) for v in np.nonzero(~np.isfinite(x)))
        raise InputError(f"argument {name!r} has a non-finite value in series {i} at index {j}")
    return x


def _check_positive(name: str, value) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InputError(f"argument {name!r} must be a positive number, got {value!r}") from None
    if not math.isfinite(out) or out <= 0:
        raise InputError(f"argument {name!r} must be a finite number > 0, got {value!r}")
    return out


def _check_n_harmonics(n_harmonics) -> int:
    if isinstance(n_harmonics, bool) or not isinstance(n_harmonics, (int, np.integer)):
        raise InputError(f"argument 'n_harmonics' must be an integer >= 1, got {n_harmonics!r}")
    if n_harmonics < 1:
        raise InputError(f"argument 'n_harmonics' must be an integer >= 1, got {n_harmonics!r}")
    return int(n_harmonics)


# --------------------------------------------------------------------------------------------
# numerical core
# --------------------------------------------------------------------------------------------
def _sine_design(tc: np.ndarray, omegas) -> np.ndarray:
    """Columns 1, t, and cos/sin at each frequency; ``tc`` centred and scaled to [-1/2, 1/2]."""
    cols = [np.ones_like(tc), tc]
    for w in omegas:
        cols.append(np.cos(w * tc))
        cols.append(np.sin(w * tc))
    return np.column_stack(cols)


def _residual_power(omega: float, t: np.ndarray, x: np.ndarray) -> float:
    """Residual sum of squares of ``x`` after fitting offset, trend and a sine at ``omega``.

    Its minimiser is the least-squares (for white noise, maximum-likelihood) frequency of a
    sinusoid with offset and trend; unlike the raw periodogram peak it is not pulled by the
    negative-frequency image when the record holds few periods.
    """
    tc = t - 0.5 * (t[0] + t[-1])
    span = t[-1] - t[0]
    basis = np.column_stack([np.ones_like(tc), tc / span, np.cos(omega * tc), np.sin(omega * tc)])
    coef, *_ = np.linalg.lstsq(basis, x, rcond=None)
    return float(np.sum((x - basis @ coef) ** 2))


def _estimate_omega(t: np.ndarray, u_mean: np.ndarray) -> float:
    """Frequency of the largest non-DC peak of the input spectrum, refined by least squares."""
    n = t.size
    dt = (t[-1] - t[0]) / (n - 1)
    tc = t - t.mean()
    # a drift would otherwise dominate the lowest bins
    trend = np.polyval(np.polyfit(tc, u_mean, 1), tc)
    spectrum = np.abs(np.fft.rfft(u_mean - trend))
    spectrum[0] = 0.0
    k = int(np.argmax(spectrum))
    if spectrum[k] <= _ZERO_AMPLITUDE_RTOL * n * max(np.max(np.abs(u_mean)), np.finfo(float).tiny):
        raise InputError("argument 'u' has no oscillating component: the input amplitude is zero")
    bin_width = 2.0 * np.pi / (n * dt)
    lo = max(k - 1.0, 0.5) * bin_width
    hi = min(k + 1.0, n / 2.0) * bin_width
    res = optimize.minimize_scalar(
        lambda w: _residual_power(w, t, u_mean),
        bounds=(lo, hi),
        method="bounded",
        options={"xatol": 1e-9 * k * bin_width},
    )
    return float(res.x)


#: Least share of the input's power (past its offset and trend) in its component at omega for
#: the record to be a sine response: a square wave's is 81 %, broadband noise's a few per cent.
MIN_INPUT_SHARE = 0.5


def _analyze(t, u, y, omega, n_harmonics, threshold, where: str) -> HarmonicAnalysis:
    """Checked inputs -> HarmonicAnalysis; ``where`` prefixes warning messages."""
    n = t.size
    dt = (t[-1] - t[0]) / (n - 1)
    n_series = u.shape[0]
    u_mean = u.mean(axis=0)
    y_mean = y.mean(axis=0)

    estimated = omega is None
    if estimated:
        omega = _estimate_omega(t, u_mean)
    nyquist = np.pi / dt
    if omega >= nyquist:
        raise InputError(
            f"argument 'omega' = {omega:g} rad/s is at or above the Nyquist frequency "
            f"{nyquist:g} rad/s of the sampling step {dt:g} s"
        )
    samples_per_period = 2.0 * np.pi / (omega * dt)
    # the small slack lets a record of exactly m periods count as m despite rounding
    m = int(math.floor(n / samples_per_period + 1e-9))
    if m < 1:
        raise InputError(
            f"the record spans {n * dt:g} s, less than one period {2 * np.pi / omega:g} s of "
            f"omega = {omega:g} rad/s (argument 't' too short or 'omega' too low)"
        )
    n_keep = min(n, int(round(m * samples_per_period)))
    sl = slice(n - n_keep, n)
    tk = t[sl]

    # rows: averaged input, averaged output, then every series' input and output
    rows = np.vstack([u_mean[sl], y_mean[sl], u[:, sl], y[:, sl]])
    k_all = np.arange(1, n_harmonics + 1)
    bins = k_all * m
    measurable = bins < n_keep / 2.0
    if not measurable[0]:
        raise InputError(
            f"argument 'omega' = {omega:g} rad/s is too close to the Nyquist frequency "
            f"{nyquist:g} rad/s: the whole periods hold no more than two samples each"
        )
    tc = tk - 0.5 * (tk[0] + tk[-1])
    span = max(tk[-1] - tk[0], dt)
    design = _sine_design(tc / span, omega * span * k_all[measurable])
    coef, *_ = np.linalg.lstsq(design, rows.T, rcond=None)
    detrended = rows - (design[:, :2] @ coef[:2]).T
    spectra = np.fft.rfft(detrended, axis=1)

    amp_scale = 2.0 / n_keep
    u_fund = spectra[0, m]
    y_fund = spectra[1, m]
    u_amp = abs(u_fund) * amp_scale
    u_scale = max(float(np.max(np.abs(u_mean))), np.finfo(float).tiny)
    if u_amp <= _ZERO_AMPLITUDE_RTOL * u_scale:
        raise InputError(
            f"argument 'u' has zero amplitude at omega = {omega:g} rad/s; the input does not "
            "excite the system at this frequency"
        )
    if not estimated:
        others = np.abs(spectra[0, 1:])
        others[m - 1] = 0.0
        j = int(np.argmax(others))
        if others[j] > _FOREIGN_PEAK_FACTOR * abs(u_fund):
            raise InputError(
                f"argument 'omega' = {omega:g} rad/s does not match the input: its spectrum peaks "
                f"at {(j + 1) * 2 * np.pi / (n_keep * dt):g} rad/s with "
                f"{others[j] / abs(u_fund):.3g} times the amplitude at omega"
            )
    # The input must be a sine at omega: its component there holds most of its power (past the
    # offset and trend). Noise or a chirp fed in gives a ratio of two small components, not G.
    power = np.abs(spectra[0, 1:]) ** 2
    share = float(abs(u_fund) ** 2 / power.sum()) if power.sum() > 0 else 1.0
    if share < MIN_INPUT_SHARE:
        raise InputError(
            f"the input is not a sine at omega = {omega:g} rad/s: its component there "
            f"holds {100 * share:.0f} % of its power (a sine's holds nearly all); give records "
            "of a sinusoidal input, one frequency per record")
    response = complex(y_fund / u_fund)

    def ratios(spec_row: np.ndarray) -> np.ndarray:
        out = np.full(n_harmonics - 1, np.nan)
        fund = abs(spec_row[m])
        if fund > 0:
            for idx, (b, ok) in enumerate(zip(bins[1:], measurable[1:])):
                if ok:
                    out[idx] = abs(spec_row[b]) / fund
        return out

    h_out = ratios(spectra[1])
    h_in = ratios(spectra[0])
    finite = h_out[np.isfinite(h_out)]
    if abs(y_fund) > 0:
        thd = float(np.sqrt(np.sum(finite**2)))
    else:
        thd = math.nan

    sigma = None
    if n_series > 1:
        u_series = spectra[2 : 2 + n_series, m]
        y_series = spectra[2 + n_series :, m]
        dead = np.flatnonzero(np.abs(u_series) * amp_scale <= _ZERO_AMPLITUDE_RTOL * u_scale)
        if dead.size:
            raise InputError(
                f"argument 'u': row {int(dead[0])} (counted from 0) has zero amplitude at "
                f"omega = {omega:g} rad/s"
            )
        g_series = y_series / u_series
        spread = np.sum(np.abs(g_series - g_series.mean()) ** 2) / (n_series - 1)
        sigma = float(np.sqrt(spread / n_series))

    distorted = h_in[np.isfinite(h_in)]
    if distorted.size and np.max(distorted) > threshold:
        # Harmonics of the input pass through a linear system as harmonics of the output:
        # the output's cannot tell whether the system is linear.
        worst = int(np.nanargmax(h_in)) + 2
        warnings.warn(
            f"{where}omega = {omega:.6g} rad/s: the input is not a pure sine (its harmonic "
            f"{worst} is {h_in[worst - 2]:.3g} of the fundamental, threshold {threshold:g}): G "
            "is the ratio of the fundamentals, which holds for a linear system, but the output's "
            "harmonics may come from the input's, so linearity is not tested",
            NonlinearityWarning,
            stacklevel=4,
        )
        finite = finite[:0]
    nonlinear = bool(finite.size and np.max(finite) > threshold)
    if nonlinear:
        worst = int(np.nanargmax(h_out)) + 2
        over = [str(k + 2) for k, r in enumerate(h_out) if np.isfinite(r) and r > threshold]
        warnings.warn(
            f"{where}omega = {omega:.6g} rad/s: output harmonic {worst} "
            f"({worst * omega:.6g} rad/s) is {h_out[worst - 2]:.3g} of the fundamental "
            f"(threshold {threshold:g}; harmonics above it: {', '.join(over)}); the system is "
            "not linear at this amplitude and G is the describing function of the fundamental",
            NonlinearityWarning,
            stacklevel=4,
        )

    h_out.setflags(write=False)
    h_in.setflags(write=False)
    return HarmonicAnalysis(
        omega=float(omega),
        response=response,
        sigma=sigma,
        gain=abs(response),
        phase_deg=float(np.degrees(np.angle(response))),
        n_periods=m,
        n_series=n_series,
        harmonic_ratio_output=h_out,
        harmonic_ratio_input=h_in,
        thd_output=thd,
        nonlinear=nonlinear,
        n_samples=n_keep,
        omega_estimated=estimated,
    )


def _check_and_analyze(t, u, y, omega, n_harmonics, nonlinearity_threshold, where=""):
    t = check_time_grid(t)
    u = _check_signal("u", u, t.size)
    y = _check_signal("y", y, t.size)
    if u.shape != y.shape:
        raise InputError(
            f"arguments 'u' and 'y' must have the same number of series, got {u.shape[0]} "
            f"and {y.shape[0]}"
        )
    if omega is not None:
        omega = _check_positive("omega", omega)
    k = _check_n_harmonics(n_harmonics)
    thr = _check_positive("nonlinearity_threshold", nonlinearity_threshold)
    return _analyze(t, u, y, omega, k, thr, where)


def analyze_sine(t, u, y, omega=None, *, n_harmonics=5, nonlinearity_threshold=0.05):
    """Frequency-response point and harmonics of one sine record.

    Parameters
    ----------
    t : array_like, shape (n,)
        Sample times in seconds, strictly increasing and uniformly spaced (each time within
        ``GRID_TOLERANCE`` of a step of the uniform grid).
    u, y : array_like, shape (n,) or (n_series, n)
        Input and output; several rows are repeated series sharing ``t``.
    omega : float, optional
        Excitation frequency in rad/s. If None it is estimated: the largest non-DC peak of the
        averaged input's spectrum, refined by a least-squares sine fit.
    n_harmonics : int, optional
        Highest harmonic ``K`` reported (ratios for ``2 .. K``); 1 reports none.
    nonlinearity_threshold : float, optional
        An output harmonic ratio above this flags the record as nonlinear.

    Returns
    -------
    HarmonicAnalysis

    Raises
    ------
    InputError
        If ``t`` is not 1-D, finite, increasing and uniform with at least ``MIN_SAMPLES``
        samples; if ``u`` or ``y`` do not match it or are not finite; if ``omega`` is not
        positive, at or above the Nyquist frequency, or longer in period than the record; if the
        input has no amplitude at ``omega`` or its spectrum peaks elsewhere; if ``n_harmonics``
        or ``nonlinearity_threshold`` is invalid.

    Warns
    -----
    NonlinearityWarning
        When an output harmonic ratio exceeds ``nonlinearity_threshold``; names the frequency
        and the harmonic.

    Notes
    -----
    The record is cut to its last ``m`` whole periods (``m`` as large as fits). When the number
    of samples per period is not an integer the cut is rounded to whole samples and the
    fundamental lies up to half a sample's worth of phase off its bin; the resulting scaling
    and phase rotation are the same for input and output and cancel in ``G``.

    White noise of standard deviation ``s`` on ``N`` kept samples of a sine of amplitude ``A``
    gives a complex-amplitude error of standard deviation ``s * sqrt(2 / N)`` per component,
    i.e. a relative gain error and a phase error (rad) of about ``s / A * sqrt(2 / N)``.

    References
    ----------
    Thesis §3.1 (FFT peak, gain ``y0/u0``, phase via ``angle``), §4.3.1 (averaging, whole
    periods, offsets and trends), §4.3.4 (dead-zone harmonics).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 20.0, 0.01)
    >>> u = np.sin(2.0 * t)
    >>> y = 0.5 * np.sin(2.0 * t - np.pi / 4)
    >>> res = analyze_sine(t, u, y, omega=2.0)
    >>> round(res.gain, 4), round(res.phase_deg, 2)
    (0.5, -45.0)
    """
    return _check_and_analyze(t, u, y, omega, n_harmonics, nonlinearity_threshold)
