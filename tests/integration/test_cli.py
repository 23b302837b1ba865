"""The command line: contracts of identify, simulate, extract; exit statuses."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from bayesfo.data import FrequencyResponse
from bayesfo.studies import OMEGA, g_spec

EXAMPLES = Path(__file__).parents[2] / "examples" / "data"


@pytest.fixture
def gspec_csv(tmp_path):
    rng = np.random.default_rng(0)
    g = g_spec() + 1e-4 * (rng.normal(size=25) + 1j * rng.normal(size=25))
    return FrequencyResponse(OMEGA, g, kind="compliance").to_csv(tmp_path / "gspec.csv")


@pytest.mark.parametrize("method", ["1", "2", "3", "4", "5", "opt"])
def test_identify_json_contract_recovers_g_spec(run_cli, gspec_csv, method):
    status, out, err = run_cli("identify", gspec_csv, "--structure", "voigt", "--method", method, "--json")
    assert status == 0, err
    res = json.loads(out)
    assert {"structure", "method", "q", "a", "b", "rmse", "stable"} <= set(res)
    assert res["structure"] == "voigt" and res["method"] == method and res["stable"]
    assert res["a"][0] == 1.0 and len(res["a"]) == 2 and len(res["b"]) == 1
    np.testing.assert_allclose([res["a"][1], res["b"][0], res["q"]], [1.0, 1.0, 0.5], atol=0.02)
    assert res["rmse"] < 1e-4


def test_identify_with_fixed_q_and_human_output(run_cli, gspec_csv):
    status, out, _ = run_cli("identify", gspec_csv, "--structure", "zener", "--q", "0.5")
    assert status == 0 and "q = 0.5" in out and "RMSE" in out


@pytest.mark.parametrize(
    "argv, message",
    [
        (["identify", "{csv}", "--structure", "maxwell", "--method", "2"], "use --method opt"),
        (["identify", "{csv}", "--structure", "zenner"], "unknown structure 'zenner'"),
        (["identify", "{csv}", "--structure", "voigt", "--q", "1.5"], "outside the prior"),
        (["identify", "{csv}", "--structure", "voigt", "--method", "7"], "invalid choice"),
        (["identify", "{csv}"], "--structure"),
        (["simulate", "table-9.9"], "unknown study 'table-9.9'"),
        (["simulate", "table-3.2", "--runs", "1"], "at least 2"),
        (["extract", "missing.csv", "--out", "x.csv"], "does not exist"),
        (["inspect", "nope.csv"], "does not exist"),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_bad_input_exit_2_one_line(run_cli, gspec_csv, argv, message):
    status, _, err = run_cli(*[a.replace("{csv}", str(gspec_csv)) for a in argv])
    assert status == 2
    assert len(err.strip().splitlines()) == 1 and message in err and "Traceback" not in err


def test_simulate_json_contract(run_cli):
    status, out, _ = run_cli("simulate", "table-3.2", "--runs", "200", "--seed", "3", "--json")
    res = json.loads(out)
    assert status == 0 and res["study"] == "table-3.2" and res["runs"] == 200 and res["seed"] == 3
    assert set(res["methods"]) == {"1", "2", "3", "4", "5"}
    row = res["methods"]["2"]
    for key in ("mean_a", "var_a", "mean_b", "var_b", "mean_q", "var_q", "rmse_spec",
                "var_rmse_spec", "rmse_noise", "var_rmse_noise"):
        assert key in row
    assert abs(row["mean_a"][1] - res["thesis"]["2"]["mean_a"][1]) < 0.005
    assert row["mean_q"] == 0.5 and row["var_q"] == 0.0


def test_simulate_local_and_global_studies_quick(run_cli):
    status, out, _ = run_cli("simulate", "table-3.4", "--runs", "20", "--json")
    res = json.loads(out)
    assert status == 0 and len(res["methods"]) == 4
    for row in res["methods"].values():  # n = 1, m = 0: every initial vector reaches q = 0.5
        assert abs(row["mean_q"] - 0.5) < 0.01
    status, out, _ = run_cli("simulate", "table-a.7", "--runs", "4", "--json")
    res = json.loads(out)
    for key in ("opt-n1m0", "opt-n1m1"):  # Table A.7: q = 0.4998 for both
        assert abs(res["methods"][key]["mean_q"] - 0.5) < 0.01


def test_extract_bundled_sine_records(run_cli, tmp_path):
    records = sorted((EXAMPLES / "sine_records").glob("*.csv"))
    out_csv = tmp_path / "fr.csv"
    status, out, err = run_cli("extract", *records, "--out", out_csv)
    assert status == 0, err
    from bayesfo.data import read_csv

    fr = read_csv(out_csv)
    assert fr.n_frequencies == 5 and fr.sigma is not None
    # Records are 1/(1 + s^0.5) with noise sd 0.01 over many periods: within 5 sigma.
    assert np.all(np.abs(fr.response - g_spec(fr.omega)) < 5 * fr.sigma + 1e-3)
    assert (tmp_path / "fr_harmonics.csv").exists()
    # The command names both files it wrote, and every record's input is a clean sine.
    assert f"wrote {out_csv} and {tmp_path / 'fr_harmonics.csv'}" in out
    assert "untested" not in out and "note:" not in out


def test_identify_max_order_loop(run_cli, gspec_csv):
    status, out, err = run_cli("identify", gspec_csv, "--structure", "max2", "--method", "3", "--json")
    assert status == 0, err
    res = json.loads(out)
    names = [r["structure"] for r in res["structures"]]
    assert names == ["max-n1m0", "max-n1m1", "max-n2m0", "max-n2m1", "max-n2m2"]
    rmse = {r["structure"]: r["rmse"] for r in res["structures"]}
    assert res["best_by_rmse"] == min(rmse, key=rmse.get)
    # The true structure already fits to the noise level: RMSE ≈ sqrt(25·2e-8)/25 = 2.8e-5.
    assert rmse["max-n1m0"] < 4e-5


def test_models_option_before_or_after_the_command(tmp_path, run_cli):
    card = (Path(__file__).parents[2] / "bayesfo" / "models" / "voigt.toml").read_text()
    (tmp_path / "kv.toml").write_text(card.replace('name = "voigt"', 'name = "kv2"'))
    for argv in (["--models", tmp_path, "structures"], ["structures", "--models", tmp_path]):
        status, out, _ = run_cli(*argv)
        assert status == 0 and "kv2 " in out and "kv2-int " in out
    status, out, _ = run_cli("structures")
    assert "kv2" not in out
    # Each structure with a mechanical picture in the modulus form too, its orders as fixed.
    lines = out.splitlines()
    # Each structure: what it is (title, aliases), its network, J(s), G*(s), inequalities, priors.
    at = next(i for i, line in enumerate(lines) if line.startswith("voigt "))
    assert lines[at].split(None, 1)[1] == ("Fractional Voigt model (also "
                                           "fractional_kelvin_voigt_s, fkvs)")
    assert lines[at + 1].strip() == "network parallel(spring(G_e), springpot(c_q, q))"
    assert lines[at + 2].strip() == "J(s) = b0 / (1 + a1 s^q)"
    assert lines[at + 3].strip() == "G*(s) = G_e + c_q s^q"
    at = next(i for i, line in enumerate(lines) if line.startswith("maxwell-int "))
    assert lines[at + 3].strip() == "G*(s) = 1/(1/(c_beta s) + 1/c_delta)"
    at = next(i for i, line in enumerate(lines) if line.startswith("maxwell "))
    assert lines[at + 4].strip() == "constraints: alpha <= beta (and stable, passive)"
    at = next(i for i, line in enumerate(lines) if line.startswith("voigt-inv "))
    assert lines[at + 2].strip().startswith("priors:")  # no network: no modulus form
    at = next(i for i, line in enumerate(lines) if line.startswith("max-n2m1 "))
    assert lines[at].endswith("denominator of degree n = 2, numerator of degree m = 1 in s^q")


ADHESIVE = EXAMPLES / "adhesive_468mp" / "Tp020C.csv"


@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_compare_writes_the_same_summary_whichever_process_computes(run_cli, tmp_path):
    """The default schedule (quick posteriors in the command's process), one process, and two
    worker processes give the same summary.json: every step runs with the same seed."""
    summaries = {}
    for workers in ("0", "1", "2"):
        out = tmp_path / f"w{workers}"
        status, _, err = run_cli("compare", ADHESIVE, "--structures", "zener-int,voigt",
                                 "--workers", workers, "--out", out, "--no-figures", "--quiet")
        assert status == 0, err
        summaries[workers] = json.loads((out / "summary.json").read_text())
    assert summaries["0"] == summaries["1"] == summaries["2"]
    assert [s["sampler"] for s in summaries["0"]["structures"]] == ["importance"] * 2


@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_figure_formats_png_alone(run_cli, tmp_path):
    out = tmp_path / "out"
    status, _, err = run_cli("compare", ADHESIVE, "--structures", "voigt", "--out", out,
                             "--figure-formats", "PNG", "--quiet")
    assert status == 0, err
    names = sorted(p.name for p in (out / "figures").iterdir())
    route = json.loads((out / "summary.json").read_text())["structures"][0]["sampler"]
    traced = ["trace_voigt.png"] if route != "importance" else []  # walkers or ladder runs
    assert names == sorted(["bode.png", "corner_voigt.png", "moduli.png", "nyquist.png",
                            "q_posteriors.png", "ranking.png", "residuals.png",
                            "time_functions.png", *traced])
    assert (out / "report.html").read_text().count("data:image/png;base64,") == len(names)


def test_structure_figures_takes_leading_a_number_or_all(run_cli, tmp_path):
    status, _, err = run_cli("compare", ADHESIVE, "--structures", "voigt", "--out",
                             tmp_path / "x", "--structure-figures", "some")
    assert status == 2
    assert ("--structure-figures takes 'leading', a number of structures or 'all', got 'some'"
            in err)
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("formats, message", [
    ("png,xyz", "--figure-formats: cannot write 'xyz' figures; use one of"),
    (",", "--figure-formats is empty")])
def test_bad_figure_formats_are_refused_before_work(run_cli, tmp_path, formats, message):
    out = tmp_path / "out"
    status, _, err = run_cli("compare", ADHESIVE, "--out", out, "--figure-formats", formats)
    assert status == 2 and err.startswith(f"bayesfo: error: {message}")
    assert len(err.strip().splitlines()) == 1 and not out.exists()


@pytest.mark.parametrize("argv", [["--holdout", "1e9"], ["--holdout", "1_0"], ["--workers", "-1"]])
def test_a_compare_that_fails_leaves_no_output_directory(run_cli, tmp_path, monkeypatch, argv):
    # Without --out the output directory is bayesfo-<data name> in the working directory: a run
    # refused before any output leaves no empty directory there, and one that existed stays.
    monkeypatch.chdir(tmp_path)
    status, _, err = run_cli("compare", ADHESIVE, "--no-figures", *argv)
    assert status == 2 and err.startswith("bayesfo: error:")
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "bayesfo-Tp020C").mkdir()
    status, _, _ = run_cli("compare", ADHESIVE, "--no-figures", *argv)
    assert status == 2 and (tmp_path / "bayesfo-Tp020C").is_dir()


_TWO_PROCESS_CLI = """
import sys
from pathlib import Path
import bayesfo.parallel as parallel
import bayesfo.plotting.output as output
from bayesfo.cli import main

marker = Path(sys.argv[1])
parallel.figure_processes = lambda since: 2  # as if a CPU were idle
draw_in_child = output._draw_in_child

def child(*args):
    marker.write_text("ran")
    draw_in_child(*args)

output._draw_in_child = child
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_compare_draws_in_two_processes_the_files_of_one(run_cli, tmp_path):
    """With a spare CPU, the default schedule draws the figures here and in a process forked
    from this one; the files are those of one process. The two-process command runs in a
    fresh interpreter: in the test process other threads (e.g. a Dask client's) may be left
    running, and then no fork is made (:func:`bayesfo.plotting.output.can_fork`)."""
    import subprocess
    import sys

    marker = tmp_path / "child-ran"
    outs = {w: tmp_path / f"w{w}" for w in ("1", "0")}
    common = ["compare", str(ADHESIVE), "--structures", "voigt", "--figure-formats", "png",
              "--quiet"]
    status, _, err = run_cli(*common, "--out", outs["1"], "--workers", "1")
    assert status == 0, err
    done = subprocess.run([sys.executable, "-W", "ignore", "-c", _TWO_PROCESS_CLI, str(marker),
                           *common, "--out", str(outs["0"]), "--workers", "0"],
                          capture_output=True, text=True, timeout=600,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert done.returncode == 0, done.stderr
    assert marker.read_text() == "ran"
    one, two = (sorted((o / "figures").iterdir()) for o in (outs["1"], outs["0"]))
    assert [p.name for p in one] == [p.name for p in two]
    assert all(a.read_bytes() == b.read_bytes() for a, b in zip(one, two))
    assert (outs["1"] / "summary.json").read_text() == (outs["0"] / "summary.json").read_text()


def test_figures_in_two_processes_only_with_a_spare_cpu(monkeypatch):
    import time

    import bayesfo.parallel as parallel

    since = parallel.cpu_times()
    assert since is not None and 0 < since[0] <= since[1]  # Linux: /proc/stat
    assert since[2] == len(os.sched_getaffinity(0))  # the CPUs this process may use
    time.sleep(0.2)
    idle = parallel.idle_cpus(since)
    assert idle is not None and 0.0 <= idle <= since[2]
    assert parallel.idle_cpus(None) is None
    # Restricted to one CPU (taskset, a cpuset): only that CPU's idle time counts.
    with monkeypatch.context() as m:
        m.setattr(os, "sched_getaffinity", lambda pid: {0})
        one = parallel.cpu_times()
        assert one[2] == 1 and one[1] <= since[1]
        assert parallel.idle_cpus(since) is None  # another CPU set: no comparison
    monkeypatch.setattr(parallel, "available_cpus", lambda: 2)
    for idle, expected in [(0.2, 1), (0.49, 1), (0.5, 2), (1.6, 2), (None, 1)]:
        monkeypatch.setattr(parallel, "idle_cpus", lambda since, idle=idle: idle)
        assert parallel.figure_processes(since) == expected, idle
    monkeypatch.setattr(parallel, "available_cpus", lambda: 1)
    assert parallel.figure_processes(since) == 1


@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_a_command_freezes_the_libraries_out_of_the_collector_while_it_runs(run_cli, tmp_path,
                                                                              monkeypatch):
    """Once the libraries are loaded, their objects are frozen out of the garbage collector
    for the rest of the command (its full collections would walk them again and again);
    when main returns, a caller in the same process has its collector back as it was."""
    import gc

    import bayesfo.comparison.steps as steps

    frozen, real = [], steps.sample

    def spy(*args, **kwargs):  # a posterior: the libraries are loaded by then
        frozen.append(gc.get_freeze_count())
        return real(*args, **kwargs)

    monkeypatch.setattr(steps, "sample", spy)
    assert gc.get_freeze_count() == 0
    status, _, err = run_cli("compare", ADHESIVE, "--structures", "voigt", "--out",
                             tmp_path / "out", "--no-figures", "--quiet")
    assert status == 0, err
    # numpy, scipy, xarray and the package alone are tens of thousands of tracked objects
    assert frozen and frozen[0] > 10_000
    assert gc.get_freeze_count() == 0


def test_writing_the_netcdf_files_does_not_import_dask_distributed(tmp_path):
    """xarray's to_netcdf asks dask for its scheduler, which imports distributed (a second on
    a busy machine); a process without it has no distributed client, so it is not needed."""
    import subprocess
    import sys

    out = tmp_path / "out"
    done = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "bayesfo.cli", "compare", str(ADHESIVE),
         "--structures", "voigt", "--out", str(out), "--no-figures", "--quiet"],
        capture_output=True, text=True, env=dict(os.environ, MPLBACKEND="Agg"))
    assert done.returncode == 0, done.stderr
    imported = {line.rsplit("|", 1)[-1].strip() for line in done.stderr.splitlines()
                if line.startswith("import time:")}
    assert "xarray" in imported and (out / "voigt.nc").is_file()
    # importtime lists the refused attempt too (a few microseconds); the package's modules
    # are not loaded.
    assert not [m for m in imported if m.startswith("distributed.")]


def test_distributed_stays_importable_around_the_netcdf_writes(monkeypatch):
    import sys
    import types

    from bayesfo.output.write import _without_distributed

    for name in ("distributed", "dask.distributed"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    with _without_distributed():
        with pytest.raises(ImportError):
            import distributed  # noqa: F401
    assert "distributed" not in sys.modules and "dask.distributed" not in sys.modules
    # A process that has imported it (a batch on a Dask cluster) keeps it.
    loaded = types.ModuleType("distributed")
    monkeypatch.setitem(sys.modules, "distributed", loaded)
    with _without_distributed():
        import distributed
    assert distributed is loaded


def test_dask_forgets_the_import_that_failed_inside_the_block(monkeypatch):
    # dask caches whether distributed imports (asked when a string scheduler is configured);
    # a failure cached inside the block would make a later Client unusable.
    import sys

    import dask.base

    from bayesfo.output.write import _without_distributed

    for name in ("distributed", "dask.distributed"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    monkeypatch.setattr(dask.base, "_DISTRIBUTED_AVAILABLE", None)
    with _without_distributed():
        assert dask.base._distributed_available() is False
    assert dask.base._DISTRIBUTED_AVAILABLE is None
    assert dask.base._distributed_available() is True


@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_compare_without_units_says_how_to_name_them(run_cli, gspec_csv, tmp_path):
    status, _, err = run_cli("compare", gspec_csv, "--structures", "voigt", "--no-figures",
                             "--out", tmp_path / "o1")
    assert status == 0, err
    assert "gives no unit for the response" in err and "[J]" in err and "# units: 1/Pa" in err
    status, _, err = run_cli("compare", ADHESIVE, "--structures", "voigt", "--no-figures",
                             "--out", tmp_path / "o2")
    assert status == 0, err
    assert "no unit" not in err


def test_a_reader_that_closes_the_pipe_early_ends_the_command_quietly(gspec_csv):
    """`bayesfo inspect FILE | head` closes the pipe before the command has written: the
    command ends with 141 (as a shell reports SIGPIPE) and no 'internal error' message."""
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-m", "bayesfo.cli", "inspect", str(gspec_csv)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # no reader left: the command's first write fails
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 141, stderr
    assert stderr == b""


def test_a_broken_pipe_that_is_not_the_output_is_an_internal_error(gspec_csv, monkeypatch,
                                                                   capsys):
    """Only a reader of the output that has gone ends the command quietly; a broken pipe
    elsewhere (a FIFO the command writes to, say) is a failure the user must see."""
    import bayesfo.cli
    import bayesfo.cli.inspect

    def broken(args):
        raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(bayesfo.cli.inspect, "run", broken)
    monkeypatch.delenv("BAYESFO_DEBUG", raising=False)
    assert bayesfo.cli.main(["inspect", str(gspec_csv)]) == 1
    assert "internal error: BrokenPipeError" in capsys.readouterr().err
