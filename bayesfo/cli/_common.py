"""What several commands share: the data arguments, reading the data, the structure library."""

from __future__ import annotations

from ..options import KINDS


def add_data_options(p):
    p.add_argument("data", metavar="DATA", help="CSV file with omega|freq and the response columns")
    p.add_argument("--kind", choices=KINDS,
                   help="what the response is (default: the file's '# kind:' line, else generic)")
    p.add_argument("--reciprocal", action="store_true",
                   help="use 1/G of the data (sigma propagated)")


def read_data(args):
    from ..data import read_csv

    data = read_csv(args.data, kind=args.kind)
    if args.reciprocal:
        data = data.reciprocal()
    return data


def library(args):
    from ..structures import default_library, load_library

    return load_library(extra=args.models) if args.models else default_library()

