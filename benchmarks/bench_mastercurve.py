"""Master curve of the 20 bundled adhesive isotherms (3M 468MP, -40 to 150 °C, 340 points):
bayesfo's joint posterior (Zener master structure, shifts, noise; certified, with ln Z) against
``mastercurves`` (Lennon et al.: a Gaussian process per isotherm and pairwise shift
likelihoods, on log ω and log G′ with its default bounds), timed in the same run, with both
sets of log10 a_T at 20 °C and their differences.

``mastercurves`` is not a dependency of bayesfo: ``pip install mastercurves`` to time it.

With ``--command``: the wall time of ``bayesfo mastercurve`` as a process on the same files with
its defaults (three master structures, the shift laws inside the posterior, figures, report),
with ``--workers 1`` (one after the other) and the default ``--workers 0`` (one process per
CPU), interleaved over ``--rounds`` rounds.

Usage: python benchmarks/bench_mastercurve.py [--structure zener] [--command [--rounds N]]
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

import bayesfo as bf
from bayesfo.data.temperature import temperature_of_file

ADHESIVE = Path(__file__).resolve().parents[1] / "examples" / "data" / "adhesive_468mp"
T_REF = 20.0


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--structure", default="zener")
    parser.add_argument("--command", action="store_true")
    parser.add_argument("--rounds", type=int, default=1)
    args = parser.parse_args()
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, python "
          f"{platform.python_version()}")
    if args.command:
        return command(args.rounds)
    files = sorted(ADHESIVE.glob("T*.csv"))
    iso = sorted(((bf.read(f), temperature_of_file(f)) for f in files), key=lambda p: p[1])
    bf.inference  # the libraries loaded before the clock starts
    from bayesfo.inference._arviz import preload

    preload()
    warnings.simplefilter("ignore")
    t0 = time.perf_counter()
    mc = bf.mastercurve(iso, [args.structure], reference_temperature=T_REF, seed=0)
    ours = time.perf_counter() - t0
    factors = mc.shift_factors()
    print(f"bayesfo mastercurve ({args.structure}): {ours:.1f} s, posterior by "
          f"{mc.posterior.sampler}, certified {mc.posterior.converged}, ln Z "
          f"{mc.log_evidence:.2f} ± {mc.log_evidence_err:.2f}")
    law = mc.shift_law()
    print("  law: " + law["name"] + ", " + ", ".join(
        f"{k} {v['mean']:.4g} [{v['hdi_low']:.4g}, {v['hdi_high']:.4g}] {v['unit']}"
        for k, v in law["parameters"].items()))
    try:
        from mastercurves import MasterCurve
        from mastercurves.transforms import Multiply
    except ImportError:
        print("mastercurves not installed: pip install mastercurves to time it")
        return
    temps = [t for _, t in iso]
    xs = [np.log(d.omega) for d, _ in iso]
    ys = [np.log(d.response.real) for d, _ in iso]
    t0 = time.perf_counter()
    peer = MasterCurve()
    peer.add_data(xs, ys, temps)
    peer.add_htransform(Multiply())
    peer.superpose()
    peer.change_ref(T_REF)
    theirs = time.perf_counter() - t0
    a = np.log10(np.asarray(peer.hparams[0], dtype=float))
    da = np.asarray(peer.huncertainties[0], dtype=float) / np.asarray(peer.hparams[0]) / np.log(10)
    print(f"mastercurves (GP, default bounds): {theirs:.1f} s")
    print(f"{'T [°C]':>7} {'bayesfo log10 aT':>18} {'mastercurves':>16} {'difference':>11}")
    for f, x, dx in zip(factors, a, da, strict=True):
        s = f["log10_aT"]
        print(f"{f['temperature']:7g} {s['mean']:10.3f} ± {s['sd']:.3f} {x:9.3f} ± {dx:.3f} "
              f"{s['mean'] - x:+11.3f}")
    steps = np.diff(a)
    print(f"mastercurves steps at its bound of 2 decades: "
          f"{int(np.sum(np.isclose(np.abs(steps), 2.0, atol=1e-3)))}")


def command(rounds: int) -> None:
    """``bayesfo mastercurve`` as a process, one worker against one per CPU."""
    workers = {"--workers 1": "1", "--workers 0 (default)": "0"}
    times = {label: [] for label in workers}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(rounds):
            for label, n in workers.items():
                out = Path(tmp) / f"mc-{r}-{n}"
                cmd = [sys.executable, "-m", "bayesfo.cli", "mastercurve", str(ADHESIVE),
                       "--out", str(out), "--workers", n]
                t0 = time.perf_counter()
                done = subprocess.run(cmd, capture_output=True, text=True,
                                      env=dict(os.environ, MPLBACKEND="Agg"))
                times[label].append(time.perf_counter() - t0)
                if done.returncode != 0:
                    raise RuntimeError(done.stderr)
                print(f"round {r + 1}, {label}: {times[label][-1]:.1f} s (load "
                      f"{os.getloadavg()[0]:.1f})", flush=True)
    for label, t in times.items():
        print(f"{label}: median {np.median(t):.1f} s over {len(t)} (range {min(t):.1f}–"
              f"{max(t):.1f})")


if __name__ == "__main__":
    main()
