"""Parameters whose posterior a prior bound ends are not estimates: flagged as not determined,
with the reason, and so are the physical quantities that follow them (found trying the tool as
a new user: a zero-shear viscosity at the top of its prior shown as a value)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import bayesfo as bf
from bayesfo.comparison.parameters import FOLLOWS, _following, prior_limited
from bayesfo.structures import get_structure

DATA = "examples/data/adhesive_468mp/Tp150C.csv"


@pytest.fixture(scope="module")
def result():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return bf.compare(bf.read(DATA), "fractional_maxwell_liquid,zener", seed=0,
                          progress=False, workers=1)


def test_a_viscosity_at_the_top_of_its_prior_is_not_an_estimate(result, tmp_path):
    # At 150 °C the adhesive still flows too slowly in the window for the dashpot of the
    # fractional Maxwell liquid: its viscosity runs to the prior's upper bound.
    fml = result["fractional_maxwell_liquid"]
    bounds = {k: s.at_prior_bound for k, s in fml.posterior.summary.items()}
    assert bounds == {"c_alpha": "", "eta": "high", "alpha": "", "sigma": ""}
    physical = fml.physical["physical"]
    assert physical["eta"]["not_determined"]
    assert physical["eta"]["not_determined_reason"].startswith(
        "its posterior runs to the prior's upper bound, which the prior, not the data, sets "
        "(--prior eta=... widens it")
    # Its relaxation time tau^(1-alpha) = eta/c_alpha follows eta; c_alpha and alpha do not.
    assert physical["tau"]["not_determined_reason"].startswith("it follows eta (rank correlation")
    assert not physical["c_alpha"]["not_determined"] and not physical["alpha"]["not_determined"]
    # The Zener's posterior ends inside its priors: nothing flagged.
    zener = result["zener"]
    assert not any(s.at_prior_bound for s in zener.posterior.summary.values())
    assert not any(v["not_determined"] for v in zener.physical["physical"].values())
    # Written and loaded back, the flag stays (a run written before it existed loads with "").
    bf.write_outputs(result, tmp_path / "run", figures=False)
    loaded = bf.load(tmp_path / "run")
    assert loaded["fractional_maxwell_liquid"].posterior.summary["eta"].at_prior_bound == "high"
    assert loaded["fractional_maxwell_liquid"].physical["physical"]["eta"]["not_determined"]


def test_a_quantity_follows_a_limited_coefficient_by_its_rank_correlation():
    """G_e = 1/b0 follows b0 wholly; a modulus fixed by the data while the coefficients it is
    made of run to their bounds together along a ridge (a1 ∝ b0 ∝ b1, so a1/b1 stays put) is
    not flagged. Orders are never limited by their prior (their bounds are the structure's
    own)."""
    zener = get_structure("zener")
    rng = np.random.default_rng(0)
    ridge = np.exp(rng.normal(size=2000))

    def scatter():
        return np.exp(0.01 * rng.normal(size=2000))

    draws = {"a1": 2.0 * ridge * scatter(), "b0": 0.5 * ridge * scatter(),
             "b1": 0.1 * ridge * scatter(), "q": 0.5 + 0.01 * rng.normal(size=2000)}
    g_e, g_m = 1.0 / draws["b0"], draws["a1"] / draws["b1"]
    form = {"G_e": (g_e, "Pa"), "G_m": (g_m, "Pa")}
    out = _following(zener, form, draws, {"a1": "upper", "b0": "upper"})
    assert list(out) == ["G_e"]
    assert out["G_e"] == ("it follows b0 (rank correlation -1.00), whose posterior runs to the "
                          "prior's upper bound, which the prior, not the data, sets (--prior "
                          "b0=... widens it, on the scaled problem)")
    assert abs(np.corrcoef(np.argsort(np.argsort(g_m)),
                           np.argsort(np.argsort(draws["a1"])))[0, 1]) < FOLLOWS

    class S:
        def __init__(self, side):
            self.at_prior_bound = side

    assert prior_limited(zener, {"a1": S("high"), "b0": S(""), "q": S("low")}) == {
        "a1": "upper"}
