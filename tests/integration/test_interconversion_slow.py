"""Known answers for the Prony export (issue 31), slow: the pyvisco verification case.

NREL pyvisco's ``verification/freq_master/prony_terms.MPL`` (BSD-3-Clause, read in place from
``../shared/data/real/pyvisco_nrel_dma``; skipped when absent) is ANSYS 2020 R1's own Prony fit
(``TBFT``, ``job_prony_fit.mac`` beside it) of the NREL DMA master curve that is bundled here as
``examples/data/nrel_dma_master.csv``: a ``TB,PRON`` table of 27 relative moduli α_i = E_i/E0 at
τ_i = 1e-14 … 1e12 s (one per decade, held fixed in the fit), written by ``MPWRITE``. It holds no
E0 (ANSYS takes the instantaneous modulus from the elastic data), so what it gives is the
normalised relaxation E(t)/E0 = 1 − Σ α_i (1 − exp(−t/τ_i)); Σ α_i = 1 − 4e-8, so ANSYS let its
series relax fully (a liquid) although the data end on a rubbery plateau of 89 MPa.

bayesfo fits the master curve (max-n3m3, the most probable structure tried, and the Zener),
``prony_series`` turns the fit into a series, and its E(t)/E0 is held against ANSYS's over the
data window t = 1/ω_max … 1/ω_min less its last decade (there ANSYS's series falls towards 0 and
the model's stays on its plateau: 16 % apart at 1/ω_min). No structure describes the curve
within its scatter (its G′ and G″ are not Kramers–Kronig consistent; ANSYS's series misses the
measured E″ by up to 85 % too), so the tolerances come from two measured sources: the model's
own misfit of E′ (a running mean over a decade of frequency around ω = 1/t) and the spread
between two reasonable Prony fits of the same data (ANSYS's, and a non-negative least-squares
fit to E′ alone on the same τ grid: 5.0 % apart). Measured (seed 0): max-n3m3 within 10.7 % of
ANSYS over the window less its last decade, 7.1 % where its running-mean E′ misfit is ≤ 4.5 %
(90 % of that window); the model's own 94 % band of E(t) is ±1.1–2.9 % there, so ANSYS's curve
lies outside it over most of the window: the band is the posterior's, not the misfit's.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import bayesfo as bf
from bayesfo.predictions import prony_series

pytestmark = pytest.mark.slow

ROOT = Path(__file__).parents[2]
REAL = Path(__file__).parents[3] / "shared" / "data" / "real"
NREL = ROOT / "examples" / "data" / "nrel_dma_master.csv"
MPL = REAL / "pyvisco_nrel_dma" / "original" / "verification" / "freq_master" / "prony_terms.MPL"

#: The spread between two reasonable Prony fits of the same data (ANSYS's and an NNLS fit to E′
#: alone on its τ grid), measured 5.0 % over the window less its last decade.
SPREAD = 0.05
#: Where the model describes E′: its running-mean relative misfit of E′ within this.
DESCRIBED = 0.045
#: Tolerances: the model's misfit of E′ where compared plus SPREAD. Over the window less its
#: last decade the running-mean misfit reaches 8.1 % (max-n3m3 at 0.1–2 Hz; allowed 8.5 %):
#: 13.5 %, measured 10.7 %; where it is ≤ 4.5 %: 9.5 %, measured 7.1 %.
TOL_WINDOW = 0.135
TOL_DESCRIBED = DESCRIBED + SPREAD


def _needs(path: Path) -> Path:
    if not path.exists():
        pytest.skip(f"{path} is not available (NREL pyvisco's verification/freq_master folder, "
                    "https://github.com/NREL/pyvisco)")
    return path


def read_ansys_prony(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(α_i, τ_i) of the ``TB,PRON`` table of an ANSYS material file."""
    lines = path.read_text().splitlines()
    n = int(next(x for x in lines if x.startswith("TB,PRON")).split(",")[4])
    values = [float(v) for x in lines if x.startswith("TBDATA,") for v in x.split(",")[2:]]
    assert len(values) == 2 * n
    return np.array(values[0::2]), np.array(values[1::2])


def relative_relaxation(alpha, tau, t) -> np.ndarray:
    """E(t)/E0 of relative moduli α_i at relaxation times τ_i."""
    t = np.asarray(t, float)
    return 1 - alpha.sum() + np.exp(-t[:, None] / tau) @ alpha


@pytest.fixture(scope="module")
def nrel():
    return bf.read(NREL)


@pytest.fixture(scope="module")
def ansys():
    return read_ansys_prony(_needs(MPL))


@pytest.fixture(scope="module")
def result(nrel, ansys):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the curve is flagged as not described: known here
        return bf.compare(nrel, "max-n3m3,zener", workers=1, progress=False, seed=0)


def _window(data):
    """105 times over 1/ω_max … 1/ω_min, and the mask of all but the last decade."""
    t = np.logspace(np.log10(1 / data.omega.max()), np.log10(1 / data.omega.min()), 105)
    return t, t <= t[-1] / 10


def _running_misfit(result, structure, t):
    """The model's relative misfit of E′, averaged over the data within ±½ decade of ω = 1/t."""
    data = result.data
    storage = result.predict("storage", data.omega, structure=structure).median
    misfit = storage / data.response.real - 1
    log_w = np.log10(data.omega)
    return np.array([misfit[np.abs(log_w + np.log10(x)) <= 0.5].mean() for x in t])


def test_the_ansys_table_and_its_frequency_convention(nrel, ansys):
    alpha, tau = ansys
    assert alpha.size == 27 and np.all(alpha >= 0)
    np.testing.assert_allclose(tau, 10.0 ** np.arange(-14, 13), rtol=1e-12)
    assert 0 < 1 - alpha.sum() < 1e-6  # it relaxes (almost) fully
    # Read with ω = 2π f, the series times its least-squares E0 reproduces the measured E′
    # within 6.9 % (E0 9.81 GPa); read with ω = f it would miss by 37 %.
    for omega, low, high in ((nrel.omega, 0.0, 0.08), (nrel.omega / (2 * np.pi), 0.3, 1.0)):
        s = 1j * omega[:, None] * tau
        shape = 1 - alpha.sum() + (alpha * s / (1 + s)).sum(axis=1)
        e0 = np.exp(np.mean(np.log(np.abs(nrel.response) / np.abs(shape))))
        assert low <= np.max(np.abs(e0 * shape.real / nrel.response.real - 1)) < high
    # A second reasonable Prony fit of the same data (NNLS on E′ alone, same τ grid, E∞ ≥ 0)
    # gives E(t)/E0 within SPREAD of ANSYS's (measured 5.0 %): the fitting ambiguity.
    from scipy.optimize import nnls

    s = 1j * nrel.omega[:, None] * tau
    basis = np.column_stack([np.ones(nrel.omega.size), (s / (1 + s)).real])
    x, _ = nnls(basis / nrel.response.real[:, None], np.ones(nrel.omega.size), maxiter=5000)
    t, inner = _window(nrel)
    direct = (x[0] + np.exp(-t[:, None] / tau) @ x[1:]) / x.sum()
    spread = np.max(np.abs(direct / relative_relaxation(alpha, tau, t) - 1)[inner])
    assert 0.03 < spread <= SPREAD + 0.005


def test_prony_series_of_the_fit_against_ansys(result, ansys):
    alpha, tau = ansys
    assert result.ranking[0] == "max-n3m3"
    prony = prony_series(result, structure="max-n3m3", seed=0)
    t, inner = _window(result.data)
    assert prony.window == pytest.approx((t[0], t[-1]))
    reference = relative_relaxation(alpha, tau, t)
    error = np.abs(prony.relaxation(t) / prony.g_0 / reference - 1)
    misfit = np.abs(_running_misfit(result, "max-n3m3", t))
    described = inner & (misfit <= DESCRIBED)
    # The premises of the tolerances: the model's misfit of E′ as measured.
    assert misfit[inner].max() <= TOL_WINDOW - SPREAD
    assert described.sum() >= 0.85 * inner.sum()
    assert error[inner].max() <= TOL_WINDOW
    assert error[described].max() <= TOL_DESCRIBED
    # The series stands for the model well inside the model's band: the gap is the model's.
    assert prony.max_rel_error_relaxation < 1e-3 < prony.band_rel_halfwidth
    # The last decade: ANSYS's series relaxes to E∞ ≈ 0, the model's stays on its plateau
    # (74 MPa beside the 89 MPa measured at ω_min); there the series part, up to 16 %.
    assert prony.g_inf > 0.5 * result.data.response.real[0]
    assert np.all(prony.relaxation(t[~inner]) / prony.g_0 > reference[~inner])

    # The check can fail: ANSYS's curve moved by 0.2 decades in time (an error of 0.2 in
    # log a_T), or scaled by 0.95, is told apart.
    shifted = relative_relaxation(alpha, tau, t * 10**0.2)
    moved = np.abs(prony.relaxation(t) / prony.g_0 / shifted - 1)
    assert moved[inner].max() > TOL_WINDOW and moved[described].max() > TOL_DESCRIBED
    assert np.max(np.abs(prony.relaxation(t) / prony.g_0 / (0.95 * reference) - 1)[inner]) \
        > TOL_WINDOW


def test_a_structure_that_misfits_more_is_told_apart(result, ansys):
    """The Zener (one relaxation process, 57.6 nats below max-n3m3) misses E′ by up to 12 %
    (running mean); its series misses ANSYS's by 20 % over the window less its last decade."""
    alpha, tau = ansys
    prony = prony_series(result, structure="zener", seed=0)
    t, inner = _window(result.data)
    error = np.abs(prony.relaxation(t) / prony.g_0 / relative_relaxation(alpha, tau, t) - 1)
    assert error[inner].max() > TOL_WINDOW
