"""``bayesfo identify``: deterministic fit of one structure (thesis methods 1-5 or optimisation)."""

from __future__ import annotations

import json

from ..errors import InputError
from ..options import (
    seed_argument,
)
from ._common import add_data_options, library, read_data


def add_parser(subparsers):
    """Register ``bayesfo identify``: deterministic fit of one structure."""
    p = subparsers.add_parser("identify", help="deterministic fit of one structure (methods 1-5 or optimisation)")
    add_data_options(p)
    p.add_argument("--structure", required=True,
                   help="structure name (e.g. zener, max-n2m1) or a list/shortcut such as max3 "
                        "for the max-order loop")
    p.add_argument("--method", default="opt", choices=("1", "2", "3", "4", "5", "opt"),
                   help="linear method of thesis Table 3.1, or global optimisation (default)")
    p.add_argument("--q", type=float, default=None,
                   help="fix the commensurate order (default: q-grid scan / optimised)")
    p.add_argument("--seed", type=seed_argument, default=0, help="seed of the optimiser's random starts")
    p.add_argument("--json", action="store_true", help="print JSON")
    return p


def run(args) -> int:
    from ..identify import identify
    from ..structures import resolve_structures

    data = read_data(args)
    structures = resolve_structures(args.structure, library(args))
    if len(structures) > 1:
        return _identify_loop(args, data, structures)
    structure = structures[0]
    result = identify(data, structure, method=args.method, q=args.q, seed=args.seed)
    if args.json:
        print(json.dumps(result, indent=2))
        return 0
    print(f"{result['structure']} by method {result['method']} on {data.label}: "
          f"{structure.formula}")
    for name, value in result["parameters"].items():
        print(f"  {name:>6} = {value:.6g}")
    print(f"  RMSE = {result['rmse']:.4g} (eq. 3.23), stable: {'yes' if result['stable'] else 'no'}")
    if result.get("rejected_unstable_q"):
        print(f"  q values rejected as unstable: {len(result['rejected_unstable_q'])} of the grid")
    return 0


def _identify_loop(args, data, structures) -> int:
    """The max-order loop of thesis §4.3.2: every member, and the one with the lowest RMSE."""
    from ..identify import check_q, identify

    if args.q is not None:  # one message for a q outside the prior, not one per member
        for s in structures:
            check_q(args.q, s)
    results, skipped = [], {}
    for s in structures:
        try:
            results.append(identify(data, s, method=args.method, q=args.q, seed=args.seed))
        except InputError as exc:
            skipped[s.name] = str(exc)
    if not results:
        raise InputError("; ".join(f"{k}: {v}" for k, v in skipped.items()))
    best = min(results, key=lambda r: r["rmse"])["structure"]
    if args.json:
        print(json.dumps({"structures": results, "skipped": skipped, "best_by_rmse": best}, indent=2))
        return 0
    print(f"{'structure':<16} {'q':>6} {'RMSE':>11}  stable")
    for r in results:
        q = "" if r["q"] is None else f"{r['q']:.3f}"
        print(f"{r['structure']:<16} {q:>6} {r['rmse']:>11.4g}  {'yes' if r['stable'] else 'no'}")
    for name, why in skipped.items():
        print(f"{name:<16} skipped: {why}")
    print(f"lowest RMSE: {best} (the thesis' choice; it favours the largest members: "
          "compare them with `bayesfo compare` for a penalised ranking)")
    return 0
