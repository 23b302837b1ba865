"""Reliability and security of the outputs: nothing outside the output directory is touched,
each output directory holds the complete output of one run, faults end with one line.

The comparisons are small (the simulated Voigt compliance of tests/integration/test_compare.py, two
structures, no figures) so the fault tests stay fast; the signal tests run the command line in a
child process on a bundled isotherm and signal it while it samples and while it writes.
"""

from __future__ import annotations

import dataclasses
import errno
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import psutil
import pytest

import bayesfo.outdir as outdir
from bayesfo.batch import expand_inputs, run_batch
from bayesfo.batch.executors import _run_processes
from bayesfo.comparison import compare
from bayesfo.data import FrequencyResponse
from bayesfo.errors import OutputError
from bayesfo.output import write_outputs
from bayesfo.structures import get_structure, resolve_structures

ROOT = Path(__file__).parents[2]
ADHESIVE = ROOT / "examples" / "data" / "adhesive_468mp"
W = np.logspace(np.log10(0.6), np.log10(300), 25)


def _tree(d: Path) -> dict:
    """Every file below ``d`` (links not followed) with its bytes."""
    return {p.relative_to(d).as_posix(): (os.readlink(p) if p.is_symlink() else p.read_bytes())
            for p in sorted(d.rglob("*")) if (p.is_symlink() or p.is_file())
            and not p.name.startswith(".bayesfo-")}  # the run's manifest and lock


@pytest.fixture(scope="module")
def comparison():
    rng = np.random.default_rng(0)
    g = get_structure("voigt").response([1.0, 1e-3, 0.5], W, "compliance")
    sd = 0.02 * np.abs(g)
    data = FrequencyResponse(W, g + sd / np.sqrt(2) * (rng.normal(size=25)
                                                        + 1j * rng.normal(size=25)),
                             sd, kind="compliance", name="simulated voigt")
    return compare(data, resolve_structures("voigt,zener"), seed=1, progress=False, workers=1)


@pytest.fixture
def earlier(comparison, tmp_path):
    """An output directory holding a complete earlier run and a file of the user's own."""
    out = tmp_path / "out"
    write_outputs(comparison, out, figures=False)
    (out / "notes.txt").write_text("mine")
    return out, _tree(out)


# ---------------------------------------------------------------------- one run per directory
def test_an_interrupted_run_leaves_the_earlier_output(comparison, earlier, monkeypatch):
    import bayesfo.output.write

    out, before = earlier
    assert set(before) == {"voigt.nc", "zener.nc", "ranking.csv", "summary.json", "notes.txt"}

    def interrupted(*args, **kwargs):  # after both NetCDF files were written
        raise KeyboardInterrupt

    monkeypatch.setattr(bayesfo.output.write, "ranking_csv", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_outputs(comparison, out, figures=False)
    assert _tree(out) == before
    assert not list(out.glob(".bayesfo-staging-*"))


def test_a_later_run_leaves_nothing_of_the_earlier_one(comparison, earlier):
    out, before = earlier
    fewer = dataclasses.replace(comparison, results=comparison.results[:1])
    written = write_outputs(fewer, out, figures=False)
    assert sorted(_tree(out)) == ["notes.txt", "ranking.csv", "summary.json", "voigt.nc"]
    assert written["summary.json"] == out / "summary.json"
    assert json.loads((out / "summary.json").read_text())["ranking"] == ["voigt"]
    assert (out / "notes.txt").read_text() == "mine"


def test_full_disk_keeps_the_earlier_output(comparison, earlier, monkeypatch):
    import bayesfo.inference.results as posterior  # where save_netcdf checks the space

    out, before = earlier
    monkeypatch.setattr(posterior.shutil, "disk_usage", lambda p: shutil._ntuple_diskusage(
        10**9, 10**9 - 1000, 1000))
    with pytest.raises(OutputError, match=r"no space left on the device of '.*out'; the "
                                          "earlier outputs there are kept"):
        write_outputs(comparison, out, figures=False)
    assert _tree(out) == before and not list(out.glob(".bayesfo-staging-*"))


def test_write_error_in_a_figure_keeps_the_earlier_output(comparison, earlier, monkeypatch):
    import bayesfo.plotting

    out, before = earlier

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(bayesfo.plotting, "write_figures", full)
    with pytest.raises(OutputError, match="no space left"):
        write_outputs(comparison, out, figures=True)
    assert _tree(out) == before and not list(out.glob(".bayesfo-staging-*"))


def test_a_swap_cut_short_is_completed_by_the_next_run(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text(json.dumps({"structures": [{"name": "a"}, {"name": "b"}]}))
    (out / "a.nc").write_text("old a")
    (out / "b.nc").write_text("old b")
    (out / "figures").mkdir()
    (out / "figures" / "old.png").write_text("old")
    (out / outdir.MANIFEST).write_text(json.dumps(  # as the earlier run recorded them
        {"format": 1, "entries": ["a.nc", "b.nc", "figures", "summary.json"]}))
    calls = []
    real_replace = os.replace

    def dies_after_two(src, dst):  # the process is killed during the renames of the swap
        calls.append(dst)
        if sum(Path(c).parent == out and Path(c).name != outdir.JOURNAL for c in calls) > 2:
            raise SystemExit("killed")
        real_replace(src, dst)

    monkeypatch.setattr(outdir.os, "replace", dies_after_two)
    with pytest.raises(SystemExit):
        with outdir.staged_run(out) as stage:
            (stage / "a.nc").write_text("new a")
            (stage / "figures").mkdir()
            (stage / "figures" / "new.png").write_text("new")
            (stage / "ranking.csv").write_text("new")
            (stage / "summary.json").write_text(json.dumps({"structures": [{"name": "a"}]}))
    monkeypatch.setattr(outdir.os, "replace", real_replace)
    assert (out / outdir.JOURNAL).exists()  # killed half way: the next run completes the swap
    outdir.recover(out)
    assert _tree(out) == {"a.nc": b"new a", "figures/new.png": b"new", "ranking.csv": b"new",
                          "summary.json": b'{"structures": [{"name": "a"}]}'}


def test_abandoned_staging_directories_are_removed(tmp_path):
    import fcntl

    out = tmp_path / "out"
    dead, live = out / ".bayesfo-staging-dead", out / ".bayesfo-staging-live"
    for d in (dead, live):
        (d / "new").mkdir(parents=True)
        (d / "new" / ".voigt.x.nc").write_text("half")
        (d / ".owner").write_text("")
    (out / "summary.json").write_text("{}")
    fd = os.open(live / ".owner", os.O_RDWR)  # another run, still writing
    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        outdir.recover(out)
    finally:
        os.close(fd)
    assert _tree(out) == {"summary.json": b"{}", ".bayesfo-staging-live/.owner": b"",
                          ".bayesfo-staging-live/new/.voigt.x.nc": b"half"}
    outdir.recover(out)  # its run has ended without swapping in
    assert _tree(out) == {"summary.json": b"{}"}


def test_a_directory_of_the_user_is_never_replaced(comparison, tmp_path, run_cli):
    out = tmp_path / "out"
    (out / "figures").mkdir(parents=True)
    (out / "figures" / "thesis_fig1.png").write_text("mine")
    (out / "error.txt").write_text("my notes")
    (out / "summary.json").write_text('{"structures": [{"name": "measurements"}]}')
    (out / "measurements.nc").write_text("mine")
    with pytest.raises(OutputError, match="figures' is a directory that no bayesfo run "
                                          "recorded"):
        write_outputs(comparison, out, figures=True)
    write_outputs(comparison, out, figures=False)  # replaces summary.json only
    assert (out / "figures" / "thesis_fig1.png").read_text() == "mine"
    assert (out / "error.txt").read_text() == "my notes"
    assert (out / "measurements.nc").read_text() == "mine"
    status, _, err = run_cli("compare", ADHESIVE / "Tp020C.csv", "--out", out)
    assert status == 2 and "holds a directory 'figures' that no bayesfo run recorded" in err


def test_a_run_leaves_no_lock_file(comparison, tmp_path, fake_compare):
    out = tmp_path / "out"
    write_outputs(comparison, out, figures=False)
    write_outputs(comparison, out, figures=False)  # over an earlier run
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == [outdir.MANIFEST]
    shutil.copy(ADHESIVE / "Tp150C.csv", tmp_path / "a.csv")
    res = run_batch(expand_inputs([tmp_path / "a.csv"], options={"structures": "voigt"}),
                    tmp_path / "batch", workers=1, progress=False, write_combined=False)
    assert res.outcomes[0].status == "ok"
    assert not list((tmp_path / "batch").rglob(outdir.LOCK))


def test_runs_take_turns_although_the_lock_file_is_removed(tmp_path, monkeypatch):
    """A run that waited on the lock file its holder then removed must not go ahead while a
    third run holds the new lock file (flock locks a file, not a path)."""
    import fcntl
    import threading

    out = tmp_path / "out"
    out.mkdir()
    opened = {name: threading.Event() for name in ("b", "c")}
    real_flock = fcntl.flock

    def flock(fd, op):  # the run has opened the lock file and now waits for it
        name = threading.current_thread().name
        if name in opened:
            opened[name].set()
        return real_flock(fd, op)

    monkeypatch.setattr(fcntl, "flock", flock)
    inside, entered, leave = [], {n: threading.Event() for n in "abc"}, {
        n: threading.Event() for n in "abc"}

    def run(name):
        with outdir._locked(out):
            inside.append(name)
            entered[name].set()
            assert leave[name].wait(10)
            inside.remove(name)

    threads = {n: threading.Thread(target=run, args=(n,), name=n) for n in "abc"}
    threads["a"].start()
    assert entered["a"].wait(10)
    threads["b"].start()
    assert opened["b"].wait(10)  # b holds a descriptor of the file a locked
    leave["a"].set()
    threads["a"].join(10)
    assert entered["b"].wait(10)
    threads["c"].start()
    assert opened["c"].wait(10)
    assert not entered["c"].wait(0.5), "two runs hold the lock at once"
    assert inside == ["b"]
    leave["b"].set()
    assert entered["c"].wait(10) and inside == ["c"]
    leave["c"].set()
    for t in threads.values():
        t.join(10)
    assert not (out / outdir.LOCK).exists()


def test_a_link_named_like_the_lock_is_never_followed(tmp_path):
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / outdir.LOCK).symlink_to(elsewhere / "made-by-bayesfo")
    with pytest.raises(OutputError, match=r"'.*\.bayesfo-lock' is a symbolic link, not "
                                          "bayesfo's lock file; remove it"):
        with outdir.staged_run(out) as stage:
            (stage / "summary.json").write_text("{}")
    assert list(elsewhere.iterdir()) == [] and not (out / "summary.json").exists()


# ---------------------------------------------------------------------- nothing outside --out
SUMMARY = {"data": {"kind": "modulus", "n_frequencies": 17}, "ranking": ["voigt"],
           "structures": [{"name": "voigt", "n_params": 3, "log_evidence": -1.5,
                           "posterior_probability": 1.0,
                           "parameters": {"q": {"mean": 0.5, "sd": 0.1, "hdi_low": 0.3,
                                                "hdi_high": 0.7, "map": 0.5}}}]}


@pytest.fixture
def fake_compare(monkeypatch):
    """compare and write_outputs replaced by instant fakes (batch runs in this process)."""
    import bayesfo.comparison
    import bayesfo.output

    def fake_outputs(comparison, out, figures=True, **figure_options):
        out = Path(out)
        (out / "voigt.nc").write_bytes(b"nc")
        (out / "figures").mkdir()
        (out / "figures" / "bode.png").write_bytes(b"png")
        (out / "summary.json").write_text(json.dumps(SUMMARY))

    monkeypatch.setattr(bayesfo.comparison, "compare", lambda *args, **kwargs: None)
    monkeypatch.setattr(bayesfo.output, "write_outputs", fake_outputs)


def test_a_full_output_directory_stops_a_batch_keeping_and_listing_what_finished(
        tmp_path, fake_compare, monkeypatch):
    """The device fills while the second of three data sets is stored: the batch stops with
    one OutputError naming it, the first data set's outputs stay and batch_summary.csv lists
    it, and no empty directory of the second is left behind; run again with room, it resumes."""
    for name in ("a", "b", "c"):
        shutil.copy(ADHESIVE / "Tp150C.csv", tmp_path / f"{name}.csv")
    out = tmp_path / "out"
    real_write = Path.write_bytes

    def full_disk(self, data):
        if self.parent.name == "new" and f"{os.sep}b{os.sep}" in str(self):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_write(self, data)

    monkeypatch.setattr(Path, "write_bytes", full_disk)
    inputs = expand_inputs([tmp_path / f"{n}.csv" for n in "abc"],
                           options={"structures": "voigt", "figures": False})
    with pytest.raises(OutputError, match=r"no space left on the device of .*b'.*the batch "
                                          r"stopped after 1 of 3 data sets, whose outputs are "
                                          r"kept, listed in batch_summary.csv"):
        run_batch(inputs, out, workers=1, progress=False)
    assert (out / "a" / "summary.json").is_file() and not (out / "b").exists()
    header, *rows = (out / "batch_summary.csv").read_text().splitlines()
    ids = [dict(zip(header.split(","), r.split(","), strict=False))["dataset"] for r in rows]
    assert set(ids) == {"a"}
    monkeypatch.setattr(Path, "write_bytes", real_write)
    res = run_batch(inputs, out, workers=1, progress=False)
    assert [o.reused for o in res.outcomes] == [True, False, False]


def _victims(tmp_path) -> dict:
    """Files outside the output directory that a hostile output directory names."""
    v = tmp_path / "victims"
    v.mkdir()
    for name in ("victim.txt", "victim.nc", "absolute.txt", "in-linked-dir.png", "x.png"):
        (v / name).write_text("precious")
    return {p: p.read_bytes() for p in v.iterdir()}


@pytest.mark.parametrize("attack", ["batch.json", "summary.json", "figures-link", "subdir-link",
                                    "journal"])
def test_a_hostile_output_directory_cannot_touch_files_outside(tmp_path, fake_compare, attack):
    victims = _victims(tmp_path)
    vdir = tmp_path / "victims"
    shutil.copy(ADHESIVE / "Tp150C.csv", tmp_path / "a.csv")
    out = tmp_path / "out"
    sub = out / "a"
    sub.mkdir(parents=True)
    if attack == "batch.json":
        (sub / "batch.json").write_text(json.dumps(
            {"format": 1, "status": "ok", "task": {},
             "files": ["../../victims/victim.txt", str(vdir / "absolute.txt")]}))
    elif attack == "summary.json":
        (sub / "summary.json").write_text(json.dumps(
            {"structures": [{"name": "../../victims/victim"}, {"name": str(vdir / "victim")}]}))
    elif attack == "figures-link":
        (sub / "figures").symlink_to(vdir)
    elif attack == "subdir-link":
        sub.rmdir()
        sub.symlink_to(vdir)
    else:
        (sub / ".bayesfo-staging-x" / "new").mkdir(parents=True)
        (sub / outdir.JOURNAL).write_text(json.dumps(
            {"staging": "../../victims", "old": ["../victims/victim.txt"], "new": []}))
    res = run_batch(expand_inputs([tmp_path / "a.csv"], options={"structures": "voigt"}),
                    out, workers=1, progress=False, write_combined=False)
    assert res.outcomes[0].status == "ok"
    assert {p: p.read_bytes() for p in vdir.iterdir()} == victims
    assert not sub.is_symlink() and (sub / "figures" / "bode.png").read_bytes() == b"png"
    assert json.loads((sub / "batch.json").read_text())["files"] == [
        "figures/bode.png", "summary.json", "voigt.nc"]


def test_a_bad_temperature_line_fails_only_its_data_set(tmp_path, fake_compare):
    shutil.copy(ADHESIVE / "Tp150C.csv", tmp_path / "a.csv")
    text = (ADHESIVE / "Tp150C.csv").read_text()
    (tmp_path / "b.csv").write_text("# temperature: warm\n" + text)
    res = run_batch(expand_inputs([tmp_path]), tmp_path / "out", workers=1, progress=False,
                    write_combined=False)
    assert [(o.dataset.id, o.status) for o in res.outcomes] == [("a", "ok"),
                                                               ("b", "input_error")]
    assert res.outcomes[1].error.startswith(f"file '{tmp_path / 'b.csv'}', line 1: '# temperat")
    assert res.exit_status == 2
    assert (tmp_path / "out" / "b" / "error.txt").read_text().startswith("file ")


# ---------------------------------------------------------------------- dead batch workers
def crashing_task(task):
    """A task whose worker dies (as if killed) for the data set 'crash'."""
    if task["id"] == "crash":
        os.kill(os.getpid(), signal.SIGKILL)
    return {"id": task["id"], "status": "ok"}


def test_one_dead_worker_fails_only_its_data_set(tmp_path):
    from bayesfo.batch import DataSet

    todo = [DataSet(name, "x.csv", {}, 0) for name in ("a", "crash", "b", "c")]
    results = {}
    _run_processes(todo, 2, lambda ds, r: results.setdefault(ds.id, r), task=crashing_task)
    assert {k: r["status"] for k, r in results.items()} == {
        "a": "ok", "b": "ok", "c": "ok", "crash": "internal_error"}
    assert "its worker process died in each of three attempts" in results["crash"]["error"]


# ---------------------------------------------------------------------- signals
def _earlier_run(tmp_path) -> tuple[Path, dict]:
    """An output directory holding (stand-ins for) an earlier run's files, and its tree."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text('{"structures": [{"name": "voigt"}]}')
    (out / "voigt.nc").write_text("earlier")
    return out, _tree(out)


def _assert_one_line_end(stderr: str) -> None:
    # Warnings of the run may come first; the end is one line, and no worker speaks.
    lines = stderr.strip().splitlines()
    assert all(line.startswith("bayesfo: ") for line in lines), stderr
    assert lines[-1].endswith("(no output is left half-written)")


def _has_loaded(proc, name: str) -> bool:
    try:
        return any(name in m.path for m in psutil.Process(proc.pid).memory_maps())
    except psutil.Error:
        return False


def _cpu_seconds(proc) -> float:
    """CPU time the process has used (its own, not its children's)."""
    try:
        t = psutil.Process(proc.pid).cpu_times()
        return t.user + t.system
    except psutil.Error:
        return float("inf")


def _cli(*args, cwd):
    # A test suite started in the background of a shell without job control (`cmd &` in a
    # script) has SIGINT ignored, which the command would inherit (an ignored signal stays
    # ignored across exec): the suite's own handler is put back, so that the command starts as
    # under a terminal, and the signal tests test the command, not how the suite was started.
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.Popen([sys.executable, "-m", "bayesfo.cli", *map(str, args)], cwd=cwd,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


#: Seconds after which a command that should have ended is taken to hang: only a bound, never a
#: speed (a busy machine may take many times the quiet one).
HANG = 120.0


def _wait_for(condition, timeout=HANG):
    t0 = time.monotonic()
    while not condition():
        if time.monotonic() - t0 > timeout:
            raise AssertionError("the awaited moment never came")
        time.sleep(0.05)


def _workers(proc) -> list:
    """The command's worker processes: spawned ones, and forked ones (which keep the command's
    own command line; bayesfo.parallel.new_pool)."""
    try:
        parent = psutil.Process(proc.pid)
        own = parent.cmdline()
        return [c for c in parent.children(recursive=True)
                if "spawn_main" in " ".join(c.cmdline()) or c.cmdline() == own]
    except psutil.Error:
        return []


@pytest.mark.parametrize("sig, moment, status", [
    (signal.SIGINT, "sampling", 130), (signal.SIGTERM, "sampling", 143),
    (signal.SIGTERM, "writing", 143), (signal.SIGKILL, "writing", -9)])
def test_a_signal_ends_compare_and_its_workers_leaving_the_earlier_output(
        tmp_path, sig, moment, status):
    out, before = _earlier_run(tmp_path)
    proc = _cli("compare", ADHESIVE / "Tp020C.csv", "--structures", "voigt,zener",
                "--workers", "2", "--out", out, "--quiet", cwd=tmp_path)
    if moment == "sampling":
        _wait_for(lambda: len(_workers(proc)) == 2)
        time.sleep(0.5)
    else:
        _wait_for(lambda: any(out.glob(".bayesfo-staging-*/new/*")))
    workers = _workers(proc)
    proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=HANG)
    assert proc.returncode == status
    gone, alive = psutil.wait_procs(workers, timeout=HANG)
    assert not alive
    if sig != signal.SIGKILL:
        _assert_one_line_end(stderr)
    outdir.recover(out)  # what the next run into the directory does first
    assert _tree(out) == before


@pytest.mark.parametrize("sig, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
@pytest.mark.parametrize("moment", ["here", "workers"])
def test_a_signal_ends_the_automatic_schedule_leaving_the_earlier_output(
        tmp_path, sig, status, moment):
    # The default schedule (--workers 0): quick posteriors in the command's own process, worker
    # processes only for the long routes. The Maxwell's posterior takes the ladder (seconds): it
    # starts the workers.
    out, before = _earlier_run(tmp_path)
    structures = "voigt,zener" if moment == "here" else "maxwell,voigt"
    proc = _cli("compare", ADHESIVE / "Tp020C.csv", "--structures", structures, "--out", out,
                "--quiet", "--no-figures", cwd=tmp_path)
    if moment == "here":
        # The command has imported its libraries (netCDF-C's is mapped among the last; signals
        # are held back meanwhile) and computed since for half a second of its own CPU time
        # (not wall-clock time: a busy machine changes nothing).
        _wait_for(lambda: _has_loaded(proc, "libnetcdf"))
        loaded = _cpu_seconds(proc)
        _wait_for(lambda: _cpu_seconds(proc) > loaded + 0.5)
    else:
        _wait_for(lambda: len(_workers(proc)) >= 1)
        time.sleep(0.5)
    assert proc.poll() is None, "the command ended before the signal"
    workers = _workers(proc)
    proc.send_signal(sig)
    _, stderr = proc.communicate(timeout=HANG)
    assert proc.returncode == status, stderr
    _, alive = psutil.wait_procs(workers, timeout=HANG)
    assert not alive
    _assert_one_line_end(stderr)
    outdir.recover(out)
    assert _tree(out) == before


def test_output_directory_that_is_a_file_is_refused_before_work(tmp_path, run_cli, monkeypatch):
    import bayesfo.cli.compare

    def work(*args, **kwargs):  # reached only if the check came after the work began
        raise AssertionError("the comparison started")

    monkeypatch.setattr(bayesfo.cli.compare, "_compare", work)
    (tmp_path / "taken").write_text("x")
    status, _, err = run_cli("compare", ADHESIVE / "Tp020C.csv", "--out", tmp_path / "taken")
    assert status == 2
    assert err == f"bayesfo: error: --out '{tmp_path / 'taken'}' is a file, not a directory; " \
                  "give a directory\n"
    status, _, err = run_cli("batch", ADHESIVE / "Tp020C.csv", "--out", tmp_path / "taken" / "x")
    assert status == 2 and "--out" in err and "a part of the path is a file" in err


@pytest.mark.parametrize("sig, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_ends_batch_and_its_workers(tmp_path, sig, status):
    for name in ("Tp020C", "Tp150C"):
        shutil.copy(ADHESIVE / f"{name}.csv", tmp_path / f"{name}.csv")
    out = tmp_path / "out"
    proc = _cli("batch", tmp_path / "Tp020C.csv", tmp_path / "Tp150C.csv", "--structures",
                "voigt,zener", "--workers", "2", "--out", out, "--quiet", "--no-figures",
                cwd=tmp_path)
    _wait_for(lambda: len(_workers(proc)) == 2)
    time.sleep(0.5)
    workers = _workers(proc)
    proc.send_signal(sig)
    _, stderr = proc.communicate(timeout=HANG)
    assert proc.returncode == status
    assert not psutil.wait_procs(workers, timeout=HANG)[1]
    assert stderr.strip().splitlines()[-1].endswith("(no output is left half-written)")
    assert "Traceback" not in stderr
    assert not list(out.rglob(".bayesfo-staging-*"))


# ---------------------------------------------------------------------- arguments and numbers
@pytest.mark.parametrize("argv, message", [
    (["compare", "x.csv", "--seed", "-1"],
     "argument --seed: expected an integer from 0 to 4294967295, got '-1'"),
    (["batch", "x.csv", "--out", "o", "--seed", str(2**32)],
     "argument --seed: expected an integer from 0 to 4294967295, got '4294967296'"),
    (["compare", str(ADHESIVE / "Tp020C.csv"), "--prior", "q=uniform:0:1", "--prior",
      "q=uniform:0.2:1"],
     "--prior 'q=uniform:0.2:1': a prior for 'q' is already given; give one --prior per "
     "parameter"),
])
def test_bad_arguments_are_one_line_errors(run_cli, argv, message):
    status, out, err = run_cli(*argv)
    assert status == 2 and out == ""
    assert err.startswith(f"bayesfo: error: {message}") and err.count("\n") == 1


def test_a_pipe_is_not_a_data_file(tmp_path, run_cli):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    status, _, err = run_cli("batch", fifo, "--out", tmp_path / "out")
    assert status == 2
    assert err == (f"bayesfo: error: INPUT '{fifo}': not a regular file (a pipe, device or "
                   "socket); give a CSV file, a directory or a pattern\n")


def test_undefined_criteria_are_empty_cells_and_rank_last(comparison):
    from bayesfo.comparison.criteria import _frequencies
    from bayesfo.comparison.table import number, ranking_lines
    from bayesfo.output import ranking_csv

    voigt, zener = comparison.results
    broken = dataclasses.replace(zener, criteria=dataclasses.replace(
        zener.criteria, loo=np.nan, loo_se=np.nan, pareto_k_max=np.inf))
    fake = dataclasses.replace(comparison, results=(voigt, broken))
    rows = {r["structure"]: r for r in fake.table()}
    assert rows["zener"]["rank_loo"] == 2 and rows["voigt"]["rank_loo"] == 1
    assert rows["voigt"]["delta_loo"] == 0.0
    text = ranking_csv(fake)
    assert "nan" not in text.lower() and "inf" not in text.lower()
    header, *lines = [line.split(",") for line in text.splitlines()]
    zrow = dict(zip(header, next(li for li in lines if li[1] == "zener"), strict=True))
    assert zrow["loo"] == zrow["loo_se"] == zrow["pareto_k_max"] == ""
    assert number(np.nan) == "-" and number(None) == "-" and number(1.234) == "1.23"
    header, *table = ranking_lines(fake.table())
    elpd = header.index("elpd_loo") + len("elpd_loo")
    assert next(li for li in table if " zener " in li)[elpd - 1] == "-"
    assert _frequencies(np.arange(1.0, 201.0)) == "omega = 1, 2, 3, 4, 5, 6 and 194 more rad/s"
    assert _frequencies(np.array([0.5, 2.0])) == "omega = 0.5, 2 rad/s"


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::bayesfo.errors.ConvergenceWarning")
@pytest.mark.filterwarnings("ignore::bayesfo.errors.EvidenceWarning")
@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
@pytest.mark.filterwarnings("ignore::bayesfo.errors.DataWarning")  # parts not KK-consistent
def test_a_hopeless_misfit_gives_reasons_not_nan(tmp_path, run_cli):
    """The integer Voigt on the NREL master curve (26 decades): its PSIS-LOO is undefined."""
    status, out, err = run_cli("compare", ROOT / "examples" / "data" / "nrel_dma_master.csv",
                               "--structures", "voigt-int", "--no-figures", "--workers", "1",
                               "--out", tmp_path / "out")
    assert status == 0
    # The warnings are filtered here (pytest turns them into errors); the table shows '-'.
    assert "nan" not in (tmp_path / "out" / "ranking.csv").read_text().lower()
    assert "nan" not in out.lower()
    s = json.loads((tmp_path / "out" / "summary.json").read_text())["structures"][0]
    assert s["loo"] is None and any(w.startswith("voigt-int: LOO cannot be computed: the "
                                                 "pointwise log-likelihood varies by")
                                    for w in s["warnings"])


# ---------------------------------------------------------------------- bad input in the shared layers
def test_a_manifest_cell_too_long_is_named(tmp_path, run_cli):
    manifest = tmp_path / "m.csv"
    manifest.write_text("path,id\n" + "x" * 200_000 + ",a\n")
    status, _, err = run_cli("batch", "--manifest", manifest, "--out", tmp_path / "out")
    assert status == 2 and err.count("\n") == 1
    assert err.startswith(f"bayesfo: error: manifest '{manifest}', line 2: a cell has more than")


def test_identify_loop_names_a_bad_q_once(run_cli):
    status, _, err = run_cli("identify", ADHESIVE / "Tp020C.csv", "--structure", "max3",
                             "--q", "1.7")
    assert status == 2 and err.count("\n") == 1
    assert "argument 'q' = 1.7 is outside the prior" in err


@pytest.mark.parametrize("argv, message", [
    (["--holdout", "1_0"], "--holdout takes comma-separated numbers"),
    (["--prior", "q=uniform:0:1_0"], "the bounds must be numbers"),
])
def test_numbers_in_options_are_plain_decimals(run_cli, argv, message):
    status, _, err = run_cli("compare", ADHESIVE / "Tp020C.csv", *argv)
    assert status == 2 and message in err and err.count("\n") == 1


def test_the_api_refuses_what_the_samplers_cannot_handle():
    from bayesfo.data import MAX_FREQUENCIES
    from bayesfo.errors import InputError

    w = np.logspace(-2, 2, 25)
    g = get_structure("voigt").response([1.0, 1e-3, 0.5], w, "compliance")
    g[3] = 0
    with pytest.raises(InputError, match=r"the response is exactly 0 at omega = 0.03162 rad/s, where relative noise"):
        compare(FrequencyResponse(w, g, kind="compliance"), "voigt", workers=1, progress=False)
    many = np.logspace(-3, 3, MAX_FREQUENCIES + 1)
    g = get_structure("voigt").response([1.0, 1e-3, 0.5], many, "compliance")
    with pytest.raises(InputError, match=f"{MAX_FREQUENCIES + 1} frequencies, more than"):
        compare(FrequencyResponse(many, g, kind="compliance"), "voigt", workers=1,
                progress=False)


_KILLED_MID_SWAP = """
import os, sys
from pathlib import Path
import bayesfo.outdir as outdir

out = Path(sys.argv[1])
real = os.replace

def die(src, dst):  # the old run's entries are moved aside; the new one's never arrive
    if (out / outdir.JOURNAL).exists() and Path(src).parent.name == "new":
        os._exit(9)
    return real(src, dst)

outdir.os.replace = die
with outdir.staged_run(out) as stage:
    (stage / "summary.json").write_text("second")
    (stage / "figures").mkdir()
    (stage / "figures" / "b.png").write_text("b")
"""


def test_a_run_killed_mid_swap_is_completed_by_the_next_check_and_by_load(tmp_path):
    out = tmp_path / "out"
    with outdir.staged_run(out) as stage:
        (stage / "summary.json").write_text("first")
        (stage / "figures").mkdir()
        (stage / "figures" / "a.png").write_text("a")
    done = subprocess.run([sys.executable, "-c", _KILLED_MID_SWAP, str(out)],
                          capture_output=True, text=True, timeout=HANG)
    assert done.returncode == 9, done.stderr
    assert not (out / "summary.json").exists()  # the swap stopped half-way
    # The next run's check completes the swap instead of refusing a 'figures' it cannot place.
    assert outdir.check_output_directory(out, directories=("figures",)) == out
    assert (out / "summary.json").read_text() == "second"
    assert sorted(p.name for p in (out / "figures").iterdir()) == ["b.png"]
    assert not list(out.glob(".bayesfo-staging-*"))


def test_load_refuses_a_record_nested_too_deeply(tmp_path):
    from bayesfo.comparison import load
    from bayesfo.errors import InputError

    out = tmp_path / "out"
    with outdir.staged_run(out) as stage:
        (stage / "summary.json").write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(InputError, match="nested too deeply"):
        load(out)


@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_load_refuses_a_netcdf_of_another_run(tmp_path):
    from bayesfo.comparison import load
    from bayesfo.errors import InputError

    data = FrequencyResponse(*_zener_points(), kind="modulus", units="Pa")
    runs = {}
    for seed in (1, 2):
        out = tmp_path / f"run{seed}"
        write_outputs(compare(data, "voigt", seed=seed, workers=1, progress=False), out,
                      figures=False)
        runs[seed] = out
    assert load(runs[1]).ranking == ["voigt"]  # as written: fine
    shutil.copy(runs[2] / "voigt.nc", runs[1] / "voigt.nc")  # the other run's posterior
    with pytest.raises(InputError, match="voigt.nc' is not the file that the run which wrote"):
        load(runs[1])


def _zener_points():
    from bayesfo.structures import get_structure

    w = np.logspace(-1, 2, 20)
    g = get_structure("zener").response([10.0, 1.0, 0.1, 0.6], w, "modulus")
    rng = np.random.default_rng(0)
    return w, g * (1 + 0.01 * (rng.normal(size=w.size) + 1j * rng.normal(size=w.size)))


def test_an_unreadable_record_leaves_the_earlier_files_in_place_and_says_so(tmp_path):
    """With the earlier run's manifest corrupt, its files cannot be told from a user's: a run
    with fewer structures leaves them in place (nothing a user made is lost) and warns, naming
    them; with the manifest intact they are removed as that run's."""
    import warnings

    from bayesfo.outdir import MANIFEST, staged_run

    def run(out, names):
        with staged_run(out) as stage:
            for name in names:
                (stage / name).write_text(name)

    for corrupt in (False, True):
        out = tmp_path / f"out{corrupt}"
        run(out, ["summary.json", "voigt.nc", "zener.nc"])
        if corrupt:
            (out / MANIFEST).write_text("{not json")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            run(out, ["summary.json", "voigt.nc"])
        messages = [str(w.message) for w in caught]
        assert (out / "zener.nc").exists() == corrupt
        assert any("is unreadable" in m and "'zener.nc' left in place" in m
                   for m in messages) == corrupt
        assert (out / "voigt.nc").read_text() == "voigt.nc"
