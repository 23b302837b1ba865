"""Signals on the automatic schedule of ``bayesfo compare`` (the default ``--workers 0``):
quick posteriors run in the command's own process and worker processes start only for the
long routes. Ctrl-C or SIGTERM, before or after the workers started, ends the command with
its one line, leaves no worker behind and the earlier output as it was."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

import bayesfo.outdir as outdir

ADHESIVE = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"


def _tree(d: Path) -> dict:
    return {p.relative_to(d).as_posix(): p.read_bytes() for p in sorted(d.rglob("*"))
            if p.is_file() and not p.name.startswith(".bayesfo-")}


def _workers(proc) -> list:
    try:
        return [c for c in psutil.Process(proc.pid).children(recursive=True)
                if "spawn_main" in " ".join(c.cmdline())]
    except psutil.Error:
        return []


def _has_loaded(proc, name: str) -> bool:
    try:
        return any(name in m.path for m in psutil.Process(proc.pid).memory_maps())
    except psutil.Error:
        return False


def _wait_for(condition, timeout=120.0):
    t0 = time.monotonic()
    while not condition():
        if time.monotonic() - t0 > timeout:
            raise AssertionError("the awaited moment never came")
        time.sleep(0.05)


@pytest.mark.parametrize("sig, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
@pytest.mark.parametrize("moment", ["here", "workers"])
def test_a_signal_ends_the_automatic_schedule_leaving_the_earlier_output(
        tmp_path, sig, status, moment):
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text('{"structures": [{"name": "voigt"}]}')
    (out / "voigt.nc").write_text("earlier")
    before = _tree(out)
    # The Maxwell's posterior takes the long route (seconds): it starts the worker processes.
    structures = "voigt,zener" if moment == "here" else "maxwell,voigt"
    proc = subprocess.Popen(
        [sys.executable, "-m", "bayesfo.cli", "compare", str(ADHESIVE), "--structures",
         structures, "--out", str(out), "--quiet", "--no-figures"],
        cwd=tmp_path, env=dict(os.environ, MPLBACKEND="Agg"), stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True)
    if moment == "here":
        # matplotlib's font library is loaded with arviz, which the noise screen imports: the
        # command is computing in its own process.
        _wait_for(lambda: _has_loaded(proc, "ft2font"))
    else:
        _wait_for(lambda: len(_workers(proc)) >= 1)
        time.sleep(0.5)
    assert proc.poll() is None, "the command ended before the signal"
    workers = _workers(proc)
    proc.send_signal(sig)
    _, stderr = proc.communicate(timeout=15)
    assert proc.returncode == status, stderr
    _, alive = psutil.wait_procs(workers, timeout=5)
    assert not alive
    lines = stderr.strip().splitlines()
    assert all(line.startswith("bayesfo: ") for line in lines), stderr
    assert lines[-1].endswith("(no output is left half-written)")
    outdir.recover(out)
    assert _tree(out) == before
