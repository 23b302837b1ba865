"""What several commands share: the data arguments, reading the data, the structure library."""

from __future__ import annotations

from ..errors import InputError
from ..options import (
    DEFAULT_STRUCTURES,
    EVIDENCE_ROUTES,
    KINDS,
    LEADING,
    LEADING_STRUCTURES,
    NOISE_MODELS,
    SAMPLE,
    SAMPLERS,
    STRUCTURE_FIGURES,
    VERY_STRONG,
    seed_argument,
)


def add_data_options(p):
    p.add_argument("data", metavar="DATA",
                   help="data file: a bayesfo CSV (omega|freq and the response columns) or a "
                        "lab export (TRIOS, RheoCompass, ARES, RepTate, pyvisco, delimited text "
                        "with recognisable headers; see docs/lab_files.md)")
    p.add_argument("--kind", choices=KINDS,
                   help="what the response is (default: what the columns say, e.g. G' a "
                        "modulus, J' a compliance; else the file's '# kind:' line, else modulus "
                        "for storage/loss columns, else generic)")
    p.add_argument("--reciprocal", action="store_true",
                   help="use 1/G of the data (sigma propagated)")
    add_column_options(p)
    p.add_argument("--block", default=None, metavar="N|LABEL",
                   help="for a file of several data sets (steps, intervals, isotherms): which "
                        "one, by number from 1 (\"#20\" where a bare 20 could also be a "
                        "temperature), label or temperature (\"20 °C\", -40C; bayesfo "
                        "inspect lists them)")
    p.add_argument("--delimiter", default=None, choices=(",", ";", "tab", "space"),
                   help="cell delimiter (default: sniffed)")
    p.add_argument("--decimal", default=None, choices=(".", ","),
                   help="decimal mark (default: sniffed)")
    p.add_argument("--duplicates", default="error", choices=("error", "first", "mean"),
                   help="rows that repeat a frequency: refuse (default), keep the first, or "
                        "average them (overlapping isotherms of a master curve)")


def add_column_options(p) -> None:
    """``--columns``: which column is what, and a unit where the file gives none."""
    p.add_argument("--columns", default=None, metavar="ROLE=COLUMN,...",
                   help="which column is what, for columns not recognised or to choose, e.g. "
                        "omega=\"Ang. Freq.\",storage=\"G'\",loss=\"G''\"; roles omega [rad/s], "
                        "freq [Hz], storage, loss, real, imag, magnitude, phase, phase_deg, "
                        "tan_delta, viscosity, eta_dyn, eta_out, sigma, series, temperature, "
                        "block; a column is its header or its number from 1, a unit in "
                        "brackets replaces the file's (E_stor=\"E_stor [Pa]\"), empty means none "
                        "(temperature=)")


def read_data(args, every: bool = False):
    """The data set of ``args.data`` read with the data options (``--reciprocal`` applied); with
    ``every``, every data set of the file as :class:`~bayesfo.data.Isotherm` objects (``--block``
    selects one; ``--reciprocal`` is left to the caller)."""
    from ..data import columns_from_text, read, read_isotherms, select

    delimiter = getattr(args, "delimiter", None)
    options = {"kind": args.kind, "columns": columns_from_text(getattr(args, "columns", None)),
               "delimiter": {"tab": "\t", "space": " "}.get(delimiter, delimiter),
               "decimal": getattr(args, "decimal", None),
               "duplicates": getattr(args, "duplicates", "error")}
    block = getattr(args, "block", None)
    if every:
        sets = read_isotherms(args.data, **options)
        return sets if block is None else [select(sets, block, f"file '{args.data}'")]
    data = read(args.data, block=block, **options)
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
                   help="noise model (default: known if the data give sigma, else constant, "
                        "proportional or relative_parts (the relative errors of the real and "
                        "imaginary parts, a rheometer's), whichever has the largest evidence "
                        "for each structure; any other value forces that model)")
    p.add_argument("--prior", action="append", default=[], metavar="NAME=TYPE:A:B",
                   help="override a prior, e.g. q=uniform:0.2:1 or sigma_rel=log-uniform:1e-4:0.1; "
                        "one per parameter; the card's coefficients are sampled on the scaled "
                        "problem (frequencies and magnitudes divided by the data's reference "
                        "values, which the report's priors section states), so their bounds "
                        "are on that scale, not in Pa or s")
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
    p.add_argument("--max-steps", type=int, default=None, metavar="N",
                   help="emcee's cap on steps per walker (default 10000): raise it when a "
                        "posterior is flagged as not converged")
    p.add_argument("--walkers", type=int, default=None, metavar="N",
                   help="emcee walkers (default max(32, 4 x parameters)); more walkers help "
                        "ridged and multimodal posteriors")
    p.add_argument("--sample", default="needed", choices=SAMPLE,
                   help="which structures get a posterior: needed (default) leaves out those "
                        "whose best fit bounds ln Z more than 10 nats below the leader's "
                        "certified ln Z (posterior probability provably below e^-10; the ranking "
                        "shows 'ln Z <=' and 'P <='), all samples every structure")
    p.add_argument("--evidence-check", action="store_true",
                   help="also compute ln Z by dynesty nested sampling and flag disagreements")


def add_figure_options(p, each: str = ""):
    """``--figure-formats`` and ``--structure-figures`` (``each``: e.g. " of each data set")."""
    p.add_argument("--figure-formats", default="png", metavar="F1,F2",
                   help=f"file formats of the figures{each} (default png, which report.html "
                        "embeds; png,pdf adds vector figures for publication, at about twice "
                        "the time)")
    p.add_argument("--structure-figures", default=STRUCTURE_FIGURES, metavar="leading|N|all",
                   help=f"which structures{each} get corner figures (and trace figures of "
                        f"walkers or ladder runs): {LEADING} (default: of the best "
                        f"{LEADING_STRUCTURES}, those the evidence does not rule out, ln Z "
                        f"within {VERY_STRONG:g} of the best, and each structure an information "
                        "criterion ranks first), N (the best N by the ranking; fewer is "
                        "faster) or all")


def figure_options(args) -> tuple[tuple[str, ...] | None, int | str | None]:
    """The figure formats (None with ``--no-figures``) and which structures get their own
    figures (``"leading"``, a number, or None: every one) of the command line, checked before
    any work."""
    text = args.structure_figures.strip().lower()
    if text not in ("all", LEADING) and not text.isdigit():
        raise InputError(f"--structure-figures takes '{LEADING}', a number of structures or "
                         f"'all', got {args.structure_figures!r}")
    detail = None if text == "all" else text if text == LEADING else int(text)
    if args.no_figures:
        return None, detail
    from ..plotting.output import check_formats

    return check_formats([f for f in args.figure_formats.split(",") if f.strip()],
                         "--figure-formats"), detail
