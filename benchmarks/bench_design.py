"""Speed of ``bayesfo design``: proposals for a comparison on the bundled 17-point isotherm.

A comparison of Voigt, Zener and the Maxwell model on the 20 °C adhesive isotherm (API, one
process), then ``bayesfo.design`` with 1, 3 and 5 points (median of five calls, seeds 0-4), and
the command ``bayesfo design DIR --points 3`` as a process (reading the stored run included).
Goal (issue): proposals for the default structures of a 17-point isotherm in at most 5 s.

Usage: python benchmarks/bench_design.py
"""

from __future__ import annotations

import platform
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

import bayesfo as bf

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"


def main() -> None:
    warnings.simplefilter("ignore")
    print(f"# {platform.node()} {platform.machine()}, bayesfo {bf.__version__}")
    result = bf.compare(bf.read(DATA), "voigt,zener,maxwell", seed=0, progress=False, workers=1)
    for points in (1, 3, 5):
        times = []
        for seed in range(5):
            t0 = time.perf_counter()
            plan = bf.design(result, points=points, seed=seed)
            times.append(time.perf_counter() - t0)
        print(f"design, {len(plan.structures)} structures, {points} point(s): "
              f"median {np.median(times):.3f} s (min {min(times):.3f}, max {max(times):.3f}); "
              f"proposed {[round(p['omega'], 4) for p in plan.proposed]}")
    with tempfile.TemporaryDirectory() as tmp:
        bf.write_outputs(result, Path(tmp) / "run", figures=False)
        for _ in range(2):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "bayesfo.cli", "design", str(Path(tmp) / "run"),
                            "--points", "3"], check=True, capture_output=True)
            print(f"bayesfo design DIR --points 3 as a process: {time.perf_counter() - t0:.2f} s")


if __name__ == "__main__":
    main()
