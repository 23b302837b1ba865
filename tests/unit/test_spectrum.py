"""The relaxation-spectrum master function: its modulus against the generalised Maxwell formula
written out, the fast imaginary-axis path against the general one, units, the NNLS seed, and
G(t) against the Prony sum."""

from __future__ import annotations

import numpy as np
import pytest

from bayesfo.data import FrequencyResponse
from bayesfo.errors import InputError
from bayesfo.structures import Scaling
from bayesfo.tts.spectrum import SMOOTHING, Spectrum

SPEC = Spectrum.over(1e-2, 1e2)  # τ from 1e-3 to 1e3: 7 modes
THETA = np.r_[0.05, np.log(2.0), [-0.5, 0.3, -1.0, 0.2, -0.7, -0.4]]


def _maxwell(theta, omega):
    """G*(iω) written out: G_e + Σ g_k (ωτ)²/(1+(ωτ)²) + i Σ g_k ωτ/(1+(ωτ)²)."""
    g = np.exp(theta[1] + np.r_[0.0, np.cumsum(theta[2:])])
    y = np.outer(omega, SPEC.tau)
    return theta[0] + (y**2 / (1 + y**2)) @ g + 1j * (y / (1 + y**2)) @ g


def test_the_modulus_is_the_generalised_maxwell_one():
    w = np.logspace(-3, 3, 13)
    assert len(SPEC.tau) == 7 and SPEC.n_params == 8
    assert SPEC.param_names[:3] == ("G_e", "ln_g_1", "dln_g_2")
    np.testing.assert_allclose(SPEC.response(THETA, w, "modulus"), _maxwell(THETA, w),
                               rtol=1e-12)
    np.testing.assert_allclose(SPEC.response(THETA, w, "compliance"), 1 / _maxwell(THETA, w),
                               rtol=1e-12)
    # Per parameter set, on the imaginary axis (the likelihood's fast path) and off it.
    thetas = np.vstack([THETA, THETA + 0.1])
    shifted = np.vstack([w, 3 * w])
    fast = SPEC.laplace(thetas, 1j * shifted, per_set=True)
    for i in range(2):
        np.testing.assert_allclose(1 / fast[i], _maxwell(thetas[i], shifted[i]), rtol=1e-12)
    s = (0.5 + 1j) * shifted
    general = SPEC.laplace(thetas, s, per_set=True)
    shared = SPEC.laplace(thetas, s[0])
    np.testing.assert_allclose(general[0], shared[0], rtol=1e-12)
    assert SPEC.constraints_hold(thetas, "modulus").all()


def test_prior_and_support():
    assert SPEC.parameters[2].prior.sd == SMOOTHING
    assert SPEC.in_support(THETA) and not SPEC.in_support(np.r_[-1.0, THETA[1:]])
    with pytest.raises(InputError, match="cannot be overridden"):
        SPEC.with_priors({"G_e": None})
    with pytest.raises(InputError, match="too few"):
        SPEC.check_data(FrequencyResponse(np.logspace(0, 1, 5), np.ones(5) + 1j,
                                          kind="modulus"))


@pytest.mark.parametrize("kind", ["modulus", "compliance"])
def test_scaled_and_physical_units_describe_the_same_material(kind):
    scaling = Scaling(omega_ref=7.0, g_ref=3e5, reciprocal=kind == "modulus")
    physical = SPEC.physical(scaling)
    np.testing.assert_allclose(np.asarray(physical.tau) * 7.0, SPEC.tau, rtol=1e-15)
    theta_phys = SPEC.to_physical(THETA, scaling)
    np.testing.assert_allclose(SPEC.to_scaled(theta_phys, scaling), THETA, rtol=1e-14)
    w = np.logspace(-1, 3, 9)
    # The likelihood compares the scaled modulus, G × gain, at ω/ω_ref.
    scaled = SPEC.response(THETA, w / 7.0, "modulus")
    np.testing.assert_allclose(physical.response(theta_phys, w, "modulus") * scaling.tf_gain,
                               scaled, rtol=1e-12)


def test_the_seed_recovers_a_spectrum_on_its_own_grid():
    w = np.logspace(-3, 3, 40)
    data = FrequencyResponse(w, _maxwell(THETA, w), kind="modulus")
    seed = SPEC.seed(data)
    np.testing.assert_allclose(SPEC.response(seed, w, "modulus"), data.response, rtol=1e-6)
    g_true = SPEC.moduli(THETA)[1][0]
    np.testing.assert_allclose(SPEC.moduli(seed)[1][0], g_true, rtol=1e-5)


def test_relaxation_modulus_is_the_prony_sum():
    from bayesfo.predictions.functions import evaluate

    t = np.logspace(-2, 2, 9)
    g_e, g = SPEC.moduli(THETA)
    exact = g_e[0] + np.exp(-t[:, None] / np.asarray(SPEC.tau)) @ g[0]
    np.testing.assert_allclose(evaluate(SPEC, THETA, "relaxation_modulus", t)[0], exact,
                               rtol=1e-7)
