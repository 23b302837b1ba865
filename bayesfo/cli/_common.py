"""What several commands share: the data arguments, reading the data, the structure library."""

from __future__ import annotations

from ..options import (
    DEFAULT_STRUCTURES,
    EVIDENCE_ROUTES,
    KINDS,
    NOISE_MODELS,
    SAMPLERS,
    seed_argument,
)


def add_data_options(p):
    p.add_argument("data", metavar="DATA", help="CSV file with omega|freq and the response columns")
    p.add_argument("--kind", choices=KINDS,
                   help="what the response is (default: the file's '# kind:' line, else modulus "
                        "for storage/loss columns, else generic)")
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



def add_comparison_options(p, each: str = "the fit"):
    """The options of a comparison that ``compare`` and ``batch`` share (``each`` names what
    they apply to in the help texts)."""
    p.add_argument("--structures", default=DEFAULT_STRUCTURES,
                   help=f"comma list, with shortcuts maxN and all (default {DEFAULT_STRUCTURES})")
    p.add_argument("--noise", default="auto", choices=NOISE_MODELS,
                   help="noise model (default: known if the data give sigma, else relative "
                        "or constant)")
    p.add_argument("--prior", action="append", default=[], metavar="NAME=TYPE:A:B",
                   help="override a prior, e.g. q=uniform:0.2:1 or sigma_rel=log-uniform:1e-4:0.1; "
                        "one per parameter")
    p.add_argument("--seed", type=seed_argument, default=0,
                   help="seed of every random step (the same numbers whatever the workers)")
    p.add_argument("--holdout", default=None, metavar="W1,W2",
                   help=f"angular frequencies [rad/s] left out of {each} for validation")
    p.add_argument("--sampler", default="auto", choices=SAMPLERS,
                   help="posterior by importance sampling from the optima where its weights "
                        "certify it, else emcee (auto), or emcee first (emcee)")
    p.add_argument("--evidence", default="auto", choices=EVIDENCE_ROUTES,
                   help="ln Z from the route that gave the posterior (auto: the importance "
                        "weights, else bridge sampling from the emcee draws, or the tempered "
                        "ladder where the walkers did not converge), or forced: bridge, ladder")
    p.add_argument("--evidence-check", action="store_true",
                   help="also compute ln Z by dynesty nested sampling and flag disagreements")
