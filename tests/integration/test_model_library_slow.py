"""The named models on published rheology data (GPL reference data, read from
``../shared/data/reference-gpl``, never copied): the model chosen and the parameters pyRheo
published in its demo notebooks (numbers from each folder's SOURCE.md)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from bayesfo.comparison import compare
from bayesfo.data import FrequencyResponse
from bayesfo.structures import coefficients_from_physical, get_structure, physical_parameters

pytestmark = pytest.mark.slow

REFERENCE = Path(__file__).parents[3] / "shared/data/reference-gpl"

#: The thesis' structures, their integer baselines and the named models: what a rheologist
#: would try on a soft solid or a transient network.
CANDIDATES = ("voigt,voigt-int,zener,zener-int,maxwell,maxwell-int,springpot,"
              "fractional_kelvin_voigt,fractional_maxwell_gel,fractional_maxwell_liquid,"
              "fractional_zener_sl,fractional_zener_ll,fractional_jeffreys,fractional_burgers")


def _saos(folder: str, name: str, delimiter: str) -> FrequencyResponse:
    path = REFERENCE / folder / "original" / name
    if not path.exists():
        pytest.skip(f"reference data not available: {path}")
    d = np.loadtxt(path, delimiter=delimiter, skiprows=1)  # omega [rad/s], G' [Pa], G'' [Pa]
    return FrequencyResponse(d[:, 0], d[:, 1] + 1j * d[:, 2], kind="modulus", units="Pa",
                             name=folder, source=str(path))


def _relative_rss(structure, theta, data):
    """pyRheo's cost: Σ((G' − Ĝ')/G')² + Σ((G'' − Ĝ'')/G'')²."""
    g = structure.response(theta, data.omega, "modulus")
    d = data.response
    return float(np.sum(((g.real - d.real) / d.real) ** 2 + ((g.imag - d.imag) / d.imag) ** 2))


def _posterior_physical(result, name):
    r = result[name]
    s, post = r.structure, r.posterior
    draws = {k: post.samples[:, i] for i, k in enumerate(post.param_names) if k in s.param_names}
    return {k: float(np.mean(v)) for k, (v, _) in physical_parameters(s, draws, "modulus", "Pa").items()}


def _compare(data, noise):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # convergence and predictive warnings are flags here
        # The tests weigh every candidate's ln Z: every one sampled.
        return compare(data, CANDIDATES, seed=1, noise=noise, progress=False, workers=2,
                       sample="all")


# pyRheo demo_oscillation_chia.ipynb, FractionalKelvinVoigt (Powell, relative RSS 0.32976).
CHIA = {"c_alpha": 5.058777910355125, "c_beta": 65.2571895459795, "alpha": 0.7952225998572212,
        "beta": 0.12782244688172384}


def test_chia_card_reproduces_the_published_cost():
    data = _saos("pyrheo_chia_pudding", "oscillation_chia_data.csv", ",")
    s = get_structure("fractional_kelvin_voigt")
    theta = [CHIA[n] for n in s.param_names]
    assert _relative_rss(s, theta, data) == pytest.approx(0.32976, abs=5e-5)


def test_chia_two_springpot_kelvin_voigt_ranks_first_with_pyrheo_parameters():
    # Under constant noise, the counterpart of the least-squares fits published: the two
    # springpots in parallel win, and their posterior means lie within 10 % of pyRheo's fit.
    data = _saos("pyrheo_chia_pudding", "oscillation_chia_data.csv", ",")
    result = _compare(data, "constant")
    assert result.ranking[0] == "fractional_kelvin_voigt"
    z = {r["structure"]: r["log_evidence"] for r in result.table()}
    best_thesis = max(z[n] for n in ("voigt", "zener", "maxwell"))
    assert z["fractional_kelvin_voigt"] > best_thesis + 20  # the issue saw 33 nats
    est = _posterior_physical(result, "fractional_kelvin_voigt")
    for name, published in CHIA.items():
        assert est[name] == pytest.approx(published, rel=0.10), name


def test_chia_with_the_noise_model_chosen_by_evidence():
    # Without σ, compare keeps the noise model of larger evidence: proportional, by ~24 nats.
    # The springpots in parallel still beat every thesis structure by far; the three-springpot
    # Zener (which holds them as a limit) may rank first, and the orders move (α ≈ 0.73).
    data = _saos("pyrheo_chia_pudding", "oscillation_chia_data.csv", ",")
    result = _compare(data, "auto")
    assert result.ranking[0] in ("fractional_kelvin_voigt", "fractional_zener_ll")
    z = {r["structure"]: r["log_evidence"] for r in result.table()}
    assert z["fractional_kelvin_voigt"] > max(z[n] for n in ("voigt", "zener", "maxwell")) + 20
    est = _posterior_physical(result, "fractional_kelvin_voigt")
    assert est["alpha"] == pytest.approx(CHIA["alpha"], rel=0.10)
    assert est["c_beta"] == pytest.approx(CHIA["c_beta"], rel=0.10)


# pyRheo demo_oscillation_metalcoordinatingnetwork.ipynb, FractionalMaxwell (Powell, relative
# RSS 0.102453): V = 233.63 Pa s^α (α = 0.8476), G = 1251.2 Pa s^β (β = 0.2852); the Bayesian
# optimisation notebook of the same package finds β = 0.23.
METAL = {"c_beta": 233.63304604847633, "beta": 0.8476056132996995,
         "c_delta": 1251.2081238527674, "delta": 0.28516902639279734}


def test_metal_network_fractional_maxwell_ranks_first():
    data = _saos("pyrheo_metal_network_epstein", "epstein.csv", "\t")
    s = get_structure("fractional_maxwell")
    coef = coefficients_from_physical(s, {"c_beta": METAL["c_beta"], "beta": METAL["beta"],
                                          "c_delta": METAL["c_delta"],
                                          "alpha": METAL["beta"] - METAL["delta"]})
    theta = [coef[n] for n in s.param_names]
    assert _relative_rss(s, theta, data) == pytest.approx(0.102453, abs=5e-5)
    result = _compare(data, "auto")
    assert result.ranking[0] == "maxwell"
    est = _posterior_physical(result, "maxwell")
    # pyRheo's β is the order of the second springpot, delta = beta - alpha here. Its two
    # published fits differ by 0.055 (Powell 0.285, Bayesian optimisation 0.23); the posterior
    # mean lies within 0.03 of the latter and within 0.06 of the former.
    assert abs(est["delta"] - 0.23) < 0.03
    assert abs(est["delta"] - METAL["delta"]) < 0.06
    assert est["beta"] == pytest.approx(METAL["beta"], abs=0.03)
    assert est["c_beta"] == pytest.approx(METAL["c_beta"], rel=0.10)


# pyRheo demo_oscillation_polystyrene_mastercurve.ipynb, FractionalZener (Powell, relative RSS
# 2.4428 on the 160-point master curve at 160 °C).
PS = {"c_alpha": 786171.4799881987, "c_beta": 94929.0614385244, "c_kappa": 607.9586728418249,
      "alpha": 0.8915947121200971, "beta": 0.19566491449873422, "kappa": 0.8225372258483875}


def test_polystyrene_master_curve_three_springpot_zener():
    data = _saos("pyrheo_polystyrene_saos", "master_curve_ps_oscillation_data.csv", ",")
    s = get_structure("fractional_zener")
    assert _relative_rss(s, [PS[n] for n in s.param_names], data) == pytest.approx(2.4428, abs=5e-4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = compare(data, "fractional_zener_ll,zener,maxwell", seed=1, progress=False,
                         workers=2)
    assert result.ranking[0] == "fractional_zener_ll"
    est = _posterior_physical(result, "fractional_zener_ll")
    # Like pyRheo's (6.9 % mean error), the fit leaves a systematic misfit on 8 decades; the
    # orders agree with the published ones within 0.06.
    for name in ("alpha", "beta", "kappa"):
        assert est[name] == pytest.approx(PS[name], abs=0.06), name


# ---------------------------------------------------------------------- pyRheo's own cost
# Under noise="relative_parts" (σ_rel·|G'| and σ_rel·|G''|) the likelihood's maximum over the
# structure parameters, at any σ_rel and with σ_rel profiled out, minimises pyRheo's cost
# Σ((G' − Ĝ')/G')² + Σ((G'' − Ĝ'')/G'')²: the optimum reproduces the published fits, and the
# posterior means lie within a small fraction of a posterior sd of them.


def _relative_parts(data, name, published):
    """(posterior means, sds, the maximum-likelihood parameters, its cost) of ``name`` under
    relative_parts noise, all physical; the optimum maximises bayesfo's likelihood from the
    posterior's best draw, with σ_rel at its maximum-likelihood value for every θ."""
    from scipy import optimize

    from bayesfo.inference.likelihood import Likelihood

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # predictive (Pareto k) warnings are flags here
        result = compare(data, name, seed=1, noise="relative_parts", progress=False, workers=1)
    post = result[name].posterior
    assert post.noise == "relative_parts" and post.converged
    s = get_structure(name)
    k = s.n_params

    def physical(theta):
        draws = {n: np.atleast_2d(theta)[:, i] for i, n in enumerate(s.param_names)}
        return {n: v for n, (v, _) in physical_parameters(s, draws, "modulus", "Pa").items()
                if n in published}

    lik = Likelihood(s, data, noise="relative_parts")

    def negative_profile(t):
        t = t[None]
        return -lik(np.column_stack([t, lik.noise_estimate(t)]))[0]

    start = lik.to_scaled(post.map_theta)[0, :k]
    best = optimize.minimize(negative_profile, start, method="Nelder-Mead",
                             options={"xatol": 1e-10, "fatol": 1e-12, "maxfev": 40_000})
    assert best.success
    theta = lik.to_physical(np.r_[best.x, 0.1])[0, :k]
    draws = physical(post.samples[:, :k])
    mean = {n: float(np.mean(v)) for n, v in draws.items()}
    sd = {n: float(np.std(v, ddof=1)) for n, v in draws.items()}
    optimum = {n: float(v[0]) for n, v in physical(theta).items()}
    return mean, sd, optimum, _relative_rss(s, theta, data)


def test_chia_relative_parts_noise_reproduces_pyrheo_fit():
    data = _saos("pyrheo_chia_pudding", "oscillation_chia_data.csv", ",")
    mean, sd, optimum, cost = _relative_parts(data, "fractional_kelvin_voigt", CHIA)
    # Measured: cost 0.3297641767 (pyRheo's parameters give 0.3297641767 + 6e-11), parameters
    # within 4.1e-6 (c_alpha), 3.2e-6 (beta), 7.5e-7 (alpha), 1e-8 (c_beta) of the published.
    assert cost == pytest.approx(0.32976, abs=5e-5)
    for name, published in CHIA.items():
        assert optimum[name] == pytest.approx(published, rel=1e-4), name
    # Posterior sds (seed 1): c_alpha 0.70 Pa·s^α (14 %), c_beta 1.3 Pa·s^β (2 %), alpha 0.031,
    # beta 0.0050; the means lie within 0.06 sd of the published fit (0.2 % at most; within
    # 0.06 sd on seeds 2-4 too), where proportional noise moves alpha to about 0.73 (2 sd).
    for name, published in CHIA.items():
        assert abs(mean[name] - published) < 0.25 * sd[name], (name, mean[name], sd[name])
        assert mean[name] == pytest.approx(published, rel=0.10), name


def test_metal_network_relative_parts_noise_reproduces_pyrheo_fit():
    data = _saos("pyrheo_metal_network_epstein", "epstein.csv", "\t")
    mean, sd, optimum, cost = _relative_parts(data, "maxwell", METAL)
    # Measured: cost 0.1024529546 (pyRheo's parameters give 3e-10 more), parameters within
    # 2.3e-5 (c_delta), 1.7e-5 (delta), 7.3e-6 (c_beta), 2.5e-6 (beta) of the published: the
    # Powell fit of the notebook, not the Bayesian optimisation's β = 0.23.
    assert cost == pytest.approx(0.102453, abs=5e-6)
    for name, published in METAL.items():
        assert optimum[name] == pytest.approx(published, rel=1e-4), name
    # Posterior sds (seed 1): c_beta 7.1 Pa·s^β (3 %), beta 0.0088, c_delta 163 Pa·s^δ (13 %),
    # delta 0.025; the means lie within 0.07 sd of the published fit (0.6 % at most; within
    # 0.08 sd on seeds 2-4). delta's
    # posterior (0.286 ± 0.025) puts the Bayesian-optimisation notebook's 0.23 2.2 sd away.
    for name, published in METAL.items():
        assert abs(mean[name] - published) < 0.25 * sd[name], (name, mean[name], sd[name])
        assert mean[name] == pytest.approx(published, rel=0.10), name
