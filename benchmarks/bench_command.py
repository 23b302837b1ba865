"""Wall time of ``bayesfo compare FILE`` as a user runs it: a new process, the default
structures and settings, figures and report (and again with ``--no-figures``), on real data
read directly from the lab files.

The data sets of the speed issue: the bundled adhesive isotherm at 20 °C (17 points), and,
where ``../shared/data/reference-gpl`` is present (GPL data, read in place, never copied), the
chia gel (25), the Epstein metal network (19), the silk feedstock (15) and polystyrene at
160 °C (32). Rounds are interleaved (every data set and variant once per round), so that a
change of the machine's load touches all alike; with ``--other DIR`` (a checkout of another
version, e.g. ``git worktree add /tmp/old <commit>``) each command also runs with that
version's package first on ``PYTHONPATH``, alternating with this one, and the script says
whether both wrote the same ln Z for every structure.

Prints the median and range of each (seconds), the load average before and after, and the
machine.

Usage: python benchmarks/bench_command.py [--rounds 3] [--datasets adh20,chia]
       [--other DIR] [--figures-only | --no-figures-only]
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

ROOT = Path(__file__).resolve().parents[1]
GPL = ROOT.parent / "shared" / "data" / "reference-gpl"

#: key -> (file, extra arguments)
DATASETS = {
    "adh20": (ROOT / "examples/data/adhesive_468mp/Tp020C.csv", []),
    "chia": (GPL / "pyrheo_chia_pudding/original/oscillation_chia_data.csv", []),
    "epstein": (GPL / "pyrheo_metal_network_epstein/original/epstein.csv", []),
    "silk": (GPL / "reptate_silk_feedstock/original/silk_feedstock.tts", []),
    "ps160": (GPL / "pyrheo_polystyrene_saos/original/oscillation_ps160_data.csv", []),
}


def run(path: Path, extra: list[str], out: Path, source: Path) -> float:
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(source))
    cmd = [sys.executable, "-m", "bayesfo.cli", "compare", str(path), "--out", str(out),
           "--quiet", *extra]
    t = time.perf_counter()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=source)
    wall = time.perf_counter() - t
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr[-2000:]}")
    return wall


def add_options(ap: argparse.ArgumentParser) -> None:
    """The options of the timed command runs: rounds, data sets, with or without figures."""
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--datasets", default=",".join(DATASETS))
    which = ap.add_mutually_exclusive_group()
    which.add_argument("--figures-only", action="store_true")
    which.add_argument("--no-figures-only", action="store_true")


def chosen(ap: argparse.ArgumentParser, args) -> tuple[list[str], dict]:
    """The data sets named (those whose file exists) and the variants of the command
    (``{label: extra arguments}``) that :func:`add_options`' options ask for."""
    keys = [k.strip() for k in args.datasets.split(",") if k.strip()]
    unknown = [k for k in keys if k not in DATASETS]
    if unknown:
        ap.error(f"unknown data set {unknown[0]!r}; choose from {', '.join(DATASETS)}")
    keys = [k for k in keys if DATASETS[k][0].is_file()]
    variants = {"figures": [], "no figures": ["--no-figures"]}
    if args.figures_only:
        del variants["no figures"]
    if args.no_figures_only:
        del variants["figures"]
    return keys, variants


def evidences(out: Path) -> list:
    summary = json.loads((out / "summary.json").read_text())
    return [(s["name"], round(s["log_evidence"], 6)) for s in summary["structures"]]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_options(ap)
    ap.add_argument("--other", type=Path, help="a checkout of another version to time beside")
    args = ap.parse_args()
    keys, variants = chosen(ap, args)
    versions = {"this": ROOT}
    if args.other is not None:
        versions = {"other": args.other.resolve(), "this": ROOT}
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, {platform.processor() or '-'}"
          f", python {platform.python_version()}; load average at start "
          + " ".join(f"{x:.2f}" for x in os.getloadavg()), flush=True)
    times: dict = {}
    same = {}
    with tempfile.TemporaryDirectory(prefix="bench-command-") as tmp:
        for r in range(args.rounds):
            for key in keys:
                path, extra = DATASETS[key]
                for variant, flags in variants.items():
                    lnz = {}
                    # Alternate which version runs first from round to round.
                    order = list(versions) if r % 2 == 0 else list(reversed(versions))
                    for version in order:
                        out = Path(tmp) / f"{r}-{key}-{variant.replace(' ', '_')}-{version}"
                        wall = run(path, [*extra, *flags], out, versions[version])
                        times.setdefault((key, variant, version), []).append(wall)
                        lnz[version] = evidences(out)
                    if len(lnz) == 2:
                        same[(key, variant)] = same.get((key, variant), True) and \
                            lnz["this"] == lnz["other"]
            print(f"round {r + 1} done; load " + " ".join(f"{x:.2f}" for x in os.getloadavg()),
                  flush=True)
    print(f"{'data set':<10} {'variant':<11} {'version':<7} {'median s':>9} {'min':>7} {'max':>7}")
    for (key, variant, version), v in times.items():
        print(f"{key:<10} {variant:<11} {version:<7} {np.median(v):>9.2f} {min(v):>7.2f} "
              f"{max(v):>7.2f}")
    for (key, variant), ok in same.items():
        print(f"{key} ({variant}): the same ln Z for every structure in both versions: {ok}")
    print("load average at the end " + " ".join(f"{x:.2f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main()
