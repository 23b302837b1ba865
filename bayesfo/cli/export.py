"""``bayesfo export``: a Prony series of a compared model, for finite-element codes."""

from __future__ import annotations


def add_parser(subparsers):
    """Register ``bayesfo export``."""
    import argparse

    from ..predictions.functions import AVERAGES
    from ..predictions.prony import FORMATS

    p = subparsers.add_parser(
        "export", help="a Prony series of the model (csv, Abaqus, ANSYS, LS-DYNA) from the "
                       "output directory of a comparison or a master curve",
        description="Fit G(t) = G_inf + sum g_i exp(-t/tau_i) (tau_i fixed per decade, g_i >= "
                    "0) to the posterior median G', G'' of a structure or an average, and "
                    "write it with its largest relative error over the data window beside the "
                    "width of the model's credible band.")
    p.add_argument("directory", metavar="DIR",
                   help="output directory of bayesfo compare, or of bayesfo mastercurve (the "
                        "series at the reference temperature, with the shift law)")
    p.add_argument("--format", required=True, choices=FORMATS,
                   help="csv (tau_s,g_i), abaqus (*VISCOELASTIC, TIME=PRONY), ansys "
                        "(TB,PRONY with TBDATA) or lsdyna (*MAT_GENERAL_VISCOELASTIC, at most "
                        "18 terms)")
    p.add_argument("--out", required=True, metavar="FILE",
                   help="the file to write ('-': standard output, the messages then go to "
                        "standard error)")
    many = p.add_mutually_exclusive_group()
    many.add_argument("--per-decade", type=int, default=2, metavar="K",
                      help="relaxation times per decade (default 2)")
    many.add_argument("--terms", type=int, default=None, metavar="N",
                      help="the number of relaxation times instead (2-100, log-spaced over the "
                           "same span; terms of zero weight are dropped)")
    p.add_argument("--liquid", action=argparse.BooleanOptionalAction, default=None,
                   help="G_inf = 0: the material relaxes fully (--no-liquid: G_inf fitted with "
                        "the terms; default: 0 where the model's long-time modulus is 0, else "
                        "fitted)")
    who = p.add_mutually_exclusive_group()
    who.add_argument("--structure", metavar="S", help="the structure (default: the best ranked)")
    who.add_argument("--average", choices=AVERAGES, help="an average over the structures")
    p.add_argument("--figure", metavar="FILE.png",
                   help="also draw the series' G(t) against the model's band and its relative "
                        "error (format from the suffix: png, pdf, svg)")
    p.add_argument("--seed", type=int, default=0, help="seed of the draws used (default 0)")
    return p


def run(args) -> int:
    import functools
    import sys
    from pathlib import Path

    from .._io import atomic_write_text, write_error
    from ..comparison import load
    from ..errors import InputError
    from ..predictions.prony import prony_series

    result = load(args.directory, models=getattr(args, "models", ()) or ())
    try:
        prony = prony_series(result, per_decade=args.per_decade, liquid=args.liquid,
                             structure=args.structure, average=args.average, seed=args.seed,
                             terms=args.terms)
    except InputError as exc:  # the API's words, in the command line's
        raise InputError(str(exc).replace("predict: ", "", 1).replace("export: ", "", 1)
                         .replace("terms per decade", "--per-decade")
                         .replace("the number of terms", "--terms")) from None
    if args.figure is not None:
        suffix = Path(args.figure).suffix.lower()
        if suffix not in (".png", ".pdf", ".svg"):
            raise InputError(f"--figure '{args.figure}': give a .png, .pdf or .svg file")
    try:
        text = prony.text(args.format)
    except InputError as exc:
        raise InputError(str(exc).replace("export: ", "", 1).replace(
            "terms 17 or 1 per decade", "--terms 17 or --per-decade 1")) from None
    # With --out - the series goes to standard output, and what is said of it to stderr.
    say = functools.partial(print, file=sys.stderr if args.out == "-" else sys.stdout)
    if args.out == "-":
        sys.stdout.write(text)
        sys.stdout.flush()
    else:
        try:
            atomic_write_text(args.out, text, named=True)
        except OSError as exc:
            raise InputError(f"--out '{args.out}': cannot be written "
                             f"({write_error(args.out, exc)})") from None
    if args.figure is not None:
        from ._libraries import load_libraries

        load_libraries((Path(args.figure).suffix.lower().lstrip("."),))
        from ..plotting.output import save_figure
        from ..plotting.prony import plot_prony

        drawn = plot_prony(result, prony, structure=args.structure, average=args.average,
                           seed=args.seed)
        try:
            save_figure(drawn.figure, args.figure, close=True, named=True)
        except OSError as exc:
            written = "" if args.out == "-" else f"; the series was written to '{args.out}'"
            raise InputError(f"--figure '{args.figure}': cannot be written "
                             f"({write_error(args.figure, exc)}){written}") from None
        say(f"wrote {args.figure}")
    error = max(prony.max_rel_error_modulus, prony.max_rel_error_relaxation)
    where = "standard output" if args.out == "-" else args.out
    say(f"{prony.tau.size} terms of {prony.source}, G0 = {prony.g_0:.6g}, G_inf = "
        f"{prony.g_inf:.6g} {prony.unit}; largest relative error over the data window "
        f"{error:.2g} (the model's 94 % band: +-{prony.band_rel_halfwidth:.2g}); wrote {where}")
    for line in prony.extrapolation_text():
        say(f"note: {line}")
    for line in prony.long_time_text():
        if prony.model_g_inf == 0.0:
            line += (" (--liquid sets G_inf = 0)" if prony.g_inf > 0 else
                     " (--no-liquid fits G_inf with the terms)" if args.liquid is None else "")
        say(f"note: {line}")
    law = prony.shift_law
    if law is not None:
        from ..tts.joint import LAW_MISS

        say(f"with the {'WLF' if law['name'] == 'wlf' else 'Arrhenius'} shift law at "
            f"T_ref = {law['reference_temperature']:g} °C (" + ", ".join(
                f"{k} = {v:.6g}" for k, v in law["parameters"].items()) + ")")
        if law["chi2_per_dof"] > LAW_MISS:
            say(f"note: the shift law misses the master curve's shifts beyond their "
                f"uncertainty (chi2/dof {law['chi2_per_dof']:.3g}): the finite-element model "
                "will be off at some temperatures; see the master curve's notes")
    if error > prony.band_rel_halfwidth:
        more = (f"--terms {min(100, 2 * args.terms)}" if args.terms is not None
                else f"--per-decade {min(10, 2 * args.per_decade)}")
        say(f"note: the series departs from the model by more than the model's uncertainty; "
            f"more terms ({more}) may help")
    return 0
