"""Degenerate posteriors give reasons, not exceptions: walkers that coincide in a corner of the
prior box, and draws whose moments overflow."""

from __future__ import annotations

import math

import numpy as np

from bayesfo.comparison.parameters import summarise_draws
from bayesfo.inference.posterior import _snooker_move


def test_snooker_proposal_through_a_walkers_own_position_stays_put():
    # emcee's snooker move divides by |walker - z|: with z equal to the walker it proposes NaN
    # (and emcee raises). Here every walker sits on one point, as the integer Voigt's do in the
    # corner of its prior box on the 26-decade NREL curve.
    point = np.array([-9.21034037, 9.21034037, 2.30258509])
    s = np.tile(point, (8, 1))
    c = [np.tile(point, (8, 1)) for _ in range(3)]  # nsplits = 4: three complementary sets
    q, factors = _snooker_move().get_proposal(s, c, np.random.RandomState(0))
    assert np.array_equal(q, s)
    assert np.all(factors == 0.0)


def test_snooker_proposal_is_ter_braak_vrugts_where_walkers_differ():
    # emcee 3.1.6's DESnookerMove divides x - z by sqrt|x - z| and halves the exponent, so the
    # move is ter Braak & Vrugt's own (its invariance: tests/integration/test_emcee_spread.py).
    rng = np.random.default_rng(1)
    s, c = rng.normal(size=(8, 3)), [rng.normal(size=(8, 3)) for _ in range(3)]
    q, factors = _snooker_move().get_proposal(s, c, np.random.RandomState(4))
    r = np.random.RandomState(4)  # the same draws: one walker per set, then their roles
    picks = np.stack([cj[r.randint(len(cj), size=8)] for cj in c], axis=1)
    picks = np.take_along_axis(picks, np.argsort(r.rand(8, 3), axis=1)[:, :, None], axis=1)
    z, z1, z2 = picks[:, 0], picks[:, 1], picks[:, 2]
    e = (s - z) / np.linalg.norm(s - z, axis=1)[:, None]
    expected = s + 1.7 * np.sum(e * (z1 - z2), axis=1)[:, None] * e
    np.testing.assert_allclose(q, expected, rtol=1e-12)
    # The step lies along x - z: the proposal, the walker and z are on one line.
    np.testing.assert_allclose(np.cross(q - z, s - z), 0.0, atol=1e-12)
    ratio = np.linalg.norm(q - z, axis=1) / np.linalg.norm(s - z, axis=1)
    np.testing.assert_allclose(factors, 2.0 * np.log(ratio), rtol=1e-12)  # (d - 1) = 2


def test_moments_that_overflow_are_undefined_not_a_warning():
    # A relaxation time b1**(1/alpha) with alpha near 0: finite draws whose square overflows.
    draws = np.array([1e200, 3e200, 2e200, 5e200, 4e200])
    s = summarise_draws(draws, 2e200, "s")
    assert math.isnan(s["sd"]) and math.isnan(s["mean"])
    assert s["median"] == 3e200
    assert s["hdi_low"] <= s["median"] <= s["hdi_high"]
    ordinary = summarise_draws(np.arange(5.0), 2.0, "s")
    assert ordinary["mean"] == 2.0 and math.isclose(ordinary["sd"], math.sqrt(2.5))


def test_the_hessian_stencil_is_evaluated_in_bounded_chunks():
    """A master curve of 200 isotherms (some 200 parameters) has 83 000 stencil points: the log
    posterior was evaluated on all of them at once (83 000 × 1000 complex, a MemoryError). The
    chunks give the same gradient and Hessian."""
    import numpy as np

    from bayesfo.inference import _peaks

    a = np.random.default_rng(0).normal(size=(30, 30))
    a = a @ a.T + 30 * np.eye(30)
    largest = []

    def f(u):
        largest.append(u.shape[0])
        return -0.5 * np.einsum("ni,ij,nj->n", u, a, u)

    out = _peaks._hessian(f, np.full(30, 0.1), np.full(30, 1e-3))
    assert max(largest) <= _peaks.STENCIL_CHUNK < 1 + 2 * 30 + 2 * 30 * 29
    f0, grad, hess = out
    np.testing.assert_allclose(hess, -a, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(grad, -a @ np.full(30, 0.1), rtol=1e-6)
