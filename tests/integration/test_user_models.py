"""models/ at the repository root: the place for users' own cards. Its two worked examples (a
custom network, a custom prior) load with --models models, evaluate as written and run."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from bayesfo.structures import load_library, resolve_structures

ROOT = Path(__file__).parents[2]
MODELS = ROOT / "models"
DATA = ROOT / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"


def test_the_example_cards_load_and_evaluate_as_written():
    assert (MODELS / "README.md").is_file()
    library = load_library([MODELS])
    network = library["springpot_dashpot"]
    assert [p.name for p in network.parameters] == ["c_alpha", "eta", "alpha"]
    # Its compliance is 1/(c_alpha s^alpha + eta s), the modulus the network's sum.
    w = np.logspace(-2, 3, 6)
    theta = np.array([[2.0, 0.5, 0.3]])
    modulus = 2.0 * (1j * w) ** 0.3 + 0.5 * 1j * w
    np.testing.assert_allclose(network.response(theta, w, "modulus")[0], modulus, rtol=1e-12)
    assert "springpot_dashpot-inv" not in library and "springpot_dashpot-int" not in library
    informed = library["zener_informed"]
    priors = {p.name: p.prior.to_dict() for p in informed.parameters}
    assert priors["q"] == {"prior": "uniform", "low": 0.3, "high": 0.7}
    assert priors["a1"] == {"prior": "log-uniform", "low": 0.01, "high": 100.0}
    # The built-in zener is untouched beside it.
    assert library["zener"].parameters[3].prior.to_dict()["low"] == 0.0
    assert [s.name for s in resolve_structures("zener_informed,springpot_dashpot", library)] \
        == ["zener_informed", "springpot_dashpot"]


@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_compare_runs_them_with_models_models(tmp_path, run_cli, monkeypatch):
    monkeypatch.chdir(ROOT)
    status, text, err = run_cli("compare", DATA, "--models", "models", "--structures",
                                "springpot_dashpot,zener_informed", "--no-figures",
                                "--workers", "1", "--out", tmp_path / "run")
    assert status == 0, err
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    found = {s["name"]: s for s in summary["structures"]}
    assert set(found) == {"springpot_dashpot", "zener_informed"}
    q = found["zener_informed"]["parameters"]["q"]
    assert 0.3 <= q["hdi_low"] <= q["mean"] <= q["hdi_high"] <= 0.7
    assert abs(q["mean"] - 0.57) < 0.05
    # The network's parameters in the data's units (c_alpha in Pa s^alpha, eta in Pa s).
    network = found["springpot_dashpot"]["parameters"]
    assert network["eta"]["unit"] == "Pa s" and network["c_alpha"]["unit"] == "Pa s^alpha"
