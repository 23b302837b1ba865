"""bayesfo batch: inputs and manifests, failures, resume, executors, temperature series.

The comparisons run on two bundled adhesive isotherms (17 frequencies, voigt and zener) and one
broken file; the reference run is in-process, and the process pool and the Dask cluster must
give the same numbers bit for bit.
"""

from __future__ import annotations

import csv
import json
import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from bayesfo.batch import (
    DataSet,
    executors,
    expand_inputs,
    parse_temperature,
    run_batch,
    temperature_from_stem,
    temperature_of_file,
)
from bayesfo.cli.batch import add_parser
from bayesfo.cli.batch import run as cmd_batch
from bayesfo.errors import InputError

ADHESIVE = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp"
NREL = Path(__file__).parents[2] / "examples" / "data" / "nrel_dma_master.csv"
STRUCTURES = "voigt,zener"
GOOD = ("Tm010C", "Tp150C")
BAD_TEXT = "omega,real,imag\n1,2,3\n2,x,4\n"


def _read_csv(path) -> list[dict]:
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def _numbers(rows) -> dict:
    """ln Z, its error, q and the criteria of every (data set, structure), as stored."""
    keys = ("log_evidence", "log_evidence_err", "posterior_probability", "q_mean", "q_sd",
            "q_hdi_low", "q_hdi_high", "loo", "bic", "rmse")
    return {(r["dataset"], r["structure"]): tuple(r[k] for k in keys)
            for r in rows if r["status"] == "ok"}


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("inputs")
    for name in GOOD:
        shutil.copy(ADHESIVE / f"{name}.csv", d / f"{name}.csv")
    (d / "broken.csv").write_text(BAD_TEXT, encoding="utf-8")
    return d


@pytest.fixture(scope="module")
def reference(inputs, tmp_path_factory):
    """The in-process run (workers=1) of the two isotherms and the broken file."""
    out = tmp_path_factory.mktemp("reference")
    datasets = expand_inputs([inputs], options={"structures": STRUCTURES, "figures": False},
                             seed=3)
    result = run_batch(datasets, out, workers=1, progress=False)
    return datasets, result, out


def _parser():
    from bayesfo.cli import _Parser

    parser = _Parser(prog="bayesfo")
    parser.add_argument("--models", action="append", default=[])
    add_parser(parser.add_subparsers(dest="command", parser_class=_Parser))
    return parser


def _run_cli(capsys, *argv):
    """``bayesfo batch ...`` in-process: through bayesfo.cli once it registers the command,
    else through a parser built here; returns (status, stdout, stderr)."""
    from bayesfo import cli

    argv = [str(a) for a in argv]
    if "batch" in getattr(cli, "COMMANDS", {}):
        status = cli.main(argv)
    else:
        try:
            status = cmd_batch(_parser().parse_args(argv))
        except InputError as exc:
            print(f"bayesfo: error: {exc}", file=sys.stderr)
            status = 2
    out, err = capsys.readouterr()
    return status, out, err


# ---------------------------------------------------------------------- inputs
def test_inputs_files_directories_globs_and_clashing_stems(tmp_path):
    for sub in ("run1", "run2"):
        (tmp_path / sub).mkdir()
        shutil.copy(ADHESIVE / "Tp020C.csv", tmp_path / sub / "Tp020C.csv")
    shutil.copy(ADHESIVE / "Tm010C.csv", tmp_path / "run2" / "Tm010C.csv")
    (tmp_path / "other").mkdir()
    shutil.copy(ADHESIVE / "Tp100C.csv", tmp_path / "other" / "sample.csv")
    shutil.copy(ADHESIVE / "Tp100C.csv", tmp_path / "other" / "tp020c.csv")

    datasets = expand_inputs(
        [tmp_path / "run1", str(tmp_path / "run2" / "*.csv"), tmp_path / "other" / "sample.csv",
         tmp_path / "run2" / "Tm010C.csv"],  # named twice: counted once
        options={"structures": STRUCTURES})
    assert [d.id for d in datasets] == ["run1-Tp020C", "Tm010C", "run2-Tp020C", "sample"]
    assert [d.temperature for d in datasets] == [20.0, -10.0, 20.0, 100.0]  # stem; name comment
    assert all(d.options["structures"] == ("voigt", "zener") and d.seed == 0 for d in datasets)

    # Stems that differ only in case clash too (case-insensitive file systems).
    ids = [d.id for d in expand_inputs([tmp_path / "run1" / "Tp020C.csv",
                                        tmp_path / "other" / "tp020c.csv"])]
    assert ids == ["run1-Tp020C", "other-tp020c"]
    # The same file with other options: numbered.
    again = expand_inputs([tmp_path / "run1" / "Tp020C.csv"], options={"kind": "generic"})
    assert again[0].id == "Tp020C" and again[0].options["kind"] == "generic"


@pytest.mark.parametrize("make, message", [
    (lambda p: [p / "missing.csv"], "INPUT '.*missing.csv': no such file or directory"),
    (lambda p: [str(p / "*.nothing")], "matches no file"),
    (lambda p: [p], "directory holds no .csv data file"),
    (lambda p: [], "no data set"),
])
def test_inputs_that_name_nothing_are_errors(tmp_path, make, message):
    with pytest.raises(InputError, match=message):
        expand_inputs(make(tmp_path))


def test_bad_options_are_errors_before_any_work(tmp_path):
    shutil.copy(ADHESIVE / "Tp020C.csv", tmp_path / "a.csv")
    with pytest.raises(InputError, match="unknown structure 'voigtt'"):
        expand_inputs([tmp_path], options={"structures": "voigtt"})
    with pytest.raises(InputError, match="prior 'alpha' names a parameter no selected structure"):
        expand_inputs([tmp_path], options={"structures": "voigt", "priors": ["alpha=uniform:0:1"]})
    with pytest.raises(InputError, match="--seed: the seed must be an integer from 0 to 4294967295, got -1"):
        expand_inputs([tmp_path], seed=-1)
    ds = expand_inputs([tmp_path])
    with pytest.raises(InputError, match="--workers applies to local processes"):
        run_batch(ds, tmp_path / "out", workers=2, scheduler="tcp://127.0.0.1:1")
    with pytest.raises(InputError, match="--workers must be a non-negative integer"):
        run_batch(ds, tmp_path / "out", workers=-1)


def _manifest(tmp_path, text, name="manifest.csv"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_manifest_with_per_file_options(tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    for name in ("Tp020C", "Tm010C"):
        shutil.copy(ADHESIVE / f"{name}.csv", data / f"{name}.csv")
    m = _manifest(tmp_path, (
        "# per-file options; empty cells take the command line's values\n"
        "path,id,kind,invert,structures,seed,temperature,prior,holdout,evidence\n"
        "data/Tp020C.csv,warm,,yes,\"voigt,zener-inv\",7,293.15 K,q=uniform:0.2:1,1.2;10,ladder\n"
        "data/Tm010C.csv,,generic,,,,,,,\n"
        "data/Tm010C.csv,,,,,,,,,\n"))
    defaults = {"structures": "zener", "priors": ["sigma_rel=log-uniform:1e-4:0.1"]}
    datasets = expand_inputs([m], options=defaults, seed=1)
    a, b, c = datasets
    assert (a.id, a.seed, a.temperature) == ("warm", 7, 20.0)
    assert a.options["reciprocal"] is True and a.options["structures"] == ("voigt", "zener-inv")
    assert a.options["priors"] == ("q=uniform:0.2:1",) and a.options["holdout"] == (1.2, 10.0)
    assert a.options["kind"] is None and a.options["evidence"] == "ladder"
    assert b.options["evidence"] == "auto"
    assert (b.options["kind"], b.seed, b.temperature) == ("generic", 1, -10.0)  # stem
    assert b.options["structures"] == ("zener",)
    assert b.options["priors"] == ("sigma_rel=log-uniform:1e-4:0.1",)
    assert c.options["kind"] is None
    # The same file twice with different options: distinct ids, stable from run to run.
    assert (b.id, c.id) == ("Tm010C-1", "Tm010C-2")
    assert [d.id for d in expand_inputs([], manifests=[m], options={"structures": "zener"})] == \
        ["warm", "Tm010C-1", "Tm010C-2"]


@pytest.mark.parametrize("text, message", [
    ("path,colour\na.csv,red\n", r"line 1: unknown column 'colour'"),
    ("kind\nmodulus\n", r"line 1: no 'path' column"),
    ("# c\npath,kind\na.csv,modulus,extra\n", r"line 3: expected 2 cells as in the header, got 3"),
    ("path,kind\na.csv,stress\n", r"line 2, column 'kind': kind must be one of"),
    ("path,evidence\na.csv,nested\n", r"line 2, column 'evidence': evidence must be one of"),
    ("path,invert\na.csv,maybe\n", r"line 2, column 'invert': expected true or false"),
    ("path,seed\na.csv,1.5\n", r"line 2, column 'seed': the seed must be an integer"),
    ("path,temperature\na.csv,warm\n", r"line 2, column 'temperature': expected a temperature"),
    ("path\nmissing.csv\n", r"line 2, column 'path': file '.*missing.csv' does not exist"),
    ("path,structures\na.csv,zenner\n", r"line 2: unknown structure 'zenner'"),
    ("path,holdout\na.csv,1;x\n", r"line 2, column 'holdout': expected numbers"),
    ("path,id\na.csv,x/y\n", r"line 2, column 'id': an id may hold only"),
    ("path,id,seed\na.csv,same,1\na.csv,same,2\n",
     r"line 3, column 'id': the id 'same' is already used"),
    ("path\n", r"line 1: a header but no data sets"),
])
def test_bad_manifests_name_file_line_and_column(tmp_path, text, message):
    shutil.copy(ADHESIVE / "Tp020C.csv", tmp_path / "a.csv")
    m = _manifest(tmp_path, text, "runs.csv")
    with pytest.raises(InputError, match=r"manifest '.*runs.csv'.*" + message):
        expand_inputs([], manifests=[m], options={"structures": STRUCTURES})


# ---------------------------------------------------------------------- temperatures
def test_temperatures_from_comments_stems_and_names(tmp_path):
    assert [temperature_from_stem(s) for s in ("Tm010C", "Tp020C", "T020C", "run_T20p5C",
                                               "T-5C", "Test", "sample3")] == \
        [-10.0, 20.0, 20.0, 20.5, -5.0, None, None]
    assert [parse_temperature(s) for s in ("20", "-10 °C", "20 C", "293.15 K", "\u22125 °C",
                                           "warm")] == [20.0, -10.0, 20.0, 20.0, -5.0, None]
    f = tmp_path / "Tp020C.csv"
    f.write_text("# name: sample at 30 °C\n# temperature: 25 C\nomega,real,imag\n1,1,1\n")
    assert temperature_of_file(f) == 25.0  # the comment first
    f.write_text("# name: sample at 30 °C\nomega,real,imag\n1,1,1\n")
    assert temperature_of_file(f) == 20.0  # then the stem
    g = tmp_path / "sample.csv"
    g.write_text("# name: sample at \u221230 °C\nomega,real,imag\n1,1,1\n")
    assert temperature_of_file(g) == -30.0  # then the name
    g.write_text("# temperature: warm\nomega,real,imag\n1,1,1\n")
    with pytest.raises(InputError, match=r"sample.csv', line 1: '# temperature:' expects"):
        temperature_of_file(g)
    # In a batch, that data set alone is an input error (tests/integration/test_reliability.py).
    assert re.search(r"sample.csv', line 1: '# temperature:' expects",
                     expand_inputs([g])[0].error)
    # The bundled isotherms: -40 °C to 150 °C in steps of 10 from their file names; the NREL
    # master curve from its name (its reference temperature).
    datasets = expand_inputs([ADHESIVE, NREL])
    assert sorted(d.temperature for d in datasets[:-1]) == [float(t) for t in range(-40, 151, 10)]
    assert datasets[-1].temperature == -5.0


# ---------------------------------------------------------------------- the runs
def test_bad_file_is_recorded_and_the_others_finish(reference):
    datasets, result, out = reference
    assert [d.id for d in datasets] == ["Tm010C", "Tp150C", "broken"]
    assert [o.status for o in result.outcomes] == ["ok", "ok", "input_error"]
    assert result.exit_status == 2 and result.executor == "in-process"
    err = (out / "broken" / "error.txt").read_text()
    assert "broken.csv', line 3, column 'real': 'x' is not a number" in err
    record = json.loads((out / "broken" / "batch.json").read_text())
    assert record["status"] == "input_error" and record["files"] == []
    assert not (out / "broken" / "summary.json").exists()

    rows = _read_csv(out / "batch_summary.csv")
    assert [(r["dataset"], r["structure"], r["rank"]) for r in rows] == [
        ("Tm010C", "zener", "1"), ("Tm010C", "voigt", "2"),
        ("Tp150C", "zener", "1"), ("Tp150C", "voigt", "2"), ("broken", "", "")]
    assert rows[-1]["status"] == "input_error" and "'x' is not a number" in rows[-1]["error"]
    for name in GOOD:
        summary = json.loads((out / name / "summary.json").read_text())
        assert summary["seed"] == 3
        mine = {r["structure"]: r for r in rows if r["dataset"] == name}
        for s in summary["structures"]:
            assert float(mine[s["name"]]["log_evidence"]) == s["log_evidence"]
            assert float(mine[s["name"]]["q_mean"]) == s["parameters"]["q"]["mean"]
            assert float(mine[s["name"]]["q_hdi_high"]) == s["parameters"]["q"]["hdi_high"]
            assert (out / name / f"{s['name']}.nc").is_file()
        best = [r for r in mine.values() if r["best"] == "True"]
        assert [b["structure"] for b in best] == [summary["ranking"][0]]
        record = json.loads((out / name / "batch.json").read_text())
        assert record["status"] == "ok" and record["task"]["seed"] == 3
        assert record["compare_seconds"] > 0
    for name in ("batch_summary.png", "temperature_q.png"):
        assert (out / name).read_bytes()[:4] == b"\x89PNG"
    # The combined figures in the formats asked for (PNG by default), as the data sets' own.
    assert not list(out.glob("*.pdf"))


def test_temperature_table_and_figure(reference):
    _, result, out = reference
    rows = _read_csv(out / "temperature_summary.csv")
    assert [(r["temperature_C"], r["dataset"], r["rank"]) for r in rows] == [
        ("-10.0", "Tm010C", "1"), ("-10.0", "Tm010C", "2"),
        ("150.0", "Tp150C", "1"), ("150.0", "Tp150C", "2")]
    by_set = {}
    for r in rows:
        by_set.setdefault(r["dataset"], []).append(r)
    for name, group in by_set.items():
        best = [r["structure"] for r in group if r["best"] == "True"]
        assert len(best) == 1 and all(r["best_structure"] == best[0] for r in group)
        p = [float(r["posterior_probability"]) for r in group]
        assert abs(sum(p) - 1) < 1e-12 and p[0] == max(p)
        for r in group:
            assert float(r["q_hdi_low"]) < float(r["q_mean"]) < float(r["q_hdi_high"])
    # The isotherm at -10 °C is stiffer and more elastic-like than at 150 °C: larger q.
    q_best = {r["dataset"]: float(r["q_mean"]) for r in rows if r["best"] == "True"}
    assert q_best["Tm010C"] > q_best["Tp150C"] + 0.1

    from matplotlib.colors import to_rgba

    from bayesfo.batch import temperature_rows
    from bayesfo.plotting.batch import plot_q_temperature

    trows = temperature_rows(result.rows)
    fig = plot_q_temperature(trows)
    ax_q, ax_p = fig.axes[:2]
    # Filled markers are the best structure at each temperature, at its posterior mean of q.
    # (each structure has its own marker; "x" marks an unconverged posterior, "_" the caps of
    # the HDI bars)
    filled = [(x, y) for line in ax_q.lines if line.get_linestyle() in ("None", "none", "")
              and line.get_marker() not in ("x", "_", "None", "")
              and to_rgba(line.get_markerfacecolor()) != to_rgba("white")
              for x, y in zip(line.get_xdata(), line.get_ydata())]
    expected = sorted((r["temperature_C"], r["q_mean"]) for r in trows if r["best"])
    got = sorted(filled)
    assert len(got) == len(expected)
    np.testing.assert_allclose([y for _, y in got], [y for _, y in expected], rtol=0, atol=0)
    np.testing.assert_allclose([x for x, _ in got], [x for x, _ in expected], atol=0.02 * 160)


def test_resume_redoes_a_data_set_whose_files_changed(reference, tmp_path, monkeypatch):
    # A truncated NetCDF (a full disk, a copy cut short) is not a complete result, though
    # batch.json lists it: its digest is not the one its run recorded.
    datasets, _, out = reference
    out2 = tmp_path / "out"
    shutil.copytree(out, out2)
    nc = sorted((out2 / "Tm010C").glob("*.nc"))[0]
    nc.write_bytes(nc.read_bytes()[: nc.stat().st_size // 2])
    calls = []
    monkeypatch.setattr(executors, "run_task", lambda task: calls.append(task["id"]) or {
        "id": task["id"], "status": "input_error", "error": "not run", "files": {}})
    run_batch(datasets, out2, workers=1, progress=False, write_combined=False)
    assert sorted(calls) == ["Tm010C", "broken"]  # Tp150C stays complete


def test_resume_skips_complete_and_redoes_incomplete(reference, tmp_path, monkeypatch):
    datasets, result, out = reference
    out2 = tmp_path / "out"
    shutil.copytree(out, out2)
    # Tp150C was interrupted after writing its outputs but before batch.json.
    (out2 / "Tp150C" / "batch.json").unlink()
    kept = {f: f.stat().st_mtime_ns for f in (out2 / "Tm010C").iterdir()}
    calls = []
    real = executors.run_task
    monkeypatch.setattr(executors, "run_task", lambda task: calls.append(task["id"]) or real(task))
    again = run_batch(datasets, out2, workers=1, progress=False)
    assert sorted(calls) == ["Tp150C", "broken"]  # failed data sets are retried too
    assert [o.reused for o in again.outcomes] == [True, False, False]
    assert {f: f.stat().st_mtime_ns for f in (out2 / "Tm010C").iterdir()} == kept
    # Redone with the same seed: the same numbers; the combined table is the same file.
    assert (out2 / "batch_summary.csv").read_text() == (out / "batch_summary.csv").read_text()
    assert again.exit_status == 2

    # Another seed, or changed data, invalidate a complete result; nothing else does.
    calls.clear()
    monkeypatch.setattr(executors, "run_task", lambda task: calls.append(task["id"]) or {
        "id": task["id"], "status": "input_error", "error": "not run", "files": {}})
    changed = [DataSet(d.id, d.path, d.options, 4 if d.id == "Tm010C" else d.seed,
                       d.temperature) for d in datasets]
    run_batch(changed, out2, workers=1, progress=False, write_combined=False)
    assert calls == ["Tm010C", "broken"]
    assert not (out2 / "Tm010C" / "summary.json").exists()  # stale results are removed
    assert (out2 / "Tp150C" / "summary.json").exists()


def test_two_workers_give_the_same_numbers(reference, tmp_path):
    datasets, result, out = reference
    two = run_batch(datasets, tmp_path / "two", workers=2, progress=False)
    assert two.executor == "processes (2)"
    assert [o.status for o in two.outcomes] == ["ok", "ok", "input_error"]
    assert _numbers(_read_csv(tmp_path / "two" / "batch_summary.csv")) == \
        _numbers(_read_csv(out / "batch_summary.csv"))


def test_dask_local_cluster_gives_the_same_numbers(reference, tmp_path):
    distributed = pytest.importorskip("distributed")
    datasets, result, out = reference
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        res = run_batch(datasets, tmp_path / "dask", scheduler=cluster.scheduler_address,
                        progress=False)
    assert res.executor == f"dask ({cluster.scheduler_address})"
    assert [o.status for o in res.outcomes] == ["ok", "ok", "input_error"]
    assert res.exit_status == 2
    assert _numbers(_read_csv(tmp_path / "dask" / "batch_summary.csv")) == \
        _numbers(_read_csv(out / "batch_summary.csv"))
    assert all(o.compare_seconds > 0 for o in res.outcomes if o.status == "ok")


def test_dask_errors_are_input_errors(reference, tmp_path, monkeypatch):
    datasets = [d for d in reference[0] if d.id == "broken"]
    monkeypatch.setattr(executors, "SCHEDULER_TIMEOUT", 0.5)
    with pytest.raises(InputError, match="cannot reach the Dask scheduler at 'tcp://127.0.0.1:9'"):
        run_batch(datasets, tmp_path / "x", scheduler="tcp://127.0.0.1:9")
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(InputError, match=r"needs dask.distributed: pip install 'bayesfo\[cl"):
        run_batch(datasets, tmp_path / "x", scheduler="tcp://127.0.0.1:9")


def test_nested_outputs_are_stored_and_stale_ones_removed(tmp_path, monkeypatch):
    import bayesfo.comparison
    import bayesfo.output

    shutil.copy(ADHESIVE / "Tp150C.csv", tmp_path / "a.csv")
    summary = {"data": {"kind": "modulus", "n_frequencies": 17}, "ranking": ["voigt"],
               "structures": [{"name": "voigt", "n_params": 3, "log_evidence": -1.5,
                               "posterior_probability": 1.0, "parameters": {"q": {
                                   "mean": 0.5, "sd": 0.1, "hdi_low": 0.3, "hdi_high": 0.7,
                                   "map": 0.5}}}]}

    def fake_outputs(comparison, out, figures=True, **kwargs):
        out = Path(out)
        (out / "voigt.nc").write_bytes(b"nc")
        if figures:
            (out / "figures").mkdir()
            (out / "figures" / "bode.png").write_bytes(b"png")
            (out / "report.html").write_text("<html>")
        (out / "summary.json").write_text(json.dumps(summary))

    monkeypatch.setattr(bayesfo.comparison, "compare", lambda *args, **kwargs: None)
    monkeypatch.setattr(bayesfo.output, "write_outputs", fake_outputs)
    sub = tmp_path / "out" / "a"
    res = run_batch(expand_inputs([tmp_path / "a.csv"], options={"structures": "voigt"}),
                    tmp_path / "out", workers=1, progress=False, write_combined=False)
    assert (sub / "figures" / "bode.png").read_bytes() == b"png"
    assert json.loads((sub / "batch.json").read_text())["files"] == [
        "figures/bode.png", "report.html", "summary.json", "voigt.nc"]
    assert res.rows[0]["log_evidence"] == -1.5 and res.rows[0]["q_hdi_high"] == 0.7
    # Run again without figures: the earlier figures and report do not linger.
    run_batch(expand_inputs([tmp_path / "a.csv"], options={"structures": "voigt",
                                                           "figures": False}),
              tmp_path / "out", workers=1, progress=False, write_combined=False)
    assert sorted(p.name for p in sub.iterdir() if not p.name.startswith(".bayesfo-")) == [
        "batch.json", "summary.json", "voigt.nc"]


def test_figure_options_reach_each_data_set_and_defaults_keep_earlier_records(tmp_path,
                                                                               monkeypatch,
                                                                               capsys):
    """``--figure-formats`` and ``--structure-figures`` apply to every data set's figures (as
    compare's options); at their defaults a data set's record is the one written before the
    options existed, so such a directory stays complete."""
    import bayesfo.comparison
    import bayesfo.output

    shutil.copy(ADHESIVE / "Tp150C.csv", tmp_path / "a.csv")
    seen = []

    def fake_outputs(comparison, out, figures=True, **kwargs):
        seen.append(kwargs)
        (Path(out) / "summary.json").write_text(json.dumps(
            {"data": {"kind": "modulus", "n_frequencies": 17}, "ranking": [],
             "structures": []}))

    monkeypatch.setattr(bayesfo.comparison, "compare", lambda *args, **kwargs: None)
    monkeypatch.setattr(bayesfo.output, "write_outputs", fake_outputs)
    status, _, err = _run_cli(capsys, "batch", tmp_path / "a.csv", "--out", tmp_path / "o1",
                              "--structures", "voigt", "--quiet", "--workers", 1,
                              "--structure-figures", "1", "--figure-formats", "png,PDF")
    assert status == 0, err
    assert seen == [{"formats": ("png", "pdf"), "structure_figures": 1}]
    _run_cli(capsys, "batch", tmp_path / "a.csv", "--out", tmp_path / "o2", "--structures",
             "voigt", "--quiet", "--workers", 1, "--structure-figures", "all")
    assert seen[1] == {"formats": ("png",), "structure_figures": None}
    default = expand_inputs([tmp_path / "a.csv"], options={"structures": "voigt"})[0]
    assert default.options["figure_formats"] == ("png",)
    assert default.options["structure_figures"] == "leading"
    record = default.fingerprint()["options"]
    assert "figure_formats" not in record and "structure_figures" not in record
    fewer = expand_inputs([tmp_path / "a.csv"], options={"structures": "voigt",
                                                         "structure_figures": 1})[0]
    assert fewer.fingerprint()["options"]["structure_figures"] == 1
    status, _, err = _run_cli(capsys, "batch", tmp_path / "a.csv", "--out", tmp_path / "o3",
                              "--figure-formats", "bmpx")
    assert status == 2 and "--figure-formats: cannot write 'bmpx' figures" in err
    status, _, err = _run_cli(capsys, "batch", tmp_path / "a.csv", "--out", tmp_path / "o3",
                              "--structure-figures", "some")
    assert status == 2
    assert ("--structure-figures takes 'leading', a number of structures or 'all', got 'some'"
            in err)
    with pytest.raises(InputError, match="figure_formats is empty"):
        expand_inputs([tmp_path / "a.csv"], options={"figure_formats": ()})
    with pytest.raises(InputError, match="figure_formats must be a sequence of file formats"):
        expand_inputs([tmp_path / "a.csv"], options={"figure_formats": 5})
    with pytest.raises(InputError, match="structure_figures must be 'leading', a non-negative "
                                         "integer"):
        expand_inputs([tmp_path / "a.csv"], options={"structure_figures": -1})
    assert not (tmp_path / "o3").exists()


def test_tasks_carry_the_data_so_workers_need_no_shared_files(tmp_path):
    from bayesfo.batch.task import _read_task_data
    from bayesfo.data import read_csv

    shutil.copy(ADHESIVE / "Tp150C.csv", tmp_path / "Tp150C.csv")
    (tmp_path / "broken.csv").write_text(BAD_TEXT)
    task = expand_inputs([tmp_path / "Tp150C.csv"])[0].task()
    assert task["content"] == (ADHESIVE / "Tp150C.csv").read_bytes()
    elsewhere = dict(task, path="/nowhere/Tp150C.csv")  # as seen by a worker on another machine
    data = _read_task_data(elsewhere, read_csv)
    assert data.source == "/nowhere/Tp150C.csv" and data.n_frequencies == 17
    np.testing.assert_array_equal(data.response, read_csv(ADHESIVE / "Tp150C.csv").response)
    bad = dict(expand_inputs([tmp_path / "broken.csv"])[0].task(), path="/nowhere/broken.csv")
    with pytest.raises(InputError, match=r"^file '/nowhere/broken.csv', line 3, column 'real'"):
        _read_task_data(bad, read_csv)


def test_internal_error_is_recorded_with_traceback(inputs, tmp_path, monkeypatch):
    import bayesfo.comparison

    def boom(*args, **kwargs):
        raise RuntimeError("solver exploded")

    monkeypatch.setattr(bayesfo.comparison, "compare", boom)
    datasets = expand_inputs([inputs / "Tm010C.csv"], options={"structures": STRUCTURES})
    res = run_batch(datasets, tmp_path, workers=1, progress=False)
    assert res.outcomes[0].status == "internal_error" and res.exit_status == 1
    text = (tmp_path / "Tm010C" / "error.txt").read_text()
    assert text.startswith("RuntimeError: solver exploded") and "Traceback" in text
    assert not (tmp_path / "batch_summary.png").exists()  # nothing to draw


def test_command_line(reference, tmp_path, capsys):
    datasets, result, out = reference
    # Everything but the broken file is complete: nothing is recomputed.
    status, stdout, stderr = _run_cli(capsys, "batch", Path(datasets[0].path).parent, "--out",
                                      out, "--structures", STRUCTURES, "--seed", 3, "--quiet",
                                      "--no-figures")
    assert status == 2
    assert stderr.strip().startswith("bayesfo: error: broken: file '")
    assert stdout.count("\n") == 1
    assert stdout.startswith("batch: 3 data sets, 2 compared (2 complete from an earlier run), "
                             "1 failed; in-process")

    status, stdout, stderr = _run_cli(capsys, "batch", "--out", tmp_path, "--manifest",
                                      tmp_path / "none.csv")
    assert status == 2 and "manifest '" in stderr and "does not exist" in stderr
    status, _, stderr = _run_cli(capsys, "batch", ADHESIVE / "Tp020C.csv", "--out", tmp_path,
                                 "--workers", "2", "--scheduler", "tcp://127.0.0.1:9")
    assert status == 2 and "--workers applies to local processes" in stderr


def test_batch_figure_orders_isotherms_by_temperature():
    import matplotlib.pyplot as plt

    from bayesfo.plotting.batch import plot_batch_summary

    rows = [{"dataset": d, "temperature_C": t, "status": "ok", "structure": "voigt",
             "posterior_probability": 1.0, "best": True, "converged": True,
             "q_mean": q, "q_hdi_low": q - 0.01, "q_hdi_high": q + 0.01}
            for d, t, q in (("Tm010C", -10.0, 0.4), ("Tm040C", -40.0, 0.1), ("Tp020C", 20.0, 0.5))]
    fig = plot_batch_summary(rows)
    ax_q = fig.axes[1]
    assert [t.get_text() for t in ax_q.get_xticklabels()] == ["Tm040C", "Tm010C", "Tp020C"]
    plt.close(fig)


def test_batch_table_points_to_the_report_when_the_best_is_not_certified(capsys, tmp_path):
    # The best structure by evidence whose posterior is not certified: the status names the
    # best certified one and the data set's report (which says what to do), as the report does.
    from types import SimpleNamespace

    from bayesfo.batch.task import OK
    from bayesfo.cli.batch import _print_table

    rows = [{"structure": "zener", "rank": 1, "best": True, "converged": False,
             "posterior_probability": 0.9, "q_mean": None},
            {"structure": "maxwell", "rank": 3, "best": False, "converged": True},
            {"structure": "voigt", "rank": 2, "best": False, "converged": True}]
    outcome = SimpleNamespace(dataset=SimpleNamespace(id="Tp017p85C", temperature=17.85),
                              status=OK, rows=rows, reused=False)
    _print_table(SimpleNamespace(outcomes=[outcome], out_dir=tmp_path))
    line = capsys.readouterr().out.splitlines()[1]
    assert "zener" in line  # without figures there is no report
    assert line.endswith("ok, not converged (best certified: voigt); see Tp017p85C/summary.json")
    (tmp_path / "Tp017p85C").mkdir()
    (tmp_path / "Tp017p85C" / "report.html").write_text("<html></html>")
    _print_table(SimpleNamespace(outcomes=[outcome], out_dir=tmp_path))
    line = capsys.readouterr().out.splitlines()[1]
    assert line.endswith("ok, not converged (best certified: voigt); see Tp017p85C/report.html")



def test_batch_table_shows_every_order_and_whether_the_best_fits(capsys, tmp_path):
    from types import SimpleNamespace

    from bayesfo.batch.task import OK
    from bayesfo.cli.batch import _print_table

    def outcome(name, t, orders, fits, warnings=()):
        rows = [{"structure": "fractional_kelvin_voigt", "rank": 1, "best": True,
                 "converged": True, "posterior_probability": 1.0, "orders": orders,
                 "fits": fits}]
        return SimpleNamespace(dataset=SimpleNamespace(id=name, temperature=t), status=OK,
                               rows=rows, reused=False, warnings=warnings)

    loss = ("adhesive, -40 °C: 1 of 17 points have negative loss (Im G < 0), impossible for a "
            "passive modulus, at omega = 125.7 rad/s; no passive structure can fit them")
    outcomes = [outcome("Tm040C", -40.0, "α 0.901 [0.88–0.92]; β 0.120 [0.11–0.13]", "no",
                        (f"DataWarning: {loss}", "PredictiveWarning: misfit", f"DataWarning: {loss}")),
                outcome("Tp020C", 20.0, "α 0.589 [0.586–0.592]; β 0.138 [0.13–0.14]", "yes")]
    _print_table(SimpleNamespace(outcomes=outcomes, out_dir=tmp_path))
    header, cold, warm, summary, data = capsys.readouterr().out.splitlines()
    # The data's own problem, once, under the table: no structure mends it.
    assert data == f"data Tm040C: {loss}"
    assert "orders (mean)" in header and header.split()[-2:] == ["fits", "status"]
    assert "α 0.901 β 0.120" in cold and cold.split()[-2:] == ["NO", "ok"]
    assert "α 0.589 β 0.138" in warm and warm.split()[-2:] == ["yes", "ok"]
    assert summary.startswith("fits NO: on 1 of 2 data sets the best structure fails")
    assert summary.endswith(": Tm040C")


def test_compare_into_a_data_set_of_a_batch_says_the_batch_summary_is_stale(tmp_path, run_cli):
    """compare --out BATCH/ID replaces that data set's run and its batch record (so the batch
    redoes it when run again) and says that BATCH/batch_summary.csv, which it does not touch,
    still shows the batch's result."""
    batch = tmp_path / "batch"
    sub = batch / "Tp150C"
    sub.mkdir(parents=True)
    (sub / "batch.json").write_text(json.dumps({"format": 1, "status": "ok"}))
    (batch / "batch_summary.csv").write_text("data_set,structure\nTp150C,voigt\n")
    status, _, err = run_cli("compare", ADHESIVE / "Tp150C.csv", "--structures", "voigt",
                             "--noise", "proportional", "--no-figures", "--quiet", "--out", sub)
    assert status == 0, err
    assert (f"bayesfo: warning: '{sub}' is a data set of the batch in '{batch}': its "
            "batch_summary.csv still shows the batch's result for it") in err
    assert (batch / "batch_summary.csv").read_text() == "data_set,structure\nTp150C,voigt\n"
    # Elsewhere (no batch beside it) nothing is said.
    status, _, err = run_cli("compare", ADHESIVE / "Tp150C.csv", "--structures", "voigt",
                             "--noise", "proportional", "--no-figures", "--quiet",
                             "--out", tmp_path / "alone")
    assert status == 0 and "batch" not in err


def test_the_combined_figures_take_the_formats_asked_for():
    from types import SimpleNamespace

    from bayesfo.batch.executors import _combined_formats

    sets = [SimpleNamespace(options={"figure_formats": ("png",)}),
            SimpleNamespace(options={"figure_formats": ("png", "pdf")}),
            SimpleNamespace(options={})]
    assert _combined_formats(sets) == ("png", "pdf")
    assert _combined_formats(sets[:1]) == ("png",) and _combined_formats(sets[2:]) == ("png",)
