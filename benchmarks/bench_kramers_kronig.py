"""The linear Kramers–Kronig test (bayesfo.data.kramers_kronig) measured by simulation:
its false-alarm rate on consistent data (fractional Zener, Maxwell and Voigt responses with
complex noise, σ given and estimated) and its power on inconsistent data (storage modulus of
one Zener, loss modulus of another whose relaxation time differs by a factor), over seeds; the
cost of one test; the bundled isotherms.

With ``--sparse``: the false-alarm rate on sparse consistent data (8–15 frequencies over
3–5.5 decades, 1–3 % noise, fractional Zener, Maxwell and Voigt as moduli and compliances, σ
given and estimated) and the power against parts of Zeners 1.5× and 3× apart, on the same
sparse grids; discrete relaxations (an integrator with a lag, as the bundled dashpot, two
Debye relaxations, two with an integrator; 8–16 frequencies over 2.5–4.5 decades, ten replicate
series of 5–15 % circular complex noise averaged, σ their standard error, as the dashpot's) and
the power against parts of dashpots whose lags are 1.5× and 3× apart and against a 3° phase
error of the instrument; then the bundled sparse files.

Usage: python benchmarks/bench_kramers_kronig.py [--seeds 200] [--sparse]
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import numpy as np

import bayesfo as bf
from bayesfo.data import FrequencyResponse
from bayesfo.data.kramers_kronig import FALSE_ALARM, kramers_kronig
from bayesfo.structures import get_structure

ROOT = Path(__file__).resolve().parents[1]


def sample(structure, rng):
    s = get_structure(structure)
    if structure == "zener":
        a1 = 10 ** rng.uniform(-1, 1)
        return s, [a1, 1.0, 10 ** rng.uniform(-3, -1) * a1, rng.uniform(0.3, 1.0)]
    if structure == "voigt":
        return s, [10 ** rng.uniform(-1, 1), 1.0, rng.uniform(0.2, 0.9)]
    # maxwell: a1 s^beta/(1 + b1 s^alpha) as a modulus, beta < alpha
    alpha = rng.uniform(0.4, 1.0)
    return s, [1.0, 10 ** rng.uniform(-1, 1), alpha, rng.uniform(0.05, 0.9) * alpha]


def noisy(g, rel, rng, known):
    sd = rel * np.abs(g)
    y = g + sd / np.sqrt(2) * (rng.normal(size=g.size) + 1j * rng.normal(size=g.size))
    return y, (sd if known else None)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, default=200)
    parser.add_argument("--sparse", action="store_true")
    args = parser.parse_args()
    if args.sparse:
        return sparse(args.seeds)
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, python "
          f"{platform.python_version()}; nominal false-alarm rate {FALSE_ALARM}")
    w = np.logspace(-1, 2, 25)
    print(f"{'case':<44} {'noise':>9} {'flagged':>8} {'median F':>16}")
    for structure in ("zener", "maxwell", "voigt"):
        for known in (True, False):
            for rel in (0.01, 0.05):
                chi, flagged = [], 0
                for seed in range(args.seeds):
                    rng = np.random.default_rng(seed)
                    s, theta = sample(structure, rng)
                    y, sd = noisy(s.response(theta, w, "modulus"), rel, rng, known)
                    kk = kramers_kronig(FrequencyResponse(w, y, sd, kind="modulus"))
                    chi.append(kk.chi2_per_dof)
                    flagged += not kk.consistent
                print(f"consistent {structure:<10} {rel:>4.0%} noise {'':<18} "
                      f"{'given' if known else 'estimated':>9} {flagged / args.seeds:8.3f} "
                      f"{np.median(chi):16.2f}")
    for factor in (1.5, 3.0, 10.0):
        for known in (True, False):
            chi, flagged = [], 0
            for seed in range(args.seeds):
                rng = np.random.default_rng(seed)
                s, theta = sample("zener", rng)
                other = list(theta)
                other[0] *= factor  # a1: the relaxation time
                other[2] *= factor  # b1, so that the plateaus stay
                g = s.response(theta, w, "modulus").real + 1j * s.response(other, w,
                                                                           "modulus").imag
                y, sd = noisy(g, 0.01, rng, known)
                kk = kramers_kronig(FrequencyResponse(w, y, sd, kind="modulus"))
                chi.append(kk.chi2_per_dof)
                flagged += not kk.consistent
            print(f"G' and G'' of Zeners with tau apart x{factor:<5} 1% noise {'':<5} "
                  f"{'given' if known else 'estimated':>9} {flagged / args.seeds:8.3f} "
                  f"{np.median(chi):16.2f}")
    data = FrequencyResponse(w, get_structure("zener").response([2.0, 1.0, 0.1, 0.6], w,
                                                                "modulus"), kind="modulus")
    t0 = time.perf_counter()
    for _ in range(100):
        kramers_kronig(data)
    print(f"one test, 25 frequencies: {(time.perf_counter() - t0) * 10:.2f} ms")
    for f in sorted((ROOT / "examples" / "data" / "adhesive_468mp").glob("T*.csv")):
        kk = kramers_kronig(bf.read(f))
        print(f"  {f.stem}: chi2/dof {kk.chi2_per_dof:8.2f} "
              f"{'consistent' if kk.consistent else 'NOT consistent'}; worst at "
              + ", ".join(f"{x:.3g}" for x in kk.worst_frequencies) + " rad/s")


def sparse_grid(rng):
    n, span = int(rng.integers(8, 16)), rng.uniform(3, 5.5)
    return np.logspace(-1, -1 + span, n)


def replicated(g, rng, n_series=10):
    """The dashpot's noise model: replicate series of 5-15 % circular complex noise, averaged,
    with σ the standard error of the mean (as bayesfo computes it from a ``series`` column)."""
    rel = rng.uniform(0.05, 0.15)
    reps = g[:, None] * (1 + rel / np.sqrt(2) * (rng.normal(size=(g.size, n_series))
                                                 + 1j * rng.normal(size=(g.size, n_series))))
    mean = reps.mean(axis=1)
    se = np.sqrt(np.sum(np.abs(reps - mean[:, None]) ** 2, axis=1) / (n_series - 1) / n_series)
    return mean, se


def discrete_grid(rng):
    n, span, lo = int(rng.integers(8, 17)), rng.uniform(2.5, 4.5), rng.uniform(-2, 0)
    return np.logspace(lo, lo + span, n)


def discrete(family: str, w: np.ndarray, rng) -> np.ndarray:
    """Closed forms: a relaxation time inside the window (and a second 3-100× slower)."""
    s = 1j * w
    t1 = 10 ** rng.uniform(-np.log10(w[-1]), -np.log10(w[0]))
    if family == "dashpot":
        return 1 / (s * (1 + t1 * s))
    t2 = t1 * 10 ** rng.uniform(0.5, 2)
    g = 1 / (1 + t1 * s) + rng.uniform(0.2, 5) / (1 + t2 * s)
    return g if family == "two Debye" else g + 1 / (s * t2 * rng.uniform(1, 30))


def sparse(seeds: int) -> None:
    print(f"{'kind':<11} {'structure':<8} {'sigma':>9} {'flagged':>8}")
    for kind in ("modulus", "compliance"):
        for known in (False, True):
            for structure in ("zener", "maxwell", "voigt"):
                flagged = 0
                for seed in range(seeds):
                    rng = np.random.default_rng(seed + 7000)
                    w = sparse_grid(rng)
                    s, theta = sample(structure, rng)
                    y, sd = noisy(s.response(theta, w, kind), rng.uniform(0.01, 0.03), rng,
                                  known)
                    flagged += not kramers_kronig(FrequencyResponse(w, y, sd,
                                                                    kind=kind)).consistent
                print(f"{kind:<11} {structure:<8} {'given' if known else 'estimated':>9} "
                      f"{flagged / seeds:8.3f}")
    for factor in (1.5, 3.0):
        flagged = 0
        for seed in range(seeds):
            rng = np.random.default_rng(seed + 5000)
            w = sparse_grid(rng)
            s, theta = sample("zener", rng)
            other = [theta[0] * factor, theta[1], theta[2] * factor, theta[3]]
            g = s.response(theta, w, "modulus").real + 1j * s.response(other, w, "modulus").imag
            y, sd = noisy(g, 0.01, rng, False)
            flagged += not kramers_kronig(FrequencyResponse(w, y, sd, kind="modulus")).consistent
        print(f"parts of Zeners x{factor} apart: flagged {flagged / seeds:.3f}")
    for family in ("dashpot", "two Debye", "two Debye + integrator"):
        flagged = 0
        for seed in range(seeds):
            rng = np.random.default_rng(seed + 9000)
            w = discrete_grid(rng)
            y, sd = replicated(discrete(family, w, rng), rng)
            flagged += not kramers_kronig(FrequencyResponse(w, y, sd,
                                                            kind="compliance")).consistent
        print(f"discrete, {family:<24} flagged {flagged / seeds:.3f}")
    for factor in (1.5, 3.0):
        flagged = 0
        for seed in range(seeds):
            rng = np.random.default_rng(seed + 9500)
            w = discrete_grid(rng)
            t1 = 10 ** rng.uniform(-np.log10(w[-1]), -np.log10(w[0]))
            s = 1j * w
            g = (1 / (s * (1 + t1 * s))).real + 1j * (1 / (s * (1 + factor * t1 * s))).imag
            y, sd = replicated(g, rng)
            flagged += not kramers_kronig(FrequencyResponse(w, y, sd,
                                                            kind="compliance")).consistent
        print(f"parts of dashpots x{factor} apart: flagged {flagged / seeds:.3f}")
    flagged = 0
    for seed in range(seeds):
        rng = np.random.default_rng(seed + 6500)
        w = sparse_grid(rng)
        s, theta = sample("zener", rng)
        g = s.response(theta, w, "modulus") * np.exp(1j * np.deg2rad(3.0))
        y, sd = noisy(g, 0.01, rng, False)
        flagged += not kramers_kronig(FrequencyResponse(w, y, sd, kind="modulus")).consistent
    print(f"Zener with a 3 deg phase error: flagged {flagged / seeds:.3f}")
    for name in ("pp_compliance", "dashpot"):
        kk = kramers_kronig(bf.read(ROOT / "examples" / "data" / f"{name}.csv"))
        print(f"{name}: F {kk.chi2_per_dof:.2f}, {kk.n_elements} elements, "
              f"{'consistent' if kk.consistent else 'NOT consistent'}")


if __name__ == "__main__":
    main()
