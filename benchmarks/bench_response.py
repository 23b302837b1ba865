"""Throughput of the vectorised structure evaluation (the core of every likelihood call).

Prints parameter sets per second for Voigt, Zener (commensurate, Horner path), generalised Maxwell
(general power-term path) and a max-order member, on 25 frequencies, plus the cost of the
Matignon test and of the dissipation check on its dense grid.
"""

from __future__ import annotations

import platform
import time

import numpy as np

from bayesfo.structures import get_structure
from bayesfo.structures.response import dissipation_grid

N_SETS = 20_000
OMEGA = np.logspace(np.log10(0.6), np.log10(300), 25)


def best_of(fn, repeat=7):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def typical(structure, rng, n):
    theta = np.empty((n, structure.n_params))
    for i, p in enumerate(structure.parameters):
        theta[:, i] = rng.uniform(0.2, 0.9, n) if p.role == "exponent" else rng.uniform(0.1, 3.0, n)
    return theta


def main():
    rng = np.random.default_rng(0)
    print(f"machine: {platform.machine()}, {platform.processor() or 'cpu'}, python {platform.python_version()}, "
          f"numpy {np.__version__}")
    print(f"{'structure':<12} {'params':>6} {'transfer [sets/s]':>18} {'stable [sets/s]':>16} "
          f"{'admissible [sets/s]':>20}")
    grid = dissipation_grid(OMEGA.min(), OMEGA.max())
    for name in ("voigt", "zener", "maxwell", "max-n2m2", "max-n3m3"):
        s = get_structure(name)
        theta = typical(s, rng, N_SETS)
        t_tf = best_of(lambda: s.transfer(theta, OMEGA))
        t_st = best_of(lambda: s.stable(theta))
        t_ad = best_of(lambda: s.admissible(theta, "compliance", grid), repeat=3)
        print(f"{name:<12} {s.n_params:>6} {N_SETS / t_tf:>18,.0f} {N_SETS / t_st:>16,.0f} "
              f"{N_SETS / t_ad:>20,.0f}")
    print(f"(25 frequencies; dissipation grid of {grid.size} frequencies; best of repeated runs)")


if __name__ == "__main__":
    main()
