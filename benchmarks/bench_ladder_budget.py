"""The tempered ladder's move budget against its accuracy: wall time, likelihood evaluations,
ln Z ± error and the certificate of the two runs (R-hat, ESS) for settings of the moves per
rung, over seeds, on the thesis' G_spec set-up (25 points, known σ).

The ladder's cost is its Metropolis steps: at each rung, differential-evolution steps until
the particles have made ``accepted_moves`` accepted moves on average, at most ``max_moves``
(``bayesfo.inference.smc.ladder_run``), plus ``guided_moves`` independence steps. At the late
rungs of the max-order members and the Maxwell, 2–4 % of the steps are accepted, so the cap
binds and sets the cost. This script measures what a smaller budget saves and what it costs in
certified posteriors and ln Z error, each setting on the same data, optimum and guide as the
default route of ``compare`` (importance proposal draws as the guide).

Each variant is given as JSON keyword arguments of ``ladder_runs``, e.g.
``'{"max_moves": 50}'``; ``{}`` is the default.

Usage: python benchmarks/bench_ladder_budget.py [--structures maxwell,max-n3m3]
       [--seeds 0,1,2] [VARIANT ...]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
import warnings

import numpy as np

from bayesfo.identify.optimize import fit_structure
from bayesfo.inference import Likelihood
from bayesfo.inference._arviz import preload
from bayesfo.inference.evidence import ladder_runs
from bayesfo.inference.importance import importance_posterior
from bayesfo.inference.results import posterior_from_particles
from bayesfo.structures import get_structure
from bayesfo.studies import g_spec_data


def guide_for(lik: Likelihood, seed: int):
    """The importance proposal's draws at the optima, as ``compare`` hands them to the ladder
    (None where importance sampling certifies the posterior: the ladder does not run there)."""
    fit = fit_structure(lik.structure, lik.data, rng=seed, seed_methods=True, linear_methods=True)
    modes = lik.structure.to_scaled(lik.structure.to_physical(fit.optima, fit.scaling),
                                    lik.scaling)
    post, _, info = importance_posterior(lik, modes, seed=seed)
    return post, info.get("proposal_draws")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--structures", default="maxwell,max-n3m3")
    parser.add_argument("--seeds", default="0,1,2")
    parser.add_argument("variants", nargs="*", default=["{}", '{"max_moves": 50}'])
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    preload()
    variants = [json.loads(v) for v in args.variants]
    print(f"machine: {platform.machine()}, python {platform.python_version()}, numpy "
          f"{np.__version__}; load {os.getloadavg()[0]:.2f}")
    print(f"{'structure':<10} {'seed':>4} {'variant':<44} {'t [s]':>6} {'calls':>6} "
          f"{'ln Z':>20} {'R-hat':>6} {'ESS':>5} certified")
    for name in args.structures.split(","):
        for seed in (int(s) for s in args.seeds.split(",")):
            lik = Likelihood(get_structure(name), g_spec_data(seed))
            post, guide = guide_for(lik, seed)
            if post is not None:
                print(f"{name:<10} {seed:>4} importance sampling certifies it: no ladder")
                continue
            for kwargs in variants:
                t = time.perf_counter()
                ev, runs = ladder_runs(lik, seed=seed, guide=guide, **kwargs)
                wall = time.perf_counter() - t
                p = posterior_from_particles(lik, runs, seed=seed, predictive=False)
                calls = sum(r.n_likelihood for r in runs)
                ess = min(p.ess_bulk_min, p.ess_tail_min)
                print(f"{name:<10} {seed:>4} {json.dumps(kwargs):<44} {wall:6.2f} "
                      f"{calls / 1e6:5.2f}M {ev.log_z:11.3f} ± {ev.log_z_err:.3f} "
                      f"{p.rhat_max:6.3f} {ess:5.0f} {p.converged}", flush=True)
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
