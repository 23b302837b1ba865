"""Time-domain validation helpers (bayesfo.timeseries.timedomain, thesis §4.3.3).

Known answers: (jω)^α for the Oustaloup filter; exact rational functions for integer exponents;
1 - exp(-t) for the step response of 1/(1+s); 1 - E_{1/2}(-t^{1/2}) = 1 - erfcx(sqrt(t)) for
1/(1+s^{1/2}); a numerical Laplace inversion (fixed Talbot contour, independent of any rational
approximation) for a three-term fractional model; |G(jω)| and arg G(jω) from the power terms for
the steady-state sine response. Tolerances are measured errors with a margin of about 1.3 to 2,
so a regression shows up while the statement "the approximation is this good" stays honest.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal, special

from bayesfo.errors import InputError
from bayesfo.timeseries.timedomain import default_band, oustaloup, rational_approximation, simulate

HALF = ([(1.0, 0.0)], [(1.0, 0.0), (1.0, 0.5)])
ZENER = ([(1.0, 0.0), (0.5, 0.6)], [(1.0, 0.0), (2.0, 0.6)])
MAX3 = (
    [(1.0, 0.0), (0.3, 0.45), (0.1, 0.9)],
    [(1.0, 0.0), (1.5, 0.45), (0.7, 0.9), (0.2, 1.35)],
)


def exact(model, omega):
    """G(jω) from the power terms, principal branch."""
    num, den = model
    s = 1j * np.asarray(omega, dtype=float)
    return sum(c * s**e for c, e in num) / sum(c * s**e for c, e in den)


def zpk_response(zpk, omega):
    z, p, k = zpk
    s = 1j * np.asarray(omega, dtype=float)[:, None]
    return k * np.prod(s - z, axis=1) / np.prod(s - p, axis=1)


def talbot_step(model, t, m=24):
    """Step response by the fixed Talbot inversion of G(s)/s (Abate & Valko 2004).

    Against 1 - erfcx(sqrt(t)) it is accurate to 1e-12 for m = 24 on t in [0.01, 10].
    """
    num, den = model
    k = np.arange(1, m)
    theta = k * np.pi / m
    cot = 1.0 / np.tan(theta)
    sigma = theta + (theta * cot - 1.0) * cot
    out = np.empty(len(t))
    for i, ti in enumerate(t):
        r = 2.0 * m / (5.0 * ti)
        s = np.concatenate([[r + 0j], r * theta * (cot + 1j)])
        f = sum(c * s**e for c, e in num) / sum(c * s**e for c, e in den) / s
        val = 0.5 * (np.exp(r * ti) * f[0]).real
        val += np.sum((np.exp(ti * s[1:]) * f[1:] * (1 + 1j * sigma)).real)
        out[i] = r / m * val
    return out


def fitted_sine(t, y, omega, window):
    """Complex amplitude of the sine at omega in y over the last `window` seconds."""
    m = t >= t[-1] - window
    basis = np.column_stack([np.sin(omega * t[m]), np.cos(omega * t[m]), np.ones(m.sum())])
    coef = np.linalg.lstsq(basis, y[m], rcond=None)[0]
    return coef[0] + 1j * coef[1]


# --------------------------------------------------------------------------------------------
# Oustaloup filter
# --------------------------------------------------------------------------------------------
def test_oustaloup_matches_the_thesis_formula_by_hand():
    # N = 1, band [0.01, 100], alpha = 0.5: omega_k^± = 0.01 * 1e4 ** ((k + 1 + (1 ± 0.5)/2) / 3)
    z, p, k = oustaloup(0.5, 0.01, 100.0, order=1)
    np.testing.assert_allclose(-z, 10.0 ** np.array([-5 / 3, -1 / 3, 1.0]), rtol=1e-14)
    np.testing.assert_allclose(-p, 10.0 ** np.array([-1.0, 1 / 3, 5 / 3]), rtol=1e-14)
    assert k == pytest.approx(10.0, rel=1e-15)


# measured maxima over alpha in 0.05..0.95 at two decades inside a six-decade band:
# magnitude 7.9e-4, 1.9e-4, 5.0e-5, 4.8e-5, 4.7e-5 for N = 5..9; phase 0.55 deg for every N,
# set by the band edges (the phase at one frequency depends on the slope over the whole axis).
@pytest.mark.parametrize("order, mag_tol", [(5, 1e-3), (6, 3e-4), (7, 1e-4), (8, 1e-4), (9, 1e-4)])
def test_oustaloup_matches_jw_alpha_inside_the_band(order, mag_tol):
    w = np.logspace(-1, 1, 400)
    for alpha in np.linspace(0.05, 0.95, 19):
        zpk = oustaloup(alpha, 1e-3, 1e3, order)
        assert zpk[0].size == zpk[1].size == 2 * order + 1
        ratio = zpk_response(zpk, w) / (1j * w) ** alpha
        assert np.max(np.abs(np.abs(ratio) - 1)) < mag_tol
        assert np.max(np.abs(np.angle(ratio, deg=True))) < 0.6


def test_oustaloup_error_falls_with_order_and_grows_towards_the_edges():
    w_mid = np.logspace(-1, 1, 200)
    w_edge = np.logspace(-2, -1.5, 50)  # within 1.5 decades of omega_low
    err = []
    for order in (2, 3, 4, 5):
        ratio = zpk_response(oustaloup(0.5, 1e-3, 1e3, order), w_mid) / (1j * w_mid) ** 0.5
        err.append(np.max(np.abs(np.abs(ratio) - 1)))
    assert all(a > b for a, b in zip(err, err[1:]))
    edge = zpk_response(oustaloup(0.5, 1e-3, 1e3, 9), w_edge) / (1j * w_edge) ** 0.5
    assert np.max(np.abs(np.angle(edge, deg=True))) > 1.0


def test_integer_exponents_are_exact():
    z, p, k = oustaloup(2, 1e-2, 1e2)
    np.testing.assert_array_equal(z, [0.0, 0.0])
    assert p.size == 0 and k == 1.0
    z, p, k = oustaloup(-1.0, 1e-2, 1e2)
    assert z.size == 0 and k == 1.0
    np.testing.assert_array_equal(p, [0.0])
    z, p, k = oustaloup(0, 1e-2, 1e2)
    assert z.size == p.size == 0 and k == 1.0


def test_integer_part_split_off_exactly():
    w = np.logspace(-1, 1, 50)
    ratio15 = zpk_response(oustaloup(1.5, 1e-3, 1e3, 7), w) / (1j * w) ** 1.5
    ratio05 = zpk_response(oustaloup(0.5, 1e-3, 1e3, 7), w) / (1j * w) ** 0.5
    np.testing.assert_allclose(ratio15, ratio05, rtol=1e-12)
    # negative orders: split towards zero, so s^-0.5 has no pole at the origin
    z, p, _ = oustaloup(-0.5, 1e-3, 1e3, 7)
    assert np.all(p < 0) and np.all(z < 0)
    ratio = zpk_response((z, p, _), w) / (1j * w) ** -0.5
    assert np.max(np.abs(ratio - 1)) < 0.01
    z, p, _ = oustaloup(-1.5, 1e-3, 1e3, 7)
    assert np.count_nonzero(p == 0) == 1


@pytest.mark.parametrize(
    "args, match",
    [
        ((np.nan, 1e-2, 1e2), "'alpha' must be a finite real number"),
        ((1j, 1e-2, 1e2), "'alpha' must be a real number"),
        ((0.5, 0.0, 1e2), "'omega_low' must be > 0"),
        ((0.5, 1e2, 1e-2), "'omega_high' .* must be larger than 'omega_low'"),
        ((0.5, 1e-2, np.inf), "'omega_high' must be a finite real number"),
        ((0.5, 1e-2, 1e2, 0), "'order' must be an integer >= 1"),
        ((0.5, 1e-2, 1e2, 2.0), "'order' must be an integer >= 1"),
    ],
)
def test_oustaloup_rejects_bad_arguments(args, match):
    with pytest.raises(InputError, match=match):
        oustaloup(*args)


# --------------------------------------------------------------------------------------------
# rational approximation of power terms
# --------------------------------------------------------------------------------------------
def test_integer_power_terms_give_the_exact_transfer_function():
    tf = rational_approximation([(1.0, 0), (2.0, 1)], [(3.0, 0), (1.0, 1), (1.0, 2)], 1e-3, 1e3)
    np.testing.assert_allclose(tf.num, [2.0, 1.0], rtol=1e-13)
    np.testing.assert_allclose(tf.den, [1.0, 1.0, 3.0], rtol=1e-13)


# measured at two decades inside [1e-3, 1e3] for N = 5..9: magnitude 1.0e-3 (half), 8.8e-4
# (zener), 2.2e-3 (three-term); phase 0.23, 0.075, 0.12 deg. The error of a sum is inherited
# from the phase error of its fractional terms (0.55 deg = 0.01 rad above).
@pytest.mark.parametrize("model", [HALF, ZENER, MAX3], ids=["half", "zener", "max3"])
@pytest.mark.parametrize("order", [5, 9])
def test_rational_approximation_inside_the_band(model, order):
    tf = rational_approximation(*model, 1e-3, 1e3, order)
    w = np.logspace(-1, 1, 200)
    _, h = signal.freqresp(tf, w)
    ratio = h / exact(model, w)
    assert np.max(np.abs(np.abs(ratio) - 1)) < 3e-3
    assert np.max(np.abs(np.angle(ratio, deg=True))) < 0.3


def test_shared_fractional_parts_share_one_filter():
    order = 5
    # zener: one fractional part on both sides -> the Oustaloup denominators cancel
    assert len(rational_approximation(*ZENER, 1e-3, 1e3, order).den) - 1 == 2 * order + 1
    # s^0.5 / (1 + s^0.5): also 2N + 1
    tf = rational_approximation([(1.0, 0.5)], [(1.0, 0.0), (1.0, 0.5)], 1e-3, 1e3, order)
    assert len(tf.den) - 1 == 2 * order + 1
    # max3: fractional parts 0.45, 0.9, 0.35 -> three filters, plus the integer part of 1.35
    assert len(rational_approximation(*MAX3, 1e-3, 1e3, order).den) - 1 == 3 * (2 * order + 1) + 1


@pytest.mark.parametrize(
    "num, den, match",
    [
        ([(1.0, -0.5)], [(1.0, 0.0)], "'numerator': term 0 has exponent -0.5"),
        ([(1.0,)], [(1.0, 0.0)], "'numerator': term 0 must be a .coefficient, exponent. pair"),
        ("1/(1+s)", [(1.0, 0.0)], "'numerator' must be a sequence"),
        ([(1.0, 0.0)], [(0.0, 0.0), (0.0, 1.0)], "'denominator' has no nonzero term"),
        ([(1.0, 0.0)], [(np.nan, 1.0)], r"'denominator\[0\] coefficient' must be a finite"),
        ([(1.0, 0.0)], [], "'denominator' has no nonzero term"),
    ],
)
def test_rational_approximation_rejects_bad_terms(num, den, match):
    with pytest.raises(InputError, match=match):
        rational_approximation(num, den, 1e-3, 1e3)


# --------------------------------------------------------------------------------------------
# simulation
# --------------------------------------------------------------------------------------------
T_STEP = np.arange(0.0, 10.0 + 1e-9, 0.01)


def test_step_response_of_first_order_lag_is_exact():
    # integer exponents: no approximation, lsim is exact for a piecewise-linear input
    y = simulate([(1.0, 0.0)], [(1.0, 0.0), (1.0, 1.0)], T_STEP, np.ones_like(T_STEP))
    np.testing.assert_allclose(y, 1.0 - np.exp(-T_STEP), rtol=0, atol=1e-12)


def test_integrator_and_static_gain():
    t = np.arange(5.0, 8.0, 0.05)  # a grid not starting at zero
    np.testing.assert_allclose(simulate([(2.0, 0.0)], [(1.0, 1.0)], t, np.ones_like(t)),
                               2.0 * (t - t[0]), atol=1e-12)
    u = np.sin(t)
    np.testing.assert_array_equal(simulate([(3.0, 0.0)], [(1.5, 0.0)], t, u), 2.0 * u)


# Error of the step response of 1/(1 + s^0.5) on t in [0.01, 10] with the default band
# (6.3e-6 .. 3.1e5 rad/s), measured: N = 5: 3.25e-3, 6: 1.37e-3, 7: 5.8e-4, 8: 2.45e-4,
# 9: 1.06e-4; the automatic order (N = 11, two pairs per decade): 2.2e-5.
@pytest.mark.parametrize(
    "order, tol", [(5, 4.5e-3), (6, 2e-3), (7, 8e-4), (8, 3.5e-4), (9, 1.5e-4), (None, 3e-5)]
)
def test_step_response_of_half_order_system(order, tol):
    y = simulate(*HALF, T_STEP, np.ones_like(T_STEP), order=order)
    ref = 1.0 - special.erfcx(np.sqrt(T_STEP))
    keep = T_STEP >= 0.01
    assert np.max(np.abs(y - ref)[keep]) < tol
    # at t = 0 the approximation jumps by its high-frequency gain 1/(1 + omega_h^0.5) (about
    # 1.8e-3 here) where the exact response is continuous
    assert 0 < y[0] < 2e-3


def test_step_response_of_three_term_model_against_laplace_inversion():
    # measured 1.3e-5 (default band and order); the Talbot reference is good to 1e-12
    t = T_STEP[1:]
    y = simulate(*MAX3, T_STEP, np.ones_like(T_STEP))[1:]
    assert np.max(np.abs(y - talbot_step(MAX3, t))) < 4e-5


def test_explicit_band_and_order():
    y = simulate(*HALF, T_STEP, np.ones_like(T_STEP), omega_low=1e-4, omega_high=1e4, order=7)
    ref = 1.0 - special.erfcx(np.sqrt(T_STEP))
    err = np.max(np.abs(y - ref)[T_STEP >= 0.01])
    assert 1e-4 < err < 3e-4  # measured 1.9e-4: narrower band than the default, coarser


@pytest.mark.parametrize("model, omega", [(HALF, 1.0), (MAX3, 2.0)], ids=["half", "max3"])
def test_sine_response_in_steady_state(model, omega):
    # 200 s of a sine from rest; the transient of a fractional system decays like a power of t
    # and is the main error left over the last 10 periods: measured 5e-6 / 0.008 deg (half)
    # and 6e-5 / 0.002 deg (max3).
    t = np.arange(0.0, 200.0, 0.01)
    y = simulate(*model, t, np.sin(omega * t))
    g_fit = fitted_sine(t, y, omega, window=10 * 2 * np.pi / omega)
    g = exact(model, omega)
    assert abs(abs(g_fit) / abs(g) - 1) < 3e-4
    assert abs(np.angle(g_fit / g, deg=True)) < 0.03


def test_default_band_follows_the_time_grid():
    lo, hi = default_band(np.arange(0.0, 10.0, 0.01))
    assert lo == pytest.approx(2 * np.pi / 10.0 * 1e-5, rel=1e-12)
    assert hi == pytest.approx(np.pi / 0.01 * 1e3, rel=1e-9)


def test_improper_model_cannot_be_simulated():
    with pytest.raises(InputError, match="improper"):
        simulate([(1.0, 2.0)], [(1.0, 0.0), (1.0, 1.0)], T_STEP, np.ones_like(T_STEP))


def test_too_wide_band_is_refused_not_garbled():
    with pytest.raises(InputError, match="narrow the band"):
        simulate(*MAX3, T_STEP, np.ones_like(T_STEP), omega_low=1e-12, omega_high=1e12)


@pytest.mark.parametrize(
    "t, u, match",
    [
        (T_STEP[:1], np.ones(1), "'t' has 1 samples; at least 2 are needed"),
        (np.r_[0.0, 0.1, 0.25, 0.3], np.ones(4), "'t' is not uniformly sampled"),
        (np.r_[0.0, 0.1, 0.1, 0.3], np.ones(4), r"strictly increasing; t\[2\] <= t\[1\]"),
        (np.r_[0.0, np.nan, 0.2], np.ones(3), "'t' has a non-finite value at index 1"),
        (T_STEP, np.ones(5), "'u' must have the shape of 't'"),
        (np.r_[0.0, 0.1, 0.2], np.r_[0.0, np.inf, 1.0], "'u' has a non-finite value at index 1"),
    ],
)
def test_simulate_rejects_bad_signals(t, u, match):
    with pytest.raises(InputError, match=match):
        simulate(*HALF, t, u)


def test_simulate_rejects_bad_band_and_order():
    with pytest.raises(InputError, match="'omega_high' .* must be larger"):
        simulate(*HALF, T_STEP, np.ones_like(T_STEP), omega_low=10.0, omega_high=1.0)
    with pytest.raises(InputError, match="'order' must be an integer >= 1"):
        simulate(*HALF, T_STEP, np.ones_like(T_STEP), order=-2)


def test_simulate_structure_integer_voigt_step_and_modulus():
    from bayesfo.structures import get_structure
    from bayesfo.timeseries.timedomain import simulate_structure

    t = np.linspace(0.0, 5.0, 2001)
    u = np.ones_like(t)
    # voigt-int: b0/(1 + a1 s): creep under a unit stress step is b0 (1 - exp(-t/a1)).
    y = simulate_structure(get_structure("voigt-int"), [0.5, 2.0], t, u)
    np.testing.assert_allclose(y, 2.0 * (1 - np.exp(-t / 0.5)), atol=1e-9)
    # voigt with q = 0.5 against the closed form b0 (1 - erfcx(sqrt(t))) (a1 = 1).
    from scipy.special import erfcx

    y = simulate_structure(get_structure("voigt"), [1.0, 2.0, 0.5], t, u)
    np.testing.assert_allclose(y[200:], 2.0 * (1 - erfcx(np.sqrt(t[200:]))), atol=1e-4)
    # A modulus simulates the reciprocal: maxwell-int as modulus is a1 s/(1 + b1 s), whose step
    # response is (a1/b1) exp(-t/b1).
    y = simulate_structure(get_structure("maxwell-int"), [3.0, 0.5], t, u, kind="modulus")
    np.testing.assert_allclose(y[1:], 6.0 * np.exp(-t[1:] / 0.5), rtol=1e-6, atol=1e-9)
