"""Coverage of the master curve's shift intervals (the model-free master, default options).

Synthetic isotherms from a generator that shares no code with the fit: a continuous
relaxation spectrum (a log-normal of relaxation times, or a power law with two cut-offs) summed
as 60 Maxwell modes in plain NumPy, at reduced frequencies a_T·ω from an exact WLF or
Arrhenius law, optionally divided by the density factor b_T = T_ref/T, with noise drawn either
independently on each part (relative, a rheometer's) or as complex noise proportional to |G*|.
WLF constants (C1 8–17, C2 50–120 °C) are drawn again where they would put an isotherm more
than 12 decades from the reference or 6 from its neighbour: near the law's divergence
(T_ref − C2) they give shifts of 20–50 decades between isotherms 10 K apart, which no
measurement shows (WLF holds above the glass transition) and which lie outside the prior's
±15 decades, where no interval can cover them (``--uncapped`` keeps them).
Each set is fitted with ``smooth_shifts`` at its defaults (noise, vertical shift and law chosen
by ln Z); the 94 % HDI of every non-reference log10 a_T that the fit calls determined
(:meth:`~bayesfo.tts.smooth_posterior.ShiftPosterior.undetermined`: the interval the tool
claims) is checked against the truth; the not-determined ones are counted and checked apart.

    python benchmarks/bench_mastercurve_coverage.py [N_SETS] [--seed S]

Prints the coverage (with its binomial standard error, and the set-clustered one), the
z-scores' sd, and each configuration's share.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bayesfo.data import FrequencyResponse  # noqa: E402
from bayesfo.inference._arviz import hdi_columns  # noqa: E402
from bayesfo.tts.isotherms import _isotherms  # noqa: E402
from bayesfo.tts.shifts import smooth_shifts  # noqa: E402

R = 8.314462618
#: WLF constants are drawn again where the shifts would leave ±CAP decades, or step by more
#: than CAP/2 between neighbours (``--uncapped`` keeps every draw).
CAP = 12.0
CAPPED = True


def spectrum_modulus(omega, rng):
    """G′, G″ of a random continuous spectrum (60 Maxwell modes) plus an equilibrium
    modulus, at angular frequencies ``omega``: plain NumPy, no bayesfo code."""
    tau = np.logspace(-8, 8, 60)
    if rng.random() < 0.5:  # log-normal spectrum around a random time
        centre, width = rng.uniform(-3, 3), rng.uniform(0.8, 2.5)
        h = np.exp(-0.5 * ((np.log10(tau) - centre) / width) ** 2)
    else:  # power law between two cut-offs (a rubbery or glassy transition)
        slope = rng.uniform(-0.7, -0.2)
        lo, hi = rng.uniform(-6, -2), rng.uniform(1, 5)
        h = tau ** slope * np.exp(-tau / 10.0 ** hi) * np.exp(-(10.0 ** lo) / tau)
    g = 1e6 * h / h.max()
    g_e = 1e6 * 10.0 ** rng.uniform(-4, -1)
    wt = omega[:, None] * tau[None, :]
    storage = g_e + np.sum(g * wt ** 2 / (1 + wt ** 2), axis=1)
    loss = np.sum(g * wt / (1 + wt ** 2), axis=1)
    return storage, loss


def one_set(rng):
    n_iso = int(rng.integers(5, 9))
    temps = np.arange(n_iso) * 10.0 + rng.uniform(-20, 40)
    ref = n_iso // 2
    t_ref = temps[ref]
    if rng.random() < 0.5:
        law = "wlf"
        dt = temps - t_ref
        while True:  # shifts inside the prior's reach (see the module)
            c1, c2 = rng.uniform(8, 17), rng.uniform(50, 120)
            log_a = -c1 * dt / (c2 + dt)
            if not CAPPED or (np.all(np.abs(log_a) <= CAP)
                              and np.all(np.abs(np.diff(log_a)) <= CAP / 2)):
                break
    else:
        law = "arrhenius"
        ea = rng.uniform(60e3, 250e3)
        log_a = ea / (R * math.log(10)) * (1 / (temps + 273.15) - 1 / (t_ref + 273.15))
    vertical = rng.random() < 0.5
    log_b = np.log10((t_ref + 273.15) / (temps + 273.15)) if vertical else np.zeros(n_iso)
    noise = "parts" if rng.random() < 0.5 else "proportional"
    rel = rng.choice([0.01, 0.03])
    omega = np.logspace(-1, 2, int(rng.integers(12, 21)))
    seed_spec = int(rng.integers(2**31))
    out = []
    for t, la, lb in zip(temps, log_a, log_b, strict=True):
        storage, loss = spectrum_modulus(omega * 10.0 ** la, np.random.default_rng(seed_spec))
        storage, loss = storage / 10.0 ** lb, loss / 10.0 ** lb
        if noise == "parts":
            storage = storage * (1 + rel * rng.standard_normal(omega.size))
            loss = loss * (1 + rel * rng.standard_normal(omega.size))
        else:
            mag = np.hypot(storage, loss)
            storage = storage + rel * mag / math.sqrt(2) * rng.standard_normal(omega.size)
            loss = loss + rel * mag / math.sqrt(2) * rng.standard_normal(omega.size)
        out.append((FrequencyResponse(omega, storage + 1j * loss, kind="modulus", units="Pa",
                                      name=f"syn {t:g}"), float(t)))
    return out, log_a, ref, {"law": law, "vertical": vertical, "noise": noise, "rel": rel}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("n", type=int, nargs="?", default=100)
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--uncapped", action="store_true")
    args = ap.parse_args()
    global CAPPED
    CAPPED = not args.uncapped
    rng = np.random.default_rng(args.seed)
    rows = []
    t0 = time.time()
    for k in range(args.n):
        data, truth, ref, cfg = one_set(rng)
        iso = _isotherms(data, data[ref][1])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sh = smooth_shifts(iso, seed=k)
        draws = sh.posterior.shift_draws
        lo, hi = hdi_columns(draws, 0.94)
        mean, sd = draws.mean(axis=0), draws.std(axis=0, ddof=1)
        undetermined = set(sh.posterior.undetermined())
        for i in range(truth.size):
            if i == ref:
                continue
            rows.append((k, cfg["law"], cfg["vertical"], cfg["noise"], sh.law, sh.vertical,
                         sh.noise, bool(lo[i] <= truth[i] <= hi[i]),
                         (mean[i] - truth[i]) / sd[i] if sd[i] > 0 else math.nan,
                         abs(mean[i] - truth[i]), sh.posterior.converged,
                         i in undetermined))
        mine = [r for r in rows if r[0] == k]
        claimed = [r[7] for r in rows if not r[11]]
        print(f"set {k}: {cfg} -> noise {sh.noise}, vertical {sh.vertical}, law {sh.law}; "
              f"covered {sum(r[7] for r in mine if not r[11])}/"
              f"{sum(not r[11] for r in mine)} determined, "
              f"{sum(r[7] for r in mine if r[11])}/{sum(r[11] for r in mine)} not; so far "
              f"{np.mean(claimed) if claimed else math.nan:.3f} of {len(claimed)}; "
              f"{time.time() - t0:.0f} s", flush=True)
    gone = np.array([r[11] for r in rows])
    print(f"\n{args.n} sets, {len(rows)} shifts, {time.time() - t0:.0f} s")
    print(f"not determined (94 % HDI wider than a decade): {gone.sum()} shifts, their HDIs "
          f"cover {np.mean([r[7] for r in rows if r[11]]) if gone.any() else math.nan:.3f}; "
          f"all shifts together {np.mean([r[7] for r in rows]):.3f}")
    rows = [r for r in rows if not r[11]]  # the intervals the tool claims
    cover = np.array([r[7] for r in rows])
    z = np.array([r[8] for r in rows])
    kept = sorted({r[0] for r in rows})
    per_set = np.array([np.mean([r[7] for r in rows if r[0] == k]) for k in kept])
    print(f"determined shifts: {cover.size}")
    print(f"94 % HDI coverage {cover.mean():.3f} (binomial SE {math.sqrt(cover.mean() * (1 - cover.mean()) / cover.size):.3f}, "
          f"set-clustered SE {per_set.std(ddof=1) / math.sqrt(len(kept)):.3f})")
    print(f"z-scores: sd {np.nanstd(z):.2f}, max |z| {np.nanmax(np.abs(z)):.1f}; median |error| "
          f"{np.median([r[9] for r in rows]):.4f} decade")
    for name, j in (("law", 1), ("vertical", 2), ("noise", 3)):
        for v in sorted({r[j] for r in rows}, key=str):
            sel = np.array([r[j] == v for r in rows])
            print(f"  {name} {v}: coverage {cover[sel].mean():.3f} of {sel.sum()}")
    chosen = {"law": [(r[1], r[4]) for r in rows], "vertical": [(r[2], r[5]) for r in rows],
              "noise": [(r[3], r[6]) for r in rows]}
    for name, pairs in chosen.items():
        right = {("wlf", "wlf"), ("arrhenius", "arrhenius"), (True, "density"),
                 (False, "none"), ("parts", "relative_parts"),
                 ("proportional", "proportional")}
        print(f"  {name} chosen as made: {np.mean([p in right for p in pairs]):.3f} of shifts")
    print(f"  certified: {np.mean([r[10] for r in rows]):.3f}")
    for ok in (True, False):
        sel = np.array([r[10] == ok for r in rows])
        if sel.any():
            print(f"  {'certified' if ok else 'not certified'} posteriors: coverage "
                  f"{cover[sel].mean():.3f} of {sel.sum()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
