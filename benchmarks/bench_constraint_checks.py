"""Cost of the constraint checks (``Structure.constraints_hold``: inequalities, Matignon
stability of both sides, exact dissipation) per call and per parameter set, with the shortcuts
(closed-form cubic roots, the certificate of non-negative dissipation polynomials) and with every
row through the companion-matrix eigenvalues, interleaved in one run; and whether the two make
the same decisions.

The parameter sets are those a tempered ladder on the thesis' G_spec set-up checks: the
particles of one ladder run of each structure, in random order.

Usage: python benchmarks/bench_constraint_checks.py [--structures S1,S2] [--repeats N]
"""

from __future__ import annotations

import argparse
import os
import time
from contextlib import contextmanager

import numpy as np

from bayesfo.inference.likelihood import Likelihood
from bayesfo.inference.smc import ladder_run
from bayesfo.inference.transform import Transform
from bayesfo.structures import get_structure, passivity, response
from bayesfo.studies import g_spec_data

CASES = "max-n2m1:compliance,max-n2m2:compliance,max-n3m1:compliance,max-n3m3:compliance," \
        "max-n3m3:modulus,maxwell:compliance,maxwell:modulus"


@contextmanager
def eigenvalues_only():
    """Every row through the eigenvalues (the route before the shortcuts)."""
    saved = (response._cubic_matignon, passivity._cubic_critical_check,
             passivity._isolated_negatives_dominated)

    def unsure(*args):
        n = args[0].shape[0]
        return np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)

    response._cubic_matignon = unsure
    passivity._cubic_critical_check = unsure
    passivity._isolated_negatives_dominated = lambda p: np.zeros(p.shape[0], dtype=bool)
    try:
        yield
    finally:
        (response._cubic_matignon, passivity._cubic_critical_check,
         passivity._isolated_negatives_dominated) = saved


def _time(fn, reps, repeats):
    out = []
    for _ in range(repeats):
        t = time.perf_counter()
        for _ in range(reps):
            fn()
        out.append((time.perf_counter() - t) / reps)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--structures", default=CASES, help="name:kind pairs")
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args(argv)
    print(f"load {os.getloadavg()[0]:.2f}")
    for case in args.structures.split(","):
        name, kind = case.split(":")
        structure = get_structure(name)
        lik = Likelihood(structure, g_spec_data(0, kind=kind))
        run = ladder_run(lik, rng=np.random.default_rng(0))
        theta = Transform(lik).to_theta(run.particles)[:, :structure.n_params]
        # Particles and their scatter: the points a ladder's moves propose.
        rng = np.random.default_rng(1)
        theta = np.concatenate([theta, theta + rng.normal(0, 0.05, theta.shape)
                                * np.std(theta, axis=0)])
        theta = theta[rng.permutation(len(theta))]
        fast = structure.constraints_hold(theta, kind, lik.grid)
        with eigenvalues_only():
            slow = structure.constraints_hold(theta, kind, lik.grid)
        line = []
        for n in (1, 50, 150, 1000):
            rows = theta[:n]
            reps = max(3, 2000 // n)
            t_fast, t_slow = [], []
            for _ in range(args.repeats):  # interleaved
                t_fast += _time(lambda: structure.constraints_hold(rows, kind, lik.grid), reps, 1)
                with eigenvalues_only():
                    t_slow += _time(lambda: structure.constraints_hold(rows, kind, lik.grid),
                                    reps, 1)
            line.append(f"n={n}: {np.median(t_slow) * 1e6:7.0f} -> {np.median(t_fast) * 1e6:6.0f} us")
        print(f"{name:9s} {kind:10s} {' '.join(line)}  same decisions: "
              f"{int(np.sum(fast == slow))}/{len(theta)}")
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
