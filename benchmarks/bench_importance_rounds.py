"""Importance posteriors on real isotherms against an unguided tempered ladder: the later rounds
(ln Z where the first round's weights are heavy-tailed) and the ridge probe (mass the proposal
does not reach).

For every isotherm of the bundled adhesive sweep (20 temperatures), each structure and each
noise model, :func:`bayesfo.inference.importance.importance_posterior` runs as ``compare`` runs
it. For every posterior it certifies, and every one it sends elsewhere because of the ridge
probe, an independent reference is computed: two unguided tempered-ladder runs from the prior
(seed 1), ln Z by bridge sampling from their particles (a reference whose runs disagree is
reported and left out of the figures). Printed per case: the k̂ of each round, the probe's
estimate, the share of the reference's draws outside the range of the reported draws on some
parameter ("missed"), the difference of ln Z in units of the combined error, and the seconds
of the importance route and of the reference.

Usage: python benchmarks/bench_importance_rounds.py [--structures voigt,zener,...]
[--temperatures Tp050C,...]
"""

from __future__ import annotations

import argparse
import math
import platform
import time
import warnings
from pathlib import Path

import numpy as np

import bayesfo as bf
from bayesfo.identify.optimize import fit_structure
from bayesfo.inference import Likelihood, certified, starting_points
from bayesfo.inference import importance as importance_module
from bayesfo.inference.evidence import ladder_runs
from bayesfo.inference.results import posterior_from_particles

SWEEP = Path(__file__).parents[1] / "examples" / "data" / "adhesive_468mp"


def _outside(reported, reference) -> float:
    """Share of the reference's draws outside the range of the reported ones on some parameter."""
    return certified._outside(reported.samples_scaled, reference.samples_scaled)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--structures", default="voigt,zener,fractional_kelvin_voigt")
    ap.add_argument("--temperatures", default=None)
    args = ap.parse_args()
    temps = (args.temperatures.split(",") if args.temperatures
             else sorted(p.stem for p in SWEEP.glob("T*.csv")))
    print(f"machine: {platform.machine()}, python {platform.python_version()}")
    rows = []
    for t in temps:
        data = bf.read(SWEEP / f"{t}.csv")
        for name in args.structures.split(","):
            s = bf.get_structure(name)
            fit = fit_structure(s, data, rng=0, seed_methods=True, linear_methods=True)
            for noise in ("constant", "proportional"):
                lik = Likelihood(s, data, noise=noise)
                modes = starting_points(lik, fit)[0]
                t0 = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    post, ev, info = importance_module.importance_posterior(lik, modes, seed=0)
                t_imp = time.perf_counter() - t0
                if post is None and "ridge" not in info:
                    continue  # another route for another reason
                t0 = time.perf_counter()
                try:
                    ref_ev, runs = ladder_runs(lik, seed=1, guide=None)
                    ref = posterior_from_particles(lik, runs, seed=1)
                except Exception as exc:  # noqa: BLE001 - a reference that fails is reported
                    print(f"{t} {name} {noise}: reference ladder failed: {exc}")
                    continue
                t_ref = time.perf_counter() - t0
                probe = info.get("probe", {})
                ks = " → ".join(f"{k:.2f}" for k in info.get("k_hat_rounds", []))
                if post is None:
                    print(f"{t} {name:24s} {noise:12s} k̂ {ks:28s} ridge along "
                          f"{info['ridge']} ({probe.get('missed', 0):.3f}): to the ladder; "
                          f"reference converged {ref.converged}", flush=True)
                    rows.append(dict(t=t, name=name, noise=noise, sent=True, ok=ref.converged))
                    continue
                missed = _outside(post, ref)
                z = (math.nan if ev is None else
                     (ev.log_z - ref_ev.log_z) / math.hypot(ev.log_z_err, ref_ev.log_z_err))
                rows.append(dict(t=t, name=name, noise=noise, sent=False, ok=ref.converged,
                                 missed=missed, z=z, widened="covered" in probe,
                                 rounds=len(info["k_hat_rounds"]), t_imp=t_imp, t_ref=t_ref,
                                 probe=probe.get("missed", math.nan),
                                 probe_points=probe.get("points", 0)))
                lz = "ladder" if ev is None else f"{ev.log_z:.3f} ± {ev.log_z_err:.3f}"
                print(f"{t} {name:24s} {noise:12s} k̂ {ks:28s} probe "
                      f"{probe.get('missed', math.nan):.3f}{' (widened)' if 'covered' in probe else ''}"
                      f"  missed {missed:.3f}  ln Z {lz:18s} ref {ref_ev.log_z:.3f} ± "
                      f"{ref_ev.log_z_err:.3f} (z {z:+.2f}){'' if ref.converged else ' REF NOT CONVERGED'}"
                      f"  {t_imp:.2f} s / {t_ref:.2f} s", flush=True)
    done = [r for r in rows if not r["sent"] and r["ok"]]
    print(f"\n{len(done)} certified importance posteriors with a converged reference "
          f"({sum(r['widened'] for r in done)} widened along a ridge); "
          f"{sum(r['sent'] for r in rows)} sent to the ladder by the ridge probe")
    if done:
        missed = np.array([r["missed"] for r in done])
        print(f"  reference draws outside the reported range: median {np.median(missed):.3f}, "
              f"max {missed.max():.3f}, over 0.05: {int(np.sum(missed > 0.05))}")
        zs = np.array([r["z"] for r in done if np.isfinite(r["z"])])
        later = [r for r in done if r["rounds"] > 1 and np.isfinite(r["z"])]
        print(f"  ln Z − reference, in combined errors ({len(zs)} with ln Z): mean "
              f"{zs.mean():+.2f}, sd {zs.std():.2f}, |z| > 2: {int(np.sum(np.abs(zs) > 2))}; "
              f"{len(later)} of them from a later round")
        print(f"  seconds: importance route median {np.median([r['t_imp'] for r in done]):.2f} "
              f"(max {max(r['t_imp'] for r in done):.2f}), reference ladder median "
              f"{np.median([r['t_ref'] for r in done]):.2f}; probe points median "
              f"{np.median([r['probe_points'] for r in done]):.0f}")


if __name__ == "__main__":
    main()
