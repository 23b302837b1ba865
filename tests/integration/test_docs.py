"""The documentation site (``make docs``) builds with warnings as errors, and its pages say what
they should: the API reference from the docstrings, the model table, a guide per command and
the gallery run at build time.

The build runs sphinx-build in a subprocess, so that Sphinx's own warnings stay out of pytest's
(``filterwarnings = error``); ``-W`` turns them into a failed build there instead.
"""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]
DOCS = ROOT / "docs"


def _api_packages() -> tuple[str, ...]:
    """API_PACKAGES of docs/conf.py, read without running it."""
    tree = ast.parse((DOCS / "conf.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.AnnAssign | ast.Assign):
            targets = [node.target] if isinstance(node, ast.AnnAssign) else node.targets
            if any(getattr(t, "id", None) == "API_PACKAGES" for t in targets):
                return ast.literal_eval(node.value)
    raise AssertionError("docs/conf.py has no API_PACKAGES")


def test_api_index_lists_every_package():
    index = (DOCS / "api" / "index.rst").read_text(encoding="utf-8")
    listed = tuple(re.findall(r"^   (bayesfo\.\w+)$", index, flags=re.M))
    assert listed == _api_packages()


def test_user_guide_has_a_page_per_command():
    from bayesfo.cli import COMMANDS

    for command in COMMANDS:
        page = (DOCS / "user_guide" / f"{command}.rst").read_text(encoding="utf-8")
        assert f":path: {command}" in page, command


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    pytest.importorskip("sphinx", reason="the docs extra is not installed (pip install -e .[docs])")
    for module in ("numpydoc", "pydata_sphinx_theme", "myst_parser", "sphinx_gallery", "sphinxarg"):
        pytest.importorskip(module, reason="the docs extra is not installed (pip install -e .[docs])")
    out = tmp_path_factory.mktemp("docs")
    done = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         "-d", str(out / "doctrees"), str(DOCS), str(out / "html")],
        cwd=ROOT, capture_output=True, text=True, env={**os.environ, "MPLBACKEND": "Agg"},
    )
    assert done.returncode == 0, done.stdout[-5000:] + done.stderr[-5000:]
    return out / "html"


def _text(path: Path) -> str:
    """The visible text of an HTML page."""
    page = re.sub(r"<(script|style)\b.*?</\1>", " ", path.read_text(encoding="utf-8"), flags=re.S)
    return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", page))


@pytest.mark.slow
def test_docs_build_without_warnings(site):
    for page in ("index.html", "getting_started.html", "models.html", "lab_files.html",
                 "adequacy.html", "examples.html", "user_guide/index.html", "api/index.html",
                 "api/bayesfo.html", "auto_examples/index.html"):
        assert (site / page).is_file(), page


@pytest.mark.slow
def test_docs_api_from_docstrings(site):
    compare = _text(site / "api" / "generated" / "bayesfo.comparison.compare.html")
    for parameter in ("structures", "noise", "seed", "workers", "holdout", "evidence"):
        assert parameter in compare, parameter
    assert "Returns" in compare and "Comparison" in compare
    flat = _text(site / "api" / "bayesfo.html")
    import bayesfo

    for name in bayesfo.__all__:
        if not name.startswith("__"):
            assert name in flat, name
    for package in _api_packages():
        assert (site / "api" / "generated" / f"{package}.html").is_file(), package


@pytest.mark.slow
def test_docs_model_table_and_guides(site):
    models = _text(site / "models.html")
    assert "fractional_kelvin_voigt" in models and "fractional_maxwell_gel" in models
    compare = _text(site / "user_guide" / "compare.html")
    for option in ("--structures", "--noise", "--workers", "--holdout"):  # from the parser
        assert option in compare, option
    batch = _text(site / "user_guide" / "batch.html")
    assert "directory of *.csv" in batch  # the help text's '*' escaped, not emphasis


@pytest.mark.slow
def test_docs_gallery_executed(site):
    page = _text(site / "auto_examples" / "plot_01_compare_adhesive.html")
    assert "ranking by ln Z" in page and "fractional_kelvin_voigt" in page
    images = list((site / "_images").glob("sphx_glr_plot_01_compare_adhesive_*.png"))
    assert len(images) >= 2, images
