"""The distinct rows of the tempered ladder's particles: ``numpy.unique(x, axis=0)`` against
:func:`bayesfo.inference.smc.unique_rows` (a lexicographic sort of the columns), the same rows in
the same order.

1. Each on the shapes the ladder gives it (1 000 particles after resampling, about a third of
   them distinct; the 5 000 reweighted guide draws), best of 200 calls.
2. Two tempered-ladder runs of the default route (the importance proposal's draws as the guide)
   on the Maxwell of the bundled 20 °C isotherm, with each in turn, alternating: wall time and
   ln Z, which must be identical.

Usage: python benchmarks/bench_unique_rows.py [--rounds 3]
"""

from __future__ import annotations

import argparse
import os
import platform
import time
import warnings
from pathlib import Path

import numpy as np

import bayesfo as bf
from bayesfo.inference import Likelihood, results, smc
from bayesfo.inference._arviz import preload
from bayesfo.inference.evidence import ladder_runs
from bayesfo.structures import get_structure

ADHESIVE = Path(__file__).parents[1] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"


def _numpy_unique(x):
    return np.unique(x, axis=0)


def _best(fn, x, calls=200):
    best = np.inf
    for _ in range(calls):
        t = time.perf_counter()
        fn(x)
        best = min(best, time.perf_counter() - t)
    return best


def _use(fn):
    smc.unique_rows = fn
    results.unique_rows = fn


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    preload()
    print(f"machine: {platform.machine()}, python {platform.python_version()}, numpy "
          f"{np.__version__}; load {os.getloadavg()[0]:.2f}")
    ours = smc.unique_rows
    rng = np.random.default_rng(0)
    print(f"{'rows':>6} {'dims':>4} {'numpy ms':>9} {'unique_rows ms':>15}")
    for n, d, distinct in [(1000, 4, 330), (1000, 6, 330), (5000, 6, 2500)]:
        x = rng.normal(size=(distinct, d))[rng.integers(0, distinct, n)]
        assert np.array_equal(ours(x), np.unique(x, axis=0))
        print(f"{n:6d} {d:4d} {1e3 * _best(_numpy_unique, x):9.3f} {1e3 * _best(ours, x):15.3f}")

    from bayesfo.identify.optimize import fit_structure
    from bayesfo.inference.importance import importance_posterior

    data = bf.read(ADHESIVE)
    lik = Likelihood(get_structure("maxwell"), data, noise="constant")
    fit = fit_structure(lik.structure, data, rng=0, seed_methods=True, linear_methods=True)
    modes = lik.structure.to_scaled(lik.structure.to_physical(fit.optima, fit.scaling),
                                    lik.scaling)
    post, _, info = importance_posterior(lik, modes, seed=0)
    guide = None if post is not None else info["proposal_draws"]
    print(f"\nmaxwell, adhesive 20 °C, constant noise, guide: "
          f"{'none' if guide is None else len(guide)} draws")
    times = {"numpy": [], "unique_rows": []}
    log_z = {}
    for _ in range(args.rounds):
        for name, fn in (("numpy", _numpy_unique), ("unique_rows", ours)):
            _use(fn)
            t = time.perf_counter()
            ev, _ = ladder_runs(lik, seed=0, guide=guide)
            times[name].append(time.perf_counter() - t)
            log_z.setdefault(name, ev.log_z)
            assert ev.log_z == log_z[name]
    _use(ours)
    assert log_z["numpy"] == log_z["unique_rows"], "unique_rows changed the ladder"
    for name, ts in times.items():
        print(f"{name:12s} median {np.median(ts):6.2f} s  (runs {', '.join(f'{t:.2f}' for t in ts)})"
              f"  ln Z {log_z[name]:.6f}")
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
