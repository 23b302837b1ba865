"""``bayesfo compare``: posteriors, criteria and ranking of several structures on one data set."""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path

from ..options import (
    check_prior_names,
    check_sampler_settings,
    parse_floats,
    parse_priors,
    sampler_options,
)
from ._common import (
    add_comparison_options,
    add_data_options,
    add_figure_options,
    figure_options,
    library,
    read_data,
)


def add_parser(subparsers):
    """Register ``bayesfo compare``: compare structures on one data set."""
    p = subparsers.add_parser("compare", help="posteriors and criteria of several structures on one data set")
    add_data_options(p)
    p.add_argument("--out", default=None, metavar="DIR",
                   help="output directory (default: bayesfo-<data name>)")
    add_comparison_options(p)
    p.add_argument("--workers", type=int, default=0, metavar="N",
                   help="processes running structures side by side and then drawing the figures "
                        "(default 0: automatic: quick posteriors in this process, the others in "
                        "one process per CPU, started only when needed, which then take the "
                        "rest; without those, the "
                        "figures are drawn here and, when a CPU is idle, in a process forked "
                        "from this one); the numbers do not depend on it")
    p.add_argument("--no-figures", action="store_true",
                   help="skip the figures and report.html (faster; summary, table and NetCDF only)")
    add_figure_options(p)
    p.add_argument("--quiet", action="store_true", help="no progress bar or table")
    return p


def _compare(data, structures, out, workers, formats, no_figures, options):
    """The comparison and its outputs, in the processes that ``workers`` asks for
    (:func:`bayesfo.parallel.executor`). With worker processes, the same pool draws the
    figures: its processes have the libraries loaded by then (with the automatic choice, only
    if some structure started them). In this process alone, the figures are drawn here, and in
    a process forked from this one where the machine had a CPU to spare during the comparison
    (:func:`bayesfo.parallel.figure_processes`)."""
    from ..comparison import compare
    from ..output import write_outputs
    from ..parallel import InlineExecutor, cpu_times, executor, figure_processes
    from ._libraries import load_libraries

    figures = {} if formats is None else {"formats": formats,
                                          "structure_figures": options.pop("structure_figures")}
    options.pop("structure_figures", None)
    start = cpu_times()
    # The libraries are loaded before any process is forked from this one, so that the
    # workers share them: with the automatic choice, once the comparison has begun the
    # optimisations, which need none of them (bayesfo.comparison.early).
    with executor(workers, len(structures),
                  prepare=lambda: load_libraries(formats or ())) as pool:
        result = compare(data, structures, pool=pool, **options)
        inline = isinstance(pool, InlineExecutor)
        extra = {} if workers != 0 or no_figures else {"figure_processes":
                                                        figure_processes(start)}
        write_outputs(result, out, figures=not no_figures, pool=None if inline else pool,
                      **extra, **figures)
    return result


def _units_note(path, kind: str, letter: str = "G") -> str:
    """What a run on data without units says: the parameters are in the data's own unit
    (``[G]``, or ``[E]`` for tensile data measured as ``letter`` E)."""
    from ..data.symbols import in_symbol

    if kind == "compliance":
        symbol, how = "[J]", ("give the response columns a unit in brackets (e.g. \"J' [1/Pa]\", "
                              "in the header or with --columns), or add a '# units: 1/Pa' line "
                              "to a bayesfo CSV")
    else:
        symbol, how = "[G]", ("give both columns a unit, e.g. --columns storage=\"Storage "
                              "Modulus [Pa]\",loss=\"Loss Modulus [Pa]\" (with the file's "
                              "headers), or add a '# units: Pa' line to a bayesfo CSV")
    return (f"bayesfo: note: '{path}' gives no unit for the response, so the parameters are in "
            f"the data's own unit ({in_symbol(symbol, letter)} in the table and report); to "
            f"name it, {in_symbol(how, letter)}")


def _quantity(data) -> str:
    """`` (tensile: E′, E″)`` after the kind for tensile data (a DMA's E′, E″ or D′, D″),
    nothing for shear data (G′, G″ or J′, J″, the default) and generic responses."""
    from ..data.symbols import mode, parts

    if data.kind not in ("modulus", "compliance") or mode(data.symbol) == "shear":
        return ""
    storage, loss = parts(data.symbol, data.kind)
    return f" ({mode(data.symbol)}: {storage}, {loss})"


def _print_undetermined(result) -> None:
    """Beneath the table: the parameters (in the form natural to the data) that the data do
    not determine, and the poorly determined orders, of each structure, best first."""
    from ..comparison.parameters import UNDETERMINED_DECADES, flagged_names
    from ..data.symbols import parameter_label

    symbol = result.data.symbol
    vague, poor, modes = [], [], []
    for row in result.table():
        if row.get("error") or not row.get("sampled", True):
            continue
        r = result[row["structure"]]
        names = [parameter_label(n, symbol) for n in flagged_names(r.natural_parameters)]
        if names:
            vague.append(f"{r.name}: {', '.join(names)}")
        orders = [n for n in r.structure.exponent_params
                  if n in r.posterior.summary and r.posterior.summary[n].poorly_determined]
        if orders:
            poor.append(f"{r.name}: {', '.join(orders)}")
        split = [n for n in r.structure.exponent_params
                 if n in r.posterior.summary and r.posterior.summary[n].multimodal]
        if split:
            modes.append(f"{r.name}: {', '.join(split)}")
    if vague:
        print(f"not determined by the data (94 % HDI over more than {UNDETERMINED_DECADES:g} "
              "decades on a log scale, reaching 0 or infinity, or undefined; the values in the "
              "report, summary.json and ranking.csv are not estimates): " + "; ".join(vague))
    if modes:
        print("orders with several separated modes (their means lie between the modes; the "
              "q_posteriors figure shows them): " + "; ".join(modes))
    if poor:
        print("orders poorly determined (94 % HDI wider than half the prior range): "
              + "; ".join(poor))


def run(args) -> int:
    from ..comparison.table import ranking_lines
    from ..outdir import check_output_directory
    from ..parallel import check_workers
    from ..structures import resolve_structures

    data = read_data(args)
    structures = resolve_structures(args.structures, library(args))
    priors = parse_priors(args.prior)
    check_prior_names(priors, structures)
    settings = {"max_steps": args.max_steps, "walkers": args.walkers}
    check_sampler_settings(settings, "compare")
    formats, detail = figure_options(args)
    holdout = parse_floats(args.holdout, "--holdout") if args.holdout else None
    check_workers(args.workers)
    progress = not args.quiet and sys.stderr.isatty()
    options = dict(noise=args.noise, seed=args.seed, priors=priors, progress=progress,
                   evidence=args.evidence, evidence_check=args.evidence_check, holdout=holdout,
                   sampler=args.sampler, sample=args.sample)
    options.update(sampler_options(settings))
    options["structure_figures"] = detail
    target = Path(args.out if args.out else f"bayesfo-{Path(args.data).stem}")
    created = not target.exists()
    out = check_output_directory(target, directories=() if args.no_figures else ("figures",))
    # A data set of a batch (its record batch.json, the batch's summary beside it): this run
    # replaces the record, so the batch redoes the data set when run again; until then the
    # batch's summary shows its own result. Nothing outside --out is touched.
    batch_of = (out.parent if (out / "batch.json").is_file()
                and (out.parent / "batch_summary.csv").is_file() else None)
    try:
        result = _compare(data, structures, out, args.workers, formats, args.no_figures,
                          options)
    except BaseException:
        if created:  # a run that wrote nothing leaves no directory behind
            with contextlib.suppress(OSError):
                out.rmdir()
        raise
    if batch_of is not None:
        print(f"bayesfo: warning: '{out}' is a data set of the batch in '{batch_of}': its "
              f"batch_summary.csv still shows the batch's result for it; run the batch again "
              f"into '{batch_of}' to redo this data set with the batch's options and update "
              "the summary", file=sys.stderr)
    if not args.quiet:
        if not data.units:
            print(_units_note(args.data, data.kind, data.symbol), file=sys.stderr)
        n_fit = result.data.n_frequencies
        held = "" if result.holdout is None else f" ({result.holdout.n_frequencies} more held out)"
        print(f"{data.label}: {n_fit} frequencies fitted{held}, kind {data.kind}"
              f"{_quantity(data)}; ranked by "
              "log-evidence ln Z (importance or bridge sampling; L: from a tempered ladder); "
              "P = posterior "
              "probability, equal prior odds; ok = posterior certified; fits = posterior "
              "predictive checks pass (small: a systematic misfit within 2° and 3.5 %; partly: "
              "pass, but the fitted noise swamps points the fit misses)")
        for line in ranking_lines(result.table()):
            print(line)
        if result.noise_note:
            print(result.noise_note)
        _print_undetermined(result)
        pairs = result.baselines()
        if pairs:
            print("integer baselines (every fractional order = 1) against their fractional "
                  "parents:")
            for b in pairs:
                if b["delta_log_evidence"] is None:
                    continue
                d = b["delta_log_evidence"]
                verdict = "fractional order favoured" if d > 0 else "integer order favoured"
                # One of the pair left out by the evidence bound: the difference is a bound,
                # which decides only where it lies on the side of its sign.
                relation = {">=": "≥ ", "<=": "≤ "}.get(b.get("delta_log_evidence_relation"), "")
                if (relation == "≥ " and d <= 0) or (relation == "≤ " and d >= 0):
                    left = b["baseline"] if relation == "≥ " else b["parent"]
                    verdict = f"not decided ({left} not sampled: its best fit bounds ln Z)"
                hdi = ""
                if b["orders"]:
                    parts = [f"{o['symbol']} in [{o['hdi'][0]:.3f}, {o['hdi'][1]:.3f}]"
                             for o in b["orders"]]
                    parts[0] = parts[0].replace(" in ", f" of {b['parent']} in ", 1)
                    ones = [o["symbol"] for o in b["orders"] if o["hdi_includes_1"]]
                    hdi = (f"; {', '.join(parts)} (94 % HDI"
                           f"{'; includes 1: ' + ', '.join(ones) if ones else ''})")
                print(f"   {b['parent']:<14} vs {b['baseline']:<16} ln Z difference "
                      f"{relation}{d:+.2f} ± {b['delta_log_evidence_err']:.2f}: "
                      f"{verdict}{hdi}")
        if result.holdout is not None:
            print("held out " + ", ".join(f"{w:.4g}" for w in result.holdout.omega) + " rad/s:")
            for row in result.table():
                if not row.get("error"):
                    print(f"   {row['structure']:<16} log predictive density {row['holdout_lpd']:10.2f}, "
                          f"RMSE {row['holdout_rmse']:.4g} (in-sample RMSE {row['rmse']:.4g})")
        if args.no_figures:
            print(f"wrote {out}/summary.json, ranking.csv and one NetCDF per sampled structure")
        else:
            print(f"report: {out / 'report.html'} (figures in {out / 'figures'}; summary.json, "
                  "ranking.csv and one NetCDF per sampled structure beside it)")
    return 0
