"""The README's code runs as written: its Python blocks execute from the repository root, and
every option of its command-line synopsis is one that the command accepts (the batch example
runs in the slow suite)."""

from __future__ import annotations

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
