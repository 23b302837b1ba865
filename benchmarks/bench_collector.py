"""Time spent in Python's garbage collector by ``bayesfo compare`` as a user runs it (a new
process, the defaults, figures and report), in the command's process and in each worker
process, and the time from the command's last step to the end of the process (the
interpreter's exit).

A ``sitecustomize`` module on ``PYTHONPATH`` (written into a temporary directory) installs a
:data:`gc.callbacks` hook in every process of the run (the workers are forked from the
command's process and keep it) that adds up the collections' durations, the full ones apart;
an ``atexit`` function registered first, so run last, stamps the end of the exit handlers.
With ``--other DIR`` (a checkout of another version, e.g. ``git worktree add /tmp/old
<commit>``) each round also runs that version, alternating.

Prints, per version, the median over the rounds of: the wall time; the collector's seconds
(all generations / full collections only) summed over the processes and in the busiest
process; and the seconds between the exit handlers and the process's end.

Usage: python benchmarks/bench_collector.py [--rounds 3] [--data FILE] [--other DIR]
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
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "examples/data/adhesive_468mp/Tp020C.csv"

HOOK = '''
import atexit, gc, json, os, time
_log = os.environ["BENCH_GC_LOG"]
_state = {"all": 0.0, "full": 0.0, "pid": os.getpid()}

def _write():
    with open(_log, "a") as f:
        f.write(json.dumps({"pid": os.getpid(), "all": _state["all"],
                            "full": _state["full"]}) + "\\n")

def _hook(phase, info):
    if os.getpid() != _state["pid"]:  # a forked worker: its own totals
        _state.update(all=0.0, full=0.0, pid=os.getpid())
    if phase == "start":
        _state["t"] = time.perf_counter()
        return
    d = time.perf_counter() - _state["t"]
    _state["all"] += d
    if info["generation"] == 2:
        _state["full"] += d
    _write()  # workers end with os._exit: every collection leaves its totals

gc.callbacks.append(_hook)

def _exit_stamp():
    _write()
    with open(_log, "a") as f:
        f.write(json.dumps({"exit_handlers_done": time.time()}) + "\\n")

atexit.register(_exit_stamp)
'''


def _load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def run(source: Path, data: Path, tmp: Path) -> dict:
    hook_dir = tmp / "hook"
    hook_dir.mkdir(exist_ok=True)
    (hook_dir / "sitecustomize.py").write_text(HOOK)
    log = tmp / "gc.log"
    log.unlink(missing_ok=True)
    out = tmp / "out"
    env = dict(os.environ, MPLBACKEND="Agg", BENCH_GC_LOG=str(log),
               PYTHONPATH=os.pathsep.join([str(source), str(hook_dir)]))
    cmd = [sys.executable, "-m", "bayesfo.cli", "compare", str(data), "--out", str(out),
           "--quiet"]
    t0 = time.perf_counter()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=source)
    wall = time.perf_counter() - t0
    end = time.time()
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {done.stderr[-2000:]}")
    last, stamp = {}, None
    for line in log.read_text().splitlines():
        rec = json.loads(line)
        if "exit_handlers_done" in rec:
            stamp = rec["exit_handlers_done"]
        else:
            last[rec["pid"]] = rec
    return {"wall": wall, "gc_all": sum(r["all"] for r in last.values()),
            "gc_full": sum(r["full"] for r in last.values()),
            "gc_busiest": max(r["all"] for r in last.values()),
            "exit": end - stamp if stamp is not None else float("nan")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--data", type=Path, default=DEMO)
    ap.add_argument("--other", type=Path, help="checkout of another version to compare")
    args = ap.parse_args()
    versions = {"this": ROOT}
    if args.other:
        versions["other"] = args.other.resolve()
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, python "
          f"{platform.python_version()}; load {_load()}")
    rows = {k: [] for k in versions}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            for name, source in (versions.items() if r % 2 == 0
                                 else reversed(list(versions.items()))):
                rows[name].append(run(source, args.data, Path(tmp)))
            print(f"round {r + 1} done; load {_load()}", flush=True)
    print(f"{args.data.name}, medians over {args.rounds} rounds [s]")
    print(f"{'version':<8}{'wall':>8}{'gc all':>9}{'gc full':>9}{'busiest':>9}{'exit':>7}")
    for name, rs in rows.items():
        med = {k: float(np.median([x[k] for x in rs])) for k in rs[0]}
        print(f"{name:<8}{med['wall']:8.2f}{med['gc_all']:9.2f}{med['gc_full']:9.2f}"
              f"{med['gc_busiest']:9.2f}{med['exit']:7.2f}")
    print(f"load at the end {_load()}")


if __name__ == "__main__":
    main()
