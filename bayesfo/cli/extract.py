"""``bayesfo extract``: sine records (one per frequency) to a frequency-response CSV."""

from __future__ import annotations

from ..errors import InputError


def add_parser(subparsers):
    """Register ``bayesfo extract``: sine records to a frequency response."""
    p = subparsers.add_parser("extract", help="sine records (one per frequency) -> frequency response CSV")
    p.add_argument("records", nargs="+", metavar="RECORD",
                   help="CSV with time,input,output[,series] and '# omega:' or '# freq:'")
    p.add_argument("--out", required=True, metavar="FILE.csv", help="output CSV")
    p.add_argument("--kind", choices=("compliance", "modulus", "generic"), default="generic")
    p.add_argument("--harmonics", type=int, default=5, help="highest harmonic reported (default 5)")
    p.add_argument("--threshold", type=float, default=0.05,
                   help="harmonic ratio above which a record is flagged as nonlinear (default 0.05)")
    return p


def run(args) -> int:
    from ..timeseries.records import extract_frequency_response, write_extraction

    if args.harmonics < 2:
        raise InputError(f"--harmonics must be at least 2, got {args.harmonics}")
    if not args.threshold > 0:
        raise InputError(f"--threshold must be positive, got {args.threshold}")
    fr, analyses = extract_frequency_response(
        args.records, kind=args.kind, n_harmonics=args.harmonics,
        nonlinearity_threshold=args.threshold,
    )
    write_extraction(args.out, fr, analyses)
    print(f"{'omega [rad/s]':>14} {'gain':>12} {'phase [deg]':>12} {'THD':>8}  linear")
    for a in analyses:
        print(f"{a.omega:14.6g} {a.gain:12.6g} {a.phase_deg:12.4f} {a.thd_output:8.4f}  "
              + ("no" if a.nonlinear else "yes"))
    print(f"wrote {args.out}")
    return 0
