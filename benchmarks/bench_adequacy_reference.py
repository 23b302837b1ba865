"""CPU time of the adequacy checks of one comparison, with the reference distributions drawn
afresh for every check and kept from the first (:func:`bayesfo.inference.adequacy._drawn`).

The default structures on the bundled 17-point adhesive isotherm at 20 °C, ``compare`` in one
process (``workers=1``), rounds alternating the two ways; prints the checks' summed time per
comparison (median and range) and whether both ways give the same p-values for every
structure.

Usage: python benchmarks/bench_adequacy_reference.py [--rounds 3]
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
import bayesfo.comparison.steps as steps
import bayesfo.inference.adequacy as adequacy
from bayesfo.inference._arviz import preload
from bayesfo.options import DEFAULT_STRUCTURES

ADHESIVE = Path(__file__).parents[1] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    preload()
    data = bf.read(ADHESIVE)
    real = steps.check_adequacy
    spent = {"fresh": [], "kept": []}
    p_values = {}

    def timed(*a, fresh=False, **k):
        if fresh:
            adequacy._drawn.cache_clear()
        t = time.process_time()
        out = real(*a, **k)
        timed.seconds += time.process_time() - t
        return out

    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, python "
          f"{platform.python_version()}; load {os.getloadavg()[0]:.2f}")
    for _ in range(args.rounds):
        for way in ("fresh", "kept"):
            adequacy._drawn.cache_clear()
            timed.seconds = 0.0
            steps.check_adequacy = lambda *a, _f=(way == "fresh"), **k: timed(*a, fresh=_f, **k)
            try:
                result = bf.compare(data, DEFAULT_STRUCTURES, seed=0, progress=False, workers=1)
            finally:
                steps.check_adequacy = real
            spent[way].append(timed.seconds)
            p_values.setdefault(way, {r.name: r.criteria.adequacy.p_values
                                      for r in result.results if r.criteria.adequacy})
    print(f"{'reference':<10} {'checks, CPU s per comparison: median':>38} {'min':>7} {'max':>7}")
    for way, v in spent.items():
        print(f"{way:<10} {np.median(v):>38.3f} {min(v):>7.3f} {max(v):>7.3f}")
    print("the same p-values for every structure both ways:", p_values["fresh"] == p_values["kept"])
    print(f"load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
