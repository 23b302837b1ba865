"""Identification benchmarks (thesis §3.4).

1. Methods 1-5 on 10 000 Monte Carlo realisations of Table 3.2's set-up (q = 0.5, n = 1, m = 0).
2. Global optimisation of max-n2m2 (5 coefficients + q, 25 points) on 100 noisy realisations of
   G_spec: median wall time per fit with the default settings, and the share of fits that reach
   the best known optimum (the best of a reference search with many more starts, relative cost
   difference <= 1e-6).

Usage: python benchmarks/bench_identify.py [--runs 100] [--reference-starts 96]
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

from bayesfo.data import FrequencyResponse
from bayesfo.identify import fit_structure
from bayesfo.identify.linear import identify_linear
from bayesfo.structures import get_structure
from bayesfo.studies import OMEGA, g_spec, thesis_noise


def bench_methods(runs=10_000):
    noisy = g_spec() + thesis_noise(np.random.default_rng(0), runs)
    t0 = time.perf_counter()
    per = {}
    for method in (1, 2, 3, 4, 5):
        t = time.perf_counter()
        identify_linear(OMEGA, noisy, 0.5, 1, 0, method)
        per[method] = time.perf_counter() - t
    total = time.perf_counter() - t0
    print(f"methods 1-5, {runs} realisations: {total:.2f} s wall "
          + "(" + ", ".join(f"{m}: {t:.2f} s" for m, t in per.items()) + ")")


def bench_global(runs=100, reference_starts=96):
    s = get_structure("max-n2m2")
    noisy = g_spec() + thesis_noise(np.random.default_rng(1), runs)
    times, hits, qs = [], 0, []
    for r in range(runs):
        data = FrequencyResponse(OMEGA, noisy[r])
        t = time.perf_counter()
        fit = fit_structure(s, data, rng=r, weighting="none", seed_methods=True)
        times.append(time.perf_counter() - t)
        ref = fit_structure(s, data, rng=10_000 + r, weighting="none", seed_methods=True,
                            n_starts=reference_starts)
        best = min(ref.chi2, fit.chi2)
        hits += fit.chi2 <= best * (1 + 1e-6) + 1e-14
        qs.append(fit.theta[-1])
    times = np.array(times)
    print(f"global optimisation max-n2m2, {runs} realisations: median {np.median(times):.3f} s/fit "
          f"(p90 {np.percentile(times, 90):.3f} s), best known optimum reached in {hits}/{runs}; "
          f"mean q = {np.mean(qs):.4f}")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=100)
    parser.add_argument("--reference-starts", type=int, default=96)
    args = parser.parse_args()
    print(f"machine: {platform.machine()}, python {platform.python_version()}, numpy {np.__version__}")
    bench_methods()
    bench_global(args.runs, args.reference_starts)


if __name__ == "__main__":
    main()
