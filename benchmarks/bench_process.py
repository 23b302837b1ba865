"""Wall time of ``bayesfo compare --structures zener,voigt`` as a whole process (start-up,
imports, posteriors, evidence, criteria, outputs) on the bundled 17-point adhesive isotherm at
20 °C, beside dynesty's evidence alone for the same two structures in the same run.

Each round runs, one after the other (interleaved, so that a change of the machine's load
touches all alike):

- ``auto``: the default ``--workers 0`` (quick posteriors in the command's own process, worker
  processes only for structures that need the long routes; the figures drawn in the command's
  process and, when a CPU was idle during the comparison, in one forked from it), with
  ``--no-figures``, with the figures in PNG alone (``--figure-formats png``) and with the
  default PNG and PDF;
- ``one process``: ``--workers 1``, PNG and PDF (everything, figures included, in the
  command's process);
- ``pool``: ``--workers 2`` (both structures in two worker processes, which also draw the
  figures), with ``--no-figures`` and with PNG and PDF. dynesty (nlive 500, uniform sampling in bounding ellipsoids, evidence
only) runs once per structure, under the noise model the comparison chose. Prints the median
and range of each, the ratio of the medians to dynesty's total, and the load average.

Usage: python benchmarks/bench_process.py [--rounds N] [--skip-dynesty SECONDS]
(``--skip-dynesty`` takes dynesty's total from an earlier run instead of running it.)
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ADHESIVE = Path(__file__).parents[1] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"
VARIANTS = {
    "auto, no figures": ["--no-figures"],
    "auto, PNG figures": ["--figure-formats", "png"],
    "auto, PNG+PDF figures": [],
    "one process (--workers 1), PNG+PDF": ["--workers", "1"],
    "pool (--workers 2), no figures": ["--workers", "2", "--no-figures"],
    "pool (--workers 2), PNG+PDF figures": ["--workers", "2"],
}


def _run_cli(out: Path, extra: list[str]) -> float:
    cmd = [sys.executable, "-m", "bayesfo.cli", "compare", str(ADHESIVE), "--structures",
           "zener,voigt", "--out", str(out), "--quiet", "--seed", "0", *extra]
    env = dict(os.environ, MPLBACKEND="Agg")
    t = time.perf_counter()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr}")
    return wall


def _dynesty(summary: dict) -> float:
    import bayesfo as bf
    from bayesfo.inference import Likelihood
    from bayesfo.inference.evidence import nested_evidence
    from bayesfo.structures import get_structure

    data = bf.read(ADHESIVE)
    total = 0.0
    for entry in summary["structures"]:
        name = entry["name"]
        noise = entry["noise_models"]["chosen"]
        t = time.perf_counter()
        ev = nested_evidence(Likelihood(get_structure(name), data, noise=noise), seed=0,
                             nlive=500)
        dt = time.perf_counter() - t
        total += dt
        print(f"   dynesty {name} ({noise} noise): ln Z {ev.log_z:.2f} ± {ev.log_z_err:.2f} in "
              f"{dt:.1f} s; bayesfo {entry['log_evidence']:.2f} ± "
              f"{entry['log_evidence_err']:.2f}")
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--skip-dynesty", type=float, default=None, metavar="SECONDS")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, python "
          f"{platform.python_version()}, numpy {np.__version__}; load average at start "
          + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    times = {k: [] for k in VARIANTS}
    summaries = {}
    with tempfile.TemporaryDirectory(prefix="bench-process-") as tmp:
        for r in range(args.rounds):
            for k, extra in VARIANTS.items():
                out = Path(tmp) / f"{r}-{len(times[k])}-{k.split(',')[0].split()[0]}"
                times[k].append(_run_cli(out, extra))
                summaries[k] = json.loads((out / "summary.json").read_text())
            print(f"round {r + 1}: " + ", ".join(f"{k} {v[-1]:.2f} s" for k, v in times.items()),
                  flush=True)
        load_mid = os.getloadavg()
        numbers = {k: [(s["name"], s["log_evidence"], s["log_evidence_err"], s["loo"])
                       for s in v["structures"]] for k, v in summaries.items()}
        same = all(v == next(iter(numbers.values())) for v in numbers.values())
        print(f"summary.json numbers (ln Z, error, LOO) identical across the variants: {same}")
        if args.skip_dynesty is None:
            total = _dynesty(next(iter(summaries.values())))
        else:
            total = args.skip_dynesty
    print(f"dynesty evidence alone, zener + voigt: {total:.1f} s"
          + (" (given)" if args.skip_dynesty is not None else ""))
    print(f"{'variant':<40} {'median s':>9} {'min':>6} {'max':>6} {'ratio':>7}")
    for k, v in times.items():
        med = float(np.median(v))
        print(f"{k:<40} {med:>9.2f} {min(v):>6.2f} {max(v):>6.2f} {med / total:>7.3f}")
    print("load average after the CLI rounds " + " ".join(f"{x:.2f}" for x in load_mid)
          + ", at the end " + " ".join(f"{x:.2f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main()
