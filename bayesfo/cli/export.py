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
        description="Fit G(t) = G_inf + sum g_i exp(-t/tau_i) (tau_i log-spaced, g_i >= 0) "
                    "to the posterior median G', G'' of a structure or an average, with the "
                    "fewest terms whose G(t) stays inside the model's 94 % band over the data "
                    "window, and write it with its largest relative errors there.")
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
    many.add_argument("--terms", type=_terms, default="auto", metavar="auto|N",
                      help="the number of relaxation times (log-spaced from two decades below "
                           "the data window to two above it; terms of zero weight are "
                           "dropped): auto (default), the fewest whose G(t) stays inside the "
                           "model's 94 %% band at 2001 times over the window (for lsdyna at "
                           "most the card's 18 rows), or N from 2 to 100")
    many.add_argument("--per-decade", type=int, default=None, metavar="K",
                      help="K relaxation times per decade instead (1-10)")
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


def _terms(text: str):
    """``auto`` or an integer, for ``--terms``."""
    import argparse

    if text.strip().lower() == "auto":
        return "auto"
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"give auto or a whole number, got {text!r}") from None


def run(args) -> int:
    import functools
    import sys
    from pathlib import Path

    from .._io import atomic_write_text, write_error
    from ..comparison import load
    from ..errors import InputError
    from ..predictions.prony import LSDYNA_MAX_TERMS, prony_series

    result = load(args.directory, models=getattr(args, "models", ()) or ())
    terms = None if args.per_decade is not None else args.terms
    prony = prony_series(result, per_decade=args.per_decade, liquid=args.liquid,
                         structure=args.structure, average=args.average, seed=args.seed,
                         terms=terms, max_terms=LSDYNA_MAX_TERMS if args.format == "lsdyna"
                         and terms == "auto" else None)
    if args.figure is not None:
        suffix = Path(args.figure).suffix.lower()
        if suffix not in (".png", ".pdf", ".svg"):
            raise InputError(f"--figure '{args.figure}': give a .png, .pdf or .svg file")
    text = prony.text(args.format)
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
    from ..data.symbols import modulus_symbol
    from ..predictions.prony import DENSE, unit_suffix

    e = modulus_symbol(prony.symbol)
    how = (f" (the fewest whose {e}(t) stays inside the model's band)"
           if prony.rule == "auto" and prony.inside_band else "")
    where = "standard output" if args.out == "-" else args.out
    say(f"{prony.tau.size} terms of {prony.source}{how}, {e}0 = {prony.g_0:.6g}, {e}_inf = "
        f"{prony.g_inf:.6g}{unit_suffix(prony.unit)}; wrote {where}")
    say(f"largest relative errors over the data window ({DENSE} log-spaced times, "
        f"frequencies): {e}(t) {prony.max_rel_error_relaxation:.2g}, |{e}*| "
        f"{prony.max_rel_error_modulus:.2g}, {e}′ {prony.max_rel_error_storage:.2g}, {e}″ "
        f"{prony.max_rel_error_loss:.2g}; the model's 94 % band of {e}(t): at least "
        f"+-{prony.band_rel_halfwidth:.2g}, the series "
        + ("inside it" if prony.inside_band else "outside it")
        + f" (largest departure {prony.band_fraction:.2g} of the band's reach)")
    for line in prony.extrapolation_text():
        say(f"note: {line}")
    for line in prony.long_time_text():
        if prony.model_g_inf == 0.0:
            line += (" (--liquid sets G_inf = 0)" if prony.g_inf > 0 else
                     " (--no-liquid fits G_inf with the terms)" if args.liquid is None else "")
        say(f"note: {line}")
    law = prony.shift_law
    if law is None and prony.shift_note:
        say(f"note: {prony.shift_note}")
    if law is not None:
        from ..tts.joint import LAW_MISS

        say(f"with the {'WLF' if law['name'] == 'wlf' else 'Arrhenius'} shift law at "
            f"T_ref = {law['reference_temperature']:g} °C (" + ", ".join(
                f"{k} = {v:.6g}" for k, v in law["parameters"].items()) + ")")
        if law["chi2_per_dof"] > LAW_MISS:
            say(f"note: the shift law misses the master curve's shifts beyond their "
                f"uncertainty (chi2/dof {law['chi2_per_dof']:.3g}): the finite-element model "
                "will be off at some temperatures; see the master curve's notes")
    if not prony.inside_band:
        if prony.rule == "auto" and prony.max_terms is not None:
            more = (f"the card's {prony.max_terms} rows are too few: the format csv, abaqus "
                    "or ansys takes as many as it needs")
        elif args.per_decade is not None:
            more = f"more terms (--per-decade {min(10, 2 * args.per_decade)}) may help"
        elif isinstance(args.terms, int):
            more = f"more terms (--terms {min(100, 2 * args.terms)} or auto) may help"
        else:
            more = "no number of terms up to 100 keeps it inside"
        say(f"note: the series leaves the model's 94 % band of {e}(t): {more}")
    return 0
