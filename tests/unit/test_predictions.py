"""Material functions of a structure against closed forms: Mittag-Leffler functions (by
pymittagleffler, Garrappa's algorithm) for fractional orders, exponentials for integer ones,
power laws for a springpot. The fixed Talbot inversion is accurate to about 1e-10 in double
precision; the tolerances below allow 1e-9."""

from __future__ import annotations

import numpy as np
import pytest
from pymittagleffler import mittag_leffler
from scipy.special import gamma

from bayesfo.errors import InputError
from bayesfo.predictions import QUANTITIES, evaluate
from bayesfo.predictions.laplace import invert
from bayesfo.structures import get_structure

T = np.logspace(-3, 3, 61)
TOL = 1e-9


def ml(z, alpha, beta=1.0):
    return np.real(mittag_leffler(np.asarray(z, dtype=complex), alpha, beta))


def test_mittag_leffler_reference_is_exact_where_a_closed_form_exists():
    # E_{1/2}(-x) = erfcx(x), E_1(-x) = exp(-x): the reference itself, against two identities.
    from scipy.special import erfcx

    x = np.logspace(-3, 2, 30)
    np.testing.assert_allclose(ml(-x, 0.5), erfcx(x), rtol=1e-13)
    np.testing.assert_allclose(ml(-x, 1.0), np.exp(-x), rtol=1e-13)


def test_talbot_inverts_known_transforms():
    # 1/(s+a) -> exp(-a t); 1/s^2 -> t; s^(-1/2) -> 1/sqrt(pi t)
    t = np.logspace(-2, 2, 9)
    np.testing.assert_allclose(invert(lambda s: 1 / (s + 2.0), t), np.exp(-2 * t), atol=1e-12)
    np.testing.assert_allclose(invert(lambda s: 1 / s**2, t), t, rtol=1e-10)
    np.testing.assert_allclose(invert(lambda s: s**-0.5, t), 1 / np.sqrt(np.pi * t), rtol=1e-10)


def test_springpot():
    s, c, a = get_structure("springpot"), 2.0, 0.4
    np.testing.assert_allclose(evaluate(s, [c, a], "relaxation_modulus", T)[0],
                               c * T**-a / gamma(1 - a), rtol=TOL)
    np.testing.assert_allclose(evaluate(s, [c, a], "creep_compliance", T)[0],
                               T**a / (c * gamma(1 + a)), rtol=TOL)
    # Its spectrum: H(τ) = c sin(πα) τ^-α / π, whose integral against exp(-t/τ) is G(t).
    np.testing.assert_allclose(evaluate(s, [c, a], "relaxation_spectrum", T)[0],
                               c * np.sin(np.pi * a) * T**-a / np.pi, rtol=1e-12)
    np.testing.assert_allclose(evaluate(s, [c, a], "retardation_spectrum", T)[0],
                               np.sin(np.pi * a) * T**a / (np.pi * c), rtol=1e-12)


def test_fractional_zener_against_mittag_leffler():
    # C(s) = (b0 + b1 s^q)/(1 + a1 s^q): J(t) = b1/a1 + (b0 − b1/a1)(1 − E_q(−t^q/a1)) and
    # G(t) = a1/b1 + (1/b0 − a1/b1)(1 − E_q(−t^q b0/b1)).
    a1, b0, b1, q = 2.0, 3.0, 0.5, 0.6
    z = get_structure("zener")
    j = b1 / a1 + (b0 - b1 / a1) * (1 - ml(-T**q / a1, q))
    g = a1 / b1 + (1 / b0 - a1 / b1) * (1 - ml(-T**q * b0 / b1, q))
    np.testing.assert_allclose(evaluate(z, [a1, b0, b1, q], "creep_compliance", T)[0], j, rtol=TOL)
    np.testing.assert_allclose(evaluate(z, [a1, b0, b1, q], "relaxation_modulus", T)[0], g,
                               rtol=TOL)


def test_fractional_maxwell_against_two_parameter_mittag_leffler():
    # G*(s) = a1 s^β/(1 + b1 s^α): G(t) = (a1/b1) t^(α−β) E_{α, 1+α−β}(−t^α/b1).
    a1, b1, alpha, beta = 2.0, 0.5, 0.8, 0.3
    m = get_structure("maxwell")
    g = a1 / b1 * T**(alpha - beta) * ml(-T**alpha / b1, alpha, 1 + alpha - beta)
    np.testing.assert_allclose(evaluate(m, [a1, b1, alpha, beta], "relaxation_modulus", T)[0],
                               g, rtol=TOL)


def test_integer_structures_against_exponentials():
    a1, b0, b1 = 2.0, 3.0, 0.5
    zi = get_structure("zener-int")
    np.testing.assert_allclose(evaluate(zi, [a1, b0, b1], "creep_compliance", T)[0],
                               b0 + (b1 / a1 - b0) * np.exp(-T / a1), rtol=TOL)
    np.testing.assert_allclose(evaluate(zi, [a1, b0, b1], "relaxation_modulus", T)[0],
                               1 / b0 + (a1 / b1 - 1 / b0) * np.exp(-T * b0 / b1), rtol=TOL)
    # A Maxwell liquid creeps without bound (the flow term t/η) and relaxes to 0.
    mi = get_structure("maxwell-int")
    np.testing.assert_allclose(evaluate(mi, [a1, b1], "creep_compliance", T)[0],
                               T / a1 + b1 / a1, rtol=TOL)
    np.testing.assert_allclose(evaluate(mi, [a1, b1], "relaxation_modulus", T)[0],
                               a1 / b1 * np.exp(-T / b1), atol=TOL * a1 / b1)
    # A Kelvin-Voigt solid: G(t) = E for t > 0 (its viscous delta at t = 0 is not a value).
    vi = get_structure("voigt-int")
    np.testing.assert_allclose(evaluate(vi, [a1, b0], "relaxation_modulus", T)[0],
                               np.full(T.size, 1 / b0), rtol=1e-7)


def test_frequency_quantities_are_the_parts_of_the_response():
    z = get_structure("zener")
    theta = [2.0, 3.0, 0.5, 0.6]
    w = np.logspace(-2, 2, 9)
    g = z.response(theta, w, "modulus")
    j = z.response(theta, w, "compliance")
    got = {q: evaluate(z, theta, q, w)[0] for q, spec in QUANTITIES.items() if spec[0] == "omega"}
    np.testing.assert_allclose(got["storage"], g.real, rtol=1e-13)
    np.testing.assert_allclose(got["loss"], g.imag, rtol=1e-13)
    np.testing.assert_allclose(got["tan_delta"], g.imag / g.real, rtol=1e-13)
    np.testing.assert_allclose(got["storage_compliance"], j.real, rtol=1e-13)
    np.testing.assert_allclose(got["loss_compliance"], -j.imag, rtol=1e-13)
    np.testing.assert_allclose(got["complex_viscosity"], np.abs(g) / w, rtol=1e-13)
    assert np.all(got["loss"] > 0) and np.all(got["loss_compliance"] > 0)  # dissipation


def test_vectorised_over_parameter_sets():
    z = get_structure("zener")
    sets = np.array([[2.0, 3.0, 0.5, 0.6], [1.0, 2.0, 0.1, 0.9]])
    both = evaluate(z, sets, "relaxation_modulus", T)
    for row, theta in zip(both, sets):
        np.testing.assert_array_equal(row, evaluate(z, theta, "relaxation_modulus", T)[0])


def test_time_functions_together_are_the_same_numbers_as_one_by_one():
    # G(t) and J(t) from one evaluation of C(s) on the contour: the same arithmetic per
    # quantity, so the same numbers to the last bit as evaluate's, which the tests above hold
    # to the closed forms.
    from bayesfo.predictions.functions import evaluate_together

    z = get_structure("zener")
    sets = np.array([[2.0, 3.0, 0.5, 0.6], [1.0, 2.0, 0.1, 0.9], [0.5, 1.0, 2.0, 0.3]])
    sets = np.repeat(sets, 100, axis=0)  # more sets than one chunk of the inversion
    pair = evaluate_together(z, sets, ("relaxation_modulus", "creep_compliance"), T)
    for q in ("relaxation_modulus", "creep_compliance"):
        np.testing.assert_array_equal(pair[q], evaluate(z, sets, q, T))
    # Frequency-domain quantities one by one, as evaluate gives them.
    parts = evaluate_together(z, sets[:3], ("storage", "loss"), [1.0, 10.0])
    np.testing.assert_array_equal(parts["loss"], evaluate(z, sets[:3], "loss", [1.0, 10.0]))
    with pytest.raises(InputError, match="must share their argument"):
        evaluate_together(z, sets[:1], ("storage", "creep_compliance"), T)


@pytest.mark.parametrize("x, message", [
    ([], "give one or more times"), ([0.0, 1.0], "finite and > 0; got 0"),
    ([1.0, np.inf], "finite and > 0; got inf"), (["a"], "must be numbers")])
def test_bad_arguments_name_what_is_wrong(x, message):
    with pytest.raises(InputError, match=message):
        evaluate(get_structure("zener"), [2.0, 3.0, 0.5, 0.6], "relaxation_modulus", x)
    with pytest.raises(InputError, match="unknown quantity 'G_t'"):
        evaluate(get_structure("zener"), [2.0, 3.0, 0.5, 0.6], "G_t", [1.0])


@pytest.mark.parametrize("name, theta, expected", [
    ("voigt", [2.0, 0.25, 0.4], 4.0),                      # 1/b0
    ("zener", [2.0, 0.5, 0.1, 0.4], 2.0),                  # 1/b0
    ("max-n2m1", [2.0, 1.0, 0.2, 0.1, 0.6], 5.0),          # 1/b0
    ("fractional_zener_sl", [7.0, 3.0, 5.0, 0.3], 7.0),    # the parallel spring G_e
    ("maxwell", [1e3, 2.0, 0.3, 0.8], 0.0),                # two springpots in series
    ("fractional_kelvin_voigt", [3.0, 5.0, 0.2, 0.7], 0.0),
    ("fractional_maxwell_gel", [7.0, 3.0, 0.4], 0.0),
    ("fractional_maxwell_liquid", [3.0, 5.0, 0.4], 0.0),
    ("fractional_jeffreys", [1.0, 3.0, 5.0, 0.4], 0.0),
    ("fractional_burgers", [7.0, 5.0, 2.0, 3.0, 0.4], 0.0),
    ("springpot", [3.0, 0.05], 0.0),                       # relaxes, if slowly
    ("maxwell-inv", [1e3, 2.0, 0.3, 0.8], np.inf),         # C(s) -> 0: G(t) grows
])
def test_long_time_modulus_from_the_lowest_powers(name, theta, expected):
    from bayesfo.predictions.long_time import equilibrium_modulus

    got = equilibrium_modulus(get_structure(name), [theta, theta])
    np.testing.assert_array_equal(got, [expected, expected])


def test_long_time_modulus_is_where_integer_orders_relax_to():
    """An independent computation: G(t) by the Talbot inversion, long after the last
    relaxation time, for structures of integer orders (exponential relaxation)."""
    from bayesfo.predictions.long_time import equilibrium_modulus

    for name, theta in [("zener-int", [2.0, 3.0, 0.5]), ("maxwell-int", [2.0, 0.5]),
                        ("max-n2m1-int", [2.0, 1.0, 0.2, 0.1])]:
        s = get_structure(name)
        late = evaluate(s, theta, "relaxation_modulus", [1e3])[0, 0]
        g_e = equilibrium_modulus(s, theta)[0]
        assert late == pytest.approx(g_e, rel=1e-8, abs=1e-10), name


def test_the_equilibrium_modulus_of_a_relaxation_spectrum_is_its_own_g_e():
    """A spectrum master (no powers of s) gives its equilibrium modulus, which its modulus
    approaches at low frequency: G*(ω → 0) → G_e (every mode relaxed)."""
    from bayesfo.predictions.long_time import equilibrium_modulus
    from bayesfo.tts.spectrum import Spectrum

    spec = Spectrum.over(0.1, 100.0)
    theta = np.r_[250.0, 5.0, np.full(len(spec.tau) - 1, -0.2)]
    g_e = equilibrium_modulus(spec, theta[None, :])
    assert g_e == pytest.approx([250.0])
    low = spec.response(theta[None, :], np.array([1e-9]), kind="modulus")
    assert np.real(low).ravel()[0] == pytest.approx(250.0, rel=1e-3)
