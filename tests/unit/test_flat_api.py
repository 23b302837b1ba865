"""The flat API: ``import bayesfo as bf`` reaches everything a user needs, and importing it stays
light (the inference stack and matplotlib load on first use)."""

from __future__ import annotations

import subprocess
import sys

import bayesfo as bf


def test_import_loads_neither_matplotlib_nor_the_samplers():
    code = ("import sys, bayesfo; "
            "sys.exit(sum(m in sys.modules for m in ('matplotlib', 'emcee', 'arviz_base', 'arviz_stats', 'xarray', 'dynesty')))")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_subpackages_are_attributes():
    from bayesfo.plotting import plot_bode

    assert bf.plotting.plot_bode is plot_bode
    assert bf.inference.Likelihood is not None and bf.identify.fit_structure is not None


def test_list_structures_names_every_structure_compare_accepts():
    table = bf.list_structures()
    assert table["name"].is_unique
    for name in table["name"]:
        assert bf.get_structure(name).name == name
    row = table.set_index("name").loc["maxwell"]
    assert row["n_params"] == 4 and row["parameters"] == "a1, b1, alpha, beta"
    # Aliases are names compare accepts too, and they resolve to the row's structure.
    for alias in row["aliases"].split(", "):
        assert bf.get_structure(alias).name == "maxwell"
    assert set(bf.__all__) >= {"compare", "load", "read", "list_structures", "write_outputs"}
