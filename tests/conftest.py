"""Shared test helpers.

The tests come in two tiers: ``tests/unit`` (no sampling: readers, structures, responses,
identification, input errors; seconds in all) and ``tests/integration`` (comparisons,
posteriors, evidence, the command line, batch runs, figures, reports, examples). Long
validation runs in either are marked ``slow`` (``make test-slow``); ``make test-unit`` runs the
first tier alone.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from bayesfo.cli import main


@pytest.fixture
def write_csv(tmp_path):
    """Write a CSV text (dedented) to a file in tmp_path and return its path."""

    def _write(text: str, name: str = "data.csv") -> Path:
        path = tmp_path / name
        path.write_text(textwrap.dedent(text).lstrip("\n"), encoding="utf-8")
        return path

    return _write


@pytest.fixture
def run_cli(capsys):
    """Run the command line in-process; return (status, stdout, stderr)."""

    def _run(*argv):
        status = main([str(a) for a in argv])
        out, err = capsys.readouterr()
        return status, out, err

    return _run
