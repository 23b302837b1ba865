"""Master curves of real isotherms, default options: how well the shifts superpose the data,
against published shifts, and the command's time.

1. The 20 bundled adhesive isotherms (3M 468MP, hermes-rheo, MIT): the rms mismatch of
   neighbouring isotherms after shifting (log10 |G*| of one interpolated at the other's reduced
   frequencies where they overlap, in decades; the −40/−30 °C pair, where the van Gurp–Palmen
   test finds superposition failing, reported apart), for the model-free shifts and for the
   shifts that best overlay each pair on its own (the floor).
2. The raw polyisoprene isotherms of RepTate (PI88K-09, −45…25 °C; GPL, read from
   ../shared/data/reference-gpl, never copied) against RepTate's published master curve of the
   same material (PI_94.9k_T-35.tts): the shift that lays each raw isotherm's loss angle on the
   published master's (tan δ is free of the vertical factor) is the published shift, taken
   relative to the reference isotherm; beside it the WLF law of the file's header
   (C1 = 8.772, C2 = 114.03 °C at −35 °C), which those shifts do not follow.
3. The command ``bayesfo mastercurve`` (figures, report) on the adhesive, as a process.

    python benchmarks/bench_mastercurve_real.py [--rounds N]
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bayesfo.cli.mastercurve import read_isotherm_files  # noqa: E402
from bayesfo.tts import mastercurve  # noqa: E402
from bayesfo.tts.isotherms import overlay_shift  # noqa: E402

ADHESIVE = ROOT / "examples" / "data" / "adhesive_468mp"
PI = (ROOT.parent / "shared" / "data" / "reference-gpl" / "reptate_pi_linear" / "original"
      / "osc_raw_PI88K-09")
PI_WLF = (8.772, 114.03, -35.0)
PI_MASTER = PI.parent / "tts_mastercurves" / "PI_94.9k_T-35.tts"


def published_shifts(isotherms):
    """Each isotherm's loss angle laid on the published master curve's: log10 a_T."""
    rows = np.loadtxt(PI_MASTER, skiprows=1)
    order = np.argsort(rows[:, 0])
    xm, phase = np.log10(rows[order, 0]), np.arctan2(rows[order, 2], rows[order, 1])
    out = []
    for d, _ in isotherms:
        o = np.argsort(d.omega)
        out.append(overlay_shift(xm, (phase,), np.log10(d.omega[o]),
                                 (np.angle(d.response[o]),), refine=True))
    return np.array(out)


def mismatch(isotherms, log_a, log_b):
    """Per neighbouring pair: rms difference of log10|G*| (decades) where the shifted pair
    overlaps."""
    out = []
    for i in range(len(isotherms) - 1):
        curves = []
        for j in (i, i + 1):
            d = isotherms[j][0]
            order = np.argsort(d.omega)
            x = np.log10(d.omega[order]) + log_a[j]
            y = np.log10(np.abs(d.response[order])) + log_b[j]
            curves.append((x, y))
        (xl, yl), (xu, yu) = curves
        inside = (xu >= xl.min()) & (xu <= xl.max())
        if inside.sum() < 2:
            out.append(math.nan)
            continue
        out.append(float(np.sqrt(np.mean((np.interp(xu[inside], xl, yl) - yu[inside]) ** 2))))
    return np.array(out)


def overlay_floor(isotherms):
    """The shifts that best overlay each pair of neighbours on its own (|G*| only)."""
    shifts = [0.0]
    for i in range(len(isotherms) - 1):
        lo, up = isotherms[i][0], isotherms[i + 1][0]
        ol, ou = np.argsort(lo.omega), np.argsort(up.omega)
        d = overlay_shift(np.log10(lo.omega[ol]), (np.log10(np.abs(lo.response[ol])),),
                          np.log10(up.omega[ou]), (np.log10(np.abs(up.response[ou])),),
                          refine=True)
        shifts.append(shifts[-1] + (0.0 if d is None else d))
    return np.array(shifts)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=1)
    args = ap.parse_args()
    warnings.simplefilter("ignore")

    iso = sorted(read_isotherm_files([ADHESIVE]), key=lambda p: p[1])
    t0 = time.perf_counter()
    mc = mastercurve(iso, "fractional_zener_ll", workers=0)
    api = time.perf_counter() - t0
    a = mc.shift_draws.mean(axis=0)
    b = np.zeros_like(a) if mc.vertical_draws is None else mc.vertical_draws.mean(axis=0)
    ours = mismatch(iso, a, b)
    floor = mismatch(iso, overlay_floor(iso), np.zeros(len(iso)))
    horizontal_only = mismatch(iso, a, np.zeros(len(iso)))
    print(f"adhesive, 20 isotherms: noise {mc.shift_evidence['noise']}, vertical {mc.vertical}, "
          f"API {api:.1f} s (fractional_zener_ll)")
    for name, v in (("model-free shifts (with their vertical shifts)", ours),
                    ("model-free horizontal shifts alone", horizontal_only),
                    ("pairwise overlay, |G*| only (floor)", floor)):
        print(f"  {name}: rms mismatch {np.sqrt(np.nanmean(v[1:] ** 2)):.4f} decade "
              f"(without -40/-30 °C), -40/-30 °C pair {v[0]:.4f}")

    if PI.is_dir():
        files = sorted(PI.glob("*.osc"))
        pi = sorted(read_isotherm_files(files), key=lambda p: p[1])
        t0 = time.perf_counter()
        mc = mastercurve(pi, "fractional_zener_ll", workers=0)
        took = time.perf_counter() - t0
        temps = np.array(mc.temperatures)
        ref = temps.tolist().index(mc.reference_temperature)
        c1, c2, t_pub = PI_WLF
        header = -c1 * (temps - t_pub) / (c2 + temps - t_pub)
        header = header - header[ref]
        published = published_shifts(pi)
        published = published - published[ref]
        f = mc.shift_factors()
        mean = np.array([x["log10_aT"]["mean"] for x in f])
        sd = np.array([x["log10_aT"]["sd"] for x in f])
        print(f"polyisoprene 94.9k, {len(pi)} isotherms, T_ref {mc.reference_temperature:g} °C: "
              f"noise {mc.shift_evidence['noise']}, vertical {mc.vertical}, {took:.1f} s")
        for t, m, s, p, h in zip(temps, mean, sd, published, header, strict=True):
            print(f"  {t:6g} °C  ours {m:8.3f} ± {s:.3f}   published master {p:8.3f}   "
                  f"difference {m - p:+.3f}   (header's WLF {h:8.3f})")
        print(f"  largest |difference| from the published master's shifts "
              f"{np.max(np.abs(mean - published)):.3f} decade")

    times = []
    for _ in range(args.rounds):
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "bayesfo.cli", "mastercurve", str(ADHESIVE),
                            "--out", f"{tmp}/mc"], check=True, capture_output=True,
                           env={"MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"})
            times.append(time.perf_counter() - t0)
    print("command 'bayesfo mastercurve' on the adhesive (default structures, figures): "
          + ", ".join(f"{t:.1f}" for t in times) + " s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
