"""Calibration of credible intervals over simulated data sets (Voigt and Zener truths).

For each data set a truth is drawn (several q and noise levels), data are simulated with known
per-point σ, the posterior is sampled and every parameter's central 50 % and 90 % intervals are
checked for the truth. Over many data sets the coverage must match the nominal rates.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from bayesfo.data import FrequencyResponse
from bayesfo.inference import ConvergenceWarning, run_posterior
from bayesfo.structures import get_structure

W = np.logspace(np.log10(0.6), np.log10(300), 25)


def _truth(name, rng):
    q = rng.choice([0.3, 0.5, 0.8])
    if name == "voigt":
        return np.array([10 ** rng.uniform(-1, 1), 10 ** rng.uniform(-4, -2), q])
    a1, b0 = 10 ** rng.uniform(-1, 1), 10 ** rng.uniform(-4, -2)
    b1 = a1 * b0 * 10 ** rng.uniform(-2, -0.5)  # instantaneous compliance below static
    return np.array([a1, b0, b1, q])


def coverage(name, n_sets, seed):
    rng = np.random.default_rng(seed)
    s = get_structure(name)
    hits = {0.5: [], 0.9: []}
    for k in range(n_sets):
        theta = _truth(name, rng)
        g = s.response(theta, W, "compliance")
        sd = rng.choice([0.01, 0.05]) * np.abs(g)
        noisy = g + sd / np.sqrt(2) * (rng.normal(size=25) + 1j * rng.normal(size=25))
        data = FrequencyResponse(W, noisy, sd, kind="compliance")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            result, _ = run_posterior(s, data, seed=k, progress=False, predictive=False)
        for level in hits:
            lo, hi = np.quantile(result.samples, [(1 - level) / 2, (1 + level) / 2], axis=0)
            hits[level].extend((theta >= lo) & (theta <= hi))
    return {level: float(np.mean(h)) for level, h in hits.items()}


@pytest.mark.parametrize("name", ["voigt", "zener"])
def test_calibration_quick(name):
    # 16 data sets x 3-4 parameters: the binomial sd of a coverage is about 0.06 (parameters of
    # one data set are correlated), so the bands are 3 sd wide.
    cov = coverage(name, 16, seed=11)
    assert 0.30 <= cov[0.5] <= 0.70, cov
    assert 0.75 <= cov[0.9] <= 1.0, cov


@pytest.mark.slow
@pytest.mark.parametrize("name", ["voigt", "zener"])
def test_calibration_full(name):
    # 200 data sets: nominal rate within ±5 % (binomial sd about 0.015-0.02 for 200-800 checks).
    cov = coverage(name, 200, seed=12)
    assert abs(cov[0.5] - 0.5) <= 0.05, cov
    assert abs(cov[0.9] - 0.9) <= 0.05, cov
