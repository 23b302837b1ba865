"""Posteriors whose optimum lies on the edge of the support (inside the prior box), before and
after the importance route takes their curvature a few steps inside.

The thesis' G_spec = 1/(1 + s^0.5) (25 points, known noise, seed 0) fitted by generalised
Maxwell members with one element too many: their optimum sets a coefficient to 0 where the
element vanishes (max-n1m1's b1, max-n2m0's a1 or a2, max-n3m0's a1 and a3, max-n2m1's second
optimum), on the edge of the dissipative support; and the fractional Kelvin–Voigt model on the
metal network (GPL data, read in place from ``../shared/data/reference-gpl``; skipped where
absent), whose two orders meet at the optimum. Each case is one ``compare`` in a new process
(``workers=1``, seed 0), timed from outside; with ``--other DIR`` (another version's checkout)
each also runs with that version's package first on ``PYTHONPATH``, alternating. The table
gives the route of the posterior and of ln Z, and ln Z ± its error: where the route changed,
the two versions' ln Z are independent estimates, and their difference over the combined error
is printed.

Usage: python benchmarks/bench_edge_optima.py [--rounds 1] [--other DIR]
"""

from __future__ import annotations

import argparse
import math
import os
import platform
from pathlib import Path

import numpy as np
from _versions import ROOT, child_run, interleaved, versions

METAL = (ROOT.parent / "shared" / "data" / "reference-gpl" / "pyrheo_metal_network_epstein"
         / "original" / "epstein.csv")
CASES = [("g_spec", "max-n1m1"), ("g_spec", "max-n2m0"), ("g_spec", "max-n3m0"),
         ("g_spec", "max-n2m1"), ("metal network", "fractional_kelvin_voigt")]
CHILD = """
import json, sys, warnings
warnings.simplefilter("ignore")
import bayesfo as bf
from bayesfo.studies import g_spec_data
data = g_spec_data(0) if sys.argv[1] == "g_spec" else bf.read(sys.argv[1])
r = bf.compare(data, sys.argv[2], seed=0, workers=1, progress=False)[sys.argv[2]]
ev = r.criteria.evidence
print(json.dumps({"sampler": r.posterior.sampler, "log_z": r.log_z, "err": r.log_z_err,
                  "method": None if ev is None else ev.method}))
"""


def run(source: Path, data: str, name: str) -> tuple[float, dict]:
    return child_run(source, CHILD, "g_spec" if data == "g_spec" else str(METAL), name)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--other", type=Path, help="a checkout of another version to time beside")
    args = ap.parse_args()
    cases = [c for c in CASES if c[0] == "g_spec" or METAL.is_file()]
    which = versions(args.other)
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, python "
          f"{platform.python_version()}; load {os.getloadavg()[0]:.2f}", flush=True)
    times, found = interleaved(args.rounds, cases, which, run)
    print(f"{'data':<14} {'structure':<24} {'version':<7} {'median s':>9} {'posterior':<11} "
          f"{'ln Z by':<11} ln Z")
    for (data, name, version), v in times.items():
        out = found[(data, name, version)]
        lz = "none" if out["log_z"] is None else f"{out['log_z']:.3f} ± {out['err']:.3f}"
        print(f"{data:<14} {name:<24} {version:<7} {np.median(v):>9.2f} {out['sampler']:<11} "
              f"{out['method'] or '-':<11} {lz}")
    if len(which) == 2:
        for data, name in cases:
            a, b = found[(data, name, "this")], found[(data, name, "other")]
            if None not in (a["log_z"], b["log_z"]):
                z = (a["log_z"] - b["log_z"]) / math.hypot(a["err"], b["err"])
                print(f"{name} on {data}: ln Z difference {a['log_z'] - b['log_z']:+.3f} "
                      f"({z:+.1f} combined errors)")
    print(f"load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
