"""The linear Kramers–Kronig test: consistent responses pass at about the stated false-alarm
rate, parts of different responses fail, and the result reaches inspect and summary.json."""

from __future__ import annotations

import json

import numpy as np
import pytest

from bayesfo.data import FrequencyResponse
from bayesfo.data.kramers_kronig import FALSE_ALARM, kramers_kronig
from bayesfo.structures import get_structure

W = np.logspace(-1, 2, 25)
ZENER = get_structure("zener")


def _zener(rng):
    a1 = 10 ** rng.uniform(-1, 1)
    return [a1, 1.0, 10 ** rng.uniform(-3, -1) * a1, rng.uniform(0.3, 1.0)]


def _noisy(g, rng, rel=0.01):
    sd = rel * np.abs(g)
    return g + sd / np.sqrt(2) * (rng.normal(size=g.size) + 1j * rng.normal(size=g.size)), sd


@pytest.mark.parametrize("known", [True, False])
def test_consistent_data_pass_at_the_stated_rate(known):
    # 200 fractional Zeners with 1 % noise: flagged ones are false alarms, binomial with
    # p = 0.01 (mean 2; 8 or more has probability 1e-3).
    flagged = 0
    for seed in range(200):
        rng = np.random.default_rng(seed)
        y, sd = _noisy(ZENER.response(_zener(rng), W, "modulus"), rng)
        kk = kramers_kronig(FrequencyResponse(W, y, sd if known else None, kind="modulus"))
        flagged += not kk.consistent
    assert flagged < 8 and FALSE_ALARM == 0.01


def test_parts_of_different_responses_fail():
    # Storage modulus of one Zener, loss modulus of one relaxing 1.5 times slower.
    failed = 0
    for seed in range(50):
        rng = np.random.default_rng(seed)
        theta = _zener(rng)
        slower = [theta[0] * 1.5, theta[1], theta[2] * 1.5, theta[3]]
        g = (ZENER.response(theta, W, "modulus").real
             + 1j * ZENER.response(slower, W, "modulus").imag)
        y, _ = _noisy(g, rng)
        kk = kramers_kronig(FrequencyResponse(W, y, kind="modulus"))
        failed += not kk.consistent
        if not kk.consistent:
            assert kk.chi2_per_dof > 3 and len(kk.worst_frequencies) == 3
    assert failed >= 45


def test_a_compliance_is_tested_on_its_own_basis():
    rng = np.random.default_rng(0)
    y, sd = _noisy(ZENER.response([2.0, 1.0, 0.1, 0.6], W, "compliance"), rng)
    kk = kramers_kronig(FrequencyResponse(W, y, sd, kind="compliance"))
    assert kk.consistent and kk.noise == "given" and 0.1 < kk.chi2_per_dof < 3


def test_too_few_points_have_no_test_and_the_blocks_are_written(run_cli, tmp_path):
    few = FrequencyResponse(W[:4], ZENER.response([2.0, 1.0, 0.1, 0.6], W[:4], "modulus"),
                            kind="modulus")
    assert few.kramers_kronig() is None and few.to_dict()["kramers_kronig"] is None
    rng = np.random.default_rng(1)
    y, _ = _noisy(ZENER.response([2.0, 1.0, 0.1, 0.6], W, "modulus"), rng)
    path = tmp_path / "z.csv"
    FrequencyResponse(W, y, kind="modulus", units="Pa").to_csv(path)
    status, out, _ = run_cli("inspect", path, "--json")
    block = json.loads(out)["kramers_kronig"]
    assert status == 0 and block["consistent"] is True
    assert set(block) == {"consistent", "chi2_per_dof", "worst_frequencies", "noise",
                          "n_elements", "misfit_rms", "misfit_max"}
    status, out, _ = run_cli("inspect", path)
    assert "Kramers–Kronig: the two parts are consistent (F = " in out


def test_the_size_of_the_inconsistency_is_stated():
    """misfit_rms is the rms of |G_fit − G|/|G| of the causal fit: about the noise on consistent
    data (1 % complex noise: the basis absorbs a few of the 50 numbers' worth), more where the
    parts come from different responses, and the verdict's sentence gives both (the noise of
    a 25-point, 1 % complex-noise set leaves a relative residual of 0.4-1.2 % rms)."""
    rng = np.random.default_rng(3)
    theta = _zener(rng)
    g = ZENER.response(theta, W, "modulus")
    y, _ = _noisy(g, rng)
    ok = kramers_kronig(FrequencyResponse(W, y, kind="modulus"))
    assert ok.consistent and 0.004 < ok.misfit_rms < 0.012 and ok.misfit_max < 0.03
    slower = [theta[0] * 3, theta[1], theta[2] * 3, theta[3]]
    mixed = g.real + 1j * ZENER.response(slower, W, "modulus").imag
    y, _ = _noisy(mixed, rng)
    bad = kramers_kronig(FrequencyResponse(W, y, kind="modulus"))
    assert not bad.consistent and bad.misfit_rms > 2 * ok.misfit_rms
    text = bad.describe()
    assert f"{100 * bad.misfit_rms:.2g} % rms" in text and "not consistent" in text
    assert bad.to_dict()["misfit_max"] == pytest.approx(bad.misfit_max)
    assert "consistent by the Kramers–Kronig relations (F =" in ok.describe()


def test_a_large_inconsistency_is_a_problem_of_the_data_a_small_one_is_not():
    """Parts of responses that relax 30 times apart are warned as a problem of the data (the
    causal fit misses them by over 5 % rms); consistent parts and a small inconsistency are
    not (real isotherms fail the test by 0.3-4 %, said in the verdict only)."""
    from bayesfo.comparison.results import KK_WARN_RMS, data_problems

    rng = np.random.default_rng(3)
    theta = _zener(rng)
    g = ZENER.response(theta, W, "modulus")
    apart = [theta[0] * 30, theta[1], theta[2] * 30, theta[3]]
    y, _ = _noisy(g.real + 1j * ZENER.response(apart, W, "modulus").imag, rng)
    data = FrequencyResponse(W, y, kind="modulus", name="mixed")
    kk = kramers_kronig(data)
    assert not kk.consistent and kk.misfit_rms > KK_WARN_RMS
    assert data_problems(data) == [f"mixed: {kk.describe()}"]
    y, _ = _noisy(g, rng)
    assert data_problems(FrequencyResponse(W, y, kind="modulus", name="fine")) == []
    slower = [theta[0] * 1.5, theta[1], theta[2] * 1.5, theta[3]]
    y, _ = _noisy(g.real + 1j * ZENER.response(slower, W, "modulus").imag, rng)
    small = FrequencyResponse(W, y, kind="modulus", name="small")
    kk = kramers_kronig(small)
    assert kk.misfit_rms < KK_WARN_RMS and data_problems(small) == []


def test_sparse_consistent_data_get_a_basis_of_one_element_per_decade():
    """12 points over 3.5 decades: the cap (n − 3)//2 gave 4 elements over the 5.5 decades of
    τ and called the bundled fractional Voigt compliance inconsistent (F = 8.6); at least one
    element per decade (7) passed it (F = 3.1), lin-KK's count takes 8 (F = 1.3). Sparse
    fractional compliances (8–15 points over 3–5.5 decades, 1–3 % noise): 300 Zeners flagged
    2.3 % (4.7 % with the cap; benchmarks/bench_kramers_kronig.py --sparse), here 150 of
    them below 9 (binomial p 0.023: mean 3.5, 9 or more with probability 0.01)."""
    from pathlib import Path

    import bayesfo as bf

    pp = bf.read(Path(__file__).parents[2] / "examples" / "data" / "pp_compliance.csv")
    kk = kramers_kronig(pp)
    assert kk.n_elements == 8 and kk.consistent and kk.chi2_per_dof < 2
    flagged = 0
    for seed in range(150):
        rng = np.random.default_rng(seed + 7000)
        w = np.logspace(-1, -1 + rng.uniform(3, 5.5), int(rng.integers(8, 16)))
        a1 = 10 ** rng.uniform(-1, 1)
        theta = [a1, 1.0, 10 ** rng.uniform(-3, -1) * a1, rng.uniform(0.3, 1.0)]
        y, _ = _noisy(ZENER.response(theta, w, "compliance"), rng, rel=rng.uniform(0.01, 0.03))
        flagged += not kramers_kronig(FrequencyResponse(w, y, kind="compliance")).consistent
    assert flagged < 9
    # Dense data keep the cap: 25 points over 3 decades, 11 elements as before.
    rng = np.random.default_rng(1)
    y, _ = _noisy(ZENER.response(_zener(rng), W, "modulus"), rng)
    assert kramers_kronig(FrequencyResponse(W, y, kind="modulus")).n_elements == 11


def _replicated(g, rng, rel, n_series=10):
    """Replicate series of circular complex noise (rel·|G| each), averaged, σ their standard
    error: the bundled dashpot's noise model, generated here with numpy alone."""
    reps = g[:, None] * (1 + rel / np.sqrt(2) * (rng.normal(size=(g.size, n_series))
                                                 + 1j * rng.normal(size=(g.size, n_series))))
    mean = reps.mean(axis=1)
    se = np.sqrt(np.sum(np.abs(reps - mean[:, None]) ** 2, axis=1) / (n_series - 1) / n_series)
    return mean, se


def test_the_dashpot_file_is_consistent():
    """dashpot.csv is simulated from 1/(a1 s (1 + 0.1908 s)) = (1/s − 0.1908/(1 + 0.1908 s))/a1:
    one discrete relaxation, which 6 elements over 4.5 decades of τ missed by 3 % beside 3 %
    noise (F = 12.6, "not consistent"); lin-KK's count takes 11 elements (F 0.8)."""
    from pathlib import Path

    import bayesfo as bf

    kk = kramers_kronig(bf.read(Path(__file__).parents[2] / "examples" / "data" / "dashpot.csv"))
    assert kk.consistent and kk.noise == "given" and kk.chi2_per_dof < 2
    assert kk.n_elements > 6 and kk.misfit_rms < 0.03


def test_parts_of_two_dashpots_fail():
    """The dashpot's grid and noise model (16 points over 0.03–10 rad/s, ten series of 10 %
    noise averaged), its real part from a lag of 0.19 s and its imaginary part from one twice
    as long: every one of 20 noise draws fails (F 14–60; before the count changed, F 19–90)."""
    w = np.logspace(np.log10(0.03), 1, 16)
    s = 1j * w
    g = (1 / (s * (1 + 0.19 * s))).real + 1j * (1 / (s * (1 + 0.38 * s))).imag
    for seed in range(20):
        y, sd = _replicated(g, np.random.default_rng(seed), 0.10)
        kk = kramers_kronig(FrequencyResponse(w, y, sd, kind="generic"))
        assert not kk.consistent and kk.chi2_per_dof > 5


def test_sparse_discrete_relaxations_rarely_raise_a_false_alarm():
    """150 consistent discrete responses (an integrator with a lag, two Debye relaxations, two
    with an integrator; 8–16 points over 2.5–4.5 decades; the dashpot's replicate noise, 5–15 %
    per series), closed forms in numpy. benchmarks/bench_kramers_kronig.py --sparse, 300 sets
    per family: flagged 2.7 %, 1.3 %, 1.3 % (9.3 %, 5.3 %, 5.0 % with the former count), so
    at most p = 0.027 here: mean 4, and 9 or more with probability 0.02 (these seeds: 4 now,
    9 with the former count)."""
    flagged = 0
    for seed in range(150):
        rng = np.random.default_rng(seed + 300)
        n, span, lo = int(rng.integers(8, 17)), rng.uniform(2.5, 4.5), rng.uniform(-2, 0)
        w = np.logspace(lo, lo + span, n)
        s = 1j * w
        t1 = 10 ** rng.uniform(-np.log10(w[-1]), -np.log10(w[0]))
        if seed % 3 == 0:
            g = 1 / (s * (1 + t1 * s))
        else:
            t2 = t1 * 10 ** rng.uniform(0.5, 2)
            g = 1 / (1 + t1 * s) + rng.uniform(0.2, 5) / (1 + t2 * s)
            if seed % 3 == 2:
                g = g + 1 / (s * t2 * rng.uniform(1, 30))
        y, sd = _replicated(g, rng, rng.uniform(0.05, 0.15))
        flagged += not kramers_kronig(FrequencyResponse(w, y, sd, kind="compliance")).consistent
    assert flagged < 9


def test_the_sign_balance_is_lin_kk_mu_for_either_sign():
    from bayesfo.data.kramers_kronig import sign_balance

    assert sign_balance(np.array([1.0, 2.0, 0.5])) == 1.0
    assert sign_balance(-np.array([1.0, 2.0, 0.5])) == 1.0  # a negative spectrum throughout
    assert sign_balance(np.array([3.0, -1.0])) == pytest.approx(1 - 1 / 3)
    assert sign_balance(np.zeros(3)) == 1.0
