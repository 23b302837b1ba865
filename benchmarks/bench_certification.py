"""Certification survey: is every reported posterior certified, on nine real data sets?

For each data set it runs the default comparison (``bayesfo.compare``, noise chosen by evidence)
on Voigt, Zener, Maxwell, max-n2m1, max-n2m2 and the integer baselines, and prints per structure
the route that produced the posterior (importance / ladder / emcee), whether it is certified and
by what figures (emcee and ladder: R-hat < 1.01 and bulk/tail ESS >= 400 over the chains or
runs; importance: Pareto k̂ < 0.7 and weight ESS >= 1000), the noise model chosen, ln Z ± error
and its method, the rank by ln Z with the posterior probability, whether the structure fits the
data (posterior predictive checks), and the warnings raised; then the wall time per data set.
The closing line counts the certified posteriors and the data sets whose top-ranked structure is
certified (issue: "certified posteriors for every structure on nine real data sets").

Data: the GPL reference data are read in place from ``../shared/data/reference-gpl`` (never
copied into the project; a data set that is absent is skipped), the rest from
``examples/data``. The nine: chia pudding, Epstein metal network, polystyrene 145 °C and 190 °C
isotherms (pyRheo), PI 94.9k master curve and silk feedstock (RepTate), the 3M 468MP adhesive
at 20 °C and -40 °C and the NREL DMA master curve (bundled).

Usage: python benchmarks/bench_certification.py [--datasets chia,pi] [--structures voigt,zener]
       [--workers 2] [--seed 0] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import time
import warnings
from pathlib import Path

import numpy as np

import bayesfo as bf
from bayesfo.inference.importance import ESS_MIN_IMPORTANCE, K_HAT_MAX
from bayesfo.inference.results import ESS_MIN, RHAT_MAX
from bayesfo.output.report import verdict

ROOT = Path(__file__).resolve().parents[1]
GPL = ROOT.parent / "shared" / "data" / "reference-gpl"
BUNDLED = ROOT / "examples" / "data"

STRUCTURES = "voigt,zener,maxwell,max-n2m1,max-n2m2,voigt-int,zener-int,maxwell-int"

#: key -> (file, units to state where the file has none, name)
DATASETS = {
    "chia": (GPL / "pyrheo_chia_pudding/original/oscillation_chia_data.csv", "Pa",
             "chia pudding (pyRheo)"),
    "epstein": (GPL / "pyrheo_metal_network_epstein/original/epstein.csv", "Pa",
                "Epstein metal network (pyRheo)"),
    "ps145": (GPL / "pyrheo_polystyrene_saos/original/oscillation_ps145_data.csv", "Pa",
              "polystyrene 145 °C (pyRheo)"),
    "ps190": (GPL / "pyrheo_polystyrene_saos/original/oscillation_ps190_data.csv", "Pa",
              "polystyrene 190 °C (pyRheo)"),
    "pi": (GPL / "reptate_pi_linear/original/tts_mastercurves/PI_94.9k_T-35.tts", None,
           "PI 94.9k master curve (RepTate)"),
    "silk": (GPL / "reptate_silk_feedstock/original/silk_feedstock.tts", None,
             "silk feedstock (RepTate)"),
    "adh20": (BUNDLED / "adhesive_468mp/Tp020C.csv", None, None),
    "adh-40": (BUNDLED / "adhesive_468mp/Tm040C.csv", None, None),
    "nrel": (BUNDLED / "nrel_dma_master.csv", None, None),
}


def _f(value, spec: str) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return format(value, spec)


def certificate(r) -> tuple[bool, str]:
    """Whether the posterior of ``r`` is certified by the figures of the route that produced
    it (checked here from those figures, not taken from ``converged`` alone), and the figures."""
    post = r.posterior
    if post.sampler == "importance":
        imp = r.criteria.importance or {}
        k_hat, ess = imp.get("k_hat", math.nan), imp.get("ess", math.nan)
        ok = k_hat < K_HAT_MAX and ess >= ESS_MIN_IMPORTANCE
        return ok, f"k̂ {k_hat:.2f}, ESS_w {ess:.0f}"
    ok = (post.rhat_max < RHAT_MAX and post.ess_bulk_min >= ESS_MIN
          and post.ess_tail_min >= ESS_MIN)
    chains = "runs" if post.sampler == "ladder" else "walkers"
    return ok, (f"R-hat {post.rhat_max:.3f}, ESS {post.ess_bulk_min:.0f}/{post.ess_tail_min:.0f}"
                f" ({post.n_walkers} {chains})")


def read(key: str):
    path, units, name = DATASETS[key]
    if not path.is_file():
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return bf.read(path, units=units, name=name)


def survey(key: str, structures: str, seed: int, workers: int) -> dict | None:
    data = read(key)
    if data is None:
        print(f"\n== {key}: {DATASETS[key][0]} not found, skipped")
        return None
    print(f"\n== {key}: {data.label}, {data.n_frequencies} points, "
          f"{data.omega.min():.3g}-{data.omega.max():.3g} rad/s, {data.kind} [{data.units or '-'}]",
          flush=True)
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = bf.compare(data, structures, seed=seed, workers=workers, progress=False)
    wall = time.perf_counter() - t0
    rank = {name: i + 1 for i, name in enumerate(result.ranking)}
    print(f"{'#':>2} {'structure':<12} {'route':<10} {'cert':<4} {'figures':<38} {'noise':<12} "
          f"{'ln Z ± err':>20} {'method':<10} {'P':>6} {'fits':<5}")
    rows = []
    for r in sorted(result.results, key=lambda r: rank.get(r.name, 99)):
        if r.error is not None:
            print(f"{'-':>2} {r.name:<12} failed: {r.error}")
            rows.append({"structure": r.name, "error": r.error})
            continue
        post, ev = r.posterior, r.criteria.evidence
        ok, figures = certificate(r)
        z = "-" if ev is None else f"{_f(ev.log_z, '.2f')} ± {_f(ev.log_z_err, '.2f')}"
        nm = r.criteria.noise_models or {}
        noise = post.noise + ("!" if nm.get("sensitive") else "")
        flag = ("yes" if ok else "NO") + ("" if ok == post.converged else "*")
        print(f"{rank[r.name]:>2} {r.name:<12} {post.sampler:<10} {flag:<4} {figures:<38} "
              f"{noise:<12} {z:>20} {'-' if ev is None else ev.method:<10} "
              f"{_f(r.criteria.posterior_probability, '.3f'):>6} {r.fits or '-':<5}")
        rows.append({
            "structure": r.name, "rank": rank[r.name], "sampler": post.sampler,
            "certified": bool(ok), "converged": bool(post.converged),
            "rhat": post.rhat_max, "ess_bulk": post.ess_bulk_min, "ess_tail": post.ess_tail_min,
            "n_chains": post.n_walkers, "n_steps": post.n_steps,
            "importance": {k: v for k, v in (r.criteria.importance or {}).items()
                           if not isinstance(v, np.ndarray)},
            "noise": post.noise, "noise_sensitive": nm.get("sensitive"),
            "noise_models": {k: {kk: vv for kk, vv in v.items() if kk != "warnings"}
                             for k, v in (nm.get("models") or {}).items()},
            "log_z": None if ev is None else ev.log_z,
            "log_z_err": None if ev is None else ev.log_z_err,
            "method": None if ev is None else ev.method,
            "probability": r.criteria.posterior_probability,
            "fits": r.fits,
            "max_phase_error_deg": None if r.adequacy is None else r.adequacy.max_phase_error_deg,
            "max_log10_mag_error": (None if r.adequacy is None
                                    else r.adequacy.max_log10_magnitude_error),
            "messages": list(post.messages), "warnings": list(r.criteria.warnings),
        })
    print("(cert: the route's own certificate, recomputed; * where it differs from "
          "posterior.converged; noise '!': exponents depend on the noise model)")
    seen = {}
    for w in caught:
        seen.setdefault((w.category.__name__, str(w.message)), None)
    if seen:
        print(f"warnings ({len(seen)}):")
        for category, message in seen:
            print(f"  {category}: {message[:230]}{'…' if len(message) > 230 else ''}")
    # What the report tells the user: its first sentence and every caution it flags.
    told = verdict(result)
    for text, flagged in told:
        if flagged or text is told[0][0]:
            print(f"  verdict{' (flagged)' if flagged else ''}: {text}")
    top = result.ranking[0] if result.ranking else None
    top_ok = next((row["certified"] for row in rows if row["structure"] == top), False)
    print(f"{key}: wall {wall:.1f} s; top by ln Z: {top} "
          f"({'certified' if top_ok else 'NOT certified'})", flush=True)
    return {"key": key, "label": data.label, "n": data.n_frequencies, "wall_s": wall,
            "top": top, "top_certified": bool(top_ok), "rows": rows,
            "warnings": [{"category": c, "message": m} for c, m in seen],
            "verdict": [{"text": t, "flagged": f} for t, f in told]}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", default=",".join(DATASETS),
                        help=f"comma list of {', '.join(DATASETS)} (default: all)")
    parser.add_argument("--structures", default=STRUCTURES)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", help="also write the figures to this JSON file")
    args = parser.parse_args(argv)
    keys = [k.strip() for k in args.datasets.split(",") if k.strip()]
    unknown = [k for k in keys if k not in DATASETS]
    if unknown:
        parser.error(f"unknown data set(s) {', '.join(unknown)}; known: {', '.join(DATASETS)}")
    print(f"machine: {platform.machine()}, python {platform.python_version()}, "
          f"numpy {np.__version__}; bayesfo from {Path(bf.__file__).parent}; seed {args.seed}, "
          f"{args.workers} worker(s)")
    done = [s for s in (survey(k, args.structures, args.seed, args.workers) for k in keys) if s]
    rows = [row for s in done for row in s["rows"] if "error" not in row]
    print("\nwall times: " + ", ".join(f"{s['key']} {s['wall_s']:.0f} s" for s in done)
          + f"; total {sum(s['wall_s'] for s in done):.0f} s")
    print(f"{sum(r['certified'] for r in rows)} of {len(rows)} posteriors certified; on "
          f"{sum(s['top_certified'] for s in done)} of {len(done)} data sets the top-ranked "
          "structure is certified")
    if args.json:
        Path(args.json).write_text(json.dumps(done, indent=1, default=float))


if __name__ == "__main__":
    main()
