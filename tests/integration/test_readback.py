"""What reads an output directory back (``load``, ``predict``, ``export``) and what writes a file
the user named (``--out``, ``--figure``) (issue 65): no node the user named is replaced (a FIFO,
a symbolic link, a device), nothing is deleted or renamed by a reader, each posterior is the
one its summary describes, and what cannot be trusted is refused with one line.

Two small comparisons (zener and voigt on the adhesive at 20 °C and at 10 °C), about 10 s.
"""

from __future__ import annotations

import json
import os
import shutil
import threading
import warnings
from pathlib import Path

import pytest

import bayesfo as bf
from bayesfo.errors import InputError

DATA = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp"


def _run(tmp_path_factory, name: str, seed: int):
    out = tmp_path_factory.mktemp(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = bf.compare(bf.read(DATA / f"{name}.csv"), "zener,voigt", workers=1,
                            progress=False, seed=seed)
    bf.write_outputs(result, out, figures=False)
    return out


@pytest.fixture(scope="module")
def cmp1(tmp_path_factory):
    return _run(tmp_path_factory, "Tp020C", 1)


@pytest.fixture(scope="module")
def cmp2(tmp_path_factory):
    return _run(tmp_path_factory, "Tp010C", 2)


def _copy(src: Path, dst: Path) -> Path:
    """A copy of the output directory with its manifest (as ``cp -a`` makes)."""
    shutil.copytree(src, dst)
    return dst


# ---------------------------------------------------------------- 1: the files the user names
def _read_fifo(path: Path, into: list) -> threading.Thread:
    def read():
        with open(path, "rb") as f:
            into.append(f.read())

    thread = threading.Thread(target=read, daemon=True)
    thread.start()
    return thread


@pytest.mark.parametrize("command", ["export", "predict"])
def test_a_fifo_named_by_out_is_written_into_not_replaced(cmp1, tmp_path, run_cli, command):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got: list = []
    reader = _read_fifo(fifo, got)
    args = (["export", cmp1, "--format", "csv"] if command == "export" else
            ["predict", cmp1, "--quantity", "storage", "--omega", "1,10"])
    status, _, err = run_cli(*args, "--out", fifo)
    reader.join(10)
    assert status == 0, err
    assert fifo.is_fifo()  # still the FIFO, not a regular file in its place
    assert got and got[0].startswith(b"# ")


def test_a_symbolic_link_named_by_out_or_figure_stays_a_link(cmp1, tmp_path, run_cli):
    target, link = tmp_path / "series.csv", tmp_path / "link.csv"
    target.write_text("old\n")
    link.symlink_to(target.name)
    picture, plink = tmp_path / "p.png", tmp_path / "plink.png"
    picture.write_bytes(b"")
    plink.symlink_to(picture.name)
    status, _, err = run_cli("export", cmp1, "--format", "csv", "--out", link,
                             "--figure", plink)
    assert status == 0, err
    assert link.is_symlink() and plink.is_symlink()
    assert target.read_text().startswith("# Prony series")
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # A link that leads nowhere is refused: writing through it would make a file elsewhere.
    dangling = tmp_path / "dangling.csv"
    dangling.symlink_to(tmp_path / "nowhere" / "x.csv")
    status, _, err = run_cli("predict", cmp1, "--quantity", "storage", "--omega", "1",
                             "--out", dangling)
    assert status == 2 and err.count("\n") == 1
    assert "symbolic link" in err and "does not exist" in err
    assert dangling.is_symlink() and not (tmp_path / "nowhere").exists()


def test_out_dash_writes_to_standard_output(cmp1, run_cli):
    status, out, err = run_cli("export", cmp1, "--format", "csv", "--out", "-")
    assert status == 0, err
    assert out.startswith("# Prony series") and "tau_s,g_i" in out
    assert "wrote standard output" in err and "terms of" not in out
    assert not Path("-").exists()
    status, out, err = run_cli("predict", cmp1, "--quantity", "loss", "--omega", "1,10",
                               "--out", "-")
    assert status == 0, err
    assert out.splitlines()[2] == "x_rad_per_s,median,hdi_low,hdi_high,extrapolated"
    assert not Path("-").exists()


# ---------------------------------------------------------------- 9: design --figure
def test_design_figure_that_cannot_be_written_is_one_line(cmp1, tmp_path, run_cli):
    folder = tmp_path / "d.png"
    folder.mkdir()
    status, _, err = run_cli("design", cmp1, "--figure", folder)
    assert status == 2 and err.count("\n") == 1 and "is a directory" in err
    assert folder.is_dir() and not any(folder.iterdir())
    if Path("/sys").is_dir():  # not writable, even by root
        status, _, err = run_cli("design", cmp1, "--figure", "/sys/design.png")
        assert status == 2 and err.count("\n") == 1
        assert "--figure '/sys/design.png': cannot be written" in err


# ---------------------------------------------------------------- 2: readers never move files
def test_a_reader_never_completes_a_swap(cmp1, tmp_path, run_cli):
    d = _copy(cmp1, tmp_path / "run")
    mine = d / "mine.nc"  # a file of the user's, which no manifest lists
    mine.write_bytes(b"mine")
    staging = d / ".bayesfo-staging-0123456789ab"
    (staging / "new").mkdir(parents=True)
    (d / ".bayesfo-swap.json").write_text(json.dumps(
        {"format": 1, "staging": staging.name, "old": ["mine.nc", "summary.json"],
         "new": []}))
    before = sorted(p.name for p in d.iterdir())
    status, _, err = run_cli("predict", d, "--quantity", "storage", "--omega", "1")
    assert status == 2 and err.count("\n") == 1
    assert "half-done move" in err and "run the command that wrote it again" in err
    assert mine.read_bytes() == b"mine" and (d / "summary.json").is_file()
    assert sorted(p.name for p in d.iterdir()) == before  # nothing deleted, renamed or made
    with pytest.raises(InputError, match="half-done move"):
        bf.load(d)


# ---------------------------------------------------------------- 3: one run's files only
def test_a_posterior_of_another_run_is_refused(cmp1, cmp2, tmp_path, run_cli):
    d = tmp_path / "mixed"
    d.mkdir()
    for f in cmp1.iterdir():  # "cp dir/* new/": the manifest stays behind
        if not f.name.startswith("."):
            shutil.copy(f, d)
    status, _, err = run_cli("predict", d, "--quantity", "storage", "--omega", "1",
                             "--average", "bma")
    assert status == 0, err
    shutil.copy(cmp2 / "zener.nc", d)  # the 10 °C posterior beside the 20 °C one
    status, _, err = run_cli("predict", d, "--quantity", "storage", "--omega", "1",
                             "--average", "bma")
    assert status == 2 and err.count("\n") == 1 and "zener.nc" in err
    shutil.copy(cmp2 / "voigt.nc", d)  # both posteriors of the other run, its summary not
    status, _, err = run_cli("export", d, "--format", "csv", "--out", tmp_path / "s.csv")
    assert status == 2 and err.count("\n") == 1
    assert "its draws are not those that" in err and "summary.json" in err
    assert not (tmp_path / "s.csv").exists()


def test_the_summary_records_a_digest_of_each_posterior(cmp1):
    summary = json.loads((cmp1 / "summary.json").read_text())
    loaded = bf.load(cmp1)
    for s, r in zip(summary["structures"], loaded.results, strict=True):
        assert len(s["draws_sha256"]) == 64
        assert r.to_dict()["draws_sha256"] == s["draws_sha256"]


# ---------------------------------------------------------------- 4, 17: what a NetCDF holds
def _without_manifest(src: Path, dst: Path) -> Path:
    dst.mkdir()
    for f in src.iterdir():
        if not f.name.startswith("."):
            shutil.copy(f, dst)
    return dst


def test_only_the_variables_bayesfo_writes_are_read(cmp1, tmp_path):
    h5py = pytest.importorskip("h5py")
    d = _without_manifest(cmp1, tmp_path / "run")
    with h5py.File(d / "zener.nc", "a") as f:
        f["posterior"].create_dataset("extra", data=[[1.0] * 500] * 4)
    loaded = bf.load(d)
    tree = loaded.results[[r.name for r in loaded.results].index("zener")].posterior.idata
    assert "extra" not in tree.posterior and "a1" in tree.posterior


def test_external_hdf5_storage_is_refused(cmp1, tmp_path):
    h5py = pytest.importorskip("h5py")
    secret = tmp_path / "secret.txt"
    secret.write_bytes(b"s3cr3t!!" * 4)
    d = _without_manifest(cmp1, tmp_path / "run")
    with h5py.File(d / "zener.nc", "a") as f:
        f["posterior"].create_dataset("leak", shape=(4,), dtype="f8",
                                      external=[(str(secret), 0, 32)])
    with pytest.raises(InputError, match="'posterior/leak' is stored in other files") as exc:
        bf.load(d)
    assert "s3cr3t" not in str(exc.value) and "\n" not in str(exc.value)


def test_a_variable_larger_than_declared_is_refused_before_it_is_read(tmp_path):
    netCDF4 = pytest.importorskip("netCDF4")
    from bayesfo.inference._arviz import open_tree

    path = tmp_path / "big.nc"
    with netCDF4.Dataset(path, "w") as nc:
        g = nc.createGroup("posterior")
        g.createDimension("chain", 4)
        g.createDimension("draw", 125_000_000)  # 5e8 values declared, none written
        g.createVariable("a1", "f8", ("chain", "draw"), zlib=True, chunksizes=(1, 1_000_000))
    assert path.stat().st_size < 1_000_000
    with pytest.raises(ValueError, match="'posterior/a1' has 125000000 values along 'draw'"):
        open_tree(path, {"posterior": ["a1"]}, {"chain": None, "draw": 500, "omega": 17,
                                                "draws": 2000})
    with pytest.raises(ValueError, match="500000000 values, more than the 1000"):
        open_tree(path, {"posterior": ["a1"]}, None, 1000)


# ---------------------------------------------------------------- 13, 14, 18, 21: records
def _cli(*argv, timeout=60):
    import subprocess
    import sys

    env = dict(os.environ, PYTHONPATH=str(Path(__file__).parents[2]), MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", "bayesfo.cli", *map(str, argv)],
                          capture_output=True, text=True, timeout=timeout, env=env)


@pytest.mark.parametrize("record", [".bayesfo-run.json", ".bayesfo-swap.json"])
@pytest.mark.parametrize("kind", ["fifo", "zero"])
def test_a_record_that_is_not_a_file_is_refused_not_read(cmp1, tmp_path, record, kind):
    d = _copy(cmp1, tmp_path / "run")
    (d / record).unlink(missing_ok=True)
    if kind == "fifo":
        os.mkfifo(d / record)
    else:
        (d / record).symlink_to("/dev/zero")
    done = _cli("predict", d, "--quantity", "storage", "--omega", "1", timeout=30)
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and record in done.stderr
    assert os.path.lexists(d / record)  # left as it was


def test_a_damaged_manifest_is_said_not_ignored(cmp1, tmp_path, run_cli):
    d = _copy(cmp1, tmp_path / "run")
    (d / ".bayesfo-run.json").write_text("{not json")
    (d / "ranking.csv").write_text("changed")
    status, _, err = run_cli("predict", d, "--quantity", "storage", "--omega", "1")
    assert status == 2 and err.count("\n") == 1
    assert ".bayesfo-run.json' (the record of the run" in err and "damaged" in err


def test_a_summary_too_large_is_refused_before_it_is_read(cmp1, tmp_path):
    d = _without_manifest(cmp1, tmp_path / "run")
    with open(d / "summary.json", "r+b") as f:
        f.truncate(65 * 1024 * 1024)  # sparse: no disk space taken
    with pytest.raises(InputError, match=r"summary.json': 68157440 bytes, more than the"):
        bf.load(d)


# ---------------------------------------------------------------- 8, 10: design's window
def test_design_proposes_no_frequency_far_beyond_the_data(cmp1, run_cli):
    omega = bf.load(cmp1).data.omega
    for window in ("1e-6,1e6", "1e-300,1e300"):
        status, out, err = run_cli("design", cmp1, "--window", window, "--json")
        assert status == 0, err
        plan = json.loads(out)
        low, high = plan["window"]
        assert low >= omega.min() / 1e3 * (1 - 1e-8) and high <= omega.max() * 1e3 * (1 + 1e-8)
        assert all(low <= p["omega"] <= high for p in plan["proposed"])
        assert any("is cut to" in n for n in plan["notes"])
    status, out, err = run_cli("design", cmp1, "--cost", "low-frequency", "--window",
                               "1e-30,1e30")
    assert status == 0, err
    assert "3 decades beyond the measured frequencies at most" in out
    status, _, err = run_cli("design", cmp1, "--window", "1e10,1e30")
    assert status == 2 and err.count("\n") == 1
    assert err.startswith("bayesfo: error: --window (1e+10, 1e+30) lies wholly more than 3 decades")


# ---------------------------------------------------------------- 11, 20: tampered summaries
@pytest.fixture(scope="module")
def master(tmp_path_factory):
    """The master curve of zener over the adhesive at 10 and 20 °C (about 10 s)."""
    from bayesfo.cli import main

    out = tmp_path_factory.mktemp("master")
    status = main(["mastercurve", str(DATA / "Tp010C.csv"), str(DATA / "Tp020C.csv"),
                   "--structures", "zener", "--no-figures", "--workers", "1", "--out", str(out)])
    assert status == 0
    return out


def _tamper(src: Path, dst: Path, change) -> Path:
    d = _without_manifest(src, dst)
    summary = json.loads((d / "summary.json").read_text())
    change(summary)
    (d / "summary.json").write_text(json.dumps(summary))
    return d


@pytest.mark.parametrize("change, message", [
    (lambda s: s.update(laws=None), "'laws' is not a table of shift laws"),
    (lambda s: s.update(laws="wlf"), "'laws' is not a table of shift laws"),
    (lambda s: s["laws"]["wlf"].update(probability=float("nan")),
     "'laws' is not a table of shift laws"),
    (lambda s: s.update(tts_checks=None), "'tts_checks' is not a table of checks"),
    (lambda s: s.update(vertical="bogus"), "'vertical' is 'bogus', not one of none"),
    (lambda s: s["posterior"].update(noise="bogus"), "the noise model of 'zener' is 'bogus'"),
    (lambda s: s.update(reference_temperature=15.0),
     "the reference temperature 15.0 is not among the isotherms' temperatures"),
])
def test_a_tampered_master_summary_is_refused_at_load(master, tmp_path, run_cli, change,
                                                      message):
    d = _tamper(master, tmp_path / "run", change)
    with pytest.raises(InputError, match=message):
        bf.load(d)
    status, _, err = run_cli("export", d, "--format", "csv", "--out", tmp_path / "s.csv")
    assert status == 2 and err.count("\n") == 1 and "edited?" in err
    assert not (tmp_path / "s.csv").exists()


def test_shift_draws_beyond_any_run_are_refused(master, tmp_path):
    h5py = pytest.importorskip("h5py")
    d = _without_manifest(master, tmp_path / "run")
    summary = json.loads((d / "summary.json").read_text())
    summary["posterior"].pop("draws_sha256")  # as a run of an earlier version wrote it
    (d / "summary.json").write_text(json.dumps(summary))
    name = next(k for k in summary["posterior"]["parameters"] if k.startswith("log10_aT"))
    with h5py.File(d / "zener.nc", "a") as f:
        f["posterior"][name][0, 0] = 1e300
    with pytest.raises(InputError, match="shift draws of log10 a_T that are not finite or "
                                         "beyond"):
        bf.load(d)
    with h5py.File(d / "zener.nc", "a") as f:
        f["posterior"][name][0, 0] = float("nan")
    with pytest.raises(InputError, match="draws that are not finite numbers"):
        bf.load(d)


@pytest.mark.parametrize("change, message", [
    (lambda s: s["structures"][0].update(posterior_probability=float("nan")),
     "posterior probability of '.*' is nan, not a number from 0 to 1"),
    (lambda s: s["structures"][1].update(noise="bogus"), "noise model of '.*' is 'bogus'"),
    (lambda s: s["structures"].append(s["structures"][0]), "is listed twice"),
    (lambda s: s["data"].update(n_frequencies="17"), "'n_frequencies' is '17', not a whole"),
])
def test_a_tampered_comparison_summary_is_refused_at_load(cmp1, tmp_path, change, message):
    d = _tamper(cmp1, tmp_path / "run", change)
    with pytest.raises(InputError, match=message):
        bf.load(d)


# ---------------------------------------------------------------- 12: Ctrl-C while loading
def test_import_bayesfo_loads_neither_numpy_nor_scipy():
    import subprocess
    import sys

    code = ("import sys, bayesfo; "
            "sys.exit(sum(m in sys.modules for m in ('numpy', 'scipy', 'importlib.metadata')))")
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).parents[2]))
    assert subprocess.run([sys.executable, "-c", code], env=env, timeout=60).returncode == 0


@pytest.mark.parametrize("delay", [0.25, 0.45, 0.7, 1.0])
def test_ctrl_c_while_export_loads_its_libraries_is_one_line(cmp1, tmp_path, delay):
    """The libraries load in the first second or so: a Ctrl-C then gave 30 to 50 lines of
    traceback (it came while ``import bayesfo`` loaded scipy, before the command line's own
    handling). Before ~0.1 s the interpreter itself is starting (its own traceback)."""
    import signal
    import subprocess
    import sys
    import time

    import psutil

    env = dict(os.environ, PYTHONPATH=str(Path(__file__).parents[2]), MPLBACKEND="Agg")
    p = subprocess.Popen([sys.executable, "-m", "bayesfo.cli", "export", str(cmp1), "--format",
                          "csv", "--out", str(tmp_path / "s.csv")], cwd=tmp_path, env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    # The signal comes after ``delay`` seconds of the process's own CPU time, not of the
    # clock: on a busy machine a wall-clock delay may end while the interpreter still starts.
    proc = psutil.Process(p.pid)
    while p.poll() is None:
        try:
            used = sum(proc.cpu_times()[:2])
        except psutil.NoSuchProcess:
            break
        if used >= delay:
            break
        time.sleep(0.005)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert "Traceback" not in err and err.count("\n") <= 1, err
    if p.returncode not in (0,):  # 0: it had finished before the signal came
        assert err == "bayesfo: interrupted (no output is left half-written)\n"


def test_a_writer_never_opens_a_record_that_is_not_a_file(tmp_path):
    """A FIFO as the manifest and as the journal: mastercurve --out (any run into the
    directory) hung on reading them."""
    import subprocess
    import sys

    out = tmp_path / "out"
    out.mkdir()
    os.mkfifo(out / ".bayesfo-run.json")
    os.mkfifo(out / ".bayesfo-swap.json")
    code = ("import sys, warnings; from bayesfo.outdir import staged_run\n"
            "warnings.simplefilter('ignore')\n"
            "with staged_run(sys.argv[1]) as stage:\n"
            "    (stage / 'summary.json').write_text('{}')\n")
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).parents[2]))
    done = subprocess.run([sys.executable, "-c", code, str(out)], env=env, timeout=30,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert (out / "summary.json").read_text() == "{}"
    assert json.loads((out / ".bayesfo-run.json").read_text())["entries"] == ["summary.json"]


# ---------------------------------------------------------------- 15: predict's memory
def test_predict_takes_the_times_in_chunks(cmp1, monkeypatch):
    """``--time 1e-6:1e6:100000`` held (250 draws, 100 000 times, 20 nodes) complex at once,
    22 GB; the times are now taken in chunks, the same band in memory that does not grow with
    their number (500 draws here, for speed)."""
    import tracemalloc

    import numpy as np

    from bayesfo.predictions import draws, functions

    monkeypatch.setattr(draws, "MAX_DRAWS", 500)
    result = bf.load(cmp1)
    x = np.logspace(-6, 6, 1200)
    tracemalloc.start()
    try:
        chunked = bf.predict(result, "relaxation_modulus", x, structure="zener")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 100e6, peak / 1e6  # one piece: about 400 MB
    monkeypatch.setattr(functions, "_X_CHUNK", 10**9)
    whole = bf.predict(result, "relaxation_modulus", x[:200], structure="zener")
    np.testing.assert_array_equal(chunked.median[:200], whole.median)
    np.testing.assert_array_equal(chunked.hdi_low[:200], whole.hdi_low)
    np.testing.assert_array_equal(chunked.values[:, :200], whole.values)
    monkeypatch.setattr(functions, "MAX_KEPT_VALUES", 1000)
    assert bf.predict(result, "storage", x, structure="zener").values is None


# ---------------------------------------------------------------- 19-21: messages
def test_g_inf_fitted_as_zero_is_not_said_to_be_asked_for(cmp1, tmp_path, run_cli):
    status, out, err = run_cli("export", cmp1, "--format", "csv", "--terms", "2", "--out",
                               tmp_path / "s.csv")
    assert status == 0, err
    assert "as asked" not in out and "g_inf was fitted as 0" in out
    status, out, err = run_cli("export", cmp1, "--format", "csv", "--terms", "2", "--liquid",
                               "--out", tmp_path / "s.csv")
    assert status == 0, err
    assert "note: g_inf = 0 as asked, where the model's long-time modulus is" in out


def test_a_figure_that_cannot_be_written_says_the_series_was(cmp1, tmp_path, run_cli):
    (tmp_path / "afile").write_text("")
    status, _, err = run_cli("export", cmp1, "--format", "csv", "--out", tmp_path / "s.csv",
                             "--figure", tmp_path / "afile" / "x.png")
    assert status == 2 and err.count("\n") == 1
    assert f"the series was written to '{tmp_path / 's.csv'}'" in err
    assert (tmp_path / "s.csv").read_text().startswith("# Prony series")


def test_a_reader_leaves_a_fifo_named_like_the_lock_in_place(cmp1, tmp_path, run_cli):
    d = _copy(cmp1, tmp_path / "run")
    os.mkfifo(d / ".bayesfo-lock")
    status, _, err = run_cli("predict", d, "--quantity", "storage", "--omega", "1")
    assert status == 0, err
    assert (d / ".bayesfo-lock").is_fifo()  # was removed as if it were the reader's own lock
