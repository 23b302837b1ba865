"""Adequacy on real data that no built-in structure describes (read from the GPL reference
data in ../shared/data/reference-gpl, never copied into the project; slow).

* The chia-seed pudding of pyRheo: the published model is two springpots in parallel; the
  fractional Voigt misses the low-frequency phase by about 14°.
* The polyisoprene master curve PI 94.9k of RepTate (8 decades): the generalised Maxwell misses
  the transition zone.
"""

from __future__ import annotations

import csv
import warnings
from pathlib import Path

import pytest

import bayesfo as bf

GPL = Path(__file__).parents[3] / "shared" / "data" / "reference-gpl"

pytestmark = pytest.mark.slow


def _write(rows, path: Path, name: str) -> Path:
    with open(path, "w", newline="") as fh:
        fh.write(f"# kind: modulus\n# units: Pa\n# name: {name}\nomega,storage,loss\n")
        csv.writer(fh).writerows(rows)
    return path


def _chia(tmp_path) -> Path:
    src = GPL / "pyrheo_chia_pudding" / "original" / "oscillation_chia_data.csv"
    if not src.is_file():
        pytest.skip("GPL reference data not available")
    with open(src, newline="") as fh:
        rows = [r[:3] for r in list(csv.reader(fh))[1:] if r]
    return _write(rows, tmp_path / "chia.csv", "chia pudding (pyRheo)")


def _pi(tmp_path) -> Path:
    src = GPL / "reptate_pi_linear" / "original" / "tts_mastercurves" / "PI_94.9k_T-35.tts"
    if not src.is_file():
        pytest.skip("GPL reference data not available")
    rows = [line.split()[:3] for line in src.read_text().splitlines()[1:] if line.strip()]
    return _write(rows, tmp_path / "pi.csv", "PI 94.9k master curve (RepTate)")


def _compare(path, structures):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # Every candidate's posterior predictive checks: every one sampled.
        return bf.compare(bf.read(path), structures, seed=0, workers=2, progress=False,
                          sample="all")


def test_no_candidate_describes_the_chia_gel(tmp_path):
    result = _compare(_chia(tmp_path), "voigt,zener,maxwell")
    fits = {r.name: r.fits for r in result.results}
    assert set(fits.values()) == {"no"}, fits
    voigt = result["voigt"].adequacy
    assert voigt.max_phase_error_deg > 10 and min(voigt.systematic_at_omega) < 0.1
    from bayesfo.output.report import verdict

    assert any(t.startswith("None of the candidates describes these data") and flagged
               for t, flagged in verdict(result))


def test_no_candidate_describes_the_polyisoprene_master_curve(tmp_path):
    result = _compare(_pi(tmp_path), "voigt,zener,maxwell")
    assert {r.fits for r in result.results} == {"no"}
    best = result[result.ranking[0]].adequacy
    assert best.max_log10_magnitude_error > 0.1  # more than 25 % in |G|
