"""The master curve of the 20 bundled adhesive isotherms beside its peers, timed in the same
rounds: ``bayesfo mastercurve`` as a process with its defaults (figures, report), against
``mastercurves`` (Lennon et al. 2023: a Gaussian process per isotherm, on ln ω and ln G′, its
defaults) and ``pyvisco`` (power laws between neighbouring isotherms, ``master.get_aT``), each
as a process from the same files, interleaved over ``--rounds``. Each method's shifts are then
scored by one measure, the rms difference of neighbouring isotherms' log10 |G*| where the
shifted pair overlaps (``bench_mastercurve_real.mismatch``; the −40/−30 °C pair, where
superposition fails, reported apart).

The peers are not dependencies of bayesfo: give a Python that has them with ``--peers``
(``python -m venv peers && peers/bin/pip install mastercurves pyvisco``); without it only
bayesfo is timed.

    python benchmarks/bench_mastercurve_peers.py [--rounds 3] [--peers PATH/TO/python]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench_mastercurve_real import ADHESIVE, mismatch  # noqa: E402

from bayesfo.cli.mastercurve import read_isotherm_files  # noqa: E402

T_REF = 20.0

MASTERCURVES = """
import json, sys
import numpy as np
from mastercurves import MasterCurve
from mastercurves.transforms import Multiply
d = np.load(sys.argv[1])
temps = list(d["temps"])
xs = [np.log(d[f"w{i}"]) for i in range(len(temps))]
ys = [np.log(d[f"gp{i}"]) for i in range(len(temps))]
mc = MasterCurve()
mc.add_data(xs, ys, temps)
mc.add_htransform(Multiply())
mc.superpose()
mc.change_ref(float(d["ref"]))
print(json.dumps([float(np.log10(a)) for a in mc.hparams[0]]))
"""

PYVISCO = """
import io, json, sys
import numpy as np
from pyvisco import load, master
with open(sys.argv[1], "rb") as f:
    data = f.read()
df_raw, arr_t, units = load.user_raw(data, "freq", "G")
df_aT, _ = master.get_aT(df_raw, float(sys.argv[2]))
print(json.dumps([float(v) for v in df_aT["log_aT"]]))
"""


def write_inputs(isotherms, tmp: Path) -> tuple[Path, Path]:
    """The isotherms as the peers read them: an npz for mastercurves, pyvisco's CSV (two
    header rows, frequency in Hz, one set per temperature, coldest first)."""
    arrays = {"temps": np.array([t for _, t in isotherms]), "ref": T_REF}
    rows = ["f,G_stor,G_loss,T,Set", "Hz,Pa,Pa,C,-"]
    for i, (d, t) in enumerate(isotherms):
        order = np.argsort(d.omega)
        w, g = d.omega[order], d.response[order]
        arrays[f"w{i}"], arrays[f"gp{i}"] = w, g.real
        rows += [f"{wk / (2 * np.pi):.10g},{gk.real:.10g},{gk.imag:.10g},{t:g},{i}"
                 for wk, gk in zip(w, g, strict=True)]
    npz, csv = tmp / "isotherms.npz", tmp / "pyvisco.csv"
    np.savez(npz, **arrays)
    csv.write_text("\n".join(rows) + "\n")
    return npz, csv


def timed(cmd, env=None) -> tuple[float, str]:
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, env=env)
    took = time.perf_counter() - t0
    if done.returncode != 0:
        raise RuntimeError(f"{cmd[:3]} failed: {done.stderr[-2000:]}")
    return took, done.stdout


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--peers", default=None, help="a Python with mastercurves and pyvisco")
    args = ap.parse_args()
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, python "
          f"{platform.python_version()}, load average {os.getloadavg()[0]:.1f} at the start")
    iso = sorted(read_isotherm_files([ADHESIVE]), key=lambda p: p[1])
    temps = np.array([t for _, t in iso])
    ref = int(np.argmin(np.abs(temps - T_REF)))
    times = {"bayesfo mastercurve (defaults, figures)": [], "mastercurves": [], "pyvisco": []}
    shifts = {}
    env = dict(os.environ, MPLBACKEND="Agg")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        npz, csv = write_inputs(iso, tmp)
        for r in range(args.rounds):
            took, _ = timed([sys.executable, "-m", "bayesfo.cli", "mastercurve", str(ADHESIVE),
                             "--reference-temperature", f"{T_REF:g}", "--out",
                             str(tmp / f"mc{r}")], env)
            times["bayesfo mastercurve (defaults, figures)"].append(took)
            summary = json.loads((tmp / f"mc{r}" / "summary.json").read_text())
            if args.peers:
                took, out = timed([args.peers, "-c", MASTERCURVES, str(npz)])
                times["mastercurves"].append(took)
                shifts["mastercurves"] = np.array(json.loads(out.strip().splitlines()[-1]))
                took, out = timed([args.peers, "-c", PYVISCO, str(csv), f"{T_REF:g}"])
                times["pyvisco"].append(took)
                shifts["pyvisco"] = np.array(json.loads(out.strip().splitlines()[-1]))
    factors = summary["shift_factors"]
    shifts["bayesfo"] = np.array([f["log10_aT"]["mean"] for f in factors])
    log_b = np.array([f["log10_bT"]["mean"] if "log10_bT" in f else 0.0 for f in factors])
    print(f"\n{args.rounds} interleaved rounds, wall times [s]:")
    for name, ts in times.items():
        if ts:
            print(f"  {name:<42} " + ", ".join(f"{t:.1f}" for t in ts)
                  + f"   median {np.median(ts):.1f}")
    print("\nrms mismatch of neighbouring isotherms' log10 |G*| after shifting [decade] "
          "(19 pairs without -40/-30 °C; that pair apart):")
    for name, a in shifts.items():
        a = a - a[ref]
        b = log_b if name == "bayesfo" else np.zeros_like(a)
        v = mismatch(iso, a, b)
        how = " (with its vertical shifts)" if name == "bayesfo" and np.any(b) else ""
        print(f"  {name + how:<42} {np.sqrt(np.nanmean(v[1:] ** 2)):.4f}   -40/-30 °C "
              f"{v[0]:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
