"""``bayesfo structures``: the available structures with their priors."""

from __future__ import annotations

import json

from ._common import library


def add_parser(subparsers):
    """Register ``bayesfo structures``: list the structures."""
    p = subparsers.add_parser("structures", help="list the available structures with priors")
    p.add_argument("--json", action="store_true", help="print JSON")
    return p


def run(args) -> int:
    lib = library(args)
    if args.json:
        print(json.dumps([s.describe() for s in lib.values()], indent=2))
        return 0
    width = max(len(n) for n in lib)
    print(f"{'':<{width}}  J(s): the card in its parameters (the compliance; for generic data "
          "the transfer function); G*(s) = 1/J(s) in the physical parameters that modulus "
          "data report")
    for s in lib.values():
        priors = ", ".join(f"{p.name}~{p.prior.describe()}" for p in s.parameters)
        print(f"{s.name:<{width}}  J(s) = {s.formula}")
        if s.modulus_formula is not None:
            print(f"{'':<{width}}  G*(s) = {s.modulus_formula}")
        print(f"{'':<{width}}  priors: {priors}")
    return 0
