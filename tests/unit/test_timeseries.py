"""Sine records -> frequency response (bayesfo.timeseries.sine, bayesfo.timeseries.records, thesis §3.1, §4.3.1, §4.3.4).

Synthetic records have a known G(jω) = 1/(1 + (jω)^0.5). Tolerances on noisy records follow from
the noise level: white noise of standard deviation s on N samples gives each component of the
complex amplitude of a sine a standard deviation s·sqrt(2/N), so the relative gain error and the
phase error (rad) of G = Y/U have standard deviation sqrt(2/N)·sqrt((s_y/A_y)² + (s_u/A_u)²).
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
from scipy import signal

from bayesfo.errors import InputError, NonlinearityWarning
from bayesfo.timeseries.records import (
    extract_frequency_response,
    read_sine_record,
    write_extraction,
)
from bayesfo.timeseries.sine import HarmonicAnalysis, analyze_sine


def g_true(omega):
    return 1.0 / (1.0 + (1j * omega) ** 0.5)


def sine_pair(t, omega, amp_u=1.0, phase0=0.3):
    """Input and noise-free output of G at omega."""
    g = g_true(omega)
    u = amp_u * np.sin(omega * t + phase0)
    y = amp_u * abs(g) * np.sin(omega * t + phase0 + np.angle(g))
    return u, y


def grid(omega, samples_per_period, n_periods):
    """Time grid with an integer number of samples per period."""
    dt = 2 * np.pi / omega / samples_per_period
    return np.arange(int(round(samples_per_period * n_periods))) * dt


def noise_sd_of_g(omega, n, amp_u, s_u, s_y, n_series=1):
    """Predicted sqrt(E|dG|^2) / |G| of the averaged record (see module docstring)."""
    amp_y = amp_u * abs(g_true(omega))
    return 2.0 / math.sqrt(n * n_series) * math.hypot(s_y / amp_y, s_u / amp_u)


def write_record(path, t, u, y, *, omega=None, freq=None, series=True):
    """Write a record CSV; u, y of shape (n_series, n)."""
    u = np.atleast_2d(u)
    y = np.atleast_2d(y)
    lines = ["# synthetic sine record"]
    if omega is not None:
        lines.append(f"# omega: {omega!r}")
    if freq is not None:
        lines.append(f"# freq: {freq!r} Hz")
    lines.append("series,time,input,output" if series else "time,input,output")
    for s in range(u.shape[0]):
        for k in range(t.size):
            row = [repr(float(t[k])), repr(float(u[s, k])), repr(float(y[s, k]))]
            lines.append(",".join(([str(s + 1)] if series else []) + row))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


# --------------------------------------------------------------------------------------------
# numerical core
# --------------------------------------------------------------------------------------------
def test_whole_periods_noise_free_is_exact():
    omega = 2.0
    t = grid(omega, 100, 6)
    u, y = sine_pair(t, omega)
    res = analyze_sine(t, u, y, omega)
    g = g_true(omega)
    assert abs(res.response / g - 1) < 1e-12
    assert res.gain == pytest.approx(abs(g), rel=1e-12)
    assert res.phase_deg == pytest.approx(np.degrees(np.angle(g)), abs=1e-10)
    assert (res.n_periods, res.n_samples, res.n_series) == (6, 600, 1)
    assert res.sigma is None and not res.nonlinear and not res.omega_estimated
    np.testing.assert_allclose(res.harmonic_ratio_output, 0.0, atol=1e-12)


def test_record_is_cut_to_whole_periods_at_its_end():
    # 7.37 periods; a fast transient in the first 0.37 periods (decayed to 1e-8 at the cut)
    # must not reach the result, which it would if the beginning were kept.
    omega = 1.0
    t = grid(omega, 100, 7.37)
    u, y = sine_pair(t, omega)
    period = 2 * np.pi / omega
    y = y + 0.5 * np.exp(-t / (0.02 * period))
    res = analyze_sine(t, u, y, omega)
    assert (res.n_periods, res.n_samples) == (7, 700)
    assert abs(res.response / g_true(omega) - 1) < 1e-6


def test_non_integer_samples_per_period():
    # 483.3 samples per period: the cut is rounded to whole samples and the fundamental lies
    # up to 0.5/483 bin off its bin. The common Dirichlet factor cancels in Y/U; what is left is
    # the negative-frequency image, of relative size <= 1/(4 * n_kept).
    omega, dt = 1.3, 0.01
    t = np.arange(0.0, 30.7, dt)
    u, y = sine_pair(t, omega, phase0=0.9)
    res = analyze_sine(t, u, y, omega)
    assert res.n_periods == 6
    assert abs(res.response / g_true(omega) - 1) < 1 / (4 * res.n_samples)


def test_offset_and_linear_trend_are_removed_without_bias():
    # two periods only: a plain linear detrend (scipy.signal.detrend) takes part of the sine
    # with the trend and is ~10 % off here; the joint fit must be exact.
    omega = 0.5
    t = grid(omega, 200, 2)
    u, y = sine_pair(t, omega)
    u = u + 3.0 - 0.4 * t
    y = y - 2.0 + 0.25 * t
    res = analyze_sine(t, u, y, omega)
    g = g_true(omega)
    assert abs(res.response / g - 1) < 1e-10
    plain = np.fft.rfft(signal.detrend(y))[2] / np.fft.rfft(signal.detrend(u))[2]
    assert abs(plain / g - 1) > 0.01  # the test would catch the naive detrend


def test_noisy_record_within_noise_derived_tolerance():
    rng = np.random.default_rng(11)
    omega, amp_u, s_u, s_y = 3.0, 2.0, 0.02, 0.05
    t = grid(omega, 64, 20.5)
    u, y = sine_pair(t, omega, amp_u=amp_u)
    u = u + s_u * rng.standard_normal(t.size)
    y = y + s_y * rng.standard_normal(t.size)
    res = analyze_sine(t, u, y, omega)
    g = g_true(omega)
    sd = noise_sd_of_g(omega, res.n_samples, amp_u, s_u, s_y) / math.sqrt(2)  # per component
    assert abs(res.gain / abs(g) - 1) < 5 * sd
    assert abs(np.radians(res.phase_deg) - np.angle(g)) < 5 * sd


def test_gain_and_phase_scatter_matches_noise_prediction():
    # 400 records: the sample standard deviation of a normal quantity has relative standard
    # error 1/sqrt(2*400) = 3.5 %, so 15 % is a > 4-sigma bound.
    rng = np.random.default_rng(12)
    omega, amp_u, s_y = 1.0, 1.0, 0.1
    t = grid(omega, 50, 16)
    u, y0 = sine_pair(t, omega, amp_u=amp_u)
    g = g_true(omega)
    gains, phases = [], []
    for _ in range(400):
        res = analyze_sine(t, u, y0 + s_y * rng.standard_normal(t.size), omega)
        gains.append(res.gain / abs(g) - 1)
        phases.append(np.radians(res.phase_deg) - np.angle(g))
    predicted = noise_sd_of_g(omega, t.size, amp_u, 0.0, s_y) / math.sqrt(2)
    assert np.std(gains) == pytest.approx(predicted, rel=0.15)
    assert np.std(phases) == pytest.approx(predicted, rel=0.15)
    assert abs(np.mean(gains)) < 4 * predicted / math.sqrt(400)


def test_repeated_series_sigma_is_calibrated():
    # 300 records of 5 noisy series each. |G_hat - G|^2 is about exponential (relative standard
    # error of its mean 1/sqrt(300) = 6 %); sigma^2 has 8 degrees of freedom per record.
    rng = np.random.default_rng(13)
    omega, amp_u, s_u, s_y, r = 2.0, 1.0, 0.03, 0.05, 5
    t = grid(omega, 40, 10.3)
    u0, y0 = sine_pair(t, omega, amp_u=amp_u)
    g = g_true(omega)
    err2, sig2 = [], []
    for _ in range(300):
        u = u0 + s_u * rng.standard_normal((r, t.size))
        y = y0 + s_y * rng.standard_normal((r, t.size))
        res = analyze_sine(t, u, y, omega)
        err2.append(abs(res.response - g) ** 2)
        sig2.append(res.sigma**2)
    assert res.n_series == r and res.n_samples == 400
    predicted = (abs(g) * noise_sd_of_g(omega, 400, amp_u, s_u, s_y, n_series=r)) ** 2
    assert np.mean(err2) / np.mean(sig2) == pytest.approx(1.0, abs=0.25)
    assert np.mean(sig2) / predicted == pytest.approx(1.0, abs=0.1)
    assert np.mean(err2) / predicted == pytest.approx(1.0, abs=0.25)


def test_sigma_from_series_spread_by_hand():
    omega = 1.0
    t = grid(omega, 32, 4)
    u, y = sine_pair(t, omega)
    gains = np.array([1.0, 1.1, 0.8])
    res = analyze_sine(t, np.vstack([u] * 3), np.vstack([k * y for k in gains]), omega)
    g_i = gains * g_true(omega)
    expected = math.sqrt(np.sum(np.abs(g_i - g_i.mean()) ** 2) / 2) / math.sqrt(3)
    assert res.sigma == pytest.approx(expected, rel=1e-10)
    assert res.response == pytest.approx(g_i.mean(), rel=1e-10)


def test_omega_is_estimated_from_the_input_spectrum():
    omega, dt = 1.3, 0.01
    t = np.arange(0.0, 30.7, dt)  # 6.35 periods
    u, y = sine_pair(t, omega)
    u = u + 0.2 + 0.01 * t
    res = analyze_sine(t, u, y)
    assert res.omega_estimated
    assert res.omega == pytest.approx(omega, rel=1e-7)
    assert abs(res.response / g_true(omega) - 1) < 1 / (4 * res.n_samples)


def test_quintic_dead_zone_harmonics():
    # thesis §4.3.4: 372 (0.1 sin wt)^5 = 2.325e-4 (10 sin wt - 5 sin 3wt + sin 5wt)
    omega = 1.0
    t = grid(omega, 200, 7.3)
    u = 0.1 * np.sin(omega * t)
    y = 372.0 * u**5
    with pytest.warns(NonlinearityWarning, match=r"omega = 1 rad/s: output harmonic 3 \(3 rad/s\)"):
        res = analyze_sine(t, u, y, omega)
    assert res.nonlinear
    np.testing.assert_allclose(res.harmonic_ratio_output, [0.0, 0.5, 0.0, 0.1], rtol=0, atol=1e-6)
    np.testing.assert_allclose(res.harmonic_ratio_input, 0.0, atol=1e-12)
    assert res.thd_output == pytest.approx(math.sqrt(0.26), abs=1e-6)
    assert res.gain == pytest.approx(2.325e-3 / 0.1, rel=1e-9)
    assert res.phase_deg == pytest.approx(0.0, abs=1e-8)


def test_threshold_argument_and_small_harmonics():
    omega = 1.0
    t = grid(omega, 100, 5)
    u = np.sin(omega * t)
    y = np.sin(omega * t) + 0.01 * np.sin(3 * omega * t)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = analyze_sine(t, u, y, omega)
        assert not res.nonlinear
        assert res.harmonic_ratio_output[1] == pytest.approx(0.01, abs=1e-12)
        loose = analyze_sine(t, u, 372 * (0.1 * u) ** 5, omega, nonlinearity_threshold=0.6)
    assert not loose.nonlinear
    with pytest.warns(NonlinearityWarning, match="harmonic 3"):
        strict = analyze_sine(t, u, y, omega, nonlinearity_threshold=0.005)
    assert strict.nonlinear


def test_harmonics_above_nyquist_are_not_reported():
    omega = 1.0
    t = grid(omega, 7, 10)  # 7 samples per period: 2w and 3w measurable, 4w and 5w are not
    u = np.sin(omega * t)
    y = np.sin(omega * t - 0.2) + 0.02 * np.sin(2 * omega * t)
    res = analyze_sine(t, u, y, omega)
    assert res.harmonic_ratio_output[0] == pytest.approx(0.02, abs=1e-12)
    assert res.harmonic_ratio_output[1] == pytest.approx(0.0, abs=1e-12)
    assert np.isnan(res.harmonic_ratio_output[2:]).all()
    assert res.thd_output == pytest.approx(0.02, abs=1e-12)
    assert res.to_dict()["harmonic_ratio_output"][2:] == [None, None]


def test_n_harmonics_sets_the_length_of_the_ratios():
    omega = 1.0
    t = grid(omega, 64, 4)
    u, y = sine_pair(t, omega)
    assert analyze_sine(t, u, y, omega, n_harmonics=9).harmonic_ratio_output.size == 8
    res = analyze_sine(t, u, y, omega, n_harmonics=1)
    assert res.harmonic_ratio_output.size == 0 and res.thd_output == 0.0


def test_to_dict_is_json_ready():
    omega = 2.0
    t = grid(omega, 50, 3)
    u, y = sine_pair(t, omega)
    res = analyze_sine(t, np.vstack([u, 1.01 * u]), np.vstack([y, y]), omega)
    d = json.loads(json.dumps(res.to_dict()))
    assert d["response_real"] == pytest.approx(res.response.real)
    assert d["response_imag"] == pytest.approx(res.response.imag)
    assert d["n_series"] == 2 and d["n_periods"] == 3 and d["sigma"] > 0
    assert len(d["harmonic_ratio_output"]) == 4
    assert isinstance(res, HarmonicAnalysis)
    with pytest.raises(AttributeError):
        res.gain = 1.0  # frozen


# --------------------------------------------------------------------------------------------
# analyze_sine: bad arguments
# --------------------------------------------------------------------------------------------
def _good():
    omega = 1.0
    t = grid(omega, 20, 3)
    u, y = sine_pair(t, omega)
    return t, u, y, omega


def _bad_time_nonuniform():
    t, u, y, w = _good()
    t = t.copy()
    t[10] += 0.2 * (t[1] - t[0])
    return t, u, y, w


def _bad_time_nan():
    t, u, y, w = _good()
    t = t.copy()
    t[3] = np.nan
    return t, u, y, w


def _bad_time_decreasing():
    t, u, y, w = _good()
    return t[::-1], u, y, w


def _bad_u_nan():
    t, u, y, w = _good()
    u = u.copy()
    u[5] = np.inf
    return t, u, y, w


@pytest.mark.parametrize(
    "make, match",
    [
        (lambda: (_good()[0][None, :],) + _good()[1:], "'t' must be 1-D"),
        (lambda: (_good()[0][:5], _good()[1][:5], _good()[2][:5], 1.0), "'t' has 5 samples"),
        (_bad_time_nan, "'t' has a non-finite value at index 3"),
        (_bad_time_decreasing, "'t' must be strictly increasing"),
        (_bad_time_nonuniform, "'t' is not uniformly sampled: t\\[10\\]"),
        (lambda: (_good()[0], _good()[1][:-1], _good()[2], 1.0), "'u' must have shape"),
        (lambda: (_good()[0], _good()[1], np.ones((2, 2, 60)), 1.0), "'y' must have shape"),
        (_bad_u_nan, "'u' has a non-finite value in series 0 at index 5"),
        (
            lambda: (_good()[0], _good()[1], np.vstack([_good()[2]] * 2), 1.0),
            "same number of series",
        ),
        (lambda: _good()[:3] + (-1.0,), "'omega' must be a finite number > 0"),
        (lambda: _good()[:3] + ("fast",), "'omega' must be a positive number"),
        (lambda: _good()[:3] + (100.0,), "'omega' = 100 rad/s is at or above the Nyquist"),
        (lambda: _good()[:3] + (0.2,), "less than one period"),
        (lambda: (_good()[0], np.zeros(60), _good()[2], 1.0), "'u' has zero amplitude"),
        (lambda: (_good()[0], np.full(60, 2.0), _good()[2], None), "'u' has no oscillating"),
        (lambda: _good()[:3] + (2.0,), "'omega' = 2 rad/s does not match the input"),
    ],
)
def test_analyze_sine_rejects_bad_input(make, match):
    t, u, y, omega = make()
    with pytest.raises(InputError, match=match):
        analyze_sine(t, u, y, omega)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"n_harmonics": 0}, "'n_harmonics' must be an integer >= 1"),
        ({"n_harmonics": 2.5}, "'n_harmonics' must be an integer >= 1"),
        ({"nonlinearity_threshold": -0.1}, "'nonlinearity_threshold' must be a finite number > 0"),
    ],
)
def test_analyze_sine_rejects_bad_options(kwargs, match):
    t, u, y, omega = _good()
    with pytest.raises(InputError, match=match):
        analyze_sine(t, u, y, omega, **kwargs)


def test_dead_series_is_named():
    t, u, y, omega = _good()
    with pytest.raises(InputError, match=r"row 1 \(counted from 0\) has zero amplitude"):
        analyze_sine(t, np.vstack([u, 0 * u]), np.vstack([y, y]), omega)


# --------------------------------------------------------------------------------------------
# record files
# --------------------------------------------------------------------------------------------
def test_read_record_with_series_and_frequency_comment(tmp_path):
    omega = 2.0
    t = grid(omega, 16, 2)
    u, y = sine_pair(t, omega)
    path = write_record(tmp_path / "r.csv", t, np.vstack([u, 2 * u]), np.vstack([y, 2 * y]),
                        freq=omega / (2 * np.pi))
    tr, ur, yr, wr = read_sine_record(path)
    np.testing.assert_array_equal(tr, t)
    np.testing.assert_array_equal(ur, np.vstack([u, 2 * u]))
    np.testing.assert_array_equal(yr, np.vstack([y, 2 * y]))
    assert wr == pytest.approx(omega, rel=1e-15)


def test_read_record_without_series_or_frequency(write_csv):
    path = write_csv(
        """
        Time, Input ,OUTPUT
        # a comment between rows
        0.0,0,1
        0.5,1,2

        1.0,0,3
        1.5,-1,4
        2.0,0,5
        2.5,1,6
        3.0,0,7
        3.5,-1,8
        """
    )
    t, u, y, omega = read_sine_record(path)
    assert omega is None
    np.testing.assert_array_equal(t, 0.5 * np.arange(8))
    assert u.shape == (1, 8) and y[0, -1] == 8.0


def test_series_rows_may_interleave(write_csv):
    rows = "\n".join(f"{s},{k * 0.1!r},{k + s},{-k}" for k in range(8) for s in (2, 1))
    path = write_csv("# omega: 3.0 rad/s\nseries,time,input,output\n" + rows)
    t, u, y, omega = read_sine_record(path)
    assert omega == 3.0
    np.testing.assert_array_equal(u[0], np.arange(8) + 2)  # series 2 first: first appearance
    np.testing.assert_array_equal(u[1], np.arange(8) + 1)


def _rows(n=8, series=None):
    out = []
    for k in range(n):
        prefix = f"{series}," if series is not None else ""
        out.append(f"{prefix}{k * 0.1!r},{math.sin(k)!r},{math.cos(k)!r}")
    return "\n".join(out)


@pytest.mark.parametrize(
    "text, match",
    [
        ("", "no header row"),
        ("# only a comment\n", "no header row"),
        ("time,input,output\n", "no data rows after the header on line 1"),
        ("time,input\n" + _rows(8).replace(",", ";"), r"line 1: missing column\(s\) output"),
        ("time,input,output,force\n", r"line 1: unknown column 'force' \(column 4\)"),
        ("time,input,output,input\n", "line 1: column 'input' appears twice"),
        ("time,input,output\n0,1,2\n0.1,1\n", "line 3: 2 cells, but the header has 3 columns"),
        ("time,input,output\n0,1,2\n0.1,abc,2\n", "line 3, column 'input': 'abc' is not a number"),
        ("time,input,output\n0,1,2\n0.1,1,nan\n", "line 3, column 'output': 'nan' is not finite"),
        ("time,input,output\n0,1,2\n0.1,1,inf\n", "line 3, column 'output': 'inf' is not finite"),
        ("time,input,output\n0,1,2\n,1,2\n", "line 3, column 'time': empty cell"),
        (
            "series,time,input,output\n1.5,0,1,2\n",
            "line 2, column 'series': '1.5' is not an integer",
        ),
        ("time,input,output\n" + _rows(5), "the record has 5 samples; at least 8"),
        (
            "series,time,input,output\n" + _rows(8, 1) + "\n" + _rows(9, 2),
            "series 2 has 9 samples but series 1 has 8",
        ),
        (
            "series,time,input,output\n" + _rows(8, 1) + "\n" + _rows(8, 2).replace("0.5", "0.55"),
            "line 15, column 'time': series 2 has time 0.55 where series 1 has 0.5",
        ),
        (
            "time,input,output\n" + _rows(8).replace("0.2,", "0.25,", 1),
            "line 4, column 'time': time 0.25 is",
        ),
        ("time,input,output\n" + _rows(8).replace("0.30000000000000004,", "0.1,", 1),
         "line 5, column 'time': time 0.1 does not increase"),
        ("# omega: fast\ntime,input,output\n" + _rows(8), "line 1: '# omega:' value 'fast' is not"),
        ("# omega: -1\ntime,input,output\n" + _rows(8), "line 1: '# omega:' value must be finite"),
        (
            "# freq: 2 rad/s\ntime,input,output\n" + _rows(8),
            "line 1: '# freq:' must be followed by",
        ),
        ("# omega: 1\n# omega: 2\ntime,input,output\n" + _rows(8), "line 2: second '# omega:'"),
        (
            "# omega: 1\n# freq: 1\ntime,input,output\n" + _rows(8),
            "line 2: '# freq:' gives 6.28319 rad/s but '# omega:' on line 1 gives 1 rad/s",
        ),
    ],
)
def test_read_record_errors_name_file_line_and_column(write_csv, text, match):
    path = write_csv(text, name="rec.csv")
    with pytest.raises(InputError, match=match) as info:
        read_sine_record(path)
    assert str(path) in str(info.value)


def test_read_record_missing_file(tmp_path):
    with pytest.raises(InputError, match="nope.csv' does not exist"):
        read_sine_record(tmp_path / "nope.csv")
    with pytest.raises(InputError, match="is a directory"):
        read_sine_record(tmp_path)


def test_consistent_omega_and_freq_comments_are_accepted(write_csv):
    path = write_csv(f"# freq: 0.5 Hz\n# omega: {np.pi!r} rad/s\ntime,input,output\n" + _rows(8))
    assert read_sine_record(path)[3] == pytest.approx(np.pi, rel=1e-15)


# --------------------------------------------------------------------------------------------
# extraction and output
# --------------------------------------------------------------------------------------------
def _campaign(tmp_path, rng, omegas, n_series=3, noise=0.01):
    paths = []
    for i, omega in enumerate(omegas):
        t = grid(omega, 40, 6.5)
        u, y = sine_pair(t, omega)
        u = u + noise * rng.standard_normal((n_series, t.size))
        y = y + noise * rng.standard_normal((n_series, t.size))
        paths.append(write_record(tmp_path / f"rec{i}.csv", t, u, y, omega=omega))
    return paths


def test_extract_frequency_response_sorted_with_sigma(tmp_path):
    rng = np.random.default_rng(21)
    omegas = [3.0, 0.3, 10.0, 1.0]
    paths = _campaign(tmp_path, rng, omegas)
    fr, analyses = extract_frequency_response(paths, kind="compliance")
    np.testing.assert_allclose(fr.omega, sorted(omegas), rtol=1e-15)
    assert fr.kind == "compliance" and fr.sigma is not None
    assert [a.omega for a in analyses] == list(fr.omega)
    g = g_true(fr.omega)
    # each point: 3 series of 260 samples, noise 0.01 on both sides -> 5-sigma bound
    for k, a in enumerate(analyses):
        sd = abs(g[k]) * noise_sd_of_g(fr.omega[k], a.n_samples, 1.0, 0.01, 0.01, n_series=3)
        assert abs(fr.response[k] - g[k]) < 5 * sd
        assert fr.sigma[k] == pytest.approx(sd, rel=0.8)  # 4 degrees of freedom per point


def test_extract_mixed_series_drops_sigma_with_a_note(tmp_path):
    rng = np.random.default_rng(22)
    paths = _campaign(tmp_path, rng, [1.0, 2.0])
    t = grid(4.0, 40, 6.5)
    u, y = sine_pair(t, 4.0)
    paths.append(write_record(tmp_path / "single.csv", t, u, y, omega=4.0, series=False))
    fr, analyses = extract_frequency_response(paths)
    assert fr.sigma is None
    assert [a.n_series for a in analyses] == [3, 3, 1]
    assert any("sigma unknown" in note for note in fr.notes)


def test_extract_rejects_duplicate_frequencies(tmp_path):
    rng = np.random.default_rng(23)
    paths = _campaign(tmp_path, rng, [1.0, 2.0, 1.00001])
    with pytest.raises(InputError, match=r"rec0.csv and .*rec2.csv both give omega = 1"):
        extract_frequency_response(paths)


def test_extract_names_the_file_of_a_bad_record(tmp_path):
    rng = np.random.default_rng(24)
    paths = _campaign(tmp_path, rng, [1.0, 2.0])
    t = grid(1.0, 40, 2)
    u, y = sine_pair(t, 1.0)
    paths.append(write_record(tmp_path / "slow.csv", t, u, y, omega=0.1))
    with pytest.raises(InputError, match=r"slow.csv: the record spans .* less than one period"):
        extract_frequency_response(paths)
    with pytest.raises(InputError, match="'paths' is empty"):
        extract_frequency_response([])


def test_extract_warns_about_the_nonlinear_record_by_file(tmp_path):
    rng = np.random.default_rng(25)
    paths = _campaign(tmp_path, rng, [2.0])
    t = grid(1.0, 100, 5)
    u = 0.1 * np.sin(t)
    paths.append(write_record(tmp_path / "deadzone.csv", t, u, 372 * u**5, omega=1.0))
    match = r"deadzone.csv: omega = 1 rad/s: output harmonic 3"
    with pytest.warns(NonlinearityWarning, match=match):
        fr, analyses = extract_frequency_response(paths)
    assert [a.nonlinear for a in analyses] == [True, False]
    assert fr.sigma is None  # the dead-zone record has a single series
    assert any("nonlinear at omega = 1 rad/s" in note for note in fr.notes)


def test_write_extraction_round_trip(tmp_path):
    from bayesfo.data import read_csv

    rng = np.random.default_rng(26)
    paths = _campaign(tmp_path, rng, [0.5, 5.0, 2.0])
    fr, analyses = extract_frequency_response(paths)
    out, sidecar = write_extraction(tmp_path / "out" / "fr.csv", fr, analyses)
    assert sidecar == tmp_path / "out" / "fr_harmonics.csv"
    back = read_csv(out)
    np.testing.assert_array_equal(back.omega, fr.omega)
    np.testing.assert_array_equal(back.response, fr.response)
    np.testing.assert_array_equal(back.sigma, fr.sigma)
    lines = sidecar.read_text(encoding="utf-8").splitlines()
    assert lines[0] == "omega,gain,phase_deg,n_periods,n_series,h2,h3,h4,h5,thd,nonlinear"
    assert len(lines) == 4
    cells = lines[2].split(",")
    assert float(cells[0]) == analyses[1].omega
    assert float(cells[1]) == analyses[1].gain
    assert float(cells[2]) == analyses[1].phase_deg
    assert cells[3:5] == [str(analyses[1].n_periods), "3"]
    assert [float(c) for c in cells[5:9]] == list(analyses[1].harmonic_ratio_output)
    assert cells[10] == "false"


def test_write_extraction_rejects_mismatched_analyses(tmp_path):
    rng = np.random.default_rng(27)
    fr, analyses = extract_frequency_response(_campaign(tmp_path, rng, [0.5, 5.0]))
    with pytest.raises(InputError, match="'analyses' has 1 entries but 'fr' has 2 points"):
        write_extraction(tmp_path / "x.csv", fr, analyses[:1])
    with pytest.raises(InputError, match=r"'analyses'\[0\] is for omega = 5 rad/s"):
        write_extraction(tmp_path / "x.csv", fr, analyses[::-1])
    assert not (tmp_path / "x.csv").exists()


def test_bundled_example_records():
    # examples/data/sine_records: G = 1/(1 + s^0.5), 3 series, noise sd 0.01 on both signals,
    # offset and drift on the output, 6.6 periods of 32 samples (make_records.py there)
    from pathlib import Path

    folder = Path(__file__).resolve().parents[2] / "examples" / "data" / "sine_records"
    fr, analyses = extract_frequency_response(sorted(folder.glob("*.csv")))
    np.testing.assert_allclose(fr.omega, [0.1, 0.3, 1.0, 3.0, 10.0], rtol=1e-12)
    g = g_true(fr.omega)
    for k, a in enumerate(analyses):
        assert (a.n_periods, a.n_samples, a.n_series) == (6, 192, 3)
        sd = abs(g[k]) * noise_sd_of_g(fr.omega[k], 192, 1.0, 0.01, 0.01, n_series=3)
        assert abs(fr.response[k] - g[k]) < 5 * sd
        assert not a.nonlinear
    assert fr.sigma is not None and fr.source.endswith("sine_records")


def test_an_input_that_is_not_a_sine_is_refused_or_leaves_linearity_untested():
    """Broadband noise as the input holds a few per cent of its power at omega: refused (its
    'gain' was a ratio of two small components). A square wave's fundamental holds 8/pi^2 = 81 %:
    G is the ratio of the fundamentals, which is right for a linear system, but the output's
    harmonics are the input's, so the record is not called nonlinear, and a warning says so."""
    import warnings as w

    from bayesfo.errors import NonlinearityWarning

    omega = 1.0
    t = grid(omega, 200, 8)
    rng = np.random.default_rng(0)
    # A weak sine in broadband noise: the largest line of the input's spectrum is at omega
    # (so omega matches it), but it holds a few per cent of the input's power.
    noisy = 0.3 * np.sin(omega * t) + rng.standard_normal(t.size)
    with pytest.raises(InputError, match=r"the input is not a sine at omega = 1 rad/s: its "
                                         r"component there holds [1-9] % of its power"):
        analyze_sine(t, noisy, 0.5 * noisy, omega)
    # A square wave (its harmonics up to the fifth, those the analysis fits) through a linear
    # system, harmonic by harmonic.
    g = g_true
    u = sum(4 / np.pi / k * np.sin(k * omega * t) for k in (1, 3, 5))
    y = sum(4 / np.pi / k * abs(g(k * omega)) * np.sin(k * omega * t + np.angle(g(k * omega)))
            for k in (1, 3, 5))
    with w.catch_warnings(record=True) as caught:
        w.simplefilter("always")
        res = analyze_sine(t, u, y, omega)
    assert not res.nonlinear
    assert res.response == pytest.approx(g(omega), rel=1e-9)
    assert any(issubclass(c.category, NonlinearityWarning)
               and "the input is not a pure sine" in str(c.message) for c in caught)
