"""The runnable examples, each in its quick form, with checks on the numbers they produce.

Every example is imported by path and its ``main(["--quick", "--out", DIR])`` run in-process;
the assertions are on summary.json and on the generated data files. The full forms are marked
slow.
"""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def load(name: str):
    """Import ``examples/<name>.py`` as a module (the examples are scripts, not a package)."""
    spec = importlib.util.spec_from_file_location(f"example_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def summary(path: Path) -> dict:
    return json.loads((path / "summary.json").read_text(encoding="utf-8"))


def by_name(s: dict) -> dict:
    return {r["name"]: r for r in s["structures"]}


@pytest.fixture(autouse=True)
def _examples_env(monkeypatch):
    # As when a script is run, its directory is on sys.path (for the shared _common module).
    monkeypatch.syspath_prepend(str(EXAMPLES))
    monkeypatch.setenv("MPLBACKEND", "Agg")


# ---------------------------------------------------------------------- generated data
@pytest.mark.parametrize("name", ["pp_compliance", "dashpot"])
def test_bundled_csv_is_what_the_generator_produces(name):
    # The bundled files are generated from thesis tables with a fixed seed: regenerating must
    # give the same file, so the data set the CLI reads is the one the example documents (the
    # same lines, each number within 1e-13 relative: the last bit of a complex power may differ
    # between CPUs).
    from _common import same_csv

    ex = load(name)
    bundled, made = ex.CSV.read_text(encoding="utf-8"), ex.csv_text()
    assert same_csv(bundled, made)
    # The comparison can fail: a number changed in its 12th digit, or a comment, is not the same.
    lines = made.splitlines()
    row = next(i for i, line in enumerate(lines) if line[:1].isdigit())
    cells = lines[row].split(",")
    cells[1] = repr(float(cells[1]) * (1 + 1e-11))
    assert not same_csv(bundled, "\n".join(lines[:row] + [",".join(cells)] + lines[row + 1:]))
    assert not same_csv(bundled, made.replace("#", "# x", 1))


def test_pp_csv_reads_back_as_the_generated_response():
    from bayesfo import read_csv

    ex = load("pp_compliance")
    data, generated = read_csv(ex.CSV), ex.generate()
    assert data.kind == "compliance" and data.n_frequencies == 12
    # freq [Hz] in the file becomes ω = 2πf: the same to rounding of the product.
    np.testing.assert_allclose(data.omega, generated.omega, rtol=1e-15)
    # The same numbers, to the last bits that a complex power may round differently on
    # another CPU than on the one that wrote the file.
    np.testing.assert_allclose(data.response, generated.response, rtol=1e-13, atol=0)
    # The noise is what the docstring says: residuals against the truth have an RMS near σ
    # (12 points: the sample RMS has a relative sd of about 1/sqrt(2·12) ≈ 0.2).
    rms = np.sqrt(np.mean(np.abs(data.response - ex.truth_response(data.omega)) ** 2))
    assert 0.5 * ex.SIGMA < rms < 1.5 * ex.SIGMA
    # Both validation frequencies of the thesis are on the grid (hold-out needs exact matches).
    for f in ex.HOLDOUT_HZ:
        assert np.isclose(data.omega, 2 * np.pi * f, rtol=1e-9).sum() == 1


def test_dashpot_csv_averages_to_an_integrator_with_known_sigma():
    from bayesfo import read_csv

    ex = load("dashpot")
    data = read_csv(ex.CSV)
    assert data.kind == "generic" and data.sigma is not None
    # Ten series with 10 % noise each: the standard error of the mean is about 3 % of |G|.
    rel = data.sigma / np.abs(data.response)
    assert 0.015 < np.median(rel) < 0.05
    # Integrator: |G| falls by a decade per decade at low frequency, phase near -90° there.
    lo = data.omega < 0.1
    slope = np.polyfit(np.log10(data.omega[lo]), np.log10(np.abs(data.response[lo])), 1)[0]
    assert abs(slope + 1) < 0.1
    assert np.all(np.abs(data.phase_deg[lo] + 90) < 10)


# ---------------------------------------------------------------------- quick forms
def test_pp_compliance_quick(tmp_path, capsys):
    ex = load("pp_compliance")
    assert ex.main(["--quick", "--out", str(tmp_path)]) == 0
    s = summary(tmp_path)
    rows = by_name(s)
    # Held-out validation was done at the thesis' two frequencies and is reported per structure.
    assert len(s["data"]["holdout_omega"]) == 2
    assert s["data"]["n_frequencies"] == 10
    for r in rows.values():
        assert math.isfinite(r["holdout_lpd"]) and r["holdout_rmse"] > 0
    # The truth (voigt) or the structure that nests it (zener, equal in ln Z within ~1 nat
    # since its extra compliance is undetermined) ranks first.
    assert s["ranking"][0] in ("voigt", "zener")
    # The integer baseline cannot bend the phase like s^0.7: many nats below.
    assert rows["voigt"]["log_evidence"] - rows["voigt-int"]["log_evidence"] > 10
    # q of the truth's structure covers the generating value 0.698 (94 % HDI; the fixed data
    # seed gives q = 0.695 ± 0.014, so this is not a coin flip).
    q = rows["voigt"]["parameters"]["q"]
    assert q["hdi_low"] <= ex.TRUTH["q"] <= q["hdi_high"]
    # The max-order member fits the fitted points more closely than the truth's structure,
    # yet has less evidence: the overfitting the example is about.
    assert rows["max-n2m2"]["rmse"] < rows["voigt"]["rmse"]
    assert rows["max-n2m2"]["log_evidence"] < rows["voigt"]["log_evidence"] - 3
    assert "Held out" in capsys.readouterr().out
    # write_outputs drew the figures and the report next to the numbers.
    assert (tmp_path / "report.html").stat().st_size > 0


def test_dashpot_quick_picks_an_inverted_structure(tmp_path, capsys):
    ex = load("dashpot")
    assert ex.main(["--quick", "--out", str(tmp_path)]) == 0
    s = summary(tmp_path)
    rows = by_name(s)
    best = rows[s["ranking"][0]]
    assert best["inverted"], s["ranking"]
    # The structure that generated the data (max-n0m2-inv at q = 1) is the winner.
    assert best["name"] == "max-n0m2-inv-int"
    # Without inversion the best a fixed leading 1 in the denominator can do is to push the
    # pole to the edge of the prior: far behind (tens of nats; a Bayes factor beyond doubt).
    plain = [r for r in rows.values() if not r["inverted"]]
    best_plain = max(r["log_evidence"] for r in plain)
    assert best["log_evidence"] - best_plain > 20
    out = capsys.readouterr().out
    assert "Without inverted structures" in out and "With inverted structures" in out


def test_real_data_quick(tmp_path, capsys):
    ex = load("real_data")
    assert ex.main(["--quick", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    # Attribution of both public data sets is printed.
    assert "MIT License" in out and "BSD-3-Clause" in out
    adhesive = by_name(summary(tmp_path / "Tp020C"))
    nrel = by_name(summary(tmp_path / "nrel_dma_master"))
    # The fractional order beats its integer baseline by tens of nats on both materials
    # (README: about 100 nats on the adhesive), and q is well inside (0, 1).
    assert adhesive["voigt"]["log_evidence"] - adhesive["voigt-int"]["log_evidence"] > 50
    assert nrel["zener"]["log_evidence"] - nrel["zener-int"]["log_evidence"] > 50
    q = adhesive["voigt"]["parameters"]["q"]
    assert 0.5 < q["hdi_low"] < q["hdi_high"] < 0.6
    # No sigma in the file: the evidence chose the noise model (constant, by about 7 nats).
    assert adhesive["voigt"]["noise"] == adhesive["voigt"]["noise_models"]["chosen"]


def test_thesis_simulation_quick(tmp_path, capsys):
    ex = load("thesis_simulation")
    assert ex.main(["--quick", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "figure-3.2.png").stat().st_size > 0
    rows = by_name(summary(tmp_path / "posterior_gspec"))
    # The n = 1, m = 0 structure pins q to the truth 0.5 within a few hundredths (σ = 0.005 on
    # |G| from 0.05 to 0.6: Table A.7's optimisation gives var q = 4.5e-5, sd 0.007).
    q1 = rows["voigt"]["parameters"]["q"]
    assert q1["hdi_low"] < 0.5 < q1["hdi_high"] and q1["hdi_high"] - q1["hdi_low"] < 0.05
    # n = m = 2 reproduces G_spec exactly at q = 1/4 as well as 1/2, yet nearly all of its
    # posterior mass lies at q = 1/2: dynesty (500 live points, slice sampling) on this data set
    # puts 0.962 of it within ±0.03 of 0.5, 2e-29 near 0.25 and 0.038 elsewhere. The walkers
    # of the quick run do not converge here; the ladder's particles are the posterior.
    q2 = rows["max-n2m2"]["parameters"]["q"]
    assert 0.44 < q2["hdi_low"] < 0.5 < q2["hdi_high"] < 0.56
    assert rows["voigt"]["log_evidence"] > rows["max-n2m2"]["log_evidence"]
    out = capsys.readouterr().out
    assert "table-a.7" in out and "aliases" in out


def test_alias_shares_partition_the_draws():
    ex = load("thesis_simulation")
    shares = ex.alias_shares([0.5, 0.51, 0.25, 0.17, 0.9])
    assert shares == {"0.5": 0.4, "0.25": 0.2, "0.167": 0.2, "other": 0.2}
    assert math.isclose(sum(shares.values()), 1.0)


# ---------------------------------------------------------------------- full forms
@pytest.mark.slow
@pytest.mark.parametrize("name", ["pp_compliance", "dashpot", "real_data", "thesis_simulation"])
def test_full_forms_run(name, tmp_path):
    ex = load(name)
    argv = ["--out", str(tmp_path)]
    if name == "thesis_simulation":
        argv += ["--runs", "2000", "--global-runs", "20"]
    assert ex.main(argv) == 0
    found = list(tmp_path.rglob("summary.json"))
    assert found
    for path in found:
        s = json.loads(path.read_text(encoding="utf-8"))
        assert s["ranking"]


if __name__ == "__main__":  # pragma: no cover
    sys.exit(pytest.main([__file__, "-q"]))
