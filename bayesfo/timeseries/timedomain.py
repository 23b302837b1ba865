"""Time-domain validation of fractional-order transfer functions (thesis §4.3.3).

A fractional-order model identified in the frequency domain is validated in the time domain by
driving it with a measured input and comparing its output with the measured output. The model
is simulated through a rational (integer-order) approximation valid on a frequency band
``[omega_low, omega_high]``: every power ``s**alpha`` is replaced by Oustaloup's recursive
filter, after which the ordinary machinery of :mod:`scipy.signal` applies.

Three layers, each usable on its own:

* :func:`oustaloup` -- zeros, poles and gain approximating ``s**alpha`` on a band;
* :func:`rational_approximation` -- a ratio of sums of power terms as a
  :class:`scipy.signal.TransferFunction`;
* :func:`simulate` -- the response to a sampled input, with a default band derived from the time
  grid.

References
----------
A. Oustaloup, F. Levron, B. Mathieu, F. M. Nanot, "Frequency-band complex noninteger
differentiator: characterization and synthesis", IEEE Trans. Circuits Syst. I 47 (2000) 25-39.
Thesis §4.3.3 (model validation in the time domain), eq. for G_f(s) and omega_k^±.

This module is longer than the project's 500-line guide: Oustaloup's approximation, the
simulation and the validation metrics are one pipeline with one set of band checks.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import polynomial as P
from scipy import signal
from scipy.linalg import lapack

from bayesfo.errors import InputError

from .sine import check_time_grid

__all__ = [
    "oustaloup",
    "rational_approximation",
    "simulate",
    "default_band",
]

# Exponents closer than this to an integer are treated as that integer, so that values such as
# 1.0000000000000002 produced by arithmetic do not create a spurious Oustaloup filter of order ~0.
_INTEGER_TOL = 1e-12

# A sample time may deviate from the uniform grid by this fraction of a step (rounding of
# recorded time stamps); the simulation then treats the samples as exactly equally spaced.

# The polynomial degree grows with the exponents; beyond this a typo is far likelier than a model.
_MAX_EXPONENT = 64


# --------------------------------------------------------------------------------------------
# argument checks
# --------------------------------------------------------------------------------------------
def _check_real(name: str, value) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InputError(f"argument {name!r} must be a real number, got {value!r}") from None
    if isinstance(value, complex) or not math.isfinite(out):
        raise InputError(f"argument {name!r} must be a finite real number, got {value!r}")
    return out


def _check_band(omega_low, omega_high) -> tuple[float, float]:
    lo = _check_real("omega_low", omega_low)
    hi = _check_real("omega_high", omega_high)
    if lo <= 0.0:
        raise InputError(f"argument 'omega_low' must be > 0 rad/s, got {lo!r}")
    if hi <= lo:
        raise InputError(
            f"argument 'omega_high' ({hi!r} rad/s) must be larger than 'omega_low' ({lo!r} rad/s)"
        )
    return lo, hi


def _check_order(order) -> int:
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)):
        raise InputError(f"argument 'order' must be an integer >= 1, got {order!r}")
    if order < 1:
        raise InputError(f"argument 'order' must be an integer >= 1, got {order!r}")
    return int(order)


def _split_exponent(alpha: float) -> tuple[int, float]:
    """Integer part (towards zero) and fractional part in (-1, 1) of an exponent."""
    nearest = round(alpha)
    if abs(alpha - nearest) <= _INTEGER_TOL * max(1.0, abs(alpha)):
        return int(nearest), 0.0
    n = math.trunc(alpha)
    return n, alpha - n


# --------------------------------------------------------------------------------------------
# Oustaloup filter
# --------------------------------------------------------------------------------------------
def _oustaloup_fraction(
    frac: float, omega_low: float, omega_high: float, order: int
) -> tuple[np.ndarray, np.ndarray, float]:
    """Oustaloup filter for ``s**frac`` with ``0 < |frac| < 1`` (thesis §4.3.3)."""
    k = np.arange(-order, order + 1, dtype=float)
    ratio = omega_high / omega_low
    width = 2 * order + 1
    omega_zero = omega_low * ratio ** ((k + order + 0.5 * (1.0 - frac)) / width)
    omega_pole = omega_low * ratio ** ((k + order + 0.5 * (1.0 + frac)) / width)
    return -omega_zero, -omega_pole, omega_high**frac


def oustaloup(alpha, omega_low, omega_high, order=5):
    r"""Oustaloup's rational approximation of :math:`s^\alpha` on a frequency band.

    The fractional part :math:`\nu` of ``alpha`` (split towards zero, so ``alpha = n + nu`` with
    integer ``n`` and :math:`-1 < \nu < 1`) is approximated by

    .. math::
        s^\nu \approx \omega_h^\nu \prod_{k=-N}^{N} \frac{s + \omega_k^-}{s + \omega_k^+},\qquad
        \omega_k^\pm = \omega_l \left(\frac{\omega_h}{\omega_l}\right)^
        {\frac{k + N + (1 \pm \nu)/2}{2N + 1}},

    and the integer part :math:`s^n` is represented exactly by ``n`` zeros (``n > 0``) or ``-n``
    poles (``n < 0``) at the origin. An integer ``alpha`` is therefore reproduced exactly.
    Splitting towards zero keeps a negative fractional order such as ``-0.5`` free of a pole at
    the origin, which a simulation would turn into an integrator.

    Inside the band the approximation is accurate away from its edges; within a decade of the
    edges the phase error stays large whatever the order, because the phase at one frequency
    depends on the slope of the magnitude over the whole axis (BENCHMARKS.md, "Measurements
    behind design choices").

    Parameters
    ----------
    alpha : float
        Exponent of ``s``; any finite real number.
    omega_low, omega_high : float
        Band of the approximation in rad/s, ``0 < omega_low < omega_high``.
    order : int, optional
        Filter order ``N >= 1``; the fractional part uses ``2 N + 1`` zero/pole pairs.

    Returns
    -------
    zeros : numpy.ndarray
        Zeros in rad/s (real, non-positive).
    poles : numpy.ndarray
        Poles in rad/s (real, non-positive).
    gain : float
        Gain ``k`` such that the approximation is ``k * prod(s - zeros) / prod(s - poles)``; the
        triple can be passed to :class:`scipy.signal.ZerosPolesGain`.

    Raises
    ------
    InputError
        If ``alpha`` is not a finite real number, the band is empty or not positive, or ``order``
        is not an integer >= 1.

    References
    ----------
    Thesis §4.3.3, Oustaloup filter G_f(s); A. Oustaloup et al., IEEE Trans. Circuits Syst. I 47
    (2000) 25-39.

    Examples
    --------
    >>> import numpy as np
    >>> z, p, k = oustaloup(0.5, 1e-3, 1e3, order=5)
    >>> w = 1.0
    >>> approx = k * np.prod(1j * w - z) / np.prod(1j * w - p)
    >>> bool(abs(approx / (1j * w) ** 0.5 - 1) < 2e-3)
    True
    """
    a = _check_real("alpha", alpha)
    lo, hi = _check_band(omega_low, omega_high)
    n_order = _check_order(order)
    n, frac = _split_exponent(a)
    if frac == 0.0:
        zeros, poles, gain = np.empty(0), np.empty(0), 1.0
    else:
        zeros, poles, gain = _oustaloup_fraction(frac, lo, hi, n_order)
    if n > 0:
        zeros = np.concatenate([zeros, np.zeros(n)])
    elif n < 0:
        poles = np.concatenate([poles, np.zeros(-n)])
    return zeros, poles, float(gain)


# --------------------------------------------------------------------------------------------
# sums of power terms as rational functions
# --------------------------------------------------------------------------------------------
def _check_terms(name: str, terms) -> list[tuple[float, float]]:
    """Validate a sequence of ``(coefficient, exponent)`` pairs."""
    if isinstance(terms, (str, bytes)) or not isinstance(terms, Sequence | np.ndarray):
        raise InputError(
            f"argument {name!r} must be a sequence of (coefficient, exponent) pairs, "
            f"got {type(terms).__name__}"
        )
    out = []
    for i, term in enumerate(terms):
        try:
            c, e = term
        except (TypeError, ValueError):
            raise InputError(
                f"argument {name!r}: term {i} must be a (coefficient, exponent) pair, got {term!r}"
            ) from None
        c = _check_real(f"{name}[{i}] coefficient", c)
        e = _check_real(f"{name}[{i}] exponent", e)
        if e < 0.0:
            raise InputError(
                f"argument {name!r}: term {i} has exponent {e!r}; exponents must be >= 0"
            )
        if e > _MAX_EXPONENT:
            raise InputError(
                f"argument {name!r}: term {i} has exponent {e!r}; exponents above "
                f"{_MAX_EXPONENT} are not supported"
            )
        if c != 0.0:
            out.append((c, e))
    if not out:
        raise InputError(f"argument {name!r} has no nonzero term")
    return out


@dataclass(frozen=True)
class _Scaled:
    """``H(s) = num(s / omega_c) / den(s / omega_c)``, coefficients ascending in ``x = s/omega_c``.

    Working in the scaled variable puts the Oustaloup corner frequencies symmetrically around 1,
    which keeps the polynomial coefficients within a few orders of magnitude of each other.
    """

    num: np.ndarray
    den: np.ndarray
    omega_c: float


def _sum_of_powers(terms, lo_x: float, hi_x: float, order: int, omega_c: float):
    """Numerator (ascending in x) and Oustaloup denominators of ``sum c s**e``.

    Terms sharing a fractional part share one Oustaloup denominator, so the common denominator
    only grows with the number of distinct fractional parts.
    """
    groups: dict[float, list[tuple[float, int]]] = {}
    for c, e in terms:
        n, frac = _split_exponent(e)
        # s**e = omega_c**e * x**e in the scaled variable
        groups.setdefault(round(frac, 12), []).append((c * omega_c**e, n))
    fracs = sorted(groups)
    filters = {}
    for f in fracs:
        if f == 0.0:
            filters[f] = (np.ones(1), np.ones(1), 1.0)
        else:
            z, p, g = _oustaloup_fraction(f, lo_x, hi_x, order)
            filters[f] = (P.polyfromroots(z).real, P.polyfromroots(p).real, g)
    numerator = np.zeros(1)
    for f in fracs:
        pz, _, g = filters[f]
        inner = np.zeros(1)
        for c, n in groups[f]:
            inner = P.polyadd(inner, np.concatenate([np.zeros(n), c * g * pz]))
        for other in fracs:
            if other != f:
                inner = P.polymul(inner, filters[other][1])
        numerator = P.polyadd(numerator, inner)
    denominators = {f: filters[f][1] for f in fracs if f != 0.0}
    return numerator, denominators


def _scaled_rational(numerator, denominator, omega_low, omega_high, order) -> _Scaled:
    num_terms = _check_terms("numerator", numerator)
    den_terms = _check_terms("denominator", denominator)
    lo, hi = _check_band(omega_low, omega_high)
    n_order = _check_order(order)
    omega_c = math.sqrt(lo * hi)
    lo_x, hi_x = lo / omega_c, hi / omega_c
    # very wide bands overflow the polynomial coefficients; that is reported below, not warned
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        pn, qn = _sum_of_powers(num_terms, lo_x, hi_x, n_order, omega_c)
        pd, qd = _sum_of_powers(den_terms, lo_x, hi_x, n_order, omega_c)
        # (pn / qn) / (pd / qd) = pn * qd / (qn * pd); Oustaloup denominators common to both
        # sides cancel exactly, which keeps the order down (e.g. s**0.5 / (1 + s**0.5)).
        num = pn
        for f, q in qd.items():
            if f not in qn:
                num = P.polymul(num, q)
        den = pd
        for f, q in qn.items():
            if f not in qd:
                den = P.polymul(den, q)
        scale = np.max(np.abs(den))
        if scale == 0.0:
            raise InputError("argument 'denominator' sums to the zero polynomial")
        num, den = num / scale, den / scale
    if not (np.all(np.isfinite(num)) and np.all(np.isfinite(den))):
        raise InputError(
            "the rational approximation overflows in double precision; narrow the band "
            f"'omega_low'..'omega_high' ({lo:g}..{hi:g} rad/s) or lower 'order' ({n_order})"
        )
    num = _trim(num)
    den = _trim(den)
    # common factors x**k (zeros and poles at the origin) cancel exactly
    k = min(_lowest_power(num), _lowest_power(den))
    return _Scaled(num[k:], den[k:], omega_c)


def _trim(c: np.ndarray) -> np.ndarray:
    c = np.asarray(c, dtype=float)
    nz = np.flatnonzero(c)
    if nz.size == 0:
        return np.zeros(1)
    return c[: nz[-1] + 1]


def _lowest_power(c: np.ndarray) -> int:
    nz = np.flatnonzero(c)
    return int(nz[0]) if nz.size else 0


def _unscale(c: np.ndarray, omega_c: float) -> np.ndarray:
    """Ascending coefficients in x = s/omega_c -> descending coefficients in s."""
    powers = np.arange(c.size, dtype=float)
    return (c * omega_c ** (-powers))[::-1]


def rational_approximation(numerator, denominator, omega_low, omega_high, order=5):
    r"""Rational approximation of a ratio of sums of power terms of ``s``.

    The transfer function

    .. math::
        G(s) = \frac{\sum_i b_i s^{\beta_i}}{\sum_j a_j s^{\alpha_j}}

    is approximated by replacing every non-integer power with its Oustaloup filter
    (:func:`oustaloup`) on ``[omega_low, omega_high]``; integer powers are kept exact. Terms with
    the same fractional part of the exponent share one filter, Oustaloup denominators common to
    numerator and denominator cancel, and the sums are formed with polynomial arithmetic on a
    common denominator. The polynomial order is ``(2 N + 1)`` times the number of distinct
    fractional parts, plus the integer parts.

    The polynomials are formed in the scaled variable ``s / sqrt(omega_low * omega_high)``, where
    the corner frequencies are symmetric about 1, and converted to ``s`` only at the end.

    Parameters
    ----------
    numerator, denominator : sequence of (float, float)
        Power terms ``(coefficient, exponent)`` meaning ``sum(c * s**e)``; exponents are real
        and >= 0, coefficients real. Zero coefficients are ignored.
    omega_low, omega_high : float
        Band of the approximation in rad/s.
    order : int, optional
        Oustaloup order ``N`` (``2 N + 1`` zero/pole pairs per fractional part).

    Returns
    -------
    scipy.signal.TransferFunction
        The rational approximation in ``s``. Its coefficients can span many orders of magnitude
        for wide bands (they are powers of the corner frequencies); :func:`simulate` therefore
        works on the scaled form instead of this object.

    Raises
    ------
    InputError
        If a term is not a pair of finite reals, an exponent is negative, a side has no nonzero
        term, or the band or order is invalid.

    References
    ----------
    Thesis §4.3.3 (time-domain validation with the Oustaloup filter, MATLAB ``oustapp``).

    Examples
    --------
    >>> import numpy as np
    >>> tf = rational_approximation([(1.0, 0.0)], [(1.0, 0.0), (1.0, 0.5)], 1e-3, 1e3, order=7)
    >>> _, h = tf.freqresp([1.0])
    >>> bool(abs(h[0] * (1 + (1j) ** 0.5) - 1) < 1e-3)
    True
    """
    scaled = _scaled_rational(numerator, denominator, omega_low, omega_high, order)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        num = _unscale(scaled.num, scaled.omega_c)
        den = _unscale(scaled.den, scaled.omega_c)
        num, den = num / den[0], den / den[0]
    if not (np.all(np.isfinite(num)) and np.all(np.isfinite(den))):
        raise InputError(
            "the transfer function in s overflows in double precision (its coefficients are "
            "powers of the corner frequencies); narrow the band 'omega_low'..'omega_high' or "
            "use simulate(), which works in a scaled variable"
        )
    return signal.TransferFunction(num, den)


# --------------------------------------------------------------------------------------------
# simulation
# --------------------------------------------------------------------------------------------
# Default band relative to what the time grid resolves, [2 pi / duration, pi / dt]: the error
# of a step response grows linearly with omega_low and stops improving once omega_high is far
# enough above pi / dt (BENCHMARKS.md, "Measurements behind design choices"). A step has the
# most low-frequency content of the usual validation inputs, so these margins are conservative
# for sine or chirp records.
_LOW_MARGIN = 1e5
_HIGH_MARGIN = 1e3
# Two zero/pole pairs per decade: a third pair per decade hardly changed the errors above
# (BENCHMARKS.md, "Measurements behind design choices").
_PAIRS_PER_DECADE = 2.0
_MIN_ORDER = 5


def default_band(t) -> tuple[float, float]:
    """Default Oustaloup band for a simulation on the time grid ``t``.

    The grid resolves angular frequencies from ``2 pi / duration`` to the Nyquist frequency
    ``pi / dt``. The band reaches five decades below the first and three decades above the
    second, because an Oustaloup filter is inaccurate for about a decade next to each edge and the
    slow tail of a fractional response depends on frequencies far below ``1 / duration``.

    Parameters
    ----------
    t : array_like
        Equally spaced sample times in seconds (at least two).

    Returns
    -------
    omega_low, omega_high : float
        Band in rad/s.

    Raises
    ------
    InputError
        If ``t`` is not a strictly increasing, equally spaced, finite 1-D grid of two or more
        samples.

    References
    ----------
    Thesis §4.3.3 (frequency set Omega of the Oustaloup filter).
    """
    t = check_time_grid(t, min_samples=2)
    dt = (t[-1] - t[0]) / (t.size - 1)
    duration = t[-1] - t[0] + dt
    return 2.0 * np.pi / duration / _LOW_MARGIN, np.pi / dt * _HIGH_MARGIN


def _auto_order(omega_low: float, omega_high: float) -> int:
    decades = math.log10(omega_high / omega_low)
    return max(_MIN_ORDER, math.ceil((_PAIRS_PER_DECADE * decades - 1.0) / 2.0))


def _realisation(scaled: _Scaled) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Balanced controllable-canonical state space of ``num(x) / den(x)``.

    The companion matrix of a wide-band Oustaloup approximation has entries spanning dozens of
    orders of magnitude; diagonal balancing (LAPACK gebal, an exact similarity by powers of two)
    brings them together: on a wide band the unbalanced form overflows inside lsim, the balanced
    one stays accurate (BENCHMARKS.md, "Measurements behind design choices"). Building a cascade
    from polynomial roots instead was worse (roots of such polynomials are inaccurate).
    """
    den = scaled.den[::-1] / scaled.den[-1]
    num = np.zeros(den.size)
    num[den.size - scaled.num.size :] = scaled.num[::-1] / scaled.den[-1]
    n = den.size - 1
    d = float(num[0])
    if n == 0:
        return np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), d
    a = np.zeros((n, n))
    a[0, :] = -den[1:]
    a[1:, :-1] = np.eye(n - 1)
    b = np.zeros((n, 1))
    b[0, 0] = 1.0
    c = (num[1:] - d * den[1:]).reshape(1, n)
    # LAPACK directly, not scipy.linalg.matrix_balance: that casts the scale factors to int for
    # its permutation output, which overflows (a RuntimeWarning, an error under the tests) on
    # the three-term model of tests/unit/test_timedomain.py, whose factors pass 2**63.
    ab, _, _, scale, info = lapack.dgebal(a, scale=1, permute=0)
    if info != 0:  # pragma: no cover - LAPACK argument error, cannot happen with these inputs
        raise RuntimeError(f"LAPACK dgebal failed with info={info}")
    return ab, b / scale[:, None], c * scale[None, :], d


def _check_realisation(scaled: _Scaled, a, b, c, d) -> None:
    """Compare the state space with the polynomials on the band; fail rather than return junk."""
    n = a.shape[0]
    x = 1j * np.logspace(-2, 2, 5)
    with np.errstate(all="ignore"):
        ref = P.polyval(x, scaled.num) / P.polyval(x, scaled.den)
        got = np.array([(c @ np.linalg.solve(xi * np.eye(n) - a, b))[0, 0] + d for xi in x])
    err = np.max(np.abs(got - ref) / np.maximum(np.abs(ref), np.finfo(float).tiny))
    if not np.isfinite(err) or err > 1e-6:
        raise InputError(
            "the rational approximation cannot be realised accurately in double precision "
            f"(relative error {err:.2g}); narrow the band 'omega_low'..'omega_high' or lower "
            "'order'"
        )


def simulate(numerator, denominator, t, u, *, omega_low=None, omega_high=None, order=None):
    r"""Response of a fractional-order transfer function to a sampled input.

    The transfer function :math:`\sum_i b_i s^{\beta_i} / \sum_j a_j s^{\alpha_j}` is replaced
    by its rational approximation (:func:`rational_approximation`) and simulated with
    :func:`scipy.signal.lsim`, with the input interpolated linearly between samples and the
    system at rest before ``t[0]``. The simulation runs in the time scale
    ``tau = omega_c * (t - t[0])``, ``omega_c = sqrt(omega_low * omega_high)``, on a balanced
    state-space realisation, which keeps bands of ten or more decades numerically sound.

    With the defaults (:func:`default_band`, ``order`` chosen for two zero/pole pairs per
    decade) the unit step responses of ``1/(1 + s**q)`` for ``q`` in 0.2..0.8 and of a
    three-term fractional model agree closely with a numerical Laplace inversion (BENCHMARKS.md,
    "Measurements behind design choices").

    Parameters
    ----------
    numerator, denominator : sequence of (float, float)
        Power terms ``(coefficient, exponent)`` as in :func:`rational_approximation`.
    t : array_like
        Equally spaced sample times in seconds, shape ``(n,)``, ``n >= 2``.
    u : array_like
        Input samples, shape ``(n,)``. Any nonzero ``u[0]`` acts as a step at ``t[0]``; remove a
        measured offset first if the system was not at rest.
    omega_low, omega_high : float, optional
        Band of the Oustaloup approximation in rad/s; each defaults to the value of
        :func:`default_band`.
    order : int, optional
        Oustaloup order ``N``. Default: ``max(5, ceil(decades - 1/2))``, two zero/pole pairs per
        decade of the band.

    Returns
    -------
    numpy.ndarray
        Output samples, shape ``(n,)``.

    Raises
    ------
    InputError
        If a term, the band or the order is invalid; if ``t`` is not an equally spaced,
        increasing, finite grid; if ``u`` does not match ``t`` or is not finite; if the
        approximation is improper (the numerator's integer order exceeds the denominator's), or
        if it cannot be realised accurately in double precision.

    References
    ----------
    Thesis §4.3.3 (validation in the time domain, error e_abs(k) = eps_m(k) - G_f sigma_m(k)).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 5.0, 0.01)
    >>> y = simulate([(1.0, 0.0)], [(1.0, 0.0), (1.0, 1.0)], t, np.ones_like(t))
    >>> bool(np.max(np.abs(y - (1.0 - np.exp(-t)))) < 1e-6)
    True
    """
    t = check_time_grid(t, min_samples=2)
    try:
        u = np.asarray(u, dtype=float)
    except (TypeError, ValueError):
        raise InputError("argument 'u' must be a 1-D array of real input samples") from None
    if u.shape != t.shape:
        raise InputError(f"argument 'u' must have the shape of 't' {t.shape}, got {u.shape}")
    if not np.all(np.isfinite(u)):
        i = int(np.flatnonzero(~np.isfinite(u))[0])
        raise InputError(f"argument 'u' has a non-finite value at index {i}")
    lo_default, hi_default = default_band(t)
    lo = lo_default if omega_low is None else omega_low
    hi = hi_default if omega_high is None else omega_high
    lo, hi = _check_band(lo, hi)
    n_order = _auto_order(lo, hi) if order is None else _check_order(order)
    scaled = _scaled_rational(numerator, denominator, lo, hi, n_order)
    if scaled.num.size > scaled.den.size:
        raise InputError(
            "the transfer function is improper (the numerator grows faster with s than the "
            "denominator) and cannot be simulated; check 'numerator' and 'denominator'"
        )
    a, b, c, d = _realisation(scaled)
    if a.shape[0] == 0:
        return d * u
    _check_realisation(scaled, a, b, c, d)
    dt = (t[-1] - t[0]) / (t.size - 1)
    # equally spaced by construction, so lsim's own spacing check cannot trip on rounding
    tau = scaled.omega_c * dt * np.arange(t.size)
    _, y, _ = signal.lsim((a, b, c, np.array([[d]])), u, tau)
    return np.asarray(y, dtype=float).reshape(t.shape)


def simulate_structure(structure, theta, t, u, *, kind="compliance", omega_low=None,
                       omega_high=None, order=None):
    """Time response of a fitted structure to a measured input (thesis §4.3.3).

    Parameters
    ----------
    structure : bayesfo.structures.Structure
    theta : array_like, shape (n_params,)
        Parameters in physical units.
    t, u : array_like
        Uniform time grid [s] and the input record (stress for a compliance, strain for a
        modulus, the input of a generic transfer function).
    kind : {"compliance", "modulus", "generic"}
        For modulus data the structure's reciprocal is simulated (cards describe compliances).
    omega_low, omega_high, order
        Band and order of the Oustaloup approximation (see :func:`simulate`).

    Returns
    -------
    numpy.ndarray
        The simulated output on ``t``.
    """
    num, den = structure.power_terms(theta)
    if kind == "modulus":
        num, den = den, num
    return simulate(num, den, t, u, omega_low=omega_low, omega_high=omega_high, order=order)
