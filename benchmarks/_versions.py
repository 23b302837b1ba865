"""Timing this checkout beside another version's, each case a new process (shared by the
benchmarks with ``--other DIR``): the versions to run, one child run, and the interleaved
rounds."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def versions(other: Path | None) -> dict[str, Path]:
    """``{"this": ROOT}``, with ``"other"`` first where another checkout is given."""
    return {"this": ROOT} if other is None else {"other": other.resolve(), "this": ROOT}


def child_run(source: Path, code: str, *argv: str) -> tuple[float, dict]:
    """Wall time of ``python -c code argv...`` with ``source`` first on ``PYTHONPATH`` (run in
    it), and the JSON object its last line of output prints."""
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(source))
    t = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", code, *argv], env=env, capture_output=True,
                          text=True, cwd=source)
    wall = time.perf_counter() - t
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} failed: {done.stderr[-2000:]}")
    return wall, json.loads(done.stdout.strip().splitlines()[-1])


def interleaved(rounds: int, cases, which: dict[str, Path], run) -> tuple[dict, dict]:
    """``run(source, *case)`` for every case and version, ``rounds`` times, the versions'
    order alternating by round: ``(times, found)``, keyed by ``(*case, version)``, the wall
    times (a list per key) and the last output."""
    times, found = {}, {}
    for r in range(rounds):
        for case in cases:
            order = list(which) if r % 2 == 0 else list(reversed(which))
            for version in order:
                wall, out = run(which[version], *case)
                times.setdefault((*case, version), []).append(wall)
                found[(*case, version)] = out
    return times, found
