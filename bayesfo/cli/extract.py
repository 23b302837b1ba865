"""``bayesfo extract``: sine records (one per frequency) to a frequency-response CSV."""

from __future__ import annotations

from ..errors import InputError


def add_parser(subparsers):
    """Register ``bayesfo extract``: sine records to a frequency response."""
    p = subparsers.add_parser("extract", help="sine records (one per frequency) -> frequency response CSV")
    p.add_argument("records", nargs="+", metavar="RECORD",
                   help="CSV with time,input,output[,series] and '# omega:' or '# freq:'")
    p.add_argument("--out", required=True, metavar="FILE.csv", help="output CSV")
    p.add_argument("--kind", choices=("compliance", "modulus", "generic"), default="generic",
                   help="what output/input is: a compliance (strain/stress), a modulus "
                        "(stress/strain), or any other transfer function (default generic)")
    p.add_argument("--harmonics", type=int, default=5, help="highest harmonic reported (default 5)")
    p.add_argument("--threshold", type=float, default=0.05,
                   help="harmonic ratio above which a record is flagged as nonlinear (default 0.05)")
    return p


def run(args) -> int:
    import numpy as np

    from ..timeseries.records import extract_frequency_response, write_extraction

    if args.harmonics < 2:
        raise InputError(f"--harmonics must be at least 2, got {args.harmonics}")
    if not args.threshold > 0:
        raise InputError(f"--threshold must be positive, got {args.threshold}")
    fr, analyses = extract_frequency_response(
        args.records, kind=args.kind, n_harmonics=args.harmonics,
        nonlinearity_threshold=args.threshold,
    )
    written, harmonics = write_extraction(args.out, fr, analyses)
    print(f"{'omega [rad/s]':>14} {'gain':>12} {'phase [deg]':>12} {'THD':>8}  linear")
    for a in analyses:
        # An input with harmonics leaves linearity untested (the output's may be the input's).
        distorted = bool(np.any(np.nan_to_num(a.harmonic_ratio_input) > args.threshold))
        print(f"{a.omega:14.6g} {a.gain:12.6g} {a.phase_deg:12.4f} {a.thd_output:8.4f}  "
              + ("untested" if distorted else "no" if a.nonlinear else "yes"))
    for note in fr.notes[1:]:  # past "extracted from N sine records"
        print(f"note: {note}")
    print(f"wrote {written} and {harmonics} (each record's harmonics)")
    return 0
