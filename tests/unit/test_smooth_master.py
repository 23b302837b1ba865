"""The model-free master of the shifts (bayesfo.tts.smooth): its marginal likelihood against a
dense Gaussian computation that shares none of its code (scipy's B-splines and multivariate
normal), its gradient against differences, and shifts recovered from isotherms of a spectrum
summed in plain NumPy."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.interpolate import BSpline
from scipy.stats import multivariate_normal

from bayesfo.data import FrequencyResponse
from bayesfo.tts.isotherms import _isotherms
from bayesfo.tts.shifts import smooth_shifts
from bayesfo.tts.smooth import KNOT_STEP, LEVEL_SD, SmoothMaster
from bayesfo.tts.smooth_posterior import sample_shifts, start_of

TEMPS = [0.0, 10.0, 20.0, 30.0, 40.0]


def maxwell_modes(omega, rng_seed=3):
    """G′, G″ of 40 Maxwell modes on a log-normal spectrum and an equilibrium modulus."""
    tau = np.logspace(-6, 6, 40)
    g = 1e6 * np.exp(-0.5 * (np.log10(tau) / 1.5) ** 2)
    wt = omega[:, None] * tau
    return (1e3 + np.sum(g * wt**2 / (1 + wt**2), axis=1), np.sum(g * wt / (1 + wt**2), axis=1))


def isotherms(log_a, log_b=None, rel=0.01, seed=0, kind="parts"):
    rng = np.random.default_rng(seed)
    omega = np.logspace(-1, 2, 15)
    log_b = np.zeros(len(TEMPS)) if log_b is None else log_b
    out = []
    for t, la, lb in zip(TEMPS, log_a, log_b, strict=True):
        gp, gpp = maxwell_modes(omega * 10.0**la)
        gp, gpp = gp / 10.0**lb, gpp / 10.0**lb
        if kind == "parts":
            gp = gp * (1 + rel * rng.standard_normal(omega.size))
            gpp = gpp * (1 + rel * rng.standard_normal(omega.size))
        out.append((FrequencyResponse(omega, gp + 1j * gpp, kind="modulus", units="Pa",
                                      name=f"t{t:g}"), t))
    return out


def _dense(model, theta):
    """ln p(y) by the covariance σ²K + B P⁻¹ Bᵀ of each part, built densely."""
    lo, n_basis = model._grid
    x = model.log_omega + model.log_shifts(theta)[0, model.point_isotherm]
    v = model.log_vertical(theta)[0, model.point_isotherm] * math.log(10.0)
    knots = lo + KNOT_STEP * (np.arange(n_basis + 4) - 3)
    basis = BSpline.design_matrix(x, knots, 3).toarray()
    d = np.diff(np.eye(n_basis), 2, axis=0)
    total = 0.0
    for p in range(2):
        y = model.y[p]
        ok = np.isfinite(y)
        kappa = (np.exp(2 * model.magnitude[ok] - 2 * y[ok]) / 2
                 if model.noise == "proportional" else np.ones(ok.sum()))
        prec = d.T @ d / theta[-4 + p] ** 2 + np.eye(n_basis) / LEVEL_SD**2
        cov = theta[-2 + p] ** 2 * np.diag(kappa) + basis[ok] @ np.linalg.inv(prec) @ basis[ok].T
        # Under proportional noise the mean of each log lies σ²κ/2 below the log of the mean.
        offset = 0.5 * theta[-2 + p] ** 2 * kappa if model.noise == "proportional" else 0.0
        total += multivariate_normal(np.full(ok.sum(), y[ok].mean()), cov).logpdf(
            y[ok] + v[ok] + offset)
    return total


@pytest.mark.parametrize("vertical,law,noise", [("free", "free", "relative_parts"),
                                                ("density", "wlf", "proportional"),
                                                ("none", "arrhenius", "relative_parts")])
def test_marginal_likelihood_is_the_dense_gaussian(vertical, law, noise):
    truth = np.array([2.0, 1.0, 0.0, -0.8, -1.5])
    iso = _isotherms(isotherms(truth, log_b=np.array([0.02, 0.01, 0, -0.01, -0.02])), 20.0)
    model = SmoothMaster.of(iso, vertical, law, reach=3.0, noise=noise)
    theta = start_of(model, truth)
    theta[-4:] = [0.2, 0.05, 0.02, 0.03]
    # Both are float64 sums of a few hundred terms of size ~10: 1e-8 relative is ~1e-6 nats.
    assert model.log_likelihood(theta)[0] == pytest.approx(_dense(model, theta), rel=1e-8)
    # A batch gives each set's value (the vectorised factorisation beside LAPACK's).
    many = np.tile(theta, (80, 1))
    many[:, -1] *= np.linspace(0.5, 2.0, 80)
    batch = model.log_likelihood(many)
    assert batch[[0, 40, 79]] == pytest.approx(
        [model.log_likelihood(many[i])[0] for i in (0, 40, 79)], rel=1e-10)


@pytest.mark.parametrize("vertical,law", [("free", "free"), ("none", "wlf"),
                                          ("density", "arrhenius")])
def test_gradient_is_the_derivative(vertical, law):
    truth = np.array([2.0, 1.0, 0.0, -0.8, -1.5])
    iso = _isotherms(isotherms(truth), 20.0)
    model = SmoothMaster.of(iso, vertical, law, reach=3.0, noise="proportional")
    u = model.to_u(start_of(model, truth)) + 0.01 * np.random.default_rng(1).standard_normal(
        len(model.param_names))
    value, grad = model.gradient(model.to_params(u))
    h = 1e-5
    numeric = [(model.log_likelihood(model.to_params(u + h * e))[0]
                - model.log_likelihood(model.to_params(u - h * e))[0]) / (2 * h)
               for e in np.eye(u.size)]
    # Central differences of a smooth function of size ~1e2 at h = 1e-5: error ~1e-5.
    assert np.max(np.abs(np.array(numeric) - grad)) < 1e-3 * max(1.0, np.max(np.abs(grad)))


def test_unordered_shifts_lie_outside_the_prior():
    iso = _isotherms(isotherms(np.array([2.0, 1.0, 0.0, -0.8, -1.5])), 20.0)
    model = SmoothMaster.of(iso, "none", "free", reach=3.0)
    theta = start_of(model, np.array([2.0, 1.0, 0.0, -0.8, -1.5]))
    swapped = theta.copy()
    swapped[[0, 1]] = swapped[[1, 0]]
    assert np.isfinite(model.log_likelihood(theta)[0])
    assert model.log_likelihood(swapped)[0] == -np.inf
    # The ordered box: the 2 colder isotherms in (0, 3) in order, 3²/2!, the 2 warmer in
    # (−3, 0), 3²/2!, and the four hyperparameters' log ranges.
    hyper = float(np.sum(np.log(np.diff(model.bounds[4:], axis=1))))
    assert model.log_prior_volume == pytest.approx(4 * math.log(3.0) - 2 * math.log(2.0)
                                                   + hyper)


def test_shifts_of_a_spectrum_are_recovered_with_their_noise_and_vertical_shift():
    truth = np.array([2.1, 1.0, 0.0, -0.9, -1.7])
    density = np.log10((20.0 + 273.15) / (np.array(TEMPS) + 273.15))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sh = smooth_shifts(_isotherms(isotherms(truth, density, rel=0.01), 20.0), law="free")
    assert sh.noise == "relative_parts" and sh.vertical == "density"
    assert sh.posterior.converged and sh.posterior.sampler == "importance"
    draws = sh.posterior.shift_draws
    z = (draws.mean(axis=0) - truth) / np.maximum(draws.std(axis=0), 1e-12)
    # 15 points of 1 % noise per part: shifts to a few thousandths of a decade, each within
    # 3.5 sd (five shifts: all inside at 99.95 % each).
    assert np.all(np.abs(draws.mean(axis=0) - truth) < 0.02)
    assert np.all(np.abs(z[[0, 1, 3, 4]]) < 3.5)
    # The noise of each part recovered (1 %), the smoothness a number of its prior range.
    sigma = np.median(sh.posterior.draws[:, -2:], axis=0)
    assert np.all((sigma > 0.006) & (sigma < 0.015))
    assert sh.vertical_evidence["density"]["probability"] > 0.9


def test_the_same_seed_gives_the_same_draws():
    truth = np.array([2.0, 1.0, 0.0, -0.8, -1.5])
    iso = _isotherms(isotherms(truth), 20.0)
    model = SmoothMaster.of(iso, "none", "free")
    a = sample_shifts(model, start_of(model, truth), seed=4)
    b = sample_shifts(model, start_of(model, truth), seed=4)
    assert np.array_equal(a.draws, b.draws) and a.log_evidence == b.log_evidence


def test_an_isotherm_on_a_featureless_stretch_is_not_determined():
    """A Maxwell transition with a constant small loss beside it: the coldest isotherm lies
    five decades beyond the transition, where G′ and G″ are flat to 1e-5, so its data fix its
    shift only to 'colder than its neighbour' (the smoothness prior alone holds it near the
    neighbour). It is reported as not determined; the others are determined to hundredths of
    a decade, and are not."""
    truth = np.array([6.0, 1.5, 0.0, -0.8, -1.5])
    rng = np.random.default_rng(5)
    omega = np.logspace(-1, 2, 15)
    data = []
    for t, la in zip(TEMPS, truth, strict=True):
        wt = 1j * omega * 10.0**la
        g = 1e6 * (1 + 0.01j) * wt / (1 + wt)
        g = (g.real * (1 + 0.01 * rng.standard_normal(omega.size))
             + 1j * g.imag * (1 + 0.01 * rng.standard_normal(omega.size)))
        data.append((FrequencyResponse(omega, g, kind="modulus", units="Pa", name=f"t{t:g}"),
                     t))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sh = smooth_shifts(_isotherms(data, 20.0), vertical="none", law="free",
                           noise="relative_parts")
    post = sh.posterior
    assert post.undetermined() == [0]
    info = post.model.shift_information(post.map_theta)
    assert 1 / math.sqrt(info[0]) > 0.5  # its own points: a decade or more either way
    assert np.all(1 / np.sqrt(info[1:]) < 0.01)
    draws = post.shift_draws
    assert np.all(draws[:, 0] > draws[:, 1])  # the prior's order holds in every draw
    assert np.all(np.abs(draws.mean(axis=0)[1:] - truth[1:]) < 0.05)


def test_shifts_are_averaged_over_the_vertical_options_the_evidence_leaves_open():
    """Isotherms scaled by half the density factor: neither no vertical shift nor the density
    correction is right, and on this draw of the noise the evidence gives them 0.13 and 0.87.
    The shifts are then a mixture of the two posteriors in those proportions, carried as free
    vertical shifts whose values are exactly 0 or the density correction's."""
    truth = np.array([2.1, 1.0, 0.0, -0.9, -1.7])
    density = np.log10((20.0 + 273.15) / (np.array(TEMPS) + 273.15))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sh = smooth_shifts(_isotherms(isotherms(truth, 0.5 * density, rel=0.03, seed=2), 20.0),
                           law="free", noise="relative_parts")
    p = {k: v["probability"] for k, v in sh.vertical_evidence.items()}
    assert 0.02 < p["none"] < 0.5 and p["density"] > 0.5
    assert sh.vertical == "free" and any("averaged over" in n for n in sh.notes)
    b = sh.posterior.vertical_draws
    on_density = np.isclose(b, density[None, :], atol=1e-12).all(axis=1)
    on_none = np.isclose(b, 0.0, atol=1e-12).all(axis=1)
    assert np.all(on_density | on_none)
    share = on_none.mean() / (p["none"] / (p["none"] + p["density"]))
    assert 0.7 < share < 1.3  # a multinomial share of 4000 draws
    assert sh.posterior.undetermined() == []
    assert np.all(np.abs(sh.posterior.shift_draws.mean(axis=0) - truth) < 0.1)
