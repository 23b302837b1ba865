"""Real data: a pressure-sensitive adhesive isotherm and a polymer DMA master curve.

Two public modulus data sets bundled in ``examples/data`` (their files carry the attribution,
printed below):

* ``adhesive_468mp/Tp020C.csv``: 3M 468MP acrylic adhesive, SAOS sweep at 20 °C, storage and loss
  shear modulus G', G'' [Pa], 17 frequencies over 0.63–100 rad/s (hermes-rheo, MIT licence);
* ``nrel_dma_master.csv``: a PV-module encapsulant, tensile DMA master curve E', E'' [MPa] at
  −5 °C, 205 frequencies over 26 decades (NREL pyvisco, BSD-3-Clause).

Structure cards describe compliances (as the thesis does); on modulus data bayesfo compares the
same material through its reciprocal, so ``voigt`` is the fractional Voigt material here too. Both
data sets span more than a decade of |G|, so the noise model is proportional (σ_rel·|G|), with
σ_rel sampled. The master curve has a glassy and a rubbery plateau: a single commensurate order
has to describe a transition over some ten decades, which is where the Zener's second plateau
and the max-order members earn their parameters.

Usage: python examples/real_data.py [--quick] [--out DIR] [--seed N] [--data adhesive|nrel|both]
"""

from __future__ import annotations

from pathlib import Path

from _common import (
    comment_lines,
    make_parser,
    print_orders,
    print_table,
    run_compare,
    save,
)

from bayesfo import read_csv
from bayesfo.structures import resolve_structures

HERE = Path(__file__).resolve().parent
NAME = "real_data"
DATA = {
    "adhesive": {
        "path": HERE / "data" / "adhesive_468mp" / "Tp020C.csv",
        "full": "voigt,zener,maxwell,max-n2m2,voigt-int,zener-int,maxwell-int",
        "quick": "voigt,voigt-int",
    },
    "nrel": {
        "path": HERE / "data" / "nrel_dma_master.csv",
        "full": "voigt,zener,maxwell,max-n2m1,max-n2m2,zener-int,max-n2m2-int",
        "quick": "zener,zener-int",
    },
}


def attribution(path) -> list[str]:
    """The provenance comment lines of a bundled file (all but kind, units and name)."""
    return [line for line in comment_lines(path)
            if line.split(":", 1)[0].strip().lower() not in ("kind", "units", "name")]


def run_one(key: str, args) -> object:
    spec = DATA[key]
    data = read_csv(spec["path"])
    print(f"\n=== {data.label} ({spec['path'].relative_to(HERE.parent)}), {data.kind} "
          f"[{data.units}]")
    for line in attribution(spec["path"]):
        print("  " + line)
    names = spec["quick"] if args.quick else spec["full"]
    comp = run_compare(data, resolve_structures(names), seed=args.seed, quick=args.quick,
                       workers=args.workers)
    noise = {comp[n].posterior.noise for n in comp.ranking}
    print_table(comp, f"Ranking by ln Z (noise model: {', '.join(sorted(noise))})")
    print_orders(comp)
    pairs = comp.baselines()
    if pairs:
        print("\nInteger baselines (q = 1) against their fractional parents:")
        for b in pairs:
            if b["delta_log_evidence"] is not None:
                print(f"  {b['parent']:<10} vs {b['baseline']:<14} ln Z difference "
                      f"{b['delta_log_evidence']:+.2f}")
    save(comp, Path(args.out) / spec["path"].stem, figures=not args.no_figures, quick=args.quick)
    return comp


def main(argv=None) -> int:
    parser = make_parser(NAME, __doc__)
    parser.add_argument("--data", choices=("adhesive", "nrel", "both"), default="both")
    args = parser.parse_args(argv)
    keys = ("adhesive", "nrel") if args.data == "both" else (args.data,)
    for key in keys:
        run_one(key, args)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
