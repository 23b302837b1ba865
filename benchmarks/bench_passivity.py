"""The exact dissipation check of commensurate structures against the dense grid.

1. Agreement: the exact check (``Structure.passive``) against the definition on a 20 000-point
   grid of x = ω^q over ±30 decades (Im[N conj D] ≤ 0 through complex λ, the same relative
   rounding tolerance), on prior draws and on positive coefficients of mixed magnitudes; and how
   many of the sets that the old grid of the data ± 3 decades accepts violate dissipation.
2. Speed per check: the exact check against the old grid route (175 points, ``is_dissipative``)
   on 10 000 sets.
3. A tempered ladder (SMC, :func:`bayesfo.inference.smc.ladder_run`) of max-n2m2 on the thesis
   G_spec set-up (σ = 0.005 known, seed 3) with the exact check and with the grid
   (``passivity.EXACT_COMMENSURATE = False``, the route before the exact check).

Usage: python benchmarks/bench_passivity.py [--sets 10000] [--repeats 3] [--no-smc]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from bayesfo.data import FrequencyResponse
from bayesfo.inference import Likelihood
from bayesfo.inference.smc import ladder_run
from bayesfo.structures import get_structure, passivity
from bayesfo.structures.response import dissipation_grid, is_dissipative
from bayesfo.studies import OMEGA, g_spec

X = np.logspace(-30, 30, 20_000)
STRUCTURES = ("max-n2m1", "max-n2m2", "max-n3m3")


def grid_passive(den, num, q):
    return passivity.passive_on_grid(den, num, q, X)


def draws(s, rng, n, near):
    theta = np.column_stack([p.prior.sample(rng, n) for p in s.parameters])
    if near:
        theta[:, :-1] = np.abs(theta[:, :-1]) * 10.0 ** rng.uniform(-3, 0, (n, theta.shape[1] - 1))
    return theta


def bench_agreement(n_sets, repeats):
    rng = np.random.default_rng(0)
    old_grid = dissipation_grid(0.6, 300)  # the thesis data range ± 3 decades: 175 points
    for name in STRUCTURES:
        s = get_structure(name)
        for kind in ("compliance", "modulus"):
            total = disagree = missed = accepted_old = 0
            t_exact = t_grid = 0.0
            for r in range(repeats):
                theta = draws(s, rng, n_sets, near=r % 2 == 1)
                den, num, q = s.polynomials(theta)
                t = time.perf_counter()
                exact = s.passive(theta, kind, old_grid)
                t_exact += time.perf_counter() - t
                t = time.perf_counter()
                old = is_dissipative(s.response(theta, old_grid, kind), kind)
                t_grid += time.perf_counter() - t
                disagree += int(np.sum(exact != grid_passive(den, num, q)))
                missed += int(np.sum(old & ~exact))
                accepted_old += int(old.sum())
                total += n_sets
            print(f"{name:9s} {kind:10s}: {disagree} disagreements with the ±30-decade grid in "
                  f"{total} sets; old grid accepts {missed} non-passive among its {accepted_old} accepted "
                  f"({100 * missed / max(accepted_old, 1):.1f} %); per check "
                  f"exact {1e6 * t_exact / total:.2f} µs, old grid {1e6 * t_grid / total:.2f} µs")


def bench_smc(repeats=1):
    rng = np.random.default_rng(3)
    noise = 5e-3 / np.sqrt(2) * (rng.normal(size=25) + 1j * rng.normal(size=25))
    data = FrequencyResponse(OMEGA, g_spec() + noise, np.full(25, 5e-3), kind="compliance")
    lik = Likelihood(get_structure("max-n2m2"), data)
    for exact in (False, True):
        passivity.EXACT_COMMENSURATE = exact
        times = []
        for r in range(repeats):
            t = time.perf_counter()
            run = ladder_run(lik, np.random.default_rng(r))
            times.append(time.perf_counter() - t)
        print(f"tempered ladder max-n2m2 on G_spec, {'exact' if exact else 'grid '} check: "
              f"{np.median(times):.2f} s (median of {repeats}), {len(run.betas)} rungs, "
              f"ln Z = {run.log_z:.2f}, {run.n_likelihood} likelihood calls")
    passivity.EXACT_COMMENSURATE = True


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sets", type=int, default=10_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-smc", action="store_true")
    args = ap.parse_args()
    bench_agreement(args.sets, args.repeats)
    if not args.no_smc:
        bench_smc()


if __name__ == "__main__":
    main()
