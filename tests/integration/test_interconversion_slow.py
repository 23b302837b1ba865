"""Known answers for the Prony export and a measured interconversion (issue 31), slow: the
pyvisco verification case, and the polystyrene at 160 °C of pyRheo (at the end of the file).

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

import glob
import subprocess
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
        # Both structures' posteriors are used (Prony series of each): both sampled.
        return bf.compare(nrel, "max-n3m3,zener", workers=1, progress=False, seed=0,
                          sample="all")


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


# ------------------------------------------------------------ a measured interconversion
# The polystyrene at 160 °C of pyRheo (GPL; read in place, never copied here): its SAOS
# isotherm (0.01–300 rad/s, in ../shared/data/reference-gpl), and a stress relaxation G(t)
# (0.2–1803 s, 1799 points) and a creep J(t) (0.2–3605 s, 3599 points) of the same material,
# read from a fetched mirror of pyRheo's repository (columns 'Time', 'Relaxation Modulus' or
# 'Creep Compliance'; s, Pa and 1/Pa as pyRheo's demos read them).
#
# bayesfo fits the SAOS alone; its G(t) and J(t) are compared with the measured ones in shape:
# one scale factor per test (least squares in log; the transient tests are ~1.3× softer than
# the SAOS, known), then the log deviation after scaling, over the measured times inside the
# SAOS window 1/ω_max … 1/ω_min = 0.0033 … 100 s (`extrapolated` False), thinned to the
# measured points nearest 20 per decade so that each decade weighs the same (the files are
# sampled nearly evenly in time, 0.1 s to 4 s apart: 58 % of their points lie in their last
# decade, 85 % of the window's in its last).
#
# The noise model is proportional (σ ∝ |G*|): under noise="auto" the evidence prefers constant
# noise for the three-springpot Zener (ln Z −546.3 against −575.2; the data are written to
# three significant digits, ±500 Pa at the top), which leaves the low-modulus end loose (G′
# 28 % high, phase 8° off at ω_min) and its G(t) 26 % off in shape near 1/ω_min (BENCHMARKS.md).
#
# Tolerances, from measured sources (seed 0): the data's own SAOS-to-transient inconsistency,
# model-free (Ninomiya–Ferry's approximations from the measured G′, G″ at 10/ω_max … 0.4/ω_min,
# themselves within 1.2 % in shape of the exact interconversion of the fitted model): 2.5 %
# (rms 0.9 %) for G(t), 4.9 % (rms 2.6 %) for J(t); the model's misfit of G*: 2.2 % in |G*| at
# the posterior mode; the prediction's 94 % band: half-width ≤ 3.2 % (rms 1.3 %) for G and
# ≤ 1.0 % (rms 0.7 %) for J in the window; the measured curves' scatter about a local fit:
# 0.18 % and 0.25 % rms. Summed: 9.3 % for G, 9.6 % for J, so the largest log deviation is held
# to TOL_SHAPE = 0.10; the rms, the same sources in quadrature (3.0 % for G, 3.7 % for J), to
# TOL_RMS = 0.04. Measured: G 0.073 (at 90 s, where G(t) already depends on G* below ω_min;
# +0.066 at 0.2 s, the step's start) and rms 0.022; J 0.054 (at 3 s) and rms 0.029. The scatter
# and the band alone (≤ 3.5 %) do not cover the deviations: the data's own inconsistency does.

PS_SAOS = (Path(__file__).parents[3] / "shared" / "data" / "reference-gpl"
           / "pyrheo_polystyrene_saos" / "original" / "oscillation_ps160_data.csv")
PYRHEO_MIRRORS = "/work/.mirror/comphy-lab+pyRheo*/repo"
PYRHEO_DIR = "demos/bayesian_optimization/data/polystyrene/"
PS_STRUCTURES = "fractional_zener_ll,maxwell,fractional_maxwell_liquid"
#: The largest |log(measured/predicted)| after scaling, and its rms, in the SAOS window.
TOL_SHAPE = 0.10
TOL_RMS = 0.04


def _pyrheo_transient(name: str) -> tuple[np.ndarray, np.ndarray]:
    """(t, value) of one of pyRheo's polystyrene files, read from a fetched mirror."""
    mirrors = sorted(glob.glob(PYRHEO_MIRRORS))
    if not mirrors:
        pytest.skip("pyRheo's polystyrene relaxation and creep files are not available: fetch "
                    "github:comphy-lab/pyRheo (a bare mirror at /work/.mirror/comphy-lab+pyRheo/"
                    "repo; GPL, read in place)")
    out = subprocess.run(["git", f"--git-dir={mirrors[0]}", "show", f"HEAD:{PYRHEO_DIR}{name}"],
                         capture_output=True, text=True)
    if out.returncode:
        pytest.skip(f"{name} is not in pyRheo's mirror {mirrors[0]}: {out.stderr.strip()}")
    header, *rows = out.stdout.splitlines()
    assert header.split("\t")[0] == "Time"
    t, value = np.loadtxt(rows, delimiter="\t", unpack=True)
    assert np.all(np.diff(t) > 0) and np.all(value > 0)
    return t, value


def _thin(t, per_decade: int = 20) -> np.ndarray:
    """Indices of the measured times nearest a log grid of ``per_decade`` points a decade."""
    log_t = np.log10(t)
    grid = np.arange(log_t[0], log_t[-1] + 0.5 / per_decade, 1 / per_decade)
    return np.unique(np.abs(log_t[:, None] - grid).argmin(axis=0))


def _loglog(x, y, at):
    return np.exp(np.interp(np.log(at), np.log(x), np.log(y), left=np.nan, right=np.nan))


def _shape(measured, predicted, inside):
    """The scale factor measured/predicted (least squares in log over ``inside``) and the log
    deviations after scaling."""
    log_ratio = np.log(measured / predicted)
    scale = log_ratio[inside].mean()
    return np.exp(scale), log_ratio - scale


def _scatter(t, y, inside) -> float:
    """rms log deviation of the measured points from a local quadratic in log–log (±0.1 in ln t)."""
    log_t, log_y = np.log(t), np.log(y)
    res = []
    for i in np.flatnonzero(inside):
        near = np.abs(log_t - log_t[i]) < 0.1
        if near.sum() > 5:
            res.append(log_y[i] - np.polyval(np.polyfit(log_t[near], log_y[near], 2), log_t[i]))
    return float(np.sqrt(np.mean(np.square(res))))


def _ninomiya_ferry(data, t):
    """G(t) and J(t) from the measured G′, G″ alone (Ninomiya & Ferry 1959), at ω = 1/t:
    G ≈ G′(ω) − 0.40 G″(0.40ω) + 0.014 G″(10ω), J ≈ J′(ω) + 0.40 J″(0.40ω) − 0.014 J″(10ω);
    NaN where 0.4ω or 10ω leaves the data."""
    w, g = data.omega, data.response
    j = 1 / g
    om = 1 / np.asarray(t, float)
    relax = (_loglog(w, g.real, om) - 0.40 * _loglog(w, g.imag, 0.40 * om)
             + 0.014 * _loglog(w, g.imag, 10 * om))
    creep = (_loglog(w, j.real, om) + 0.40 * _loglog(w, -j.imag, 0.40 * om)
             - 0.014 * _loglog(w, -j.imag, 10 * om))
    return relax, creep


@pytest.fixture(scope="module")
def polystyrene():
    """The SAOS fit, the measured G(t) and J(t), their thinned indices and the times to
    predict at."""
    if not PS_SAOS.is_file():
        pytest.skip(f"{PS_SAOS} is not available (pyRheo's polystyrene SAOS isotherms, GPL)")
    measured = {"relaxation_modulus": _pyrheo_transient("stressrelaxation_ps160_data.csv"),
                "creep_compliance": _pyrheo_transient("creep_ps160_data.csv")}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        data = bf.read(PS_SAOS, units="Pa")
        result = bf.compare(data, PS_STRUCTURES, noise="proportional", workers=1,
                            progress=False, seed=0, sample="all")  # each one predicts
    thinned = {q: _thin(t) for q, (t, _) in measured.items()}
    # Predict both at the union of the thinned times and a wide grid (for J·G ≤ 1).
    t_all = np.unique(np.concatenate([np.logspace(-4, 4, 33)]
                                     + [measured[q][0][i] for q, i in thinned.items()]))
    return {"data": data, "result": result, "measured": measured, "thinned": thinned,
            "t": t_all}


def _compare_shape(ps, structure):
    """Per quantity: times, measured, prediction at them, inside-window mask, scale, deviations."""
    out = {}
    for q, (t_m, y_m) in ps["measured"].items():
        pred = bf.predict(ps["result"], q, ps["t"], structure=structure)
        i = ps["thinned"][q]
        at = np.searchsorted(pred.x, t_m[i])
        assert np.allclose(pred.x[at], t_m[i])
        inside = ~pred.extrapolated[at]
        scale, dev = _shape(y_m[i], pred.median[at], inside)
        half = np.log(pred.hdi_high[at] / pred.hdi_low[at]) / 2
        out[q] = {"t": t_m[i], "y": y_m[i], "pred": pred, "at": at, "inside": inside,
                  "scale": scale, "dev": dev, "half": half}
    return out


def test_polystyrene_160c_interconversion_from_saos(polystyrene):
    """G(t) and J(t) predicted from the SAOS alone against the measured ones, in shape."""
    ps = polystyrene
    result, data = ps["result"], ps["data"]
    assert result.ranking[0] == "fractional_zener_ll"
    # The premise: the structure describes the SAOS (not within its scatter: the checks fail,
    # as for every structure tried), within 2.2 % in |G*| and 2.6° in phase at the mode.
    adequacy = result["fractional_zener_ll"].criteria.adequacy
    assert adequacy.max_log10_magnitude_error <= 0.01 and adequacy.max_phase_error_deg <= 3.0
    shapes = _compare_shape(ps, "fractional_zener_ll")
    g, j = shapes["relaxation_modulus"], shapes["creep_compliance"]
    for s in (g, j):
        assert s["inside"].sum() >= 40  # 0.2 … 100 s, 48 of each
        assert np.all(s["t"][s["inside"]] <= 1 / data.omega.min())
    # The sources of the tolerances, as measured.
    for q, top in (("relaxation_modulus", 0.04), ("creep_compliance", 0.012)):
        t_m, y_m = ps["measured"][q]
        inside = (t_m >= 1 / data.omega.max()) & (t_m <= 1 / data.omega.min())
        assert _scatter(t_m, y_m, inside) <= 0.003
        assert shapes[q]["half"][shapes[q]["inside"]].max() <= top
    # Model-free: Ninomiya–Ferry at t = 1/ω for the measured ω with 0.4ω and 10ω in the data.
    t_nf = np.sort(1 / data.omega)
    t_nf = t_nf[(t_nf >= 10 / data.omega.max()) & (t_nf <= 0.4 / data.omega.min())]
    relax_nf, creep_nf = _ninomiya_ferry(data, t_nf)
    for q, approx, top in (("relaxation_modulus", relax_nf, 0.03),
                           ("creep_compliance", creep_nf, 0.055)):
        t_m, y_m = ps["measured"][q]
        ok = np.isfinite(approx) & (t_nf >= t_m[0])
        assert ok.sum() >= 12
        _, dev_nf = _shape(_loglog(t_m, y_m, t_nf[ok]), approx[ok], np.ones(ok.sum(), bool))
        assert np.abs(dev_nf).max() <= top

    # The shapes, in the SAOS window.
    for s in (g, j):
        dev = s["dev"][s["inside"]]
        assert np.abs(dev).max() <= TOL_SHAPE
        assert np.sqrt(np.mean(dev**2)) <= TOL_RMS
    # The amplitudes: the transient tests are softer than the SAOS (G by 1/0.76, J by 1.22).
    assert 1.2 <= 1 / g["scale"] <= 1.4 and 1.15 <= j["scale"] <= 1.3

    # Outside the window the SAOS does not reach the terminal flow: the model keeps relaxing
    # as a power law while the material flows, G(t) measured below and J(t) above the
    # prediction, far outside its band (G about 3× low from 800 s, J 1.5× high at 3600 s).
    for s, sign, least in ((g, -1, 1.0), (j, +1, 0.35)):
        out = ~s["inside"] & (s["t"] > 1 / data.omega.min())
        assert np.all(sign * s["dev"][out] > 0)
        assert np.abs(s["dev"][out]).max() >= least
        assert np.all(np.abs(s["dev"][out][-5:]) > s["half"][out][-5:])

    # J(t) G(t) ≤ 1 for every draw at every time (10⁻⁴ … 10⁴ s and the measured times).
    # (Both predictions use the same draws: same seed, same structure; measured max 0.93.)
    product = g["pred"].values * j["pred"].values
    assert np.all(np.isfinite(product)) and np.max(product) <= 1.0 + 1e-9

    # The check can fail: the measured curves stretched in time by 2 (an a_T off by a factor 2,
    # 0.3 in log a_T) or compressed by 2 are told apart (measured, ×2: G 0.21 and rms 0.13,
    # J 0.12 and 0.065; ×0.5: G 0.37 and 0.17, J 0.20 and 0.12).
    for q in ("relaxation_modulus", "creep_compliance"):
        s, (t_m, y_m) = shapes[q], ps["measured"][q]
        for factor in (2.0, 0.5):
            moved = _loglog(t_m, y_m, s["t"] / factor)
            ok = s["inside"] & np.isfinite(moved)
            _, dev = _shape(moved[ok], s["pred"].median[s["at"]][ok], np.ones(ok.sum(), bool))
            assert np.abs(dev).max() > TOL_SHAPE or np.sqrt(np.mean(dev**2)) > TOL_RMS


def test_polystyrene_a_structure_that_misses_the_saos_is_told_apart(polystyrene):
    """The fractional Maxwell liquid (85 nats below, phase 9° off at the mode) misses the shape
    of G(t) by 0.47 in log (at 90 s; J(t) by 0.085, rms 0.053)."""
    shapes = _compare_shape(polystyrene, "fractional_maxwell_liquid")
    s = shapes["relaxation_modulus"]
    assert np.abs(s["dev"][s["inside"]]).max() > TOL_SHAPE
    s = shapes["creep_compliance"]
    assert np.sqrt(np.mean(s["dev"][s["inside"]] ** 2)) > TOL_RMS
