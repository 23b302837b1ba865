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
    pad = " " * width
    for s in lib.values():
        priors = ", ".join(f"{p.name}~{p.prior.describe()}" for p in s.parameters)
        print(f"{s.name:<{width}}  {_title(s)}")
        network = s.pictures[0].network if s.pictures else None
        if network is not None:
            print(f"{pad}  network {network.text}")
        print(f"{pad}  J(s) = {s.formula}")
        if s.modulus_formula is not None:
            print(f"{pad}  G*(s) = {s.modulus_formula}")
        inequalities = [c.text for c in s.constraints if not isinstance(c, str)]
        if inequalities:
            print(f"{pad}  constraints: {', '.join(inequalities)} (and stable, passive)")
        print(f"{pad}  priors: {priors}")
    return 0


def _title(s) -> str:
    """What the structure is, in words: its title, the degrees of a max-order member, the
    names it also answers to."""
    text = s.title or s.name
    if s.degrees is not None:
        n, m = s.degrees
        text += f": denominator of degree n = {n}, numerator of degree m = {m} in s^q"
    aliases = getattr(s, "aliases", ())
    return text + (f" (also {', '.join(aliases)})" if aliases else "")
