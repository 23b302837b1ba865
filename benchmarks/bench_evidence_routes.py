"""The evidence routes on the thesis' G_spec set-up (25 points, complex noise σ = 0.005, known):
bridge sampling from the emcee draws, bridge sampling from the particles of a tempered ladder,
and dynesty static nested sampling on the same prior and likelihood, for each structure given.

Prints ln Z ± error of each route with its wall time (the emcee time includes optimisation,
posterior and criteria), whether the posterior converged, the route ``compare`` takes by
default (the draws where the posterior converged, the ladder where it did not) and its
difference from nested sampling. Goal (issue 5): agreement within 0.3 nats.

Usage: python benchmarks/bench_evidence_routes.py [--structures voigt,zener,maxwell,max3]
       [--nlive 500] [--seed 0] [--sample unif] [--slices N] [--no-nested]

Uniform draws (dynesty's default here) stall on the ridges of the max-order members with n >= 2;
use ``--sample rslice --slices 25`` for those (dynesty's default of 3 + ndim slices gives ln Z
too low by 0.5-1.3 nats on these data).
"""

from __future__ import annotations

import argparse
import platform
import time
import warnings

import numpy as np

from bayesfo.comparison import compare
from bayesfo.errors import InputError
from bayesfo.inference import Likelihood
from bayesfo.inference._arviz import preload
from bayesfo.inference.evidence import ladder_evidence, nested_evidence
from bayesfo.structures import resolve_structures
from bayesfo.studies import g_spec_data


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--structures", default="voigt,zener,maxwell,max3")
    parser.add_argument("--nlive", type=int, default=500)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--sample", default="unif", help="dynesty's sampler (unif, rslice, …)")
    parser.add_argument("--slices", type=int, default=None, help="slices per new point (rslice)")
    parser.add_argument("--no-nested", action="store_true", help="skip nested sampling")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    preload()
    print(f"machine: {platform.machine()}, python {platform.python_version()}, numpy {np.__version__}")
    data = g_spec_data(args.seed)
    print(f"{'structure':<12} {'bridge (draws)':>16} {'t [s]':>6} {'ladder':>16} {'t [s]':>6} "
          f"{'nested':>16} {'t [s]':>6} conv default {'diff':>6}", flush=True)
    for s in resolve_structures(args.structures):
        t = time.perf_counter()
        try:
            r = compare(data, [s], seed=args.seed, progress=False, evidence="bridge").results[0]
        except InputError as exc:
            print(f"{s.name:<12} not run: {exc}", flush=True)
            continue
        t_bridge = time.perf_counter() - t
        bridge = r.criteria.evidence
        lik = Likelihood(s, data)
        ladder = ladder_evidence(lik, seed=args.seed, guide=r.posterior)
        default = bridge if r.posterior.converged else ladder
        line = (f"{s.name:<12} {bridge.log_z:9.2f} ± {bridge.log_z_err:4.2f} {t_bridge:6.1f} "
                f"{ladder.log_z:9.2f} ± {ladder.log_z_err:4.2f} {ladder.seconds:6.1f} ")
        if args.no_nested:
            print(f"{line}{'':>24} {str(r.posterior.converged):<5} {default.method}", flush=True)
            continue
        nested = nested_evidence(lik, seed=args.seed, nlive=args.nlive, sample=args.sample,
                                 slices=args.slices)
        diff = default.log_z - nested.log_z
        print(f"{line}{nested.log_z:9.2f} ± {nested.log_z_err:4.2f} {nested.seconds:6.0f} "
              f"{str(r.posterior.converged):<5} {default.method:<7} {diff:+6.2f}", flush=True)


if __name__ == "__main__":
    main()
