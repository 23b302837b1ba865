"""Likelihood and noise models against an independent computation (scipy.stats)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from bayesfo.data import FrequencyResponse
from bayesfo.errors import InputError
from bayesfo.inference.likelihood import Likelihood, choose_noise
from bayesfo.priors import LogUniform
from bayesfo.structures import get_structure

W = np.logspace(np.log10(0.6), np.log10(300), 25)
ZENER = get_structure("zener")
TRUTH = np.array([0.5, 2e-3, 1e-4, 0.6])  # physical compliance units
G = ZENER.response(TRUTH, W, "compliance")


def _data(sigma=None, kind="compliance", seed=0):
    rng = np.random.default_rng(seed)
    g = G + 2e-5 * (rng.normal(size=25) + 1j * rng.normal(size=25))
    return FrequencyResponse(W, g if kind == "compliance" else 1 / g, sigma, kind=kind)


def _independent(g_data, g_model, sd):
    # Real and imaginary parts independent normals with variance sd²/2 each.
    s = sd / np.sqrt(2)
    return stats.norm.logpdf(g_data.real, g_model.real, s) + stats.norm.logpdf(g_data.imag, g_model.imag, s)


@pytest.mark.parametrize("noise", ["known", "constant", "proportional"])
def test_pointwise_equals_stacked_real_gaussians_in_physical_units(noise):
    sigma = np.full(25, 3e-5)
    data = _data(sigma if noise == "known" else None)
    lik = Likelihood(ZENER, data, noise=noise)
    phys = np.r_[TRUTH * [1.1, 0.9, 1.2, 1.0], [] if noise == "known" else [2.5e-5 if noise == "constant" else 0.02]]
    theta = lik.to_scaled(phys)
    model = ZENER.response(TRUTH * [1.1, 0.9, 1.2, 1.0], W, "compliance")
    sd = {"known": sigma, "constant": np.full(25, 2.5e-5), "proportional": 0.02 * np.abs(data.response)}[noise]
    expected = _independent(data.response, model, sd)
    np.testing.assert_allclose(lik.pointwise(theta)[0], expected, rtol=1e-10)
    np.testing.assert_allclose(lik(theta)[0], expected.sum(), rtol=1e-10)
    np.testing.assert_allclose(lik.to_physical(theta)[0], phys, rtol=1e-12)


def test_modulus_data_compare_the_reciprocal_material():
    data = _data(np.full(25, 1.0), kind="modulus")
    lik = Likelihood(ZENER, data, noise="known")
    theta = lik.to_scaled(TRUTH)
    expected = _independent(data.response, 1 / G, np.full(25, 1.0))
    np.testing.assert_allclose(lik.pointwise(theta)[0], expected, rtol=1e-10)


def test_vectorised_over_sets_equals_loop_and_support():
    lik = Likelihood(ZENER, _data(), noise="constant")
    rng = np.random.default_rng(1)
    theta = lik.to_scaled(np.column_stack([TRUTH * rng.uniform(0.5, 1.5, (50, 4)), np.full(50, 3e-5)]))
    theta[:5, 2] = theta[:5, 0] * theta[:5, 1] * 1.5  # b1 > a1 b0: not dissipative
    batch = lik(theta)
    np.testing.assert_allclose(batch, [lik(t[None, :])[0] for t in theta], rtol=1e-12)
    lp = lik.log_prior(theta)
    assert np.all(np.isinf(lp[:5])) and np.all(np.isfinite(lp[5:]))
    # Log-uniform priors: the density is -sum(log θ) + const inside the support.
    const = -3 * np.log(np.log(1e8)) - np.log(np.log(1e7))  # a1, b0, b1 and sigma; q uniform on (0, 1)
    np.testing.assert_allclose(lp[5:], -np.log(theta[5:, [0, 1, 2, 4]]).sum(axis=1) + const, rtol=1e-12)


def test_noise_choice_is_stated():
    assert choose_noise(_data(np.full(25, 1e-5)))[0] == "known"
    wide = FrequencyResponse(W, np.logspace(0, 3, 25))
    assert choose_noise(wide) == ("proportional", "|G| spans 3.0 decades")
    assert choose_noise(_data())[0] in ("constant", "proportional")
    with pytest.raises(InputError, match="needs sigma"):
        choose_noise(_data(), "known")
    with pytest.raises(InputError, match="noise model must be"):
        choose_noise(_data(), "gaussian")


def test_prior_overrides():
    lik = Likelihood(ZENER, _data(), noise="constant", priors={"sigma": LogUniform(1e-3, 1.0)})
    assert lik.prior_list[-1] == LogUniform(1e-3, 1.0)
    with pytest.raises(InputError, match="unknown parameter 'c'"):
        Likelihood(ZENER, _data(), priors={"c": LogUniform(1, 2)})


@pytest.mark.parametrize("noise", ["constant", "proportional", "relative_parts"])
def test_the_noise_scale_integrated_out_matches_quadrature(noise):
    """Likelihood.log_noise_marginal (closed form, incomplete gamma) against scipy's quadrature
    of exp(ln L(θ, σ)) over the log-uniform prior of σ, at the truth and away from it."""
    from scipy import integrate

    lik = Likelihood(ZENER, _data(), noise=noise)
    truth = lik.to_scaled(np.append(TRUTH, 1.0))[0, :4]
    theta = np.vstack([truth, truth * [1.02, 0.97, 1.05, 1.01]])
    got = lik.log_noise_marginal(theta)
    prior = lik.noise_param[1]
    for row, value in zip(theta, got, strict=True):
        peak = np.log(lik.noise_estimate(row[None, :])[0])

        def density(log_s, row=row, value=value):
            full = np.append(row, np.exp(log_s))[None, :]
            return np.exp(lik(full)[0] - value) / np.log(prior.high / prior.low)

        total, _ = integrate.quad(density, np.log(prior.low), np.log(prior.high),
                                  points=[peak], limit=200)
        assert total == pytest.approx(1.0, rel=1e-8)
    assert Likelihood(ZENER, _data(sigma=np.full(25, 2e-5)), noise="known") \
        .log_noise_marginal(theta) is None
