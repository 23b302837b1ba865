"""``bayesfo batch``: compare structures on many data sets (local processes or a Dask cluster)."""

from __future__ import annotations

import sys
from pathlib import Path

from ..batch import OK, BatchResult, expand_inputs, run_batch
from ..options import (
    KINDS,
    parse_floats,
)
from ._common import add_comparison_options, add_figure_options, figure_options
from ._libraries import load_libraries


def add_parser(subparsers):
    """Register the ``batch`` sub-command on the ``bayesfo`` command line.

    Parameters
    ----------
    subparsers
        The object returned by ``ArgumentParser.add_subparsers``.

    Returns
    -------
    argparse.ArgumentParser
        The ``batch`` parser (its command is :func:`cmd_batch`).
    """
    p = subparsers.add_parser(
        "batch", help="compare structures on many data sets (local processes or a Dask cluster)",
        description="Run 'compare' on every data set; write DIR/<id>/ per data set, "
                    "DIR/batch_summary.csv and its figure, and, for isotherms, "
                    "DIR/temperature_summary.csv and the figure of q against temperature. "
                    "A re-run skips the data sets whose results are complete.")
    p.add_argument("inputs", nargs="*", metavar="INPUT",
                   help="CSV file, directory of *.csv, glob pattern, or manifest (a CSV with a "
                        "'path' column and per-file options)")
    p.add_argument("--manifest", action="append", default=[], metavar="FILE",
                   help="manifest CSV: path[,id,kind,reciprocal|invert,structures,noise,prior,"
                        "seed,holdout,evidence,evidence_check,temperature,sampler,max_steps,"
                        "walkers]; repeatable")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--kind", choices=KINDS,
                   help="what the responses are (default: each file's '# kind:' line, else "
                        "modulus for storage/loss columns, else generic)")
    p.add_argument("--reciprocal", action="store_true",
                   help="use 1/G of the data (sigma propagated)")
    add_comparison_options(p, each="every fit")
    p.add_argument("--no-figures", action="store_true",
                   help="skip each data set's figures and report.html (the combined figures "
                        "are still drawn)")
    add_figure_options(p, each=" of each data set")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="processes running data sets side by side (default 0: one per CPU; "
                        "1: in this process); the numbers do not depend on it")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a Dask cluster (e.g. tcp://10.0.0.5:8786); needs bayesfo[cluster]")
    p.add_argument("--quiet", action="store_true",
                   help="no progress bar or table; only the one-line summary and errors")
    return p


def run(args) -> int:
    """Run ``bayesfo batch``; returns the exit status (0 all compared, 2 bad input in some data
    set, 1 an internal error in some data set). Problems with the command itself (arguments,
    manifests, scheduler) raise :class:`~bayesfo.errors.InputError`."""
    formats, detail = figure_options(args)
    options = {"kind": args.kind, "reciprocal": args.reciprocal, "structures": args.structures,
               "noise": args.noise, "priors": tuple(args.prior),
               "holdout": parse_floats(args.holdout, "--holdout") if args.holdout else None,
               "evidence": args.evidence, "evidence_check": args.evidence_check,
               "sampler": args.sampler, "max_steps": args.max_steps, "walkers": args.walkers,
               "models": tuple(getattr(args, "models", None) or ()),
               "figures": not args.no_figures, "figure_formats": formats,
               "structure_figures": detail, "sample": args.sample}
    datasets = expand_inputs(args.inputs, manifests=args.manifest, options=options,
                             seed=args.seed, exclude=args.out)
    progress = not args.quiet and sys.stderr.isatty()
    # The data sets are compared (and drawn) here or in processes forked from this one.
    load_libraries(formats or ())
    result = run_batch(datasets, args.out, workers=args.workers, scheduler=args.scheduler,
                       progress=progress)
    for o in result.failed:
        print(f"bayesfo: error: {o.dataset.id}: {o.error}", file=sys.stderr)
    if not args.quiet:
        _print_table(result)
    n_ok = sum(o.status == OK for o in result.outcomes)
    reused = sum(o.reused for o in result.outcomes)
    names = ", ".join(n for n in result.written)
    print(f"batch: {len(result.outcomes)} data sets, {n_ok} compared ({reused} complete from an "
          f"earlier run), {len(result.failed)} failed; {result.executor}, "
          f"{result.wall_seconds:.1f} s; wrote {result.out_dir}/{{<id>/, {names}}}")
    temperatures = {o.dataset.temperature for o in result.outcomes} - {None}
    if len(temperatures) > 1 and not args.quiet:
        # Isotherms compared one by one may each pick another structure: the figure of the
        # orders against temperature then jumps between models, not between material states.
        print(f"note: {len(temperatures)} temperatures: each isotherm was compared on its own; "
              "for one master structure and the shift factors of all of them, run 'bayesfo "
              "mastercurve' on the same files")
    return result.exit_status


#: How a batch task records a warning about the data (negative loss, parts not Kramers–Kronig
#: consistent, a sheet left out): the category, then the message.
DATA_WARNING = "DataWarning: "


def _print_table(result: BatchResult) -> None:
    """A line per data set: its best structure by ln Z, P, every order's mean, whether the
    structure describes the data (fits: the posterior predictive checks, as ``compare``
    prints), and the status; then how many data sets no structure describes."""
    from ..comparison.table import order_means

    width = max([7] + [len(o.dataset.id) for o in result.outcomes])
    means = {o.dataset.id: order_means(next((r for r in o.rows if r.get("best")), {}))
             for o in result.outcomes if o.status == OK}
    o_width = max([13] + [len(v) for v in means.values()])
    b_width = max([14] + [len(r["structure"]) for o in result.outcomes for r in o.rows
                          if r.get("best")])
    print(f"{'dataset':<{width}} {'T [°C]':>7}  {'best':<{b_width}} {'P':>6}  "
          f"{'orders (mean)':<{o_width}} {'fits':>6}  status")
    misfit = []
    for o in result.outcomes:
        t = "" if o.dataset.temperature is None else f"{o.dataset.temperature:g}"
        if o.status != OK:
            print(f"{o.dataset.id:<{width}} {t:>7}  {'-':<{b_width}} {'-':>6}  {'-':<{o_width}} "
                  f"{'-':>6}  {o.status.replace('_', ' ')}")
            continue
        best = next((r for r in o.rows if r.get("best")), None)
        if best is None:
            print(f"{o.dataset.id:<{width}} {t:>7}  no ranked structure")
            continue
        p = best.get("posterior_probability")
        fits = best.get("fits")
        if fits == "no":
            misfit.append(o.dataset.id)
        flags = "reused" if o.reused else "ok"
        if not best.get("converged"):
            # The report says what to do (more steps, another prior); name it, and the best
            # structure whose posterior is certified.
            ranked = sorted((r for r in o.rows if r.get("rank") is not None),
                            key=lambda r: r["rank"])
            certified = next((r["structure"] for r in ranked if r.get("converged")), None)
            report = "report.html" if (Path(result.out_dir) / o.dataset.id
                                       / "report.html").exists() else "summary.json"
            flags += (", not converged" + (f" (best certified: {certified})" if certified else "")
                      + f"; see {o.dataset.id}/{report}")
        print(f"{o.dataset.id:<{width}} {t:>7}  {best['structure']:<{b_width}} "
              f"{'-' if p is None else f'{p:.3f}':>6}  {means[o.dataset.id]:<{o_width}} "
              f"{(fits or '-').replace('no', 'NO'):>6}  {flags}")
    if misfit:
        print(f"fits NO: on {len(misfit)} of {len(result.outcomes)} data sets the best structure "
              "fails the posterior predictive checks (none of the candidates describes those "
              "data; see each report's verdict): " + ", ".join(misfit))
    # Problems of the data themselves (compare's data warnings), which no structure mends.
    for o in result.outcomes:
        for w in dict.fromkeys(getattr(o, "warnings", ())):
            if w.startswith(DATA_WARNING):
                print(f"data {o.dataset.id}: {w[len(DATA_WARNING):]}")
