"""Time of the posteriors whose tempered-ladder runs cannot succeed, before and after they give
up early, on the silk feedstock (GPL data, read in place from ``../shared/data/reference-gpl``;
skipped where absent).

The structures of ``--structures all`` on the silk whose ladder runs tried first fail: the
prior draws of max-n2m3-inv and max-n2m3-inv-int are admissible about once in 10 000 (too few
to start a ladder; the search now gives up once a bound of that fraction cannot reach its
particles), and the first two runs of max-n2m2-inv (constant noise) and max-n3m3-inv disagree
and end far below the best fit (no second pair is made now). Each structure and noise model is
one ``compare`` in a new process (``workers=1``, seed 0), timed from outside; with ``--other
DIR`` (another version's checkout) each also runs with that version's package first on
``PYTHONPATH``, alternating, and the script says whether both gave the same ln Z and route.

Usage: python benchmarks/bench_ladder_give_up.py [--rounds 1] [--other DIR]
"""

from __future__ import annotations

import argparse
import os
import platform
from pathlib import Path

import numpy as np
from _versions import ROOT, child_run, interleaved, versions

SILK = (ROOT.parent / "shared" / "data" / "reference-gpl" / "reptate_silk_feedstock" / "original"
        / "silk_feedstock.tts")
CASES = [("max-n2m3-inv", "constant"), ("max-n2m3-inv-int", "proportional"),
         ("max-n2m2-inv", "constant"), ("max-n3m3-inv", "constant"),
         ("max-n3m3-inv", "proportional")]
CHILD = """
import json, sys, warnings
warnings.simplefilter("ignore")
import bayesfo as bf
r = bf.compare(bf.read(sys.argv[1]), sys.argv[2], noise=sys.argv[3], seed=0, workers=1,
               progress=False)[sys.argv[2]]
print(json.dumps({"log_z": r.log_z, "sampler": r.posterior.sampler}))
"""


def run(source: Path, name: str, noise: str) -> tuple[float, dict]:
    return child_run(source, CHILD, str(SILK), name, noise)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--other", type=Path, help="a checkout of another version to time beside")
    args = ap.parse_args()
    if not SILK.is_file():
        print(f"skipped: {SILK} not found (GPL reference data)")
        return
    which = versions(args.other)
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, python "
          f"{platform.python_version()}; load {os.getloadavg()[0]:.2f}", flush=True)
    times, found = interleaved(args.rounds, CASES, which, run)
    print(f"{'structure':<18} {'noise':<13} {'version':<7} {'median s':>9} {'route':<11} ln Z")
    for (name, noise, version), v in times.items():
        out = found[(name, noise, version)]
        lz = "none" if out["log_z"] is None else f"{out['log_z']:.3f}"
        print(f"{name:<18} {noise:<13} {version:<7} {np.median(v):>9.2f} {out['sampler']:<11} {lz}")
    if len(which) == 2:
        same = all(found[(n, z, "this")] == found[(n, z, "other")] for n, z in CASES)
        print("the same ln Z and route in both versions:", same)
    print(f"load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
