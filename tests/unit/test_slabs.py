"""The slabs of configurations where an element vanishes: their density is the one they draw
from (the ladder's independence moves are exact only with the right proposal density)."""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

from bayesfo.inference._configurations import _Slab


def _slab():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(3, 3))
    chol = np.linalg.cholesky(a @ a.T + 0.5 * np.eye(3))
    return _Slab(index=1, lo=-9.0, hi=-5.5, mean=np.array([0.3, 99.0, -1.0, 2.0]), chol=chol)


def test_slab_density_is_uniform_times_normal():
    slab = _slab()
    rng = np.random.default_rng(1)
    x = rng.normal(size=(50, 4))
    x[:, 1] = rng.uniform(-10.0, -5.0, size=50)
    inside = (x[:, 1] >= -9.0) & (x[:, 1] <= -5.5)
    normal = stats.multivariate_normal(slab.mean[[0, 2, 3]], slab.chol @ slab.chol.T)
    expected = np.where(inside, normal.logpdf(x[:, [0, 2, 3]]) - math.log(3.5), -np.inf)
    assert inside.any() and not inside.all()
    np.testing.assert_allclose(slab.log_pdf(x), expected, rtol=1e-12)


def test_slab_draws_follow_its_density():
    slab = _slab()
    x = slab.sample(40_000, np.random.default_rng(2))
    assert np.all((x[:, 1] >= -9.0) & (x[:, 1] <= -5.5))
    # Uniform along the coordinate: mean and variance of U(-9, -5.5), within 4 standard errors.
    n = len(x)
    assert abs(x[:, 1].mean() + 7.25) < 4 * math.sqrt(3.5**2 / 12 / n)
    assert abs(x[:, 1].var() - 3.5**2 / 12) < 4 * 3.5**2 / 12 * math.sqrt(0.8 / n)
    # Normal in the others: mean and covariance.
    rest = x[:, [0, 2, 3]]
    cov = slab.chol @ slab.chol.T
    se = np.sqrt(np.diag(cov) / n)
    assert np.all(np.abs(rest.mean(axis=0) - slab.mean[[0, 2, 3]]) < 4 * se)
    tolerance = 4 * np.max(np.diag(cov)) * math.sqrt(2 / n)
    np.testing.assert_allclose(np.cov(rest, rowvar=False), cov, atol=tolerance)
