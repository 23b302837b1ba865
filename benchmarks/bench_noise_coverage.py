"""Coverage of the G(t) band of a comparison under the default noise choice, against the truth.

Synthetic fractional-Zener moduli G*(ω) = (G_e + G_g (iωτ)^α)/(1 + (iωτ)^α), with α in
0.2–0.9, G_g/G_e in 10–1000, 20–40 frequencies over 3–5 decades placed around 1/τ, and 1–3 %
relative noise drawn independently on G′ and G″ (a rheometer's). The truth G(t) = G_e +
(G_g − G_e) E_α(−(t/τ)^α) comes from the Mittag-Leffler function (pymittagleffler, Garrappa's
algorithm), code the fit does not share. Each set is compared with the ``zener`` structure
(the fractional Zener) under each noise choice asked for, and the posterior G(t)
(:func:`bayesfo.predict`) is checked at 15 times inside the data window, 1/ω_max … 1/ω_min:
the 94 % HDI, and the equal-tailed intervals at 50/80/90/99 %.

Noise choices: ``before`` is ``noise="auto"`` choosing between constant and proportional noise
only (the default until relative-parts noise joined it: the candidates of
:data:`bayesfo.comparison.steps.NOISE_CANDIDATES` are set to those two for the run);
``auto`` the default; any noise model name forces it.

    python benchmarks/bench_noise_coverage.py [N_SETS] [--seed S] [--modes before,auto]

Prints one row per noise choice: the coverage of the 94 % HDI (with the binomial standard
error over sets), its value for α < 0.45, the equal-tailed coverages, and the noise models
chosen.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bayesfo as bf  # noqa: E402
from bayesfo.comparison import steps  # noqa: E402
from bayesfo.data import FrequencyResponse  # noqa: E402

LEVELS = (0.5, 0.8, 0.9, 0.99)
N_TIMES = 15


def mittag_leffler(z, alpha):
    from pymittagleffler import mittag_leffler as ml

    return np.real(ml(np.asarray(z, dtype=complex), alpha, 1.0))


def make_set(rng, index: int = 0):
    """One data set and its truth: (data, times, G(t) at them, α)."""
    alpha = rng.uniform(0.2, 0.9)
    ratio = 10.0 ** rng.uniform(1, 3)
    g_e = 1e5 * 10.0 ** rng.uniform(-1, 1)
    g_g = g_e * ratio
    tau = 10.0 ** rng.uniform(-1, 1)
    decades = rng.uniform(3, 5)
    n = int(rng.integers(20, 41))
    # The window reaches the transition: its centre within a decade and a half of 1/τ.
    centre = -np.log10(tau) + rng.uniform(-1.5, 1.5)
    omega = np.logspace(centre - decades / 2, centre + decades / 2, n)
    s = (1j * omega * tau) ** alpha
    g = (g_e + g_g * s) / (1 + s)
    level = rng.uniform(0.01, 0.03)
    noisy = (g.real * (1 + level * rng.normal(size=n))
             + 1j * g.imag * (1 + level * rng.normal(size=n)))
    data = FrequencyResponse(omega, noisy, kind="modulus", name=f"fractional Zener {index}")
    times = np.logspace(-np.log10(omega.max()), -np.log10(omega.min()), N_TIMES)
    truth = g_e + (g_g - g_e) * mittag_leffler(-(times / tau) ** alpha, alpha)
    return data, times, truth, alpha


@contextlib.contextmanager
def candidates(noises):
    """``noise="auto"`` choosing among ``noises`` for the duration."""
    kept = steps.NOISE_CANDIDATES
    steps.NOISE_CANDIDATES = tuple(noises)
    try:
        yield
    finally:
        steps.NOISE_CANDIDATES = kept


def one_run(data, times, truth, mode: str, seed: int) -> dict:
    """Coverage of one set under one noise choice: the share of times inside each band."""
    noise = "auto" if mode in ("before", "auto") else mode
    context = (candidates(("constant", "proportional")) if mode == "before"
               else contextlib.nullcontext())
    with context, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = bf.compare(data, "zener", seed=seed, progress=False, noise=noise)
    r = result["zener"]
    if r.posterior is None:
        return {"error": r.error}
    p = bf.predict(result, "relaxation_modulus", times, structure="zener", seed=seed)
    out = {"hdi": float(np.mean((p.hdi_low <= truth) & (truth <= p.hdi_high))),
           "noise": r.posterior.noise}
    values = np.asarray(p.values)
    for level in LEVELS:
        lo, hi = np.nanquantile(values, [(1 - level) / 2, (1 + level) / 2], axis=0)
        out[level] = float(np.mean((lo <= truth) & (truth <= hi)))
    return out


def study(n_sets: int, seed: int, modes) -> dict:
    rng = np.random.default_rng(seed)
    sets = [make_set(rng, i) for i in range(n_sets)]
    rows = {m: [] for m in modes}
    for i, (data, times, truth, alpha) in enumerate(sets):
        for mode in modes:
            t0 = time.perf_counter()
            got = one_run(data, times, truth, mode, seed + i)
            got.update(alpha=alpha, seconds=time.perf_counter() - t0)
            rows[mode].append(got)
            print(f"set {i:3d} α {alpha:.2f} {mode:>14}: "
                  + (f"HDI {got['hdi']:.2f} ({got['noise']}, {got['seconds']:.0f} s)"
                     if "error" not in got else f"error {got['error']}"), flush=True)
    return rows


def summarise(rows) -> str:
    lines = ["| noise choice | G(t) 94 % HDI, inside | α < 0.45 | "
             + " | ".join(f"{int(100 * lv)} % eq.-tailed" for lv in LEVELS)
             + " | chosen | sets |", "|---" * (5 + len(LEVELS)) + "|"]
    for mode, runs in rows.items():
        ok = [r for r in runs if "error" not in r]
        hdi = np.array([r["hdi"] for r in ok])
        low = np.array([r["hdi"] for r in ok if r["alpha"] < 0.45])
        se = hdi.std(ddof=1) / np.sqrt(hdi.size) if hdi.size > 1 else float("nan")
        chosen = {}
        for r in ok:
            chosen[r["noise"]] = chosen.get(r["noise"], 0) + 1
        lines.append(
            f"| {mode} | {hdi.mean():.3f} ± {se:.3f} | "
            + (f"{low.mean():.3f} ({low.size})" if low.size else "–") + " | "
            + " | ".join(f"{np.mean([r[lv] for r in ok]):.3f}" for lv in LEVELS) + " | "
            + ", ".join(f"{k} {v}×" for k, v in sorted(chosen.items())) + f" | {len(ok)} |")
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("n_sets", nargs="?", type=int, default=30)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--modes", default="before,auto")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = study(args.n_sets, args.seed, args.modes.split(","))
    print(summarise(rows))
    print(f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
