"""Cost of the likelihood of the structures whose responses are sums of power terms (not
commensurate: the Maxwell and the springpot cards), per call on a batch of parameter sets as
the tempered ladder makes them, with this version's ``power_sum`` and, with ``--other DIR``,
another version's (``bayesfo/structures/response.py`` of that checkout, e.g. from
``git worktree add /tmp/old <commit>``) in the same process, alternating, so that the load
touches both alike.

Data: the bundled adhesive isotherm at 20 °C (17 points), constant noise; 700 parameter sets
drawn from the priors. Prints the best of ``--repeat`` rounds of 20 calls, in ms per call.

Usage: python benchmarks/bench_power_sum.py [--other DIR] [--repeat 15]
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import platform
import time
import warnings
from pathlib import Path

import numpy as np

import bayesfo as bf
from bayesfo.inference import Likelihood
from bayesfo.structures import get_structure, response

DATA = Path(__file__).resolve().parents[1] / "examples/data/adhesive_468mp/Tp020C.csv"
CARDS = ("maxwell", "fractional_kelvin_voigt", "fractional_zener_sl", "fractional_burgers",
         "fractional_jeffreys")


def other_power_sum(checkout: Path):
    """``power_sum`` of another checkout's ``response.py`` (loaded beside this package's)."""
    spec = importlib.util.spec_from_file_location(
        "bayesfo.structures._other_response", checkout / "bayesfo/structures/response.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.power_sum


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--other", type=Path)
    ap.add_argument("--repeat", type=int, default=15)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, python "
          f"{platform.python_version()}, numpy {np.__version__}; load average "
          + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    versions = {"this": response.power_sum}
    if args.other is not None:
        versions["other"] = other_power_sum(args.other.resolve())
    data = bf.read(DATA)
    try:
        for name in CARDS:
            lik = Likelihood(get_structure(name), data, noise="constant")
            rng = np.random.default_rng(0)
            theta = np.column_stack([p.sample(rng, 700) for p in lik.prior_list])
            best = {k: np.inf for k in versions}
            values = {}
            for _ in range(args.repeat):
                for k, fn in versions.items():
                    response.power_sum = fn  # power_ratio looks it up at each call
                    t = time.perf_counter()
                    for _ in range(20):
                        values[k] = lik.pointwise(theta)
                    best[k] = min(best[k], (time.perf_counter() - t) / 20)
            same = all(np.array_equal(v, values["this"], equal_nan=True) for v in values.values())
            print(f"{name:<26} " + ", ".join(f"{k} {1e3 * v:.3f} ms" for k, v in best.items())
                  + (f"; the same values: {same}" if len(versions) > 1 else ""))
    finally:
        response.power_sum = versions["this"]


if __name__ == "__main__":
    main()
