"""Simulation study of ``bayesfo design``: how fast the proposed points settle a model choice,
against as many points placed by rules of thumb.

Truth: a fractional Zener (the demo's Zener posterior median with its second plateau moved to
begin near 10⁴ rad/s) on the 17 frequencies of the bundled 20 °C isotherm, 2 % complex noise
given as σ; Voigt and Zener are not yet told apart there. For k = 1, 2, 3 added points — the
first k proposed by ``bayesfo.design`` (window up to 1000 × the highest frequency), k
log-uniform over the same window, k in the decade above the data, k in the decade below — the
points are simulated from the truth (noise seeds 1-3), added, and the comparison rerun; ln B of
Zener over Voigt is printed and drawn (``--figure FILE.png``; the docs show it).

Usage: python benchmarks/bench_design_study.py [--figure docs/user_guide/design-study.png]
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

import bayesfo as bf
from bayesfo.data import FrequencyResponse
from bayesfo.structures import get_structure

ROOT = Path(__file__).resolve().parents[1]
TRUTH = [1.78398201, 1.65441487e-05, 8.7e-08, 0.569527278]  # a1, b0, b1, q (zener card)
NOISE = 0.02


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--figure", default=None)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    zener = get_structure("zener")
    w = bf.read(ROOT / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv").omega

    def simulate(omega, rng):
        g = zener.response([TRUTH], omega, "modulus")[0]
        sd = NOISE * np.abs(g)
        return g + sd / np.sqrt(2) * (rng.normal(size=g.size) + 1j * rng.normal(size=g.size)), sd

    def log_b(omega, y, sd):
        c = bf.compare(FrequencyResponse(omega, y, sd, kind="modulus"), "voigt,zener", seed=0,
                       progress=False, workers=1)
        return c, c["zener"].criteria.evidence.log_z - c["voigt"].criteria.evidence.log_z

    t0 = time.perf_counter()
    y, sd = simulate(w, np.random.default_rng(0))
    first, before = log_b(w, y, sd)
    plan = bf.design(first, points=3, window=(w.min() / 10, w.max() * 1000))
    lo, hi = w.min(), w.max()
    rules = {"proposed": lambda k: np.array([p["omega"] for p in plan.proposed[:k]]),
             "log-uniform": lambda k: np.logspace(np.log10(lo / 10), np.log10(hi * 1000),
                                                  k + 2)[1:-1],
             "decade above": lambda k: np.logspace(np.log10(hi), np.log10(hi * 10), k + 1)[1:],
             "decade below": lambda k: np.logspace(np.log10(lo / 10), np.log10(lo), k + 1)[:-1]}
    print(f"ln B (zener over voigt) on the data: {before:+.2f}; proposed "
          f"{[round(p['omega'], 1) for p in plan.proposed]} rad/s")
    table = {name: np.zeros((3, 3)) for name in rules}
    for s, seed in enumerate((1, 2, 3)):
        for name, rule in rules.items():
            for k in (1, 2, 3):
                if name == "proposed" and k > len(plan.proposed):
                    table[name][s, k - 1] = np.nan  # the design proposes no more
                    continue
                extra = rule(k)
                y2, sd2 = simulate(extra, np.random.default_rng(100 * seed + k))
                table[name][s, k - 1] = log_b(np.r_[w, extra], np.r_[y, y2], np.r_[sd, sd2])[1]
    print(f"{'points':>14} {'k=1':>18} {'k=2':>18} {'k=3':>18}   (ln B, min-max over 3 seeds)")
    for name, v in table.items():
        print(f"{name:>14} " + " ".join(
            f"{v[:, k].min():8.1f}–{v[:, k].max():<8.1f}" if np.isfinite(v[:, k]).all()
            else f"{'(none)':>17}" for k in range(3)))
    print(f"{time.perf_counter() - t0:.0f} s")
    if args.figure:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from bayesfo.plotting import save_figure
        from bayesfo.plotting.style import COLUMN_WIDTH, style

        with style():
            fig, ax = plt.subplots(figsize=(COLUMN_WIDTH, 2.8), layout="constrained")
            for name, v in table.items():
                k = np.flatnonzero(np.isfinite(v).all(axis=0))
                m = np.median(v[:, k], axis=0)
                ax.errorbar(k + 1, m, yerr=[m - v[:, k].min(0), v[:, k].max(0) - m],
                            marker="o", ms=3, capsize=2, label=name)
            ax.axhline(np.log(100), color="0.4", lw=0.7, ls=":")
            ax.text(3.05, np.log(100), "decisive", fontsize=6.5, va="center", color="0.3")
            # ln B stays positive in this study (the truth is the Zener): a log axis.
            ax.set_yscale("log")
            ax.set_ylim(0.3, 2 * max(np.nanmax(v) for v in table.values()))
            ax.set_xlim(0.8, 3.5)
            ax.set_xticks([1, 2, 3])
            ax.set_xlabel("points added")
            ax.set_ylabel("ln B, Zener over Voigt")
            fig.legend(loc="outside upper center", ncols=2, fontsize=7)
            save_figure(fig, args.figure)
            plt.close(fig)


if __name__ == "__main__":
    main()
