"""Wall time of ``bayesfo compare FILE`` with the evidence bound (the default, ``--sample
needed``) against ``--sample all`` (every structure sampled, as before issue 64), with figures
and report and with ``--no-figures``, on the data sets of the speed issue: the bundled adhesive
isotherm at 20 °C and, where ``../shared/data/reference-gpl`` is present (GPL data, read in
place), chia, the Epstein metal network, silk and polystyrene at 160 °C
(:data:`bench_command.DATASETS`).

Rounds are interleaved (every data set, variant and sampling once per round), so that a change
of the machine's load touches all alike. For each data set the script checks that the two
samplings give the same ranking order and the same ln Z for every structure both sampled, and
states the structures the bound left out, by how many nats their bound lies below the leader's
ln Z (and, from the ``--sample all`` run, where their sampled ln Z lies), and the bytes
written.

Prints the median and range of each (seconds), the load average before and after, and the
machine. Record the machine's other load next to the numbers (BENCHMARKS.md).

Usage: python benchmarks/bench_bound.py [--rounds 3] [--datasets adh20,chia]
       [--figures-only | --no-figures-only]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_command import DATASETS, ROOT, add_options, chosen, run  # noqa: E402

SAMPLINGS = {"bound": [], "sample all": ["--sample", "all"]}


def _summary(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())


def _size(out: Path) -> int:
    return sum(f.stat().st_size for f in out.rglob("*") if f.is_file())


def _check(key: str, variant: str, bound: dict, every: dict) -> list[str]:
    """What the two samplings of one data set say, in lines; a disagreement is marked."""
    lines = []
    z_bound = {s["name"]: s.get("log_evidence") for s in bound["structures"]}
    z_all = {s["name"]: s.get("log_evidence") for s in every["structures"]}
    same_z = all(z_bound[n] == z_all[n] for n in z_bound if z_bound[n] is not None)
    sampled = [n for n in every["ranking"] if z_bound.get(n) is not None]
    same_order = [n for n in bound["ranking"] if z_bound.get(n) is not None] == sampled
    lines.append(f"{key} ({variant}): ranking order of the sampled structures the same: "
                 f"{same_order}; ln Z of every sampled structure the same: {same_z}"
                 + ("" if same_order and same_z else "   <-- DISAGREE"))
    record = bound.get("evidence_bound", {})
    leader = record.get("leader_log_evidence")
    lines.append(f"   optimiser shortfall {record.get('optimiser_shortfall')}; re-checked and "
                 f"sampled: {record.get('rechecked', [])}")
    for s in bound["structures"]:
        if s.get("sampled", True):
            continue
        gap = None if leader is None else leader - s["log_evidence_bound"]
        full = z_all.get(s["name"])
        below = "" if full is None else f"; sampled ln Z {full:.2f} (bound - ln Z " \
            f"{s['log_evidence_bound'] - full:.2f})"
        lines.append(f"   bounded: {s['name']}: ln Z <= {s['log_evidence_bound']:.2f}, "
                     f"{gap:.1f} nats below the leader's certified ln Z{below}")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_options(ap)
    args = ap.parse_args()
    keys, variants = chosen(ap, args)
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, {platform.processor() or '-'}"
          f", python {platform.python_version()}; load average at start "
          + " ".join(f"{x:.2f}" for x in os.getloadavg()), flush=True)
    times: dict = {}
    sizes: dict = {}
    checks: dict = {}
    with tempfile.TemporaryDirectory(prefix="bench-bound-") as tmp:
        for r in range(args.rounds):
            for key in keys:
                path, extra = DATASETS[key]
                for variant, flags in variants.items():
                    summaries = {}
                    order = list(SAMPLINGS) if r % 2 == 0 else list(reversed(SAMPLINGS))
                    for sampling in order:
                        out = Path(tmp) / f"{r}-{key}-{variant[:2]}-{sampling.replace(' ', '_')}"
                        wall = run(path, [*extra, *flags, *SAMPLINGS[sampling]], out, ROOT)
                        times.setdefault((key, variant, sampling), []).append(wall)
                        sizes[(key, variant, sampling)] = _size(out)
                        summaries[sampling] = _summary(out)
                    checks[(key, variant)] = _check(key, variant, summaries["bound"],
                                                    summaries["sample all"])
            print(f"round {r + 1} done; load " + " ".join(f"{x:.2f}" for x in os.getloadavg()),
                  flush=True)
    print(f"{'data set':<10} {'variant':<11} {'sampling':<11} {'median s':>9} {'min':>7} "
          f"{'max':>7} {'MB written':>11}")
    for (key, variant, sampling), v in times.items():
        print(f"{key:<10} {variant:<11} {sampling:<11} {np.median(v):>9.2f} {min(v):>7.2f} "
              f"{max(v):>7.2f} {sizes[(key, variant, sampling)] / 1e6:>11.2f}")
    for lines in checks.values():
        print("\n".join(lines))
    print("load average at the end " + " ".join(f"{x:.2f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main()
