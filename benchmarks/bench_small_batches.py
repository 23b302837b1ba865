"""The log posterior on the small batches of the optimisers and certificates: the per-call
cost of ``log_prob`` (prior box, constraint checks, likelihood) for 1, 9 and 33 parameter sets
at once, the batch sizes of a Nelder-Mead step, an L-BFGS-B gradient stencil and a Newton
Hessian stencil on a five-parameter posterior, where fixed costs outweigh the arithmetic; and
the importance route's whole posterior (``compare`` of one structure, one process, no
figures), whose ridge probe and configuration search are made of such calls.

Data: the bundled adhesive isotherm at 20 °C (17 frequencies, modulus), constant noise. The
points are drawn once per structure inside the prior box, near a point of the support.

``--other DIR`` runs the same measurements with the package in DIR (e.g. a worktree of an
earlier commit) in alternating rounds, in separate processes, and prints both.

Usage: python benchmarks/bench_small_batches.py [--structures S1,S2] [--rounds N] [--other DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ADHESIVE = Path(__file__).parents[1] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"
STRUCTURES = "voigt,zener,zener-int,max-n2m1,fractional_kelvin_voigt,maxwell"
BATCHES = (1, 9, 33)


def measure(names: list[str], calls: int) -> dict:
    """``{structure: {"batch N": µs per call, ..., "posterior s": s}}`` in this process."""
    warnings.simplefilter("ignore")
    import bayesfo
    from bayesfo.comparison import compare
    from bayesfo.inference import Likelihood
    from bayesfo.inference.transform import Transform, _log_prob_fn
    from bayesfo.output.write import preload
    from bayesfo.structures import get_structure

    preload()
    data = bayesfo.read(ADHESIVE)
    out = {}
    for name in names:
        lik = Likelihood(get_structure(name), data, noise="constant")
        tr = Transform(lik)
        log_prob = _log_prob_fn(lik, tr)
        rng = np.random.default_rng(0)
        for _ in range(10_000):  # a point of the support
            u = tr.lo_u + rng.random(tr.lo_u.size) * (tr.hi_u - tr.lo_u)
            if np.isfinite(log_prob(u[None])[0]):
                break
        row = {}
        for n in BATCHES:
            pts = np.clip(u + 1e-3 * (tr.hi_u - tr.lo_u) * rng.standard_normal((n, u.size)),
                          tr.lo_u, tr.hi_u)
            best = np.inf
            for _ in range(3):
                t = time.perf_counter()
                for _ in range(calls):
                    log_prob(pts)
                best = min(best, (time.perf_counter() - t) / calls)
            row[f"batch {n}"] = best * 1e6
        t = time.perf_counter()
        compare(data, [name], seed=0, workers=1, noise="constant")
        row["posterior s"] = time.perf_counter() - t
        out[name] = row
    return out


def _child(root: Path, names: list[str], calls: int) -> dict:
    code = ("import json, sys; sys.path.insert(0, sys.argv[1]); "
            "sys.path.insert(1, sys.argv[2]); import bench_small_batches as b; "
            "print(json.dumps(b.measure(sys.argv[3].split(','), int(sys.argv[4]))))")
    env = dict(os.environ, PYTHONPATH=str(root))
    done = subprocess.run([sys.executable, "-c", code, str(root), str(Path(__file__).parent),
                           ",".join(names), str(calls)], env=env, capture_output=True,
                          text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--structures", default=STRUCTURES)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--calls", type=int, default=2000)
    ap.add_argument("--other", default=None, metavar="DIR")
    args = ap.parse_args()
    names = args.structures.split(",")
    here = Path(__file__).resolve().parents[1]
    roots = {"this": here} | ({"other": Path(args.other).resolve()} if args.other else {})
    runs = {k: [] for k in roots}
    for _ in range(args.rounds):
        for key, root in roots.items():
            runs[key].append(_child(root, names, args.calls))
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
          f"load {os.getloadavg()[0]:.1f}; {args.rounds} rounds: per call the best of "
          f"3 × {args.calls} calls in any round, the posterior's median")
    cols = [f"batch {n}" for n in BATCHES] + ["posterior s"]
    print(f"{'structure':26s} {'version':6s} " + " ".join(f"{c:>12s}" for c in cols))
    for name in names:
        for key in roots:
            # Per call: the least over the rounds (what the code costs, where the machine's
            # other work only adds); the posterior: the median.
            vals = [float((np.median if c == "posterior s" else np.min)(
                [r[name][c] for r in runs[key]])) for c in cols]
            print(f"{name:26s} {key:6s} " + " ".join(
                f"{v:10.1f}µs" if c != "posterior s" else f"{v:11.2f}s"
                for c, v in zip(cols, vals)))


if __name__ == "__main__":
    main()
