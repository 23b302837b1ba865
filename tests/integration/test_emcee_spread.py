"""emcee's posterior spread: its moves leave the target invariant, so the sds of converged walkers
match those of importance sampling.

emcee's own DE snooker move (3.1.6) does not: it kept walkers with sd 0.61 of the truth on a
5-D normal of sd 0.03, and as a fifth of bayesfo's move mixture made the Zener's posterior sds
on the bundled 20 °C isotherm 2–4 % too narrow (3–5 % on long runs), while importance sampling
and random-walk Metropolis agreed. bayesfo's snooker move (``_snooker_move``) is ter Braak &
Vrugt's.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from bayesfo import read_csv
from bayesfo.identify.optimize import fit_structure
from bayesfo.inference import Likelihood, run_posterior
from bayesfo.inference.importance import importance_posterior
from bayesfo.inference.posterior import _snooker_move
from bayesfo.structures import get_structure

ADHESIVE = Path(__file__).resolve().parents[2] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"


def test_snooker_move_alone_keeps_a_normal_invariant():
    """32 walkers on N(0, 0.03² I) in 5-D, moved by the snooker move alone, from exact draws.

    2 700 kept steps give an ESS of some 2 300 per coordinate (τ ≈ 38): an sd's relative Monte
    Carlo error is about 1/√(2·2300) = 1.5 %, that of the mean over the five coordinates 0.7 %;
    the bounds are four and six of those. Measured on seeds 0-3: means 0.996-1.007, coordinates
    0.978-1.030, 2 s each. emcee's DESnookerMove gives means 0.59-0.61 (coordinates down to
    0.47; 0.83 at sd 1: not scale invariant either).
    """
    import emcee

    d, sd = 5, 0.03
    rng = np.random.default_rng(0)

    def log_prob(x):
        return -0.5 * np.sum(x * x, axis=1) / sd**2

    sampler = emcee.EnsembleSampler(32, d, log_prob, moves=[(_snooker_move(), 1.0)],
                                    vectorize=True)
    sampler.random_state = np.random.RandomState(0).get_state()
    sampler.run_mcmc(sd * rng.standard_normal((32, d)), 3000, progress=False)
    spread = sampler.get_chain(discard=300).reshape(-1, d).std(axis=0) / sd
    assert abs(spread.mean() - 1.0) < 0.03, spread
    assert np.all(np.abs(spread - 1.0) < 0.06), spread


@pytest.mark.slow
def test_zener_emcee_sds_match_importance_sampling():
    """The Zener on the bundled 20 °C isotherm under constant noise (the model ``compare``
    chooses), one long emcee run (50·τ → 400·τ, some 12 000 steps) against importance sampling
    with 100 000 proposals (Pareto k̂ ≈ 0.3, weight ESS ≈ 36 000, 20 000 draws resampled).

    Tolerance: the relative error of an sd from n effective draws is about 1/√(2n); emcee's ESS
    is ≥ 11 000 (0.7 %), the importance draws' about 13 000 (0.6 %), together 0.9 %; 2.5 % is
    2.8 of those. Measured on seeds 1-4: within 0.8 % with bayesfo's snooker move, 2.4-4.8 %
    too narrow with emcee's (every seed fails at least one parameter). b1 leans on its prior
    bound (heavy upper tail, 2-3 % error) and is left out.
    """
    data = read_csv(ADHESIVE)
    lik = Likelihood(get_structure("zener"), data, noise="constant")
    fit = fit_structure(lik.structure, data, rng=0, seed_methods=True, scaling=lik.scaling)
    modes = lik.structure.to_scaled(lik.structure.to_physical(fit.optima, fit.scaling),
                                    lik.scaling)
    ref, _, info = importance_posterior(lik, modes, seed=0, n_proposals=100_000,
                                        n_draws=20_000, predictive=False)
    assert ref is not None and info["k_hat"] < 0.5, info
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        post, _ = run_posterior(lik.structure, data, noise="constant", seed=1, fit=fit,
                                progress=False, predictive=False, tau_factor=400,
                                max_steps=20_000, max_draws=20_000)
    assert post.converged and post.ess_bulk_min > 8000, post.messages
    ratios = {k: post.summary[k].sd / ref.summary[k].sd for k in ("a1", "b0", "q", "sigma")}
    assert all(abs(r - 1.0) < 0.025 for r in ratios.values()), ratios
