"""Sphinx configuration of the bayesfo documentation (``make docs``).

The site is built with warnings as errors (``sphinx-build -W``): the markdown pages through
myst-parser, the command-line guides from the parser itself (sphinx-argparse on
``bayesfo.cli.build_parser``), the API reference by autosummary and numpydoc from the
docstrings, and the gallery by sphinx-gallery, which runs ``docs/gallery/*.py`` at build time.
"""

from __future__ import annotations

import os
import re
import sys
from importlib.metadata import version as _version
from pathlib import Path

os.environ.setdefault("MPLBACKEND", "Agg")

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS))  # _cli.py: the command-line parser for sphinx-argparse

project = "bayesfo"
author = "the bayesfo developers"
copyright = "the bayesfo developers, MIT License"
release = _version("bayesfo")  # from the installed package's metadata (pyproject.toml)
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinxarg.ext",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "gallery/README.rst",
                    "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip"]

# -- markdown (the existing pages docs/*.md are also read on GitHub) -------------------------
myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3
# The pages link to repository files (tests/..., models/...) by relative path, which are no
# documents of the site; myst says so as "xref_missing". Those links are meant for GitHub.
suppress_warnings = ["myst.xref_missing"]

# -- API reference --------------------------------------------------------------------------
autosummary_generate = True
autosummary_ignore_module_all = False  # a package's __all__ is its public API
autosummary_imported_members = False
autodoc_default_options = {"member-order": "bysource"}
# The docstrings give every type in their numpydoc sections; signatures stay short, and the
# (string) annotations are not turned into cross-references that the re-exports of the flat
# API (bayesfo.read is bayesfo.data.read) would make ambiguous.
autodoc_typehints = "none"
autodoc_preserve_defaults = True

numpydoc_show_class_members = False  # methods are documented in place (:members:)
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True
numpydoc_xref_param_type = False

# numpydoc's docstring validation runs on every documented object, and with -W a failed check
# fails the build: a parameter documented that the signature lacks (PR02) or in another order
# (PR03), an unknown section (GL06), a missing docstring (GL08), ... All checks run except
# these (in brackets the documented objects failing each when this was set up):
#   too broad to fix in the docstrings now: SA01 no See Also section (193), EX01 no Examples
#   section (183), ES01 no extended summary (115), PR01 a parameter not documented (93), RT01
#   no Returns section (83), SS06 summary over several lines (51), GL02 closing quotes on the
#   last line of text (43), PR07 a parameter without description (24);
#   the project's style: RT03 a return type without description (8: "Returns / Comparison"),
#   SS05 a summary in the third person (7: "Returns ...", not "Return ...");
#   misfiring on mathematical notation: SS02 and RT04, a summary or return description not
#   starting with a capital letter ("arg G(jω) in degrees", "ω in rad/s").
numpydoc_validation_checks = {
    "all",
    "SA01", "EX01", "ES01", "PR01", "RT01", "SS06", "GL02", "PR07",
    "RT03", "SS05",
    "SS02", "RT04",
}
# Objects with no docstring yet (GL08), in modules being reworked: add one, then drop it here.
numpydoc_validation_exclude = {
    r"^bayesfo\.comparison\.ranking_csv$",
    r"^bayesfo\.comparison\.StructureResult\.data_kind$",
}

# The docstrings are written to be read as plain text too: |G| is a magnitude and |z_k| a
# modulus, where reStructuredText would see a substitution reference. We define no
# substitutions in docstrings, so every bar outside inline literals, math roles, literal
# blocks and doctests is escaped before the docstring is parsed.
_LITERAL = re.compile(r"(``.*?``|:math:`[^`]*`)")


def _escape_bars(line: str) -> str:
    parts = _LITERAL.split(line)
    return "".join(p if i % 2 else p.replace("|", r"\|") for i, p in enumerate(parts))


def escape_plain_text_bars(app, what, name, obj, options, lines):
    block_indent = None  # indentation of the paragraph that opened a literal block ("::")
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if block_indent is not None:
            if not stripped or indent > block_indent:
                continue
            block_indent = None
        if stripped.startswith(">>>") or stripped.startswith("..."):
            continue
        if "|" in line:
            lines[i] = _escape_bars(line)
        if stripped.endswith("::"):
            block_indent = indent


#: The packages of the API reference (docs/api/index.rst lists the same), in data-flow order.
API_PACKAGES = ("bayesfo.data", "bayesfo.structures", "bayesfo.identify", "bayesfo.inference",
                "bayesfo.comparison", "bayesfo.tts", "bayesfo.predictions", "bayesfo.planning",
                "bayesfo.output", "bayesfo.plotting", "bayesfo.batch", "bayesfo.timeseries",
                "bayesfo.errors")


def flat_api() -> list[str]:
    """Where each name of ``bayesfo.__all__`` is documented: ``package.name`` relative to
    ``bayesfo``, the first package of :data:`API_PACKAGES` that exports the same object."""
    import importlib

    import bayesfo

    out = []
    for name in bayesfo.__all__:
        if name.startswith("__"):
            continue
        obj = getattr(bayesfo, name)
        for package in API_PACKAGES:
            module = importlib.import_module(package)
            public = getattr(module, "__all__", None)
            if public is None:  # the names defined there (bayesfo.errors has no __all__)
                public = [n for n, v in vars(module).items()
                          if not n.startswith("_") and getattr(v, "__module__", None) == package]
            if name in public and getattr(module, name, None) is obj:
                entry = f"{package.removeprefix('bayesfo.')}.{name}"
                out.append((API_PACKAGES.index(package), entry))
                break
        else:
            raise RuntimeError(f"bayesfo.{name} is exported by none of {API_PACKAGES}")
    return [entry for _, entry in sorted(out)]


def write_flat_api(app):
    """docs/api/generated/flat_api.rst.txt: the autosummary list included by api/bayesfo.rst."""
    target = Path(app.srcdir) / "api" / "generated" / "flat_api.rst.txt"
    target.parent.mkdir(parents=True, exist_ok=True)
    text = ".. autosummary::\n   :nosignatures:\n\n" + "".join(
        f"   {entry}\n" for entry in flat_api())
    if not target.exists() or target.read_text(encoding="utf-8") != text:
        target.write_text(text, encoding="utf-8")


def setup(app):
    app.connect("autodoc-process-docstring", escape_plain_text_bars)
    app.connect("builder-inited", write_flat_api)


# -- gallery: small scripts executed at build time ----------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": ["gallery"],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": r"/plot_",
    "abort_on_example_error": True,
    # Run every script at every build, not only changed ones: a change of bayesfo that breaks
    # a script must fail the build, not leave the output of an earlier run in the page.
    "run_stale_examples": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "capture_repr": (),  # print() shows what a script means to show, not a last expression
    "show_memory": False,
}

# -- HTML -----------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"bayesfo {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "navigation_depth": 2,
    "header_links_before_dropdown": 4,
    "secondary_sidebar_items": ["page-toc"],
}
html_static_path: list[str] = []
html_show_sourcelink = False
