"""Posteriors certified by an independent route: where the emcee walkers do not converge, the
final particles of the tempered-ladder runs (which give ln Z) are the posterior, if the runs
agree.

Known answer: on the bundled 20 °C adhesive isotherm the Zener posterior by importance sampling
with weights of Pareto k̂ < 0.5 (an exact route with its own certificate). The walkers are
stopped early (300 steps) so that they cannot converge; the ladder's posterior must then agree
with the reference within Monte Carlo error.

A converged emcee run is not the reference: on these data its standard deviations come out
4–7 % below those of importance sampling and of the ladder, which agree with each other
(measured, seeds 1–5: a1 0.057–0.059 against 0.060–0.062), so emcee's passed the 15 % bar
below only by the seed's luck.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import bayesfo as bf
from bayesfo.errors import CertifiedWarning, ConvergenceWarning, PredictiveWarning

DATA = Path(__file__).parents[1] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"


@pytest.fixture(scope="module")
def runs():
    data = bf.read(DATA)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        short = bf.compare(data, "zener", seed=1, workers=1, progress=False, max_steps=300,
                           sampler="emcee")
    with warnings.catch_warnings():
        # Pareto k near 0.7 at the lowest frequency, depending on the draws.
        warnings.simplefilter("ignore", PredictiveWarning)
        reference = bf.compare(data, "zener", seed=1, workers=1, progress=False,
                               noise=short["zener"].criteria["noise_models"]["chosen"])
    assert {w.category for w in record} <= {ConvergenceWarning, CertifiedWarning,
                                             PredictiveWarning}
    return reference["zener"], short["zener"], record


def test_the_ladder_certifies_where_the_walkers_did_not_converge(runs):
    reference, short, record = runs
    assert reference.posterior.sampler == "importance" and reference.posterior.converged
    assert reference.criteria["importance"]["k_hat"] < 0.5
    post = short.posterior
    assert post.sampler == "ladder" and post.converged
    assert post.rhat_max < 1.01 and post.ess_min >= 400 and post.n_walkers == 2
    messages = [str(w.message) for w in record]
    # Stopped at the cap, or earlier where τ already shows that the cap cannot be met.
    assert any(m.startswith("zener: stopped at the cap of 300 steps")
               or (m.startswith("zener: stopped after ") and "cap of 300 steps" in m)
               for m in messages)
    certified = [m for m in messages if "tempered-ladder runs of 1000 particles, which agree" in m]
    assert len(certified) == 1 and certified[0].endswith("the emcee walkers did not converge")
    assert short.criteria["evidence"].method == "ladder"
    # LOO and WAIC come from the particles: one pointwise value per frequency and draw.
    assert post.idata.log_likelihood["G"].shape == (2, 1000, 17)


def test_the_ladder_posterior_agrees_with_importance_sampling(runs):
    reference, short, _ = runs
    a, b = short.posterior, reference.posterior
    for name in b.param_names:
        sa, sb = a.summary[name], b.summary[name]
        # Two independent estimates of the mean: their difference has the standard error
        # sd·sqrt(1/ESS_a + 1/ESS_b) (about 0.04 sd here); 5 of them allow for a skewed
        # parameter (b1 sits near zero).
        se = sb.sd * math.sqrt(1 / a.ess_min + 1 / b.ess_min)
        assert abs(sa.mean - sb.mean) < 5 * se, name
        assert sa.sd == pytest.approx(sb.sd, rel=0.15), name
    # The evidence and LOO of the two routes agree within their errors.
    ea, eb = short.criteria["evidence"], reference.criteria["evidence"]
    assert abs(ea.log_z - eb.log_z) < 3 * math.hypot(ea.log_z_err, eb.log_z_err) + 0.05
    assert abs(short.criteria["loo"] - reference.criteria["loo"]) < 2 * reference.criteria["loo_se"]


def test_particles_are_drawn_as_histograms_per_run(runs):
    from bayesfo.plotting import plot_trace

    _, short, _ = runs
    drawn = plot_trace(short)
    assert "tempered-ladder runs × 1000 particles" in drawn.figure._suptitle.get_text()
    assert len(drawn.artists["q"]) == 2
    assert np.asarray(drawn.values["q"]).shape == (2, 1000)


def test_importance_route_agrees_with_converged_emcee(runs):
    """The default route for a well-posed structure: importance sampling from the optimum,
    certified by its weights, against the converged emcee run on the same data."""
    reference, _, _ = runs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PredictiveWarning)
        fast = bf.compare(bf.read(DATA), "zener", seed=3, workers=1, progress=False)["zener"]
    post, b = fast.posterior, reference.posterior
    info = fast.criteria["importance"]
    assert post.sampler == "importance" and post.converged
    assert info["k_hat"] < 0.7 and info["ess"] >= 1000
    for i, name in enumerate(b.param_names):
        # In the sampling coordinates (log for the log-uniform coefficients): b1 has a long
        # tail towards its upper values whose physical sd is dominated by a few draws.
        xa, xb = post.samples[:, i], b.samples[:, i]
        if name != "q":
            xa, xb = np.log(xa), np.log(xb)
        # The resampled draws (2000) carry the Monte Carlo error of the mean.
        se = xb.std() * math.sqrt(1 / min(post.ess_min, post.samples.shape[0]) + 1 / b.ess_min)
        assert abs(xa.mean() - xb.mean()) < 5 * se, name
        assert xa.std() == pytest.approx(xb.std(), rel=0.1), name
    ea, eb = fast.criteria["evidence"], reference.criteria["evidence"]
    assert ea.method == "importance"
    assert abs(ea.log_z - eb.log_z) < 3 * math.hypot(ea.log_z_err, eb.log_z_err) + 0.05
