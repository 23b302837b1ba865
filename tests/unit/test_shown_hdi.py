"""The interval a report shows for a quantity with a unit is the one its 'not determined' flag
judges: the 94 % HDI on a log scale (``log_scale_hdi``), not the HDI of the values."""

from __future__ import annotations

import math

import numpy as np

from bayesfo.comparison.parameters import (
    UNDETERMINED_DECADES,
    log_scale_hdi,
    shown_hdi,
    summarise_draws,
    with_determination,
)


def _block(draws, unit="Pa"):
    return with_determination({"x": summarise_draws(draws, float(np.median(draws)), unit)},
                              draws={"x": draws})["x"]


def test_a_lognormal_quantity_shows_the_hdi_of_its_logarithm():
    # log10 x ~ N(3, 0.4): the 94 % HDI of the logarithm is 3 ± 1.881·0.4 (closed form).
    draws = 10 ** np.random.default_rng(0).normal(3.0, 0.4, 40_000)
    s = _block(draws)
    lo, hi = shown_hdi(s)
    z = 1.8808  # the 97th percentile of the standard normal
    assert math.isclose(math.log10(lo), 3 - z * 0.4, abs_tol=0.02)
    assert math.isclose(math.log10(hi), 3 + z * 0.4, abs_tol=0.02)
    # The HDI of the values leans towards small values: both its ends lie below.
    assert s["hdi_low"] < lo and s["hdi_high"] < hi


def test_the_flag_and_the_shown_interval_agree_on_both_sides_of_the_threshold():
    # The case of the issue: an HDI of the values 2.1 decades wide for a quantity whose
    # logarithms' HDI is narrower than the threshold; and its mirror case.
    rng = np.random.default_rng(1)
    for sd in (0.40, 0.50, 0.52, 0.56, 0.60, 0.70):
        draws = 10 ** rng.normal(9.0, sd, 20_000)
        s = _block(draws)
        lo, hi = shown_hdi(s)
        assert s["not_determined"] == (math.log10(hi / lo) > UNDETERMINED_DECADES), sd
        # a quantity and its reciprocal: the same flag and reciprocal shown intervals
        r = _block(1.0 / draws, "1/Pa")
        assert r["not_determined"] == s["not_determined"]
        rlo, rhi = shown_hdi(r)
        assert math.isclose(rlo * hi, 1.0, rel_tol=1e-9) and math.isclose(rhi * lo, 1.0,
                                                                          rel_tol=1e-9)


def test_pure_numbers_signed_and_undefined_quantities_show_the_hdi_of_the_values():
    rng = np.random.default_rng(2)
    order = rng.uniform(0.4, 0.6, 4000)
    assert log_scale_hdi({"unit": ""}, order) is None
    s = _block(order, unit="")
    assert shown_hdi(s) == (s["hdi_low"], s["hdi_high"])
    signed = rng.normal(0.0, 1.0, 4000)
    assert log_scale_hdi({"unit": "Pa"}, signed) is None
    with_nan = np.where(rng.uniform(size=4000) < 0.01, np.nan, 1.0 + order)
    assert log_scale_hdi({"unit": "Pa"}, with_nan) is None
