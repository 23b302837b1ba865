"""Multi-start least squares: exact recovery without noise, reproducibility, input checks."""

from __future__ import annotations

import numpy as np
import pytest

from bayesfo.data import FrequencyResponse
from bayesfo.errors import InputError
from bayesfo.identify import fit_structure
from bayesfo.structures import get_structure

W = np.logspace(np.log10(0.6), np.log10(300), 25)  # the thesis' simulation grid (§3.4)


@pytest.mark.parametrize(
    "name, theta, kind",
    [
        ("voigt", [1.0, 1.0, 0.5], "compliance"),             # G_spec = 1/(1 + s^0.5), eq. (3.24)
        ("zener", [0.5, 2e-3, 1e-5, 0.6], "compliance"),       # physical units, plateaus 2e-3 and 2e-5
        ("maxwell", [3e4, 0.2, 0.3, 0.7], "compliance"),
        ("zener", [0.5, 2e-3, 1e-5, 0.6], "modulus"),
        ("max-n2m1", [0.8, 0.15, 1.0, 0.1, 0.45], "generic"),
    ],
)
def test_noise_free_data_recover_the_parameters(name, theta, kind):
    s = get_structure(name)
    data = FrequencyResponse(W, s.response(theta, W, kind), kind=kind)
    fit = fit_structure(s, data, rng=3)
    assert fit.admissible
    np.testing.assert_allclose(fit.theta, theta, rtol=1e-6)
    assert fit.rmse < 1e-9 * np.abs(data.response).max()


def test_same_seed_same_numbers_and_reported_counts():
    s = get_structure("zener")
    rng = np.random.default_rng(11)
    g = s.response([0.5, 1.0, 0.02, 0.5], W, "compliance")
    data = FrequencyResponse(W, g + 1e-3 * (rng.normal(size=25) + 1j * rng.normal(size=25)),
                             kind="compliance")
    a = fit_structure(s, data, rng=5)
    b = fit_structure(s, data, rng=5)
    np.testing.assert_array_equal(a.theta, b.theta)
    # The search stops once 4 starts agree on the best optimum and at least 12 have run.
    assert 12 <= a.n_starts < 24 and 4 <= a.n_at_best <= a.n_admissible <= a.n_starts
    full = fit_structure(s, data, rng=5, stop_after=None)
    assert full.n_starts == 24 and full.chi2 == pytest.approx(a.chi2, rel=1e-6)
    assert abs(a.theta[3] - 0.5) < 0.05


def test_fit_checks_input():
    s = get_structure("zener")
    small = FrequencyResponse(W[:3], np.ones(3), kind="compliance")
    with pytest.raises(InputError, match="fewer than the 4 parameters"):
        fit_structure(s, small)
    data = FrequencyResponse(W, np.ones(25), kind="compliance")
    with pytest.raises(InputError, match="weighting 'sigma' needs sigma"):
        fit_structure(s, data, weighting="sigma")
    with pytest.raises(InputError, match="'n_starts' must be at least 1"):
        fit_structure(s, data, n_starts=0)


def _g_spec_noisy():
    """G_spec with complex noise of sd 0.005 (σ known), seed 3: the set-up of the posterior tests."""
    from bayesfo.studies import OMEGA, g_spec

    rng = np.random.default_rng(3)
    noise = 5e-3 / np.sqrt(2) * (rng.normal(size=25) + 1j * rng.normal(size=25))
    return FrequencyResponse(OMEGA, g_spec() + noise, np.full(25, 5e-3), kind="compliance")


def test_optima_on_the_passivity_boundary_are_found():
    # On G_spec data the unconstrained max-n2m0 optima have a1 < 0 (q ≈ 0.25) or a2 < 0
    # (q ≈ 0.5): dissipation turns negative decades outside the data, so no local optimum is
    # admissible. The optimiser re-solves them onto the boundary a1 = 0 (resp. a2 = 0).
    from bayesfo.structures.passivity import commensurate_passive

    s = get_structure("max-n2m0")
    fit = fit_structure(s, _g_spec_noisy(), rng=0, seed_methods=True)
    assert fit.admissible and len(fit.optima) >= 2
    assert commensurate_passive(*s.polynomials(fit.optima)).all()
    qs = sorted(fit.optima[:, -1])
    assert abs(qs[0] - 0.25) < 0.02 and abs(qs[-1] - 0.5) < 0.02
    a1, a2 = fit.theta_scaled[0], fit.theta_scaled[1]
    assert min(abs(a1), abs(a2)) < 1e-4 and min(a1, a2) >= 0


def test_repair_is_off_without_the_exact_check(monkeypatch):
    from bayesfo.identify import optimize
    from bayesfo.structures import passivity

    monkeypatch.setattr(passivity, "EXACT_COMMENSURATE", False)
    calls = []
    monkeypatch.setattr(optimize._Problem, "repair", lambda *a: calls.append(a))
    fit_structure(get_structure("max-n2m0"), _g_spec_noisy(), rng=0, n_starts=4, min_starts=4)
    assert not calls
