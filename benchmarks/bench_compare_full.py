"""Full comparison: Voigt, Zener, Maxwell, every max-order member with n <= 3 and the integer
baseline of each, on the thesis' G_spec set-up (25 points, complex noise σ = 0.005, known).

Prints the wall time of the whole comparison (optimisation, posterior, evidence, WAIC, PSIS-LOO,
AIC/BIC for every structure) and each structure's sampler figures and evidence route (bridge
sampling from the draws, or the tempered ladder where the posterior did not converge), and the
machine's load average (timings on a shared machine are only comparable at similar load).
Goal (issue 14): the whole comparison in ≤ 30 s on 2 cores.

Usage: python benchmarks/bench_compare_full.py [--seed N] [--workers N]
"""

from __future__ import annotations

import argparse
import os
import platform
import time
import warnings

import numpy as np

from bayesfo.comparison import compare
from bayesfo.inference._arviz import preload
from bayesfo.structures import resolve_structures
from bayesfo.studies import g_spec_data

STRUCTURES = "voigt,zener,maxwell,max3,voigt-int,zener-int,maxwell-int,max3-int"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=0, help="processes (default: one per CPU)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    preload()
    print(f"machine: {platform.machine()}, python {platform.python_version()}, numpy {np.__version__}; "
          f"load {os.getloadavg()[0]:.2f}")
    data = g_spec_data(args.seed)
    structures = resolve_structures(STRUCTURES)
    t0 = time.perf_counter()
    result = compare(data, structures, seed=args.seed, progress=False, workers=args.workers)
    total = time.perf_counter() - t0
    print(f"{'structure':<14} {'steps':>6} {'ln Z':>16} {'route':>7} {'t [s]':>6} {'R-hat':>6} "
          "converged")
    for r in result.results:
        if r.error:
            print(f"{r.name:<14}  not run: {r.error}")
            continue
        ev = r.criteria.evidence
        print(f"{r.name:<14} {r.posterior.n_steps:6d} {ev.log_z:9.2f} ± {ev.log_z_err:4.2f} "
              f"{ev.method:>7} {ev.seconds:6.1f} {r.posterior.rhat_max:6.3f} {r.posterior.converged}")
    print(f"{len(structures)} structures on {data.n_frequencies} points, {args.workers or 'one per CPU'} "
          f"worker(s): {total:.1f} s (goal ≤ 30 s on 2 cores); load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
