"""Simulation-based calibration of one card by the default route, split by the route each
posterior took and by parameter.

The same data sets as ``tests/integration/test_calibration.py::coverage(name, n, seed,
route="default")`` (truths from the card's priors on the fixed scaling, 25 frequencies
0.6–300 rad/s, 1 % or 5 % complex noise with σ known), the posterior as ``compare`` computes it;
for each data set the rank of the truth among the posterior draws, per parameter. Printed: the
central 50 % and 90 % coverage per route and per parameter, over all data sets, and the
histogram of the ranks (ten bins; flat when the posteriors are calibrated). A split by a route
that the data choose need not be nominal; the whole is. The same per noise level.

With ``--reference``, each data set's posterior is also computed by an independent route: two
tempered-ladder runs of 3 000 particles started from the prior without a guide (they cannot
inherit what the optima miss), the truth's rank under it printed beside the route's, and the
coverage of both over the same data sets: where the two agree, the route computes the
posterior the model defines, and a coverage off nominal is the model's (or chance), not the
route's. ``--first`` skips the first data sets (their draws are made all the same, so the data
sets are those of a full run), to split a long run over processes.

Usage: python benchmarks/bench_calibration_routes.py [--card fractional_zener_sl] [--n 300]
[--seed 14] [--first 0] [--reference] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parents[1] / "tests" / "integration"))
import test_calibration as calibration  # noqa: E402  (the study's data sets and route)

from bayesfo.data import FrequencyResponse  # noqa: E402
from bayesfo.inference import Likelihood  # noqa: E402
from bayesfo.inference.evidence import ladder_runs  # noqa: E402
from bayesfo.inference.results import posterior_from_particles  # noqa: E402
from bayesfo.structures import get_structure  # noqa: E402


def _coverage(ranks: np.ndarray, level: float) -> np.ndarray:
    half = level / 2
    return np.mean((ranks > 0.5 - half) & (ranks < 0.5 + half), axis=0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--card", default="fractional_zener_sl")
    ap.add_argument("--n", type=int, default=300)
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--reference", action="store_true")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    s = get_structure(args.card)
    table = calibration.PRIORS_RIDGED.get(args.card, calibration.PRIORS)
    priors = {k: v for k, v in table.items() if k in s.param_names}
    w = calibration.W
    template = FrequencyResponse(w, np.ones(w.size), np.ones(w.size), kind="compliance")
    rows = []
    t0 = time.perf_counter()
    for k in range(args.n):  # the draws in the order of calibration.coverage
        theta = calibration.draw_truth(
            Likelihood(s, template, priors=priors, scaling=calibration.SCALING), rng)
        g = s.response(theta, w, "compliance")
        level = rng.choice([0.01, 0.05])
        sd = level * np.abs(g)
        noisy = g + sd / np.sqrt(2) * (rng.normal(size=w.size) + 1j * rng.normal(size=w.size))
        data = FrequencyResponse(w, noisy, sd, kind="compliance")
        if k < args.first:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            post, route = calibration.default_route(s, data, priors, seed=k)
            row = {"set": k, "route": route, "noise": float(level),
                   "certified": bool(post.converged),
                   "ranks": np.mean(post.samples < theta, axis=0).tolist()}
            if args.reference:
                lik = Likelihood(s, data, priors=priors, scaling=calibration.SCALING)
                _, runs = ladder_runs(lik, seed=10_000 + k, n_particles=3000, guide=None)
                ref = posterior_from_particles(lik, runs, seed=k)
                row["reference_ranks"] = np.mean(ref.samples[:, :theta.size] < theta,
                                                 axis=0).tolist()
                row["reference_certified"] = bool(ref.converged)
        rows.append(row)
    names = list(s.param_names)
    print(f"{args.card}: data sets {args.first}-{args.n - 1} (seed {args.seed}), "
          f"{time.perf_counter() - t0:.0f} s")
    groups = {route: [r for r in rows if r["route"] == route]
              for route in sorted({r["route"] for r in rows})}
    groups.update({f"noise {100 * level:.0f} %": [r for r in rows if r["noise"] == level]
                   for level in sorted({r["noise"] for r in rows})})
    groups["all"] = rows
    keys = ["ranks"] + (["reference_ranks"] if args.reference else [])
    for group, members in groups.items():
        for key in keys:
            ranks = np.array([r[key] for r in members])
            c50, c90 = _coverage(ranks, 0.5), _coverage(ranks, 0.9)
            extreme = np.mean((ranks < 0.02) | (ranks > 0.98), axis=0)
            cells = ", ".join(f"{n} {a:.2f}/{b:.2f} (extreme {e:.3f})"
                              for n, a, b, e in zip(names, c50, c90, extreme, strict=True))
            by = "route" if key == "ranks" else "reference"
            print(f"  {group} ({len(members)}), {by}: 50 %/90 % coverage: {cells}")
    if args.reference:
        diff = np.abs(np.array([r["ranks"] for r in rows])
                      - np.array([r["reference_ranks"] for r in rows]))
        print("  |rank by the route - rank by the reference|: mean "
              + ", ".join(f"{n} {d:.3f}" for n, d in zip(names, diff.mean(0), strict=True))
              + "; largest " + ", ".join(f"{n} {d:.3f}" for n, d in zip(names, diff.max(0),
                                                                         strict=True)))
    ranks = np.array([r["ranks"] for r in rows])
    for j, n in enumerate(names):
        print(f"  ranks of {n}: {np.histogram(ranks[:, j], bins=10, range=(0, 1))[0].tolist()}")
    if args.json:
        Path(args.json).write_text(json.dumps({"card": args.card, "params": names,
                                               "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
