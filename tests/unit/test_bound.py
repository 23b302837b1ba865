"""The evidence bound's rule (bayesfo.inference.bound): one rule, one margin."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bayesfo.inference.bound import (
    BOUND_MARGIN,
    bounded,
    model_probabilities,
    probability_bound,
)


def test_one_margin_of_ten_nats_shared_by_compare_and_mastercurve():
    from bayesfo.tts import joint, shifts

    assert BOUND_MARGIN == 10.0
    assert shifts.BOUND_MARGIN is BOUND_MARGIN and joint.LAW_BOUND_MARGIN is BOUND_MARGIN


def test_a_best_fit_more_than_the_margin_below_the_leader_is_ruled_out():
    assert bounded(-110.01, -100.0)
    assert not bounded(-110.0, -100.0)  # exactly at the margin: not beyond it
    assert not bounded(-95.0, -100.0)
    assert bounded(-math.inf, -100.0)  # no admissible point at all
    assert not bounded(-500.0, None) and not bounded(-500.0, math.nan)
    assert bounded(-101.0, -100.0, margin=0.5) and not bounded(-101.0, -100.0, margin=2.0)
    with pytest.raises(ValueError, match="margin"):
        bounded(-1.0, 0.0, margin=-1.0)


def test_probabilities_from_log_evidence_and_prior_odds():
    p = model_probabilities([0.0, np.log(3.0), -np.inf])
    assert p == pytest.approx([0.25, 0.75, 0.0])
    assert model_probabilities([0.0, 0.0], np.log([1.0, 4.0])) == pytest.approx([0.2, 0.8])
    assert np.isnan(model_probabilities([-np.inf, -np.inf])).all()
    # Huge ln Z do not overflow.
    assert model_probabilities([-1e6, -1e6 - np.log(2)]) == pytest.approx([2 / 3, 1 / 3])


def test_the_probability_of_a_bounded_model_is_at_most_that_at_its_bound():
    upper = probability_bound(-110.0, [-100.0, -100.0])
    assert upper == pytest.approx(np.exp(-10) / (2 + np.exp(-10)))
    assert upper < np.exp(-BOUND_MARGIN)
    # Any ln Z below the bound gives a smaller probability (the bound is an upper bound).
    for log_z in (-110.5, -120.0, -400.0):
        assert model_probabilities([log_z, -100.0, -100.0])[0] < upper
    assert probability_bound(-np.inf, [-100.0]) == 0.0
