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
