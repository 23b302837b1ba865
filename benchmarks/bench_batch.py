"""Wall time of ``bayesfo batch``: 1 and 2 local workers, and a Dask LocalCluster.

N simulated fractional-Zener compliances (default 20) with 25 to 40 log-spaced frequencies in
[0.6, 300] rad/s, 1 % complex noise with known sigma and q from 0.35 to 0.75, compared with
voigt, zener and maxwell (the full comparison of each: optimisation, emcee posterior, criteria,
bridge-sampling ln Z, output files). The same seed for every run: the three executors must give
identical numbers, which is checked.

Figures:

* ``speed-up``: wall(2 local workers) / wall(1 worker); goal <= 0.6. The 1-worker run is
  in-process with bayesfo already imported, the 2-worker run includes spawning the workers and
  their imports, so the ratio is conservative.
* Dask per-data-set overhead = (wall(Dask) x workers - sum of the tasks' times) / N, where a
  task is what any executor runs for one data set: read the CSV, ``compare``, write its outputs
  (summary, ranking, NetCDF). The overhead is what the Dask path adds beyond that: scheduling,
  moving the outputs to the client and writing them there, the workers' first imports, idle
  cores at the end of the run. Goal <= 1 s. Printed beside it: the same with ``compare`` alone
  in place of the task (the task's reading and writing then count as overhead too). The
  cluster's start-up is reported separately (a cluster is usually started once for many
  batches).

Per-data-set figures and reports are off (``--figures`` turns them on: they cost more than the
comparison itself, and are the same work for every executor).

Run: ``python benchmarks/bench_batch.py`` (about 2 x N x 7 s of CPU on the project machine);
``--n 4`` for a quick check. Measure on a quiet machine: other jobs on the cores distort every
figure here.
"""

from __future__ import annotations

import argparse
import csv
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

from bayesfo.batch import expand_inputs, run_batch
from bayesfo.data import FrequencyResponse
from bayesfo.inference._arviz import preload
from bayesfo.structures import get_structure


def make_datasets(directory: Path, n: int, seed: int = 0) -> list[Path]:
    """N noisy fractional-Zener compliances, 25 to 40 points each, written as CSV."""
    rng = np.random.default_rng(seed)
    zener = get_structure("zener")
    paths = []
    for i in range(n):
        n_points = 25 + (7 * i) % 16
        w = np.logspace(np.log10(0.6), np.log10(300), n_points)
        q = 0.35 + 0.4 * i / max(n - 1, 1)
        g = zener.response(np.array([0.5, 1.0, 0.05, q]), w, "compliance")
        sd = 0.01 * np.abs(g)
        noisy = g + sd / np.sqrt(2) * (rng.normal(size=n_points) + 1j * rng.normal(size=n_points))
        fr = FrequencyResponse(w, noisy, sd, kind="compliance", name=f"zener q={q:.3f}")
        paths.append(fr.to_csv(directory / f"zener_{i:02d}.csv"))
    return paths


def numbers(out: Path) -> dict:
    with open(out / "batch_summary.csv", newline="", encoding="utf-8") as fh:
        return {(r["dataset"], r["structure"]): (r["log_evidence"], r["q_mean"], r["loo"])
                for r in csv.DictReader(fh)}


def report(label: str, result, n: int) -> None:
    cmp_s = sum(o.compare_seconds or 0 for o in result.outcomes)
    cpu_s = sum(o.compare_cpu_seconds or 0 for o in result.outcomes)
    task_s = sum(o.task_seconds or 0 for o in result.outcomes)
    failed = len(result.failed)
    print(f"{label:<26} wall {result.wall_seconds:7.1f} s | sum over data sets: compare "
          f"{cmp_s:7.1f} s wall, {cpu_s:7.1f} s CPU; task {task_s:7.1f} s"
          + (f" | FAILED {failed}" if failed else ""))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=20, help="number of data sets (default 20)")
    parser.add_argument("--structures", default="voigt,zener,maxwell")
    parser.add_argument("--workers", type=int, default=2, help="parallel workers (default 2)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--no-dask", action="store_true", help="skip the Dask run")
    parser.add_argument("--figures", action="store_true",
                        help="also draw each data set's figures and report")
    args = parser.parse_args(argv)

    preload()
    print(f"machine: {platform.machine()}, python {platform.python_version()}, "
          f"numpy {np.__version__}")
    with tempfile.TemporaryDirectory(prefix="bench-batch-") as tmp:
        tmp = Path(tmp)
        (tmp / "data").mkdir()
        make_datasets(tmp / "data", args.n, args.seed)
        datasets = expand_inputs([tmp / "data"], seed=args.seed,
                                 options={"structures": args.structures, "figures": args.figures})
        sizes = [25 + (7 * i) % 16 for i in range(args.n)]
        print(f"{args.n} data sets of {min(sizes)}-{max(sizes)} points, "
              f"structures {args.structures}, seed {args.seed}")

        one = run_batch(datasets, tmp / "one", workers=1, progress=False)
        report("1 worker (in-process)", one, args.n)
        many = run_batch(datasets, tmp / "many", workers=args.workers, progress=False)
        report(f"{args.workers} local workers", many, args.n)
        ratio = many.wall_seconds / one.wall_seconds
        print(f"speed-up: wall({args.workers} workers) / wall(1 worker) = {ratio:.2f} "
              f"(goal <= 0.6 for 2 workers)")
        same = numbers(tmp / "one") == numbers(tmp / "many")

        if not args.no_dask:
            from distributed import LocalCluster

            t = time.perf_counter()
            with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                              host="127.0.0.1", dashboard_address=None) as cluster:
                start = time.perf_counter() - t
                dask = run_batch(datasets, tmp / "dask", scheduler=cluster.scheduler_address,
                                 progress=False)
            report(f"Dask LocalCluster ({args.workers})", dask, args.n)
            busy = dask.wall_seconds * args.workers
            task_s = sum(o.task_seconds or 0 for o in dask.outcomes)
            cmp_s = sum(o.compare_seconds or 0 for o in dask.outcomes)
            print(f"Dask overhead per data set: (wall x {args.workers} - sum task) / {args.n} = "
                  f"{(busy - task_s) / args.n:.2f} s (goal <= 1 s); beyond compare() alone "
                  f"{(busy - cmp_s) / args.n:.2f} s; cluster start-up {start:.1f} s (not "
                  "included)")
            same = same and numbers(tmp / "one") == numbers(tmp / "dask")
        print(f"identical numbers across executors: {'yes' if same else 'NO'}")


if __name__ == "__main__":
    main()
