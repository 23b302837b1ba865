"""Where the wall time of ``bayesfo compare FILE`` goes: a timeline of one command, each step
stamped in the process that ran it, and the CPU time of each kind of step.

The command runs in a new process as a user runs it (the default structures and settings,
figures and report unless ``--no-figures``), with the steps of the comparison wrapped so that
each writes (process, start, end, step) to a log: the optimisations (in the process forked
for them before the imports, and in the command's), each structure's posterior (``sample``,
with its structure), the conclusions, each figure, the NetCDF files and the other outputs.
Printed: the timeline (seconds from the start), then per kind of step the time spent in it
summed over processes (the CPU each kind costs, where each process has a CPU of its own), the
wall time, the process tree's CPU time (user + system, from ``resource``) and the stretch
before the first optimisation (interpreter, imports, reading).

The data sets are those of ``bench_command.py`` (GPL data read in place where present).

Usage: python benchmarks/bench_timeline.py [--datasets adh20,chia] [--no-figures]
       [--structures S]
"""

from __future__ import annotations

import argparse
import collections
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_command import DATASETS

ROOT = Path(__file__).resolve().parents[1]

#: Run in the command's process: wraps the steps, then calls the command line.
WRAPPER = r'''
import functools, os, sys, time
T0 = float(os.environ["TIMELINE_T0"])
fd = os.open(os.environ["TIMELINE_LOG"], os.O_WRONLY | os.O_CREAT | os.O_APPEND)

def stamp(name, a, b):
    os.write(fd, f"{os.getpid()} {a - T0:.4f} {b - T0:.4f} {name}\n".encode())

def wrapped(f, label, named=True):
    @functools.wraps(f)
    def g(*args, **kw):
        a = time.time()
        try:
            return f(*args, **kw)
        finally:
            name = getattr(args[0], "name", None) if named and args else None
            stamp(f"{label}:{name}" if isinstance(name, str) else label, a, time.time())
    return g

import bayesfo.comparison.early as early
import bayesfo.comparison.schedule as schedule
import bayesfo.comparison.steps as steps
import bayesfo.output.write as write
import bayesfo.plotting.output as figures

# The schedule and the early process name these functions as their own: the same wrapper in
# both modules, so that the tasks sent to the workers still pickle (by name).
for name, label in (("fit_and_probe", "fit"), ("fit_and_screen", "fit"),
                    ("sample_held", "sample"), ("conclude", "conclude")):
    w = wrapped(getattr(steps, name), label)
    setattr(steps, name, w)
    if hasattr(schedule, name):
        setattr(schedule, name, w)
early._fit = wrapped(early._fit, "optimise (early process)")
_save_all = figures._save_all

def save_all(makers, *args, **kwargs):
    a = time.time()
    try:
        return _save_all(makers, *args, **kwargs)
    finally:
        stamp("figure:" + ",".join(makers), a, time.time())

figures._save_all = save_all
write._write_netcdf = wrapped(write._write_netcdf, "netcdf", named=False)
write.write_outputs = wrapped(write.write_outputs, "outputs (with the figures drawn here)",
                              named=False)
stamp("interpreter and bayesfo imported", T0, time.time())
from bayesfo.cli import main
main(sys.argv[1:])
'''


def run(path: Path, extra: list[str]) -> tuple[float, float, list[tuple]]:
    """(wall, CPU of the process tree, stamps) of one command."""
    with tempfile.TemporaryDirectory() as tmp:
        log = Path(tmp) / "timeline.log"
        env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(ROOT), TIMELINE_LOG=str(log))
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.time()
        env["TIMELINE_T0"] = repr(t0)
        done = subprocess.run([sys.executable, "-c", WRAPPER, "compare", str(path), "--out",
                               str(Path(tmp) / "out"), "--quiet", "--seed", "0", *extra],
                              env=env, capture_output=True, text=True)
        wall = time.time() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if done.returncode != 0:
            raise RuntimeError(f"compare {path} failed: {done.stderr}")
        stamps = []
        for line in log.read_text().splitlines():
            pid, a, b, name = line.split(maxsplit=3)
            stamps.append((int(pid), float(a), float(b), name))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, sorted(stamps, key=lambda s: s[1])


def kind(name: str) -> str:
    """The kind of a step: its label, with the figure's name (structure figures as one)."""
    label, _, what = name.partition(":")
    if label == "figure":
        return "figure " + ("corner/trace" if what.startswith(("corner_", "trace_")) else what)
    return label


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--datasets", default=",".join(DATASETS))
    ap.add_argument("--no-figures", action="store_true")
    ap.add_argument("--structures", default=None)
    args = ap.parse_args()
    extra = (["--no-figures"] if args.no_figures else []) + (
        ["--structures", args.structures] if args.structures else [])
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
          f"Python {platform.python_version()}; load before {os.getloadavg()[0]:.2f}")
    for key in args.datasets.split(","):
        path = DATASETS[key][0]
        if not path.exists():
            print(f"{key}: {path} not present, skipped")
            continue
        wall, cpu, stamps = run(path, extra + DATASETS[key][1])
        pids = {pid: i for i, pid in enumerate(dict.fromkeys(s[0] for s in stamps))}
        print(f"\n== {key} ({path.name}){' --no-figures' if args.no_figures else ''}: "
              f"wall {wall:.2f} s, CPU of the process tree {cpu:.2f} s "
              f"({cpu / wall:.2f} CPUs busy on average)")
        print("  process  start    end  seconds  step")
        for pid, a, b, name in stamps:
            print(f"  P{pids[pid]:<6d} {a:6.2f} {b:6.2f} {b - a:7.3f}  {name}")
        first = min((a for _, a, _, n in stamps if n.startswith(("fit", "optimise"))),
                    default=float("nan"))
        totals = collections.defaultdict(float)
        for _, a, b, name in stamps:
            if not name.startswith(("interpreter", "outputs")):
                totals[kind(name)] += b - a
        print(f"  first optimisation at {first:.2f} s; seconds per kind of step (summed over "
              "processes):")
        for k, v in sorted(totals.items(), key=lambda kv: -kv[1]):
            print(f"    {v:6.2f}  {k}")
    print(f"\nload after {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
