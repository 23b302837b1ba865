"""The importance proposal in unbounded coordinates (issue 34): routes, ln Z against known
answers, and the demo command's time before and after.

Three parts, each optional:

- ``--routes``: for each data set and structure (the demo isotherm and the certification data
  sets found), the noise screen's quick ln Z and Pareto k̂ of each noise model, whether it
  decided, and the importance route's verdict per noise model (certified, or why not) with the
  time of each. Run it with each source tree on ``PYTHONPATH`` to compare them.
- ``--agreement``: ln Z by importance sampling against the tempered ladder (unguided, several
  seeds) and dynesty, on the demo isotherm's Voigt with priors that put its optimum on three
  bounds of the box, and on the demo's Maxwell (its order α at 0), whose quick estimates are
  set against the ladders' under both noise models; and the screen's decision over seeds.
- ``--trees before=PATH,after=PATH``: ``bayesfo compare`` on the demo isotherm (defaults, with
  and without figures) from each source tree in turn, alternating, ``--rounds`` times; wall
  and CPU time (the command and its worker processes), the load average, and the route and
  noise models of the Maxwell.

Usage: python benchmarks/bench_unbounded_proposal.py [--routes] [--agreement]
       [--trees before=/tmp/a,after=/tmp/b] [--rounds 4] [--datasets adh20,chia]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

DEMO = Path(__file__).resolve().parents[1] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"
STRUCTURES = "voigt,zener,maxwell,fractional_kelvin_voigt,voigt-int,zener-int,maxwell-int"


def _datasets(keys):
    sys.path.insert(0, str(Path(__file__).parent))
    import bench_certification as bc

    import bayesfo as bf

    for key in keys:
        path, units, _ = bc.DATASETS[key]
        if Path(path).exists():
            yield key, (bf.read(path, units=units) if units else bf.read(path))


def routes(keys) -> None:
    import bayesfo as bf
    from bayesfo.comparison.steps import RunOptions, _fit, _quick_estimates, screen
    from bayesfo.inference import Likelihood, starting_points
    from bayesfo.inference.importance import importance_posterior
    from bayesfo.parallel import single_blas_thread

    with single_blas_thread():
        for key, data in _datasets(keys):
            for s in bf.resolve_structures(STRUCTURES):
                options = RunOptions()
                candidates, fit = _fit(s, data, options)
                t = time.perf_counter()
                quick = _quick_estimates(s, data, candidates, fit, options)
                t_screen = time.perf_counter() - t
                decided = screen(s, data, candidates, fit, options, quick=quick)
                shown = ", ".join(f"{n}: " + ("none" if q is None else
                                              f"{q['log_z']:.2f} (k̂ {q['k_hat']:.2f})")
                                  for n, q in quick.items())
                print(f"{key:8} {s.name:24} screen {t_screen:5.2f} s, decided "
                      f"{decided.leader if decided else '-':12} {shown}")
                for noise in candidates:
                    lik = Likelihood(s, data, noise=noise)
                    modes, _ = starting_points(lik, fit)
                    t = time.perf_counter()
                    post, ev, info = importance_posterior(lik, modes, seed=0)
                    dt = time.perf_counter() - t
                    verdict = (f"certified, k̂ {info['k_hat']:.2f}, ESS {info['ess']:.0f}"
                               + (f", ln Z {ev.log_z:.3f} ± {ev.log_z_err:.3f}" if ev else "")
                               if post is not None else info.get("reason", ""))
                    print(f"{'':34} {noise:12} {dt:5.2f} s  {verdict}")


def agreement(seeds: int) -> None:
    import bayesfo as bf
    from bayesfo.comparison.steps import RunOptions, _fit, screen
    from bayesfo.inference import Likelihood, starting_points
    from bayesfo.inference.evidence import ladder_runs, nested_evidence
    from bayesfo.inference.importance import importance_posterior, screen_noise
    from bayesfo.inference.results import posterior_from_particles
    from bayesfo.priors import LogUniform, Uniform

    data = bf.read(DEMO)
    priors = {"a1": LogUniform(1e-2, 6.0), "b0": LogUniform(7.0, 1e2),
              "q": Uniform(0.58, 0.9), "sigma": LogUniform(1e-3, 1.0)}
    s = bf.get_structure("voigt")
    _, fit = _fit(s, data, RunOptions(priors=priors))
    lik = Likelihood(s, data, noise="constant", priors=priors)
    modes, _ = starting_points(lik, fit)
    print(f"voigt, priors {', '.join(f'{k} {v.to_dict()}' for k, v in priors.items())}; "
          f"optimum {modes[0]}")
    for seed in range(seeds):
        post, ev, info = importance_posterior(lik, modes, seed=seed)
        if post is None:
            print(f"  importance seed {seed}: {info['reason']}")
            continue
        print(f"  importance seed {seed}: ln Z {ev.log_z:.3f} ± {ev.log_z_err:.3f} (k̂ "
              f"{info['k_hat']:.2f}, ESS {info['ess']:.0f}); mean {post.samples_scaled.mean(0)}")
    for seed in range(seeds):
        ev, runs = ladder_runs(lik, seed=seed, guide=None)
        ref = posterior_from_particles(lik, runs, seed=seed)
        print(f"  ladder seed {seed}: ln Z {ev.log_z:.3f} ± {ev.log_z_err:.3f}; mean "
              f"{ref.samples_scaled.mean(0)}")
    nested = nested_evidence(lik, seed=0)
    print(f"  dynesty: ln Z {nested.log_z:.3f} ± {nested.log_z_err:.3f}")

    s = bf.get_structure("maxwell")
    _, fit = _fit(s, data, RunOptions())
    print("maxwell on the demo isotherm")
    for noise in ("constant", "proportional"):
        lik = Likelihood(s, data, noise=noise)
        modes, _ = starting_points(lik, fit)
        quick = [screen_noise(lik, modes, seed=seed) for seed in range(seeds)]
        ladders = [ladder_runs(lik, seed=seed, guide=None)[0] for seed in range(seeds)]
        print(f"  {noise}: quick ln Z " + ", ".join(
            "none" if q is None else f"{q['log_z']:.2f} (k̂ {q['k_hat']:.2f})" for q in quick))
        print(f"  {noise}: ladder ln Z " + ", ".join(
            f"{e.log_z:.3f} ± {e.log_z_err:.3f}" for e in ladders))
    decided = [screen(s, data, ("constant", "proportional"), fit, RunOptions(seed=seed))
               for seed in range(seeds)]
    print("  screen over seeds: " + ", ".join(d.leader if d else "-" for d in decided))


def command(trees: dict, rounds: int) -> None:
    variants = {"no figures": ["--no-figures"], "figures + report": []}
    wall = {(t, v): [] for t in trees for v in variants}
    cpu = {(t, v): [] for t in trees for v in variants}
    loads = []
    out_root = Path(os.environ.get("TMPDIR", "/tmp")) / "bench-unbounded"
    for r in range(rounds):
        names = list(trees)
        order = names[r % len(names):] + names[:r % len(names)]
        for v, extra in variants.items():
            for t in order:
                out = out_root / f"{t}-{r}-{v.split()[0]}"
                subprocess.run(["rm", "-rf", str(out)], check=True)
                env = dict(os.environ, PYTHONPATH=trees[t], MPLBACKEND="Agg")
                loads.append(os.getloadavg()[0])
                c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
                t0 = time.perf_counter()
                done = subprocess.run([sys.executable, "-m", "bayesfo.cli", "compare", str(DEMO),
                                       "--out", str(out), "--quiet", *extra], env=env,
                                      capture_output=True, text=True, cwd=out_root.parent)
                dt = time.perf_counter() - t0
                c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
                if done.returncode:
                    raise RuntimeError(done.stderr)
                used = c1.ru_utime - c0.ru_utime + c1.ru_stime - c0.ru_stime
                wall[(t, v)].append(dt)
                cpu[(t, v)].append(used)
                summary = json.loads((out / "summary.json").read_text())
                mx = next(x for x in summary["structures"] if x["name"] == "maxwell")
                how = {k: m["evidence_method"] for k, m in mx["noise_models"]["models"].items()}
                print(f"round {r} {v:17} {t:8} {dt:6.2f} s, CPU {used:6.2f} s, load "
                      f"{loads[-1]:.2f}; maxwell {mx['sampler']}, {how}", flush=True)
    for (t, v), xs in wall.items():
        c = cpu[(t, v)]
        print(f"{v:17} {t:8} wall median {statistics.median(xs):6.2f} ({min(xs):.2f}–"
              f"{max(xs):.2f}), CPU median {statistics.median(c):6.2f} ({min(c):.2f}–"
              f"{max(c):.2f}), {len(xs)} runs")
    print(f"load average at the starts {min(loads):.2f}–{max(loads):.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--routes", action="store_true")
    parser.add_argument("--agreement", action="store_true")
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--datasets", default="adh20,chia,epstein,silk,ps145,ps190,adh-40,nrel")
    parser.add_argument("--trees", default=None, metavar="NAME=PATH,NAME=PATH")
    parser.add_argument("--rounds", type=int, default=4)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    np.set_printoptions(precision=4, suppress=True, linewidth=120)
    print("load average at start " + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    if args.routes:
        routes(args.datasets.split(","))
    if args.agreement:
        agreement(args.seeds)
    if args.trees:
        command(dict(item.split("=", 1) for item in args.trees.split(",")), args.rounds)
    if not (args.routes or args.agreement or args.trees):
        parser.error("nothing to do: give --routes, --agreement or --trees")
    print("load average at end " + " ".join(f"{x:.2f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main()
