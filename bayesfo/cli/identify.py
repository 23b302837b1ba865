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
    from ..structures import picture_for, resolve_structures

    data = read_data(args)
    lib = library(args)
    structures = resolve_structures(args.structure, lib)
    if len(structures) > 1:
        return _identify_loop(args, data, structures)
    structure = structures[0]
    # An alias that names a picture (fpt: the Poynting–Thomson reading of zener) reports it.
    picture = picture_for(args.structure.strip(), lib)
    result = with_units(identify(data, structure, method=args.method, q=args.q, seed=args.seed),
                        structure, data, picture=picture)
    if args.json:
        print(json.dumps(result, indent=2))
        return 0
    print(f"{result['structure']} by method {result['method']} on {data.label}: "
          f"{structure.formula}")
    for line in _parameter_lines(result):
        print(line)
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
            results.append(with_units(identify(data, s, method=args.method, q=args.q,
                                               seed=args.seed), s, data))
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


def with_units(result: dict, structure, data, picture: str | None = None) -> dict:
    """The result of :func:`bayesfo.identify.identify` with units and the physical form.

    Adds ``units`` (``{parameter: unit}`` of ``parameters``, from the data's kind and unit;
    ``""`` for orders), ``natural_form`` (``"physical"`` for modulus data on a structure with
    a mechanical picture, else ``"coefficients"``), ``picture`` (its name, or None: the
    structure's default picture unless ``picture`` names another) and
    ``parameters_physical`` (``{name: {"value": ..., "unit": ...}}``: moduli,
    quasi-properties, orders and derived times of the picture; None without a picture).
    """
    from ..structures import coefficient_units, physical_parameters, picture_of
    from ..structures.physical import stress_unit

    kind, unit = data.kind, data.units or ""
    own = coefficient_units(structure, kind, unit)
    params = result["parameters"]
    # Parameters fixed by --q (or by an -int variant) are orders: no unit.
    units = {n: own.get(n, "") for n in params}
    phys = None
    if structure.pictures:
        values = physical_parameters(structure, params, kind, unit, picture=picture)
        phys = {n: {"value": float(v), "unit": u} for n, (v, u) in values.items()}
    return result | {
        "units": units,
        "stress_unit": stress_unit(kind, unit),
        "natural_form": "physical" if kind == "modulus" and phys is not None else "coefficients",
        "picture": picture_of(structure, picture).name if phys is not None else None,
        "parameters_physical": phys,
    }


def _parameter_lines(result: dict) -> list[str]:
    """The parameters with units, the form natural to the data first."""
    own = [f"  {n:>6} = {v:.6g}" + (f" {result['units'][n]}" if result["units"].get(n) else "")
           for n, v in result["parameters"].items()]
    phys = result["parameters_physical"]
    if phys is None:
        return own
    width = max(6, *(len(n) for n in phys))
    physical = [f"  {n:>{width}} = {p['value']:.6g}" + (f" {p['unit']}" if p["unit"] else "")
                for n, p in phys.items()]
    head_phys = f"  physical parameters ({result['picture']}):"
    head_own = "  coefficients of the card:"
    if result["natural_form"] == "physical":
        return [head_phys, *physical, head_own, *own]
    return [head_own, *own, head_phys, *physical]
