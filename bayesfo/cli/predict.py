"""``bayesfo predict``: a material function with its credible band from a finished comparison."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from ..errors import InputError

#: Option of each kind of argument, and what it is.
_X_OPTIONS = {"omega": "--omega", "time": "--time", "tau": "--tau"}
_X_NAMES = {"omega": "angular frequency", "time": "time", "tau": "relaxation time"}


def add_parser(subparsers):
    """Register ``bayesfo predict``."""
    from ..predictions.functions import AVERAGES, QUANTITIES

    p = subparsers.add_parser(
        "predict", help="a material function (G(t), J(t), G', G'', spectra) with its credible "
                        "band, from the output directory of a comparison")
    p.add_argument("directory", metavar="DIR",
                   help="output directory of bayesfo compare or bayesfo mastercurve")
    p.add_argument("--quantity", required=True, choices=tuple(QUANTITIES), metavar="Q",
                   help="one of " + ", ".join(QUANTITIES))
    x = p.add_mutually_exclusive_group(required=True)
    x.add_argument("--omega", metavar="W,...", help="angular frequencies [rad/s]: a comma list, "
                   "or LOW:HIGH:N for N log-spaced values")
    x.add_argument("--time", metavar="T,...", help="times [s] (comma list or LOW:HIGH:N)")
    x.add_argument("--tau", metavar="TAU,...",
                   help="relaxation or retardation times [s] (comma list or LOW:HIGH:N)")
    who = p.add_mutually_exclusive_group()
    who.add_argument("--structure", metavar="S", help="the structure (default: the best ranked)")
    who.add_argument("--average", choices=AVERAGES,
                     help="average over the ranked structures by posterior model probability "
                          "(bma) or stacking weights (stacking)")
    out = p.add_mutually_exclusive_group()
    out.add_argument("--json", action="store_true", help="print the prediction as JSON")
    out.add_argument("--out", metavar="FILE.csv",
                     help="write the prediction as CSV ('-': to standard output)")
    p.add_argument("--temperature", type=float, default=None, metavar="T",
                   help="[°C] of a master curve: the function at T (within the isotherms' "
                        "temperatures) instead of the reference temperature, each draw with its "
                        "own shift factors")
    p.add_argument("--figure", metavar="FILE.png",
                   help="also draw the median and 94 %% band (png, pdf or svg by the suffix)")
    p.add_argument("--seed", type=int, default=0, help="seed of the draws used (default 0)")
    return p


def parse_grid(text: str, option: str) -> list[float]:
    """``1,2,5`` as it is; ``LOW:HIGH:N`` as N log-spaced values from LOW to HIGH."""
    from .._io import parse_number
    from ..options import parse_floats

    if ":" not in text:
        return parse_floats(text, option)
    parts = text.split(":")
    try:
        if len(parts) != 3:
            raise ValueError("three parts")
        low, high, n = parse_number(parts[0]), parse_number(parts[1]), int(parts[2])
    except ValueError:
        raise InputError(f"{option} takes LOW:HIGH:N (e.g. 0.01:100:50), got {text!r}") from None
    if not (low > 0 and high > low and math.isfinite(high)) or not 2 <= n <= 100_000:
        raise InputError(f"{option} LOW:HIGH:N needs 0 < LOW < HIGH and 2 <= N <= 100000, "
                         f"got {text!r}")
    return [low * (high / low) ** (i / (n - 1)) for i in range(n)]


def run(args) -> int:
    from ..comparison import load
    from ..predictions import predict
    from ..predictions.functions import QUANTITIES

    domain = QUANTITIES[args.quantity][0]
    option = _X_OPTIONS[domain]
    given = next(k for k in _X_OPTIONS.values()
                 if getattr(args, k.lstrip("-")) is not None)
    if given != option:
        raise InputError(f"--quantity {args.quantity} is a function of {_X_NAMES[domain]}: "
                         f"give {option}, not {given}")
    x = parse_grid(getattr(args, option.lstrip("-")), option)
    if args.figure is not None and Path(args.figure).suffix.lower() not in (".png", ".pdf",
                                                                           ".svg"):
        raise InputError(f"--figure '{args.figure}': give a .png, .pdf or .svg file")
    result = load(args.directory, models=getattr(args, "models", ()) or ())
    p = predict(result, args.quantity, x, structure=args.structure, average=args.average,
                seed=args.seed, temperature=args.temperature)
    if args.figure is not None:
        _figure(p, args.figure)
    if args.json:
        print(json.dumps(p.to_dict(), indent=1))
        return 0
    if args.out == "-":
        sys.stdout.write(_csv_text(p))
        return 0
    if args.out:
        _write_csv(p, args.out)
        print(f"wrote {args.out}")
        return 0
    _print(p)
    return 0


def _figure(p, path) -> None:
    from .._io import write_error
    from ..plotting.material import plot_prediction
    from ..plotting.output import save_figure
    from ._libraries import load_libraries

    load_libraries((Path(path).suffix.lower().lstrip("."),))
    try:
        save_figure(plot_prediction(p).figure, path, close=True, named=True)
    except OSError as exc:
        raise InputError(f"--figure '{path}': cannot be written ({write_error(path, exc)})") \
            from None


def _csv_text(p) -> str:
    from ..predictions.functions import QUANTITIES

    lines = [f"# {p.symbol or QUANTITIES[p.quantity][1]} ({p.quantity}) in {p.unit or 'no unit'}; "
             f"94 % HDI of the posterior; "
             + (f"structure {p.structure}" if p.weights is None else
                f"{p.average} average: {_weights(p)}")
             + (f" at {p.temperature:g} °C" if p.temperature is not None else "")]
    lines += [f"# note: {n}" for n in p.notes]
    lines.append(f"x_{p.x_unit.replace('/', '_per_')},median,hdi_low,hdi_high,extrapolated")
    for row in zip(p.x, p.median, p.hdi_low, p.hdi_high, p.extrapolated, strict=True):
        lines.append(",".join(f"{v:.10g}" for v in row[:4]) + f",{int(row[4])}")
    return "\n".join(lines) + "\n"


def _write_csv(p, path) -> None:
    from .._io import atomic_write_text, write_error

    try:
        atomic_write_text(path, _csv_text(p), named=True)
    except OSError as exc:
        raise InputError(f"--out '{path}': cannot be written ({write_error(path, exc)})") \
            from None


def _print(p) -> None:
    from ..predictions.functions import QUANTITIES
    from ..structures.physical import in_brackets

    who = f"structure {p.structure}" if p.weights is None else f"{p.average} average ({_weights(p)})"
    unit = in_brackets(p.unit)
    print(f"{p.symbol or QUANTITIES[p.quantity][1]}{unit} of {who}: posterior median and 94 % "
          "HDI")
    print(f"{'x [' + p.x_unit + ']':>14} {'median':>12} {'HDI low':>12} {'HDI high':>12}")
    for x, m, lo, hi, out in zip(p.x, p.median, p.hdi_low, p.hdi_high, p.extrapolated,
                                 strict=True):
        print(f"{x:14.5g} {m:12.5g} {lo:12.5g} {hi:12.5g}" + ("  extrapolated" if out else ""))
    for n in p.notes:
        print(f"note: {n}")


def _weights(p) -> str:
    """The weights of an average that count (0.001 or more), largest first."""
    shown = sorted(((v, k) for k, v in p.weights.items() if v >= 0.001), reverse=True)
    rest = len(p.weights) - len(shown)
    return ", ".join(f"{k} {v:.3f}" for v, k in shown) + (
        f"; {rest} more below 0.001" if rest else "")
