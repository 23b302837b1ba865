"""The later rounds and the ridge probe of the importance route (issues 32 and 34).

ln Z of a posterior that importance sampling certifies with heavy-tailed weights
(0.5 ≤ k̂ < 0.7): the adapted second round, or a third whose proposal is a normal mixture
fitted to the certified draws, gives it, where the tempered ladder used to be run for ln Z
alone. The ridge probe: posterior mass along a curved ridge that a proposal built at the optima
never visits is found, the proposal is widened along it, and where that does not certify, the
posterior goes to the tempered ladder.

Known answers: an analytic density (a peak and a curved ridge of known mass, in closed form);
on real isotherms, an unguided tempered ladder (two runs from the prior, an independent route)
for ln Z and the posterior; and the weights' own certificate, k̂ < 0.5 in the round that gives
ln Z.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.special import logsumexp
from scipy.stats import norm

import bayesfo as bf
from bayesfo.identify.optimize import fit_structure
from bayesfo.inference import Likelihood, certified, starting_points
from bayesfo.inference import importance as importance_module
from bayesfo.inference.evidence import ladder_runs
from bayesfo.inference.results import posterior_from_particles

SWEEP = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp"


def _with_reference(isotherm: str, structure: str, noise: str = "constant"):
    """A structure's likelihood on an isotherm of the bundled sweep, its optima, and an
    unguided ladder's ln Z and posterior as reference."""
    data = bf.read(SWEEP / f"{isotherm}.csv")
    lik = Likelihood(bf.get_structure(structure), data, noise=noise)
    fit = fit_structure(lik.structure, data, rng=0, seed_methods=True, linear_methods=True)
    ref_ev, runs = ladder_runs(lik, seed=1, guide=None)
    ref = posterior_from_particles(lik, runs, seed=1)
    assert ref.converged
    return lik, starting_points(lik, fit)[0], ref_ev, ref


@pytest.fixture(scope="module")
def fkv():
    """The fractional Kelvin–Voigt on the 50 °C isotherm under constant noise (it misfits:
    the first round's weights have k̂ ≈ 0.6)."""
    return _with_reference("Tp050C", "fractional_kelvin_voigt")


def test_the_adapted_round_gives_ln_z_where_the_first_round_is_heavy_tailed(fkv):
    """Measured: first round k̂ 0.60, second 0.12; ln Z −286.314 ± 0.009 against the ladder's
    −286.326 ± 0.013. The means agree within 4 Monte Carlo errors, the sds within 10 %."""
    lik, modes, ref_ev, ref = fkv
    post, ev, info = importance_module.importance_posterior(lik, modes, seed=0)
    assert post is not None, info
    first, second = info["k_hat_rounds"]
    assert importance_module.K_HAT_EVIDENCE <= first < importance_module.K_HAT_MAX
    assert second < importance_module.K_HAT_EVIDENCE and info["k_hat"] == second
    assert info["rounds"] == 2
    assert ev is not None and ev.method == "importance"
    assert abs(ev.log_z - ref_ev.log_z) < 3 * math.hypot(ev.log_z_err, ref_ev.log_z_err)
    assert ev.log_z_err < 0.05
    got, want = post.samples_scaled, ref.samples_scaled
    mc = want.std(0) * np.sqrt(1 / post.ess_min + 1 / ref.ess_min)
    assert np.all(np.abs(got.mean(0) - want.mean(0)) < 4 * mc), (got.mean(0), want.mean(0), mc)
    np.testing.assert_allclose(got.std(0), want.std(0), rtol=0.1)


def _spoilt(real):
    """``real`` (a round's proposal and draws), with one weight above all the others: the
    round does not certify."""
    def spoilt(*args):
        out = real(*args)
        if out is None:
            return None
        x, log_w, finite, n_modes, prop = out
        log_w = log_w.copy()
        log_w[np.flatnonzero(finite)[0]] += 50.0
        return x, log_w, finite, n_modes, prop
    return spoilt


def test_the_fitted_mixture_gives_ln_z_where_the_adapted_round_fails(fkv, monkeypatch):
    """With the adapted round spoilt, the third round (a normal mixture fitted to the first
    round's certified draws) gives ln Z, which agrees with the ladder's."""
    lik, modes, ref_ev, ref = fkv
    monkeypatch.setattr(importance_module, "_adapted", _spoilt(importance_module._adapted))
    post, ev, info = importance_module.importance_posterior(lik, modes, seed=0)
    assert post is not None, info
    first, spoilt, fitted = info["k_hat_rounds"]
    assert importance_module.K_HAT_EVIDENCE <= first < importance_module.K_HAT_MAX
    assert spoilt > importance_module.K_HAT_MAX
    assert fitted < importance_module.K_HAT_EVIDENCE and info["k_hat"] == fitted
    assert ev is not None and ev.method == "importance"
    assert abs(ev.log_z - ref_ev.log_z) < 3 * math.hypot(ev.log_z_err, ref_ev.log_z_err)
    got, want = post.samples_scaled, ref.samples_scaled
    mc = want.std(0) * np.sqrt(1 / post.ess_min + 1 / ref.ess_min)
    assert np.all(np.abs(got.mean(0) - want.mean(0)) < 4 * mc), (got.mean(0), want.mean(0), mc)


def test_a_certified_first_round_is_kept_when_the_later_ones_are_not(fkv, monkeypatch):
    """Where neither later round certifies, the first round still gives the posterior (and ln Z
    is left to the ladder): the later rounds can only add an evidence, never take away a
    certified posterior."""
    lik, modes, _, _ = fkv
    monkeypatch.setattr(importance_module, "_adapted", _spoilt(importance_module._adapted))
    monkeypatch.setattr(importance_module, "_fitted", _spoilt(importance_module._fitted))
    post, ev, info = importance_module.importance_posterior(lik, modes, seed=0)
    assert post is not None and ev is None
    assert len(info["k_hat_rounds"]) == 3
    assert info["k_hat"] == info["k_hat_rounds"][0] >= importance_module.K_HAT_EVIDENCE
    assert info["ess"] >= importance_module.ESS_MIN_IMPORTANCE


# A unit normal peak at the origin, and a ridge from x = 4 to 20 whose crest curves up as
# y = 0.05 (x - 4)^2 (width 0.3 across it), its density falling as c exp(-(x - 4)/tau) along it.
C, TAU, X0, X1, WIDTH, BEND = 0.03, 10.0, 4.0, 20.0, 0.3, 0.05
LO, HI = np.array([-5.0, -50.0]), np.array([30.0, 50.0])


def _log_density(u):
    u = np.atleast_2d(u)
    x, y = u[:, 0], u[:, 1]
    peak = norm.logpdf(x) + norm.logpdf(y)
    on = (x >= X0) & (x <= X1)
    ridge = np.where(on, math.log(C) - (x - X0) / TAU
                     + norm.logpdf(y, BEND * (x - X0) ** 2, WIDTH), -np.inf)
    inside = np.all((u >= LO) & (u <= HI), axis=1)
    return np.where(inside, np.logaddexp(peak, ridge), -np.inf)


RIDGE_MASS = C * TAU * (1 - math.exp(-(X1 - X0) / TAU))  # the crest stays inside the box in y
PEAK_MASS = (norm.cdf(HI[0]) - norm.cdf(LO[0])) * (norm.cdf(HI[1]) - norm.cdf(LO[1]))
RIDGE_SHARE = RIDGE_MASS / (RIDGE_MASS + PEAK_MASS)


def _first_round(seed):
    tr = SimpleNamespace(lo_u=LO, hi_u=HI)
    out = importance_module._proposal(_log_density, tr, [np.zeros(2)], {}, 20_000,
                                      np.random.default_rng(seed), unbounded=False)
    assert not isinstance(out, dict), out
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_probe_finds_a_curved_ridge_and_the_widened_round_weighs_it(seed):
    """The ridge holds 19.3 % of the mass. The proposal at the peak weighs it at 10-15 %
    (measured); the probe finds it along x, and the round widened along its crest certifies
    and gives the ridge's share and the total mass within 3 Monte Carlo standard errors
    (measured: 0.205, 0.194, 0.187 ± 0.007)."""
    out = _first_round(seed)
    x, log_w, finite, _, _ = out
    w = np.exp(log_w[finite] - logsumexp(log_w[finite]))
    assert float(w[x[finite][:, 0] > X0].sum()) < RIDGE_SHARE - 0.04
    probe = importance_module._ridge_probe(out)
    assert probe["coordinate"] == 0
    assert probe["missed"] > importance_module.PROBE_MISSED
    widened = importance_module._with_ridge(out, probe, 20_000, np.random.default_rng(seed + 10))
    assert importance_module._certifies(importance_module._assessed(widened))
    x, log_w, finite, _, _ = widened
    n = len(log_w)
    lw = np.where(finite, log_w, -np.inf)
    log_z = float(logsumexp(lw) - math.log(n))
    rel_err = float(np.std(np.exp(lw - log_z)) / math.sqrt(n))
    assert abs(log_z - math.log(RIDGE_MASS + PEAK_MASS)) < 3 * rel_err, (log_z, rel_err)
    w = np.exp(lw - logsumexp(lw))
    on = x[:, 0] > X0
    share = float(w[on].sum())
    se = math.sqrt(float(np.sum(w**2 * (on - share) ** 2)))  # of a ratio of weighted sums
    assert abs(share - RIDGE_SHARE) < 3 * se, (share, RIDGE_SHARE, se)
    assert importance_module._ridge_probe(widened)["missed"] <= importance_module.PROBE_MISSED


def test_a_peak_without_a_ridge_is_left_alone():
    """The normal peak alone: the probe finds nothing the proposal misses."""
    tr = SimpleNamespace(lo_u=LO, hi_u=HI)

    def peak(u):
        u = np.atleast_2d(u)
        inside = np.all((u >= LO) & (u <= HI), axis=1)
        return np.where(inside, norm.logpdf(u[:, 0]) + norm.logpdf(u[:, 1]), -np.inf)

    out = importance_module._proposal(peak, tr, [np.zeros(2)], {}, 20_000,
                                      np.random.default_rng(0), unbounded=False)
    probe = importance_module._ridge_probe(out)
    assert probe["missed"] < 1e-3 and probe["components"] == []


@pytest.fixture(scope="module")
def voigt_150():
    """The Voigt on the 150 °C isotherm under constant noise: its posterior has a ridge where
    both coefficients grow together up to their prior bound (q falling slowly along it), a few
    nats below the peak."""
    return _with_reference("Tp150C", "voigt")


def _outside(post, ref) -> float:
    return certified._outside(post.samples_scaled, ref.samples_scaled)


def test_without_the_probe_the_weights_certify_a_posterior_that_misses_the_ridge(voigt_150,
                                                                                monkeypatch):
    """Measured: 4.5-8 % of the reference's draws lie beyond the reported draws' range (the
    share depends on the optimiser's and the draws' path, which the CPU's rounding changes),
    and ln Z is low by about 0.06 nats. A miss by the tool's own rule for a ladder beside
    importance draws: more than :data:`~bayesfo.inference.certified.LADDER_MISSED` above the
    share that draws of one posterior leave outside each other's range."""
    lik, modes, _, ref = voigt_150
    monkeypatch.setattr(importance_module, "PROBE_MISSED", math.inf)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        post, _, info = importance_module.importance_posterior(lik, modes, seed=0)
    assert post is not None and info["k_hat"] < importance_module.K_HAT_MAX
    null = certified._expected_outside(lik.ndim, post.ess_min)
    assert _outside(post, ref) > certified.LADDER_MISSED + null


def test_the_probe_widens_the_proposal_along_the_ridge(voigt_150):
    """With the probe, the round widened along the ridge certifies a posterior that covers it
    (measured: 0.4 % of the reference's draws outside, against 7-8 %), and its ln Z agrees
    with the reference's."""
    lik, modes, ref_ev, ref = voigt_150
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        post, ev, info = importance_module.importance_posterior(lik, modes, seed=0)
    assert post is not None, info
    assert info["probe"]["ridge"] == "a1" and "covered" in info["probe"]
    assert info["probe"]["covered"] > importance_module.PROBE_MISSED
    assert info["probe"]["missed"] <= importance_module.PROBE_MISSED
    assert _outside(post, ref) < 0.02
    assert ev is not None
    assert abs(ev.log_z - ref_ev.log_z) < 3 * math.hypot(ev.log_z_err, ref_ev.log_z_err)


def test_a_ridge_the_widened_round_does_not_certify_goes_to_the_ladder(voigt_150,
                                                                       monkeypatch):
    lik, modes, _, _ = voigt_150
    monkeypatch.setattr(importance_module, "_with_ridge", lambda *args: None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        post, ev, info = importance_module.importance_posterior(lik, modes, seed=0)
    assert post is None and ev is None
    assert info["ridge"] == "a1" and "ridge of the posterior along a1" in info["reason"]
    assert len(info["proposal_draws"]) > 0  # the guide of the ladder that takes over


def test_the_report_says_what_the_certificate_checked():
    """The report's diagnostics name the ridge probe, the widening and the rounds."""
    from bayesfo.output.report import _diagnostics_section

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        comparison = bf.compare(bf.read(SWEEP / "Tp150C.csv"), "voigt", noise="constant",
                                workers=1, progress=False)
    text = _diagnostics_section(comparison)
    assert "ridge probe:" in text and "after widening it along a ridge in a1" in text
    assert re.search(r"4 rounds of importance sampling \(k̂ (-?[0-9.]+ → ){3}-?[0-9.]+\)", text)


def test_a_posterior_of_many_parameters_is_not_probed_and_says_so(fkv, monkeypatch):
    """Above PROBE_MAX_DIM parameters (the joint master-curve posteriors) the probe is skipped,
    and the certificate says so; the posterior is that of the rounds alone."""
    lik, modes, _, _ = fkv
    monkeypatch.setattr(importance_module, "PROBE_MAX_DIM", lik.ndim - 1)
    post, _, info = importance_module.importance_posterior(lik, modes, seed=0)
    assert post is not None
    assert info["probe"]["points"] == 0 and "more than" in info["probe"]["skipped"]
    monkeypatch.setattr(importance_module, "PROBE_MAX_DIM", lik.ndim)
    probed, _, info = importance_module.importance_posterior(lik, modes, seed=0)
    assert info["probe"]["points"] > 0
    np.testing.assert_array_equal(post.samples_scaled, probed.samples_scaled)
