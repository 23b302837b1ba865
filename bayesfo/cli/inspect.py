"""``bayesfo inspect``: read and check a data file; show what it holds and how it was read."""

from __future__ import annotations

import json

from ..options import (
    parse_floats,
)
from ._common import add_data_options, library, read_data


def add_parser(subparsers):
    """Register ``bayesfo inspect``: read and check a data file."""
    p = subparsers.add_parser(
        "inspect", help="read and check a data file; show what it holds and how it was read",
        description="Read a data file and print every choice the reader made (format, "
                    "delimiter, columns used, units converted to SI, kind and why, temperature, "
                    "rows skipped, columns ignored) and what the data hold. A file of several "
                    "data sets (steps, intervals, isotherms) prints each.")
    add_data_options(p)
    p.add_argument("--structures", default=None,
                   help="comma list of structures to check the data against (e.g. voigt,zener,max3)")
    p.add_argument("--holdout", default=None, metavar="W1,W2",
                   help="angular frequencies [rad/s] to hold out for validation")
    p.add_argument("--json", action="store_true",
                   help="print JSON: one object, or a list of objects for a file of several "
                        "data sets")
    return p


def _info(iso, args, structures) -> dict:
    data = iso.data.reciprocal() if args.reciprocal else iso.data
    info = data.to_dict()
    info.update(
        omega_ref=data.omega_ref,
        g_ref=data.g_ref,
        magnitude_min=float(data.magnitude.min()),
        magnitude_max=float(data.magnitude.max()),
        block=iso.label,
        temperature_C=iso.temperature,
        reading=iso.reading.to_dict(),
    )
    if args.holdout:
        train, test = data.split(parse_floats(args.holdout, "--holdout"))
        info["holdout"] = test.omega.tolist()
        data = train
    if structures:
        for s in structures:
            s.check_data(data)
        info["structures"] = {s.name: s.n_params for s in structures}
    return info


def run(args) -> int:
    from ..structures import resolve_structures

    sets = read_data(args, every=True)
    structures = resolve_structures(args.structures, library(args)) if args.structures else None
    infos = [_info(iso, args, structures) for iso in sets]
    if args.json:
        print(json.dumps(infos[0] if len(infos) == 1 else infos, indent=2))
        return 0
    if len(infos) > 1:
        first = infos[0]["reading"]
        print(f"{args.data}: {len(infos)} data sets, read as {first['format']} "
              f"({first['delimiter']}-separated, decimal '{first['decimal']}', "
              f"{first['encoding']}); each one:")
    seen = set()
    for k, info in enumerate(infos, start=1):
        if len(infos) > 1:
            label = info["block"] or "data set"
            t = info["temperature_C"]
            print(f"\n[{k}] {label}" + (f" ({t:g} °C)" if t is not None and "°C" not in label
                                          else ""))
        _print(info, seen)
    return 0


def _print(info: dict, seen: set | None = None) -> None:
    """One data set's description; a note already printed for an earlier data set of the file
    (``seen``) is not repeated (a file of 20 isotherms printed the same 8 notes 20 times)."""
    from ..data.symbols import describe, mode, response_symbol

    reading = info["reading"]
    symbol = info.get("symbol", "G")
    # Tensile data say so (E′, E″ of a DMA); shear, the default, is not repeated.
    quantity = describe(symbol, info["kind"]) if mode(symbol) == "tensile" else ""
    print(f"{info['name']}: {info['n_frequencies']} frequencies, "
          f"{info['omega_min']:.4g} to {info['omega_max']:.4g} rad/s, kind {info['kind']}"
          + (f" ({quantity})" if quantity else "")
          + (f", units {info['units']}" if info["units"] else ""))
    letter = response_symbol(symbol, info["kind"])
    star = "*" if info["kind"] in ("modulus", "compliance") else ""
    unit = f" {info['units']}" if info["units"] else ""
    print(f"|{letter}{star}| from {info['magnitude_min']:.4g} to {info['magnitude_max']:.4g}"
          f"{unit}; "
          f"scaling omega_ref = {info['omega_ref']:.4g} rad/s, g_ref = {info['g_ref']:.4g}")
    print("sigma: " + ("given per point" if info["has_sigma"] else "not given (estimated when fitting)"))
    bad = info["dissipation_violations"]
    if bad:
        print(f"warning: {len(bad)} point(s) with negative loss, impossible for a passive "
              f"{info['kind']}: omega = " + ", ".join(f"{w:.4g}" for w in bad) + " rad/s")
    kk = info.get("kramers_kronig")
    if kk is not None:
        worst = ", ".join(f"{w:.4g}" for w in kk["worst_frequencies"])
        if kk["consistent"]:
            print(f"Kramers–Kronig: the two parts are consistent (F = {kk['chi2_per_dof']:.2f})")
        else:
            print(f"warning: the two parts are not consistent by the Kramers–Kronig relations "
                  f"(F = {kk['chi2_per_dof']:.3g}, most at omega = {worst} rad/s; the best "
                  f"causal description misses them by {100 * kk['misfit_rms']:.2g} % rms): an "
                  "instrument artefact (inertia, compliance), parts from different measurements, "
                  "or a master curve whose isotherms do not superpose")
    if reading["format"] == "bayesfo CSV":
        print(f"read as bayesfo CSV: columns {', '.join(reading['columns'])}; "
              + (f"temperature {info['temperature_C']:g} °C ('# temperature:' line); "
                 if info["temperature_C"] is not None else "")
              + "no units converted (the '# units:' line is a label)")
    repeated = 0
    for note in info["notes"]:
        if seen is not None and note in seen:
            repeated += 1
            continue
        print(f"note: {note}")
        if seen is not None:
            seen.add(note)
    if repeated:
        print(f"note: and {repeated} note(s) as for the data sets above")
    if "holdout" in info:
        print("held out: " + ", ".join(f"{w:.4g}" for w in info["holdout"]) + " rad/s")
    if "structures" in info:
        print("structures (parameters): "
              + ", ".join(f"{k} ({v})" for k, v in info["structures"].items()))
