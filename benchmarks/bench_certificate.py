"""Does a certified posterior hold the whole posterior? Simulated springpot data against an
unguided reference.

For each data set: parameters drawn from the card's own prior as the tool defines it (the
sampling coordinates of ``Likelihood``, restricted to its support), 25 frequencies 0.01-100
rad/s, 2 % complex noise given as σ; ``bayesfo.compare(data, card, noise="known")`` with the
defaults gives the reported posterior (its route: importance, ladder or emcee). The reference
posterior is that of two tempered-ladder runs of 3 000 particles from the prior *without* a guide
(``ladder_runs(..., guide=None)``), on the same likelihood and support: it does not start from
the optima, so it cannot inherit a mode they miss. The figure of merit is the share of the
reference draws that lie outside the range of the reported draws on some parameter (a lower
bound on the mass the reported posterior misses); a data set "misses" when it exceeds 5 %.
For importance posteriors the widest parameter's share of its prior range is printed too (the
second part of the certificate, ``bayesfo.inference.importance.UNDETERMINED``).

With ``--reference-slabs`` the reference ladder also proposes in the configurations where an
element vanishes, searched from the comparison's optima
(:func:`bayesfo.inference._configurations.configurations`): without them an unguided ladder of
3 000 particles can lose such a region too (on one fractional_zener_sl data set it kept 0.042
of the posterior where 0.095 lie; ``bench_configurations.py``), and the share it finds outside
the reported draws is then too small. ``--without-configurations`` runs the route without the
search for them (as before it existed; the reference keeps its slabs). ``--without-orders-rule``
runs the route without the second part of the importance certificate (an order left
undetermined by the weights no longer sends the posterior to the tempered ladder): what the
other parts (the ridge probe, the search for configurations, the ladder run for ln Z) catch
on their own.

Usage: python benchmarks/bench_certificate.py [--cards fractional_kelvin_voigt,...] [--n 40]
       [--first-seed 0] [--reference-slabs] [--without-configurations]
       [--without-orders-rule] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import platform
import time
import warnings

import numpy as np

import bayesfo as bf
from bayesfo.data import FrequencyResponse
from bayesfo.inference import Likelihood, certified, importance, starting_points
from bayesfo.inference._configurations import configurations
from bayesfo.inference.evidence import ladder_runs
from bayesfo.inference.results import posterior_from_particles
from bayesfo.inference.transform import Transform
from bayesfo.structures import get_structure

OMEGA = np.logspace(-2, 2, 25)
NOISE = 0.02
MISS = 0.05


def simulate(card: str, seed: int) -> FrequencyResponse:
    """A data set from ``card`` with parameters drawn from its prior on the support."""
    s = get_structure(card)
    rng = np.random.default_rng(seed)
    dummy = FrequencyResponse(OMEGA, np.ones(OMEGA.size) + 1j, NOISE * np.ones(OMEGA.size),
                              kind="modulus")
    lik = Likelihood(s, dummy, noise="known")
    tr = Transform(lik)
    k = s.n_params
    while True:
        u = rng.uniform(tr.lo_u[:k], tr.hi_u[:k])
        theta = np.where(tr.log[:k], np.exp(u), u)
        if s.admissible(theta, "modulus", lik.grid):
            break
    g = s.response(theta, OMEGA, "modulus")
    sd = NOISE * np.abs(g)
    y = g + sd / np.sqrt(2) * (rng.normal(size=OMEGA.size) + 1j * rng.normal(size=OMEGA.size))
    return FrequencyResponse(OMEGA, y, sd, kind="modulus", name=f"{card} seed {seed}")


def one(card: str, seed: int, reference_slabs: bool = False) -> dict:
    data = simulate(card, seed)
    t0 = time.perf_counter()
    r = bf.compare(data, card, noise="known", workers=1, progress=False, seed=seed)[card]
    seconds = time.perf_counter() - t0
    lik = Likelihood(get_structure(card), data, noise="known")
    slabs = []
    if reference_slabs:
        modes, _ = starting_points(lik, r.fit)
        slabs = configurations(lik, modes)
    _, runs = ladder_runs(lik, seed=10_000 + seed, n_particles=3000, guide=None, slabs=slabs)
    ref = posterior_from_particles(lik, runs, seed=seed)
    k = lik.structure.n_params
    outside = certified._outside(r.posterior.samples[:, :k], ref.samples[:, :k])
    info = r.criteria.importance or {}
    widest = info.get("widest") or {}
    return {"k_hat": info.get("k_hat"), "evidence_method": r.criteria.evidence.method,
            "configurations_missed": (info.get("configurations") or {}).get("missed"),
            "ladder_outside": info.get("ladder_outside"),
            "card": card, "seed": seed, "route": r.posterior.sampler,
            "certified": bool(r.posterior.converged), "outside": outside,
            "reference_certified": bool(ref.converged), "seconds": seconds,
            "widest": widest.get("share_of_prior"), "reference_slabs": len(slabs)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cards", default="fractional_kelvin_voigt,fractional_zener_sl,"
                                       "fractional_maxwell_liquid")
    ap.add_argument("--n", type=int, default=40)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--reference-slabs", action="store_true")
    ap.add_argument("--without-configurations", action="store_true")
    ap.add_argument("--without-orders-rule", action="store_true")
    ap.add_argument("--json")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    if args.without_configurations:  # the route as before the configurations were searched
        certified.configurations = lambda *a, **k: []
    if args.without_orders_rule:  # every order counts as determined
        importance.UNDETERMINED = np.inf
    print(f"# {platform.node()} {platform.processor() or platform.machine()}, "
          f"bayesfo {bf.__version__}")
    rows = []
    for card in args.cards.split(","):
        for seed in range(args.first_seed, args.first_seed + args.n):
            row = one(card, seed, args.reference_slabs)
            rows.append(row)
            print(f"{card:28s} {seed:4d} {row['route']:10s} certified={row['certified']!s:5s} "
                  f"outside {row['outside']:.3f}{'  MISS' if row['outside'] > MISS else ''}  "
                  f"{row['seconds']:.2f} s"
                  + (f"  widest {row['widest']:.2f} k {row['k_hat']:.2f} "
                     f"lnZ {row['evidence_method']}" if row["widest"] is not None else "")
                  + (f" conf {row['configurations_missed']:.3f}"
                     if row["configurations_missed"] is not None else "")
                  + (f" ladder-out {row['ladder_outside']:.3f}"
                     if row["ladder_outside"] is not None else "")
                  + (f"  reference slabs {row['reference_slabs']}" if args.reference_slabs
                     else ""),
                  flush=True)
    print()
    print(f"{'card':28s} {'n':>4s} {'importance':>10s} {'ladder':>7s} {'emcee':>6s} "
          f"{'misses':>7s} {'median s':>9s}")
    for card in args.cards.split(","):
        sub = [r for r in rows if r["card"] == card]
        routes = [r["route"] for r in sub]
        print(f"{card:28s} {len(sub):4d} {routes.count('importance'):10d} "
              f"{routes.count('ladder'):7d} {routes.count('emcee'):6d} "
              f"{sum(r['outside'] > MISS and r['certified'] for r in sub):7d} "
              f"{np.median([r['seconds'] for r in sub]):9.2f}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
