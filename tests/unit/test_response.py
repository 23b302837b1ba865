"""Vectorised transfer functions, Matignon stability and passivity against independent answers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from bayesfo.structures.response import (
    commensurate_response,
    dissipation_grid,
    is_dissipative,
    jw_power,
    matignon_stable,
    power_ratio,
)

W = np.logspace(-2, 3, 37)


def test_half_order_closed_form():
    # 1/(1 + (jw)^0.5) with (jw)^0.5 = sqrt(w) (cos 45° + j sin 45°) written out by hand.
    expected = 1.0 / (1.0 + np.sqrt(W) * (np.sqrt(0.5) + 1j * np.sqrt(0.5)))
    np.testing.assert_allclose(power_ratio(W, [1.0], [0.0], [1.0, 1.0], [0.0, 0.5]), expected,
                               rtol=1e-13)
    np.testing.assert_allclose(commensurate_response(W, [1.0, 1.0], [1.0], 0.5), expected,
                               rtol=1e-13)


def test_jw_power_principal_branch():
    np.testing.assert_allclose(jw_power(4.0, 0.5), 2.0 * np.exp(1j * np.pi / 4), rtol=1e-15)
    np.testing.assert_allclose(jw_power(3.0, 2.0), -9.0, atol=1e-13)


def test_integer_order_equals_rational_function_from_scipy():
    rng = np.random.default_rng(0)
    for n, m in [(1, 0), (2, 1), (3, 3), (2, 2)]:
        a = np.concatenate([[1.0], rng.uniform(0.1, 2.0, n)])
        b = rng.uniform(-1.0, 2.0, m + 1)
        _, h = signal.freqs(b[::-1], a[::-1], worN=W)  # scipy takes descending powers
        np.testing.assert_allclose(commensurate_response(W, a, b, 1.0), h, rtol=1e-11)
        np.testing.assert_allclose(
            power_ratio(W, b, np.arange(m + 1), a, np.arange(n + 1)), h, rtol=1e-11
        )


def test_batches_have_shape_sets_by_frequencies_and_match_loop():
    rng = np.random.default_rng(1)
    a = np.column_stack([np.ones(50), rng.uniform(0, 2, (50, 2))])
    b = rng.uniform(0, 2, (50, 2))
    q = rng.uniform(0.1, 1.0, 50)
    g = commensurate_response(W, a, b, q)
    assert g.shape == (50, W.size)
    for i in (0, 17, 49):
        single = power_ratio(W, b[i], [0, q[i]], a[i], [0, q[i], 2 * q[i]])
        np.testing.assert_allclose(g[i], single, rtol=1e-12)


# ---------------------------------------------------------------- Matignon
def _stable_by_roots(a, q):
    roots = np.roots(a[::-1])
    return bool(np.all(np.abs(np.angle(roots)) > q * np.pi / 2))


@pytest.mark.parametrize("degree", [1, 2, 3, 4])
def test_matignon_matches_numpy_roots(degree):
    rng = np.random.default_rng(degree)
    a = np.column_stack([np.ones(400), rng.normal(size=(400, degree))])
    q = rng.uniform(0.05, 1.0, 400)
    got = matignon_stable(a, q)
    expected = [_stable_by_roots(a[i], q[i]) for i in range(400)]
    np.testing.assert_array_equal(got, expected)
    assert 0 < got.sum() < 400  # both outcomes occur, so the comparison means something


def test_matignon_known_cases():
    # 1 + λ²: roots ±j (|arg| = π/2): stable iff qπ/2 < π/2, i.e. q < 1 (thesis Theorem 3).
    assert matignon_stable([1.0, 0.0, 1.0], 0.5)
    assert not matignon_stable([1.0, 0.0, 1.0], 1.0)
    # 1 - λ: root at λ = 1 (arg 0) is unstable for every q; 1 + λ is stable.
    assert not matignon_stable([1.0, -1.0], 0.3)
    assert matignon_stable([1.0, 1.0], 0.99)
    # A vanishing leading coefficient lowers the degree instead of adding a root at infinity.
    assert matignon_stable([1.0, 1.0, 0.0], 0.5)
    assert matignon_stable([1.0, 1.0, 0.0, 0.0], 0.5)
    # A pole at the origin (integrator) is rejected unless allowed.
    assert not matignon_stable([0.0, 1.0], 0.5)
    assert matignon_stable([0.0, 1.0], 0.5, allow_integrator=True)
    assert not matignon_stable([0.0, -1.0, 1.0], 0.5, allow_integrator=True)
    assert not matignon_stable([0.0, 0.0], 0.5, allow_integrator=True)


def test_matignon_broadcasts():
    out = matignon_stable(np.array([[1.0, 1.0], [1.0, -1.0]]), np.array([0.5, 0.5]))
    np.testing.assert_array_equal(out, [True, False])
    assert matignon_stable([1.0], 0.5)  # constant denominator: no poles


# ---------------------------------------------------------------- passivity
def test_dissipation_sign_by_kind():
    grid = dissipation_grid(1.0, 10.0)
    assert grid[0] == pytest.approx(1e-3) and grid[-1] == pytest.approx(1e4)
    voigt = commensurate_response(grid, [1.0, 2.0], [1.0], 0.6)  # compliance, Im <= 0
    assert is_dissipative(voigt, "compliance")
    assert not is_dissipative(voigt, "modulus")
    assert is_dissipative(1 / voigt, "modulus")
    assert is_dissipative(np.conj(voigt), "generic")
    # Zener compliance dissipates iff b1 <= a1 b0 (static >= instantaneous compliance).
    a = np.array([[1.0, 2.0], [1.0, 2.0]])
    b = np.array([[1.0, 1.9], [1.0, 2.1]])
    g = commensurate_response(grid, a, b, np.array([0.7, 0.7]))
    np.testing.assert_array_equal(is_dissipative(g, "compliance"), [True, False])


def test_real_response_counts_as_dissipative_within_rounding():
    assert is_dissipative(np.array([1.0 + 1e-18j, 2.0 - 0j]), "compliance")
    assert not is_dissipative(np.array([1.0 + 1e-3j]), "compliance")
    assert not is_dissipative(np.array([np.nan + 0j]), "compliance")
