"""Does a certified joint master-curve posterior hold the whole posterior? Simulated isotherms
against an unguided reference.

The master-curve counterpart of ``bench_certificate.py``. Each data set is one of the
calibration of the shifts (``tests/integration/test_calibration.py::mastercurve_shift_coverage``:
six isotherms of a random Zener, 12 frequencies each, shifted by a random WLF law plus an
independent departure per isotherm, 1 % or 3 % proportional noise); ``bayesfo.mastercurve(data,
"zener", law="free")`` gives the joint posterior by the default route (structure, five shifts,
the noise: ten parameters). The reference is the posterior of two tempered-ladder runs of 3 000
particles from the prior *without* a guide (``ladder_runs(..., guide=None)``) on the same joint
likelihood: it does not start from the joint fit, so it cannot inherit a configuration the fit
misses (shifts are exchangeable-looking nuisance parameters: an isotherm slid by a decade along a
featureless stretch of the master curve). The figure of merit is the share of the reference's
draws outside the range of the reported draws on some parameter, beside the share expected of
draws from the same posterior (``certified._expected_outside``: two per parameter over the ESS);
a data set "misses" where it exceeds that by 5 %.

``--bundled`` runs the bundled 20 adhesive isotherms instead (``bayesfo mastercurve
examples/data/adhesive_468mp --reference-temperature 20``'s joint posterior with the Zener
master and free shifts, proportional noise: 24 parameters, more than the configurations search
covers): one real joint posterior against its unguided reference.

Usage: python benchmarks/bench_certificate_mastercurve.py [--n 10] [--seed 21] [--bundled]
       [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parents[1] / "tests" / "integration"))
import test_calibration as calibration  # noqa: E402  (the calibration's isotherms)

import bayesfo as bf  # noqa: E402
import bayesfo.inference as inference  # noqa: E402
from bayesfo.inference import certified  # noqa: E402
from bayesfo.inference.evidence import ladder_runs  # noqa: E402
from bayesfo.inference.results import posterior_from_particles  # noqa: E402

MISS = 0.05


def bundled():
    """The bundled sweep's isotherms, as the command reads them."""
    from bayesfo.cli.mastercurve import read_isotherm_files

    return read_isotherm_files([str(Path(__file__).parents[1] / "examples" / "data"
                                    / "adhesive_468mp")])


def one(data, k: int) -> dict:
    """The route's joint posterior and the unguided reference on its likelihood."""
    seen = {}
    route = inference.certified_posterior

    def recording(lik, *args, **kwargs):  # the joint likelihood the route samples
        seen["lik"] = lik
        return route(lik, *args, **kwargs)

    inference.certified_posterior = recording
    try:
        t0 = time.perf_counter()
        mc = bf.mastercurve(data, "zener", reference_temperature=20.0, law="free", seed=0)
        seconds = time.perf_counter() - t0
    finally:
        inference.certified_posterior = route
    lik = seen["lik"]
    t0 = time.perf_counter()
    _, runs = ladder_runs(lik, seed=10_000 + k, n_particles=3000, guide=None)
    ref = posterior_from_particles(lik, runs, seed=k, predictive=False)
    ref_seconds = time.perf_counter() - t0
    post = mc.posterior
    outside = certified._outside(post.samples_scaled, ref.samples_scaled)
    expected = certified._expected_outside(lik.ndim, post.ess_min)
    return {"set": k, "route": post.sampler, "certified": bool(post.converged),
            "n_params": lik.ndim, "outside": outside, "expected": expected,
            "reference_certified": bool(ref.converged), "reference_rhat": ref.rhat_max,
            "seconds": seconds, "reference_seconds": ref_seconds,
            "log_z": mc.log_evidence, "notes": list(mc.notes)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--seed", type=int, default=21)
    ap.add_argument("--bundled", action="store_true")
    ap.add_argument("--json")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    print(f"# {platform.node()} {platform.processor() or platform.machine()}, "
          f"bayesfo {bf.__version__}; seed {args.seed}")
    rows = []
    sets = ([(bundled(), None, None)] if args.bundled
            else calibration.mastercurve_sets(args.n, args.seed))
    for k, (data, _, rel) in enumerate(sets):
        row = one(data, k)
        row["noise"] = None if rel is None else float(rel)
        rows.append(row)
        miss = row["outside"] > row["expected"] + MISS and row["certified"]
        level = "bundled" if rel is None else f"{rel:.2f}"
        print(f"set {k:3d} noise {level} {row['route']:10s} certified={row['certified']!s:5s}"
              f" {row['n_params']} parameters  outside {row['outside']:.3f} (expected "
              f"{row['expected']:.3f}){'  MISS' if miss else ''}  reference R-hat "
              f"{row['reference_rhat']:.3f} certified={row['reference_certified']}  "
              f"{row['seconds']:.1f} s + reference {row['reference_seconds']:.1f} s", flush=True)
    routes = [r["route"] for r in rows]
    print(f"\n{len(rows)} data sets: " + ", ".join(f"{s} {routes.count(s)}"
                                                  for s in sorted(set(routes)))
          + f"; largest share outside {max(r['outside'] for r in rows):.3f}; misses "
          f"{sum(r['outside'] > r['expected'] + MISS and r['certified'] for r in rows)}; "
          f"median {np.median([r['seconds'] for r in rows]):.1f} s per master curve")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
