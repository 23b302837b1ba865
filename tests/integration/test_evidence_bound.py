"""The evidence bound in compare (issue 64): a structure whose best fit lies more than
BOUND_MARGIN nats below the leader's certified ln Z is not sampled by default; sample="all"
samples it, and its ln Z then lies below the bound; the outputs and load carry it; the
bounded structures are re-checked when a sampled structure's draws beat the optimiser."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import pytest

from bayesfo import read
from bayesfo.comparison import compare, load
from bayesfo.inference.bound import BOUND_MARGIN, BOUND_REASON
from bayesfo.output import write_outputs
from bayesfo.output.write import _finite

ADHESIVE = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"
# On this isotherm the fractional Kelvin-Voigt model is certified quickly (importance
# sampling) and the generalised Maxwell model misfits by tens of nats and would need the
# tempered ladder: the case the bound is for.
PAIR = "fractional_kelvin_voigt,maxwell"


def _compare(**kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return compare(read(ADHESIVE), PAIR, progress=False, **kwargs)


@pytest.fixture(scope="module")
def needed():
    return _compare()


@pytest.fixture(scope="module")
def every():
    return _compare(sample="all")


def test_a_structure_whose_best_fit_bounds_its_evidence_is_not_sampled(needed):
    lead, out = needed["fractional_kelvin_voigt"], needed["maxwell"]
    assert lead.sampled and lead.posterior.converged
    assert not out.sampled and out.posterior is None and out.log_z is None
    bound = out.criteria.bound
    assert bound["reason"] == BOUND_REASON and bound["leader"] == "fractional_kelvin_voigt"
    assert bound["margin"] == BOUND_MARGIN
    # ln Z <= max ln L: the bound is the largest best fit over the noise models considered.
    assert out.log_z_bound == max(bound["by_noise"].values()) == out.criteria.max_log_likelihood
    assert set(bound["by_noise"]) == {"constant", "proportional", "relative_parts"}
    assert out.log_z_bound < lead.log_z - BOUND_MARGIN
    assert bound["posterior_probability_bound"] < math.exp(-BOUND_MARGIN)
    assert out.probability is None and lead.probability == 1.0
    # What needs only the best fit stays; what needs a posterior is absent.
    c = out.criteria
    assert all(math.isfinite(getattr(c, k)) for k in ("aic", "aicc", "bic", "rmse"))
    assert c.loo is None and c.waic is None
    # The posterior predictive checks with the best fit standing in for the posterior.
    assert out.adequacy is not None and out.adequacy.n_draws == 1 and out.fits == "no"
    assert needed.ranking == ["fractional_kelvin_voigt", "maxwell"]
    assert needed.evidence_bound["bounded"] == ["maxwell"]
    text = needed.summary()
    assert f"≤ {out.log_z_bound:.2f}" in text and BOUND_REASON in text


def test_sample_all_samples_it_and_its_evidence_lies_below_the_bound(needed, every):
    out = every["maxwell"]
    assert out.sampled and out.criteria.bound is None
    assert out.log_z < needed["maxwell"].log_z_bound
    # The draws never beat the optimiser's maximum (by more than rounding).
    assert out.posterior.max_log_likelihood <= needed["maxwell"].log_z_bound + 1e-6
    # The leader's numbers do not depend on the bound.
    assert every["fractional_kelvin_voigt"].log_z == needed["fractional_kelvin_voigt"].log_z
    assert every.ranking == needed.ranking
    assert every.evidence_bound["bounded"] == []


def test_summary_and_load_round_trip_a_bounded_structure(needed, tmp_path):
    from bayesfo.output.report import render_report

    write_outputs(needed, tmp_path, figures=False)
    assert not (tmp_path / "maxwell.nc").exists()  # no NetCDF for a structure not sampled
    summary = json.loads((tmp_path / "summary.json").read_text())
    record = next(s for s in summary["structures"] if s["name"] == "maxwell")
    assert record["sampled"] is False and record["log_evidence"] is None
    assert record["log_evidence_bound"] == pytest.approx(needed["maxwell"].log_z_bound)
    assert record["posterior_probability_bound"] < math.exp(-BOUND_MARGIN)
    assert "global multi-start" in record["best_fit_source"]
    assert record["adequacy_of"] == "best fit" and record["adequacy"]["adequate"] is False
    assert summary["evidence_bound"]["margin"] == BOUND_MARGIN
    lead = next(s for s in summary["structures"] if s["name"] == "fractional_kelvin_voigt")
    assert lead["sampled"] is True
    loaded = load(tmp_path)
    again = json.loads(json.dumps(_finite(loaded.to_summary())))
    assert again["structures"] == summary["structures"]
    assert loaded.evidence_bound == summary["evidence_bound"]
    assert loaded["maxwell"].log_z_bound == needed["maxwell"].log_z_bound
    assert loaded.summary() == needed.summary()
    html = render_report(loaded)
    assert "≤ " in html and "not sampled" in html


def test_bounded_structures_are_sampled_when_draws_beat_the_optimiser(monkeypatch):
    from bayesfo.comparison import schedule

    true_best_fit = schedule.best_fit

    def missing(*args, **kwargs):
        # An optimiser that misses the maximum of the sampled structure by 100 nats: its
        # draws then reach 100 nats higher, and the bounds of the others are not trusted.
        return true_best_fit(*args, **kwargs) - 100.0

    monkeypatch.setattr(schedule, "best_fit", missing)
    result = _compare()
    assert result["maxwell"].sampled and result["maxwell"].log_z is not None
    assert result.evidence_bound["rechecked"] == ["maxwell"]
    assert result.evidence_bound["optimiser_shortfall"] > 90.0
    assert result.evidence_bound["bounded"] == []
