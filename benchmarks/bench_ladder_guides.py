"""Tempered-ladder evidence where importance sampling does not certify the posterior: ln Z ±
error, the route and the runs' agreement over seeds, for one data set and structure.

The ladder's runs are guided by draws that cover the optima (``bayesfo.inference.smc``); a
guide that leads both runs astray the same way makes them agree on a wrong ln Z. Over several
seeds, the scatter of ln Z shows whether the stated error covers it. ``--guide-draws`` sets how
many draws of the importance proposal are handed to the ladder
(``bayesfo.inference.importance.GUIDE_DRAWS``; each of the two runs takes half).

Default: max-n2m1 on the bundled 3M 468MP adhesive at 20 °C, the noise model chosen by
evidence, seeds 0–3.

Usage: python benchmarks/bench_ladder_guides.py [--data adh20|adh-40|nrel|chia|...]
       [--structure max-n2m1] [--seeds 0,1,2,3] [--guide-draws N] [--noise auto]
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import bayesfo as bf
import bayesfo.inference.importance as importance

sys.path.insert(0, str(Path(__file__).parent))
from bench_certification import DATASETS, certificate, read  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", default="adh20", help=", ".join(DATASETS))
    parser.add_argument("--structure", default="max-n2m1")
    parser.add_argument("--seeds", default="0,1,2,3")
    parser.add_argument("--noise", default="auto")
    parser.add_argument("--guide-draws", type=int, default=importance.GUIDE_DRAWS)
    args = parser.parse_args(argv)
    importance.GUIDE_DRAWS = args.guide_draws  # read at call time; one process (workers=1)
    data = read(args.data)
    if data is None:
        sys.exit(f"{args.data}: data not found")
    print(f"machine: {platform.machine()}, python {platform.python_version()}, numpy "
          f"{np.__version__}; load {os.getloadavg()[0]:.2f}; {args.data} {args.structure}, "
          f"noise {args.noise}, guide draws {args.guide_draws}")
    values = []
    for seed in (int(s) for s in args.seeds.split(",")):
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = bf.compare(data, args.structure, seed=seed, workers=1, progress=False,
                           noise=args.noise)[args.structure]
        ev = r.criteria.evidence
        ok, figures = certificate(r)
        values.append((ev.log_z, ev.log_z_err))
        print(f"seed {seed}: {r.posterior.sampler:<10} noise {r.posterior.noise:<12} ln Z "
              f"{ev.log_z:9.3f} ± {ev.log_z_err:.3f} ({ev.method}); certified {ok} ({figures}); "
              f"{time.perf_counter() - t0:.1f} s", flush=True)
    z = np.array([v for v, _ in values])
    err = np.array([e for _, e in values])
    print(f"ln Z over {len(z)} seeds: range {z.min():.3f} … {z.max():.3f} (spread "
          f"{z.max() - z.min():.3f}), sd {z.std(ddof=1) if len(z) > 1 else 0:.3f}; stated "
          f"errors {err.min():.3f} … {err.max():.3f}")


if __name__ == "__main__":
    main()
