"""The wheel ships every subpackage (an editable install would hide a missing one)."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).parents[2]


def test_every_subpackage_is_listed():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(config["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "bayesfo").rglob("__init__.py")}
    assert found <= listed, f"missing from pyproject.toml packages: {sorted(found - listed)}"
    assert "package-dir" not in config, "every package lives under bayesfo/"
    assert any((ROOT / "bayesfo" / "models").glob("*.toml"))
    assert config["package-data"]["bayesfo.models"] == ["*.toml"]
