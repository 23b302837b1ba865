"""The README's code runs as written: its Python blocks execute from the repository root, and
every option of its command-line synopsis is one that the command accepts (the batch example
runs in the slow suite)."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", README, flags=re.S)


def _synopsis() -> list[str]:
    """The lines of the command-line synopsis (the block under '## Command line')."""
    section = README.split("## Command line", 1)[1]
    block = re.search(r"```\n(.*?)```", section, flags=re.S).group(1)
    return [line for line in block.splitlines() if line.startswith("bayesfo ")]


@pytest.mark.parametrize("index", range(len(_blocks("python"))))
def test_python_blocks_run(index, monkeypatch):
    monkeypatch.chdir(ROOT)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # convergence and Pareto-k flags of the real data
        exec(compile(_blocks("python")[index], f"README.md python block {index + 1}", "exec"),
             {"__name__": "readme"})


@pytest.mark.parametrize("line", _synopsis(), ids=lambda line: line.split()[1])
def test_synopsis_options_exist(line):
    command = line.split()[1]
    shown = subprocess.run([sys.executable, "-m", "bayesfo.cli", command, "--help"],
                           capture_output=True, text=True, cwd=ROOT, check=True).stdout
    usage = line.split("#", 1)[0]
    options = set(re.findall(r"(--[a-z][a-z-]*)", usage))
    assert options, line
    missing = sorted(o for o in options if o not in shown)
    assert not missing, f"README synopsis of '{command}' names {missing}, not in --help"


def test_two_commands_are_make_targets():
    makefile = (ROOT / "Makefile").read_text()
    for target in re.findall(r"^make ([a-z-]+)", README, flags=re.M):
        assert re.search(rf"^{target}:", makefile, flags=re.M), target


@pytest.mark.slow
def test_batch_example_runs(tmp_path):
    line = next(s for s in _blocks("") if s.startswith("bayesfo batch")).strip()
    argv = line.split()[1:]
    argv[argv.index("--out") + 1] = str(tmp_path / "adhesive-batch")
    done = subprocess.run([sys.executable, "-m", "bayesfo.cli", *argv], cwd=ROOT,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "adhesive-batch" / "temperature_summary.csv").exists()


def _demo_rows(text: str) -> dict:
    """The ranking rows of the demo's terminal table, by structure: k, ln Z and its error, the
    orders' means by symbol, ok and fits."""
    rows = {}
    for line in text.splitlines():
        m = re.match(r"\s*(\d+) (\S+)\s+(\d+)\s+(-?[0-9.]+) ± ([0-9.]+)( L)?\s+(-?[0-9.]+)\s+"
                     r"([0-9.]+)\s+(-?[0-9.]+)\s+(-?[0-9.]+)\s+(.*?)\s+(-|[0-9.]+) (yes|NO)\s+(\S+)$",
                     line)
        if m:
            orders = dict(zip(m[11].split()[::2], map(float, m[11].split()[1::2]), strict=True))
            rows[m[2]] = {"rank": int(m[1]), "k": int(m[3]), "log_z": float(m[4]),
                          "err": float(m[5]), "orders": orders, "ok": m[13], "fits": m[14]}
        # A structure the evidence bound left out: ln Z <= its best fit's log-likelihood.
        m = re.match(r"\s*(\d+) (\S+)\s+(\d+)\s+≤ (-?[0-9.]+)\s+≤ (-?[0-9.]+)\s+≤ \S+\s+-\s+"
                     r"(-?[0-9.]+)\s+.*?(\S+)$", line)
        if m:
            rows[m[2]] = {"rank": int(m[1]), "k": int(m[3]), "bound": float(m[4]), "fits": m[7]}
    return rows


@pytest.mark.filterwarnings("always::bayesfo.errors.PredictiveWarning")
def test_the_readme_demo_table_is_what_the_demo_prints(run_cli, tmp_path):
    """The README shows the output of `make demo`: the same structures in the same order, with
    the same ln Z (within three times its error), orders, certificates and fit checks.
    Regenerate the README block from a run when this fails.

    An order's mean is compared within 0.005 or three standard errors of the difference of two
    certified posteriors' means, whichever is larger: each has an ESS of at least 400 (the
    certificate's floor), so the difference has a standard error of at most sd·√(2/400). A
    sharp order (sd 0.001) is held to 0.005; an undetermined one (the Maxwell's α, sd about
    0.15, whose posterior two machines reach by different floating-point paths) to about 0.03.
    """
    makefile = (ROOT / "Makefile").read_text()
    data = re.search(r"^DEMO_DATA \?= (\S+)", makefile, flags=re.M)[1]
    structures = re.search(r"^DEMO_STRUCTURES \?= (\S+)", makefile, flags=re.M)[1]
    status, out, err = run_cli("compare", ROOT / data, "--structures", structures,
                               "--out", tmp_path / "demo", "--no-figures")
    assert status == 0, err
    shown = _demo_rows(re.search(r"```\n( # structure.*?)```", README, flags=re.S)[1])
    ran = _demo_rows(out)
    assert list(shown) == list(ran) and len(ran) == len(structures.split(","))
    summary = json.loads((tmp_path / "demo" / "summary.json").read_text())
    # The sd of each order shown, by symbol; an order derived from others (the Maxwell's
    # δ = β − α) at most the sum of theirs.
    names = {"q": "q", "α": "alpha", "β": "beta", "γ": "gamma"}
    order_sd = {}
    for r in summary["structures"]:
        sds = {n: p["sd"] for n, p in r["parameters"].items() if n in names.values()}
        order_sd[r["name"]] = {symbol: sds.get(names.get(symbol), sum(sds.values()))
                               for symbol in ran.get(r["name"], {}).get("orders", {})}
    for name, row in ran.items():
        want = shown[name]
        if "bound" in row:  # the optimiser's maximum: the same within rounding
            assert (want["rank"], want["k"], want["fits"]) == (row["rank"], row["k"],
                                                               row["fits"]), name
            assert "bound" in want and abs(want["bound"] - row["bound"]) <= 0.02, name
            continue
        assert (want["rank"], want["k"], want["ok"], want["fits"]) == \
            (row["rank"], row["k"], row["ok"], row["fits"]), name
        assert abs(want["log_z"] - row["log_z"]) <= 3 * max(want["err"], row["err"]) + 0.02, name
        assert want["orders"].keys() == row["orders"].keys(), name
        for symbol, mean in row["orders"].items():
            tolerance = max(0.005, 3 * order_sd[name][symbol] * math.sqrt(2 / 400))
            assert abs(want["orders"][symbol] - mean) <= tolerance, (name, symbol, tolerance)
    # The baseline lines are shown as printed, their ln Z differences within the tolerance of
    # the ln Z above (the last digits of a ladder's ln Z move with the machine's floating point).
    pattern = re.compile(r"^\s*(\S+)\s+vs (\S+)\s+ln Z difference\s+([+-][\d.]+) ± ([\d.]+):",
                         flags=re.M)
    shown_pairs = {(m[1], m[2]): (float(m[3]), float(m[4])) for m in pattern.finditer(README)}
    ran_pairs = {(m[1], m[2]): (float(m[3]), float(m[4])) for m in pattern.finditer(out)}
    assert ran_pairs and set(ran_pairs) <= set(shown_pairs), (ran_pairs, shown_pairs)
    for pair, (d, e) in ran_pairs.items():
        want, want_e = shown_pairs[pair]
        assert abs(want - d) <= 3 * max(e, want_e) + 0.02, (pair, d, want)
    held = "bayesfo: warning: PSIS-LOO is unreliable (Pareto k above 0.7) at some frequencies"
    assert held in README and err.count(held) == 1 and "Pareto k up to" not in err
