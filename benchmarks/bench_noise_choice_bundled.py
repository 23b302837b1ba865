"""The noise model that ``noise="auto"`` chooses on bundled data sets, and ln Z, before and after
relative-parts noise joined the candidates.

``before`` runs ``noise="auto"`` with the candidates of
:data:`bayesfo.comparison.steps.NOISE_CANDIDATES` set to constant and proportional (the default
until then); ``after`` the default. Each file is compared with the default structures (or
``--structures``); one row per structure: the noise model chosen and ln Z under each, and the
winner of each run.

    python benchmarks/bench_noise_choice_bundled.py [FILE ...] [--structures S] [--seed N]
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_noise_coverage import candidates  # noqa: E402

import bayesfo as bf  # noqa: E402
from bayesfo.options import DEFAULT_STRUCTURES  # noqa: E402

FILES = ["examples/data/adhesive_468mp/Tp020C.csv", "examples/data/adhesive_468mp/Tm030C.csv",
         "examples/data/adhesive_468mp/Tp080C.csv", "examples/data/adhesive_468mp/Tp150C.csv",
         "examples/data/pp_compliance.csv", "examples/data/dashpot.csv"]


def run(path, structures, seed, before: bool):
    data = bf.read(ROOT / path)
    with (candidates(("constant", "proportional")) if before else _nothing()), \
            warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        result = bf.compare(data, structures or DEFAULT_STRUCTURES, seed=seed, progress=False)
    return result, time.perf_counter() - t0


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="*", default=FILES)
    ap.add_argument("--structures", default=None)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    print("| data | structure | noise before | ln Z before | noise after | ln Z after |")
    print("|---|---|---|---|---|---|")
    for path in args.files:
        old, t_old = run(path, args.structures, args.seed, before=True)
        new, t_new = run(path, args.structures, args.seed, before=False)
        for r in new.results:
            o = old[r.name]
            if r.posterior is None or o.posterior is None:
                continue
            print(f"| {Path(path).name} | {r.name} | {o.posterior.noise} | {o.log_z:.2f} | "
                  f"{r.posterior.noise} | {r.log_z:.2f} |", flush=True)
        print(f"| {Path(path).name} | winner | {old.ranking[0] if old.ranking else '-'} "
              f"({t_old:.0f} s) | | {new.ranking[0] if new.ranking else '-'} "
              f"({t_new:.0f} s) | |", flush=True)


if __name__ == "__main__":
    main()
