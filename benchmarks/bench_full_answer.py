"""Wall time of a full Bayesian answer: optimisation + certified posterior + ln Z ± err + LOO
(+ the adequacy checks), by route, beside dynesty's evidence alone on the same data.

1. One well-posed structure: fractional Zener compliance, 1 % noise with known σ, 25 and 40
   log-spaced points, five seeds; ``bayesfo.compare(data, "zener", workers=1)`` with
   ``sampler="auto"`` (importance sampling from the optimum where its weights certify it) and
   ``sampler="emcee"``; dynesty (500 live points, uniform sampling in bounding ellipsoids) for
   the first seed.
2. The default six structures on the bundled 17-point adhesive isotherm (20 °C), no figures:
   the automatic schedule (``workers=0``: this process runs what importance sampling certifies,
   worker processes start on demand, inside the clock) and, for comparison, two worker processes
   started before the clock, with both routes.

Imports (ArviZ, emcee) are done before the clock starts. Usage: python benchmarks/bench_full_answer.py
"""

from __future__ import annotations

import platform
import time
import warnings
from pathlib import Path

import numpy as np

import bayesfo as bf
from bayesfo.data import FrequencyResponse
from bayesfo.inference import Likelihood
from bayesfo.inference._arviz import preload
from bayesfo.inference.evidence import nested_evidence
from bayesfo.options import DEFAULT_STRUCTURES
from bayesfo.parallel import process_pool
from bayesfo.structures import get_structure

ADHESIVE = Path(__file__).parents[1] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"


def _zener_data(n: int, seed: int) -> FrequencyResponse:
    s = get_structure("zener")
    w = np.logspace(np.log10(0.6), np.log10(300), n)
    g = s.response(np.array([0.5, 1.0, 0.05, 0.6]), w, "compliance")
    sd = 0.01 * np.abs(g)
    rng = np.random.default_rng(seed)
    noisy = g + sd / np.sqrt(2) * (rng.normal(size=n) + 1j * rng.normal(size=n))
    return FrequencyResponse(w, noisy, sd, kind="compliance")


def one_structure() -> None:
    print("\n1. fractional Zener, full answer per call (median of 5 seeds; ln Z ± err of seed 0)")
    print(f"{'points':>6} {'route':<8} {'median s':>9} {'max s':>7} {'posterior':<11} "
          f"{'ln Z (seed 0)':>20}")
    for n in (25, 40):
        for route in ("auto", "emcee"):
            times, samplers, first = [], set(), None
            for seed in range(5):
                data = _zener_data(n, seed)
                t = time.perf_counter()
                r = bf.compare(data, "zener", seed=seed, workers=1, progress=False,
                               sampler=route)["zener"]
                times.append(time.perf_counter() - t)
                samplers.add(r.posterior.sampler)
                if seed == 0:
                    first = r.criteria.evidence
            print(f"{n:>6} {route:<8} {np.median(times):>9.3f} {np.max(times):>7.3f} "
                  f"{'/'.join(sorted(samplers)):<11} {first.log_z:>12.3f} ± {first.log_z_err:.3f}")
        lik = Likelihood(get_structure("zener"), _zener_data(n, 0))
        t = time.perf_counter()
        ev = nested_evidence(lik, seed=0, nlive=500)
        print(f"{n:>6} {'dynesty':<8} {time.perf_counter() - t:>9.3f} {'':>7} {'(ln Z only)':<11} "
              f"{ev.log_z:>12.3f} ± {ev.log_z_err:.3f}")


def six_structures() -> None:
    print(f"\n2. default comparison ({DEFAULT_STRUCTURES}) of the 17-point adhesive isotherm, "
          "no figures")
    data = bf.read(ADHESIVE)
    t = time.perf_counter()
    result = bf.compare(data, DEFAULT_STRUCTURES, seed=0, workers=0, progress=False)
    wall = time.perf_counter() - t
    routes = ", ".join(f"{r.name}: {r.posterior.sampler}" for r in result.results)
    print(f"   {'auto, automatic schedule':<26} {wall:6.1f} s  ({routes})")
    for route in ("auto", "emcee"):
        with process_pool(2) as pool:
            pool.submit(int).result()  # processes started before the clock
            t = time.perf_counter()
            result = bf.compare(data, DEFAULT_STRUCTURES, seed=0, pool=pool, progress=False,
                                sampler=route)
            wall = time.perf_counter() - t
        routes = ", ".join(f"{r.name}: {r.posterior.sampler}" for r in result.results)
        print(f"   {route + ', 2 processes started':<26} {wall:6.1f} s  ({routes})")


def main() -> None:
    warnings.simplefilter("ignore")
    preload()
    import emcee  # noqa: F401

    print(f"machine: {platform.machine()}, {platform.processor() or 'cpu'}, python "
          f"{platform.python_version()}, numpy {np.__version__}")
    one_structure()
    six_structures()


if __name__ == "__main__":
    main()
