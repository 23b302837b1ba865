"""``bayesfo compare``: posteriors, criteria and ranking of several structures on one data set."""

from __future__ import annotations

import contextlib
import os
import sys
from pathlib import Path

from ..errors import InputError
from ..options import (
    STRUCTURE_FIGURES,
    check_sampler_settings,
    parse_floats,
    parse_priors,
    sampler_options,
)
from ._common import add_comparison_options, add_data_options, library, read_data


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
                        "one process per CPU, started only when needed; without those, the "
                        "figures are drawn here and, when a CPU is idle, in a process forked "
                        "from this one); the numbers do not depend on it")
    p.add_argument("--no-figures", action="store_true",
                   help="skip the figures and report.html (faster; summary, table and NetCDF only)")
    p.add_argument("--figure-formats", default="png", metavar="F1,F2",
                   help="file formats of the figures (default png, which report.html embeds; "
                        "png,pdf adds vector figures for publication, at about twice the time)")
    p.add_argument("--structure-figures", default=str(STRUCTURE_FIGURES), metavar="N|all",
                   help="how many structures, the best by the ranking, get corner and trace "
                        f"figures (default {STRUCTURE_FIGURES}; 'all' for every one)")
    p.add_argument("--quiet", action="store_true", help="no progress bar or table")
    return p


def _cpu_times() -> tuple[float, float, int] | None:
    """(idle, total, CPUs) time so far, in clock ticks (``/proc/stat``), of the CPUs this
    process may run on (its affinity set: under taskset, a cpuset or a batch scheduler, idle
    CPUs outside it are no use); ``None`` where the system does not tell."""
    try:
        allowed = os.sched_getaffinity(0)
    except (AttributeError, OSError):
        allowed = None
    idle = total = 0.0
    count = 0
    try:
        with open("/proc/stat") as f:
            for line in f:
                name, _, rest = line.partition(" ")
                if not name.startswith("cpu") or name == "cpu":
                    continue
                if allowed is not None and int(name[3:]) not in allowed:
                    continue
                fields = [float(x) for x in rest.split()]
                if len(fields) < 4:
                    return None
                idle += fields[3] + (fields[4] if len(fields) > 4 else 0.0)  # idle + iowait
                total += sum(fields[:8])
                count += 1
    except (OSError, ValueError):
        return None
    return (idle, total, count) if count else None


def _idle_cpus(since) -> float | None:
    """CPUs of this process's set left idle on average since ``since`` (from
    :func:`_cpu_times`)."""
    now = _cpu_times()
    if since is None or now is None or now[2] != since[2] or now[1] <= since[1]:
        return None
    return now[2] * (now[0] - since[0]) / (now[1] - since[1])


#: Idle CPUs during the comparison from which the figures are drawn in two processes.
SPARE_CPU_FOR_FIGURES = 0.5


def _figure_processes(since) -> int:
    """2 when a second process can draw figures beside this one: two CPUs or more, and at
    least :data:`SPARE_CPU_FOR_FIGURES` of them idle during the comparison (measured, two
    cores: with one core idle, 9 figures in PNG and PDF 5.5 → 3.1 s; with another job keeping
    one core busy, the two processes shared the other and the command took 0.1-1.5 s longer
    than in one process)."""
    from ..parallel import available_cpus

    if available_cpus() < 2:
        return 1
    idle = _idle_cpus(since)
    return 2 if idle is not None and idle >= SPARE_CPU_FOR_FIGURES else 1


def _compare(data, structures, out, n_proc, workers, formats, no_figures, options):
    """The comparison and its outputs, in the processes that ``workers`` asks for."""
    from ..comparison import compare
    from ..output import write_outputs
    from ..parallel import lazy_process_pool, process_pool

    figures = {} if formats is None else {"formats": formats,
                                          "structure_figures": options.pop("structure_figures")}
    options.pop("structure_figures", None)
    if workers == 0:
        # The quick steps here, the long ones in worker processes started only if some
        # structure needs them; those then draw the figures too. Otherwise the figures are
        # drawn here, and in a process forked from this one if the machine has a spare CPU.
        start = _cpu_times()
        with lazy_process_pool(n_proc) as pool:
            result = compare(data, structures, pool=pool, **options)
            write_outputs(result, out, figures=not no_figures, pool=pool,
                          figure_processes=1 if no_figures else _figure_processes(start),
                          **figures)
    elif n_proc > 1:
        # One pool for the structures and then the figures: its processes have the libraries
        # loaded by the time they draw.
        with process_pool(n_proc) as pool:
            result = compare(data, structures, pool=pool, **options)
            write_outputs(result, out, figures=not no_figures, pool=pool, **figures)
    else:
        result = compare(data, structures, workers=1, **options)
        write_outputs(result, out, figures=not no_figures, **figures)
    return result


def _units_note(path, kind: str) -> str:
    """What a run on data without units says: the parameters are in the data's own unit."""
    if kind == "compliance":
        symbol, how = "[J]", ("give the response columns a unit in brackets (e.g. \"J' [1/Pa]\", "
                              "in the header or with --columns), or add a '# units: 1/Pa' line "
                              "to a bayesfo CSV")
    else:
        symbol, how = "[G]", ("give both columns a unit, e.g. --columns storage=\"Storage "
                              "Modulus [Pa]\",loss=\"Loss Modulus [Pa]\" (with the file's "
                              "headers), or add a '# units: Pa' line to a bayesfo CSV")
    return (f"bayesfo: note: '{path}' gives no unit for the response, so the parameters are in "
            f"the data's own unit ({symbol} in the table and report); to name it, {how}")


def _print_undetermined(result) -> None:
    """Beneath the table: the parameters (in the form natural to the data) that the data do
    not determine, and the poorly determined orders, of each structure, best first."""
    from ..comparison.parameters import UNDETERMINED_DECADES, flagged_names

    vague, poor = [], []
    for row in result.table():
        if row.get("error"):
            continue
        r = result[row["structure"]]
        names = flagged_names(r.natural_parameters)
        if names:
            vague.append(f"{r.name}: {', '.join(names)}")
        orders = [n for n in r.structure.exponent_params
                  if n in r.posterior.summary and r.posterior.summary[n].poorly_determined]
        if orders:
            poor.append(f"{r.name}: {', '.join(orders)}")
    if vague:
        print(f"not determined by the data (94 % HDI over more than {UNDETERMINED_DECADES:g} "
              "decades on a log scale, reaching 0 or infinity, or undefined; the values in the "
              "report, summary.json and ranking.csv are not estimates): " + "; ".join(vague))
    if poor:
        print("orders poorly determined (94 % HDI wider than half the prior range): "
              + "; ".join(poor))


def run(args) -> int:
    from ..comparison.table import ranking_lines
    from ..outdir import check_output_directory
    from ..parallel import available_cpus
    from ..structures import resolve_structures
    from ._libraries import load_libraries

    data = read_data(args)
    structures = resolve_structures(args.structures, library(args))
    priors = parse_priors(args.prior)
    known = {p for s in structures for p in s.param_names} | {"sigma", "sigma_rel"}
    unknown = [k for k in priors if k not in known]
    if unknown:
        raise InputError(f"--prior names '{unknown[0]}', which no selected structure has")
    settings = {"max_steps": args.max_steps, "walkers": args.walkers}
    check_sampler_settings(settings, "compare")
    formats = None
    if not args.no_figures:
        from ..plotting.output import check_formats

        formats = check_formats([f for f in args.figure_formats.split(",") if f.strip()],
                                "--figure-formats")
    detail = args.structure_figures.strip().lower()
    if detail != "all" and not detail.isdigit():
        raise InputError(f"--structure-figures takes a number of structures or 'all', got "
                         f"{args.structure_figures!r}")
    holdout = parse_floats(args.holdout, "--holdout") if args.holdout else None
    if args.workers < 0:
        raise InputError(f"--workers must be 0 (one per CPU) or a positive number, got {args.workers}")
    progress = not args.quiet and sys.stderr.isatty()
    options = dict(noise=args.noise, seed=args.seed, priors=priors, progress=progress,
                   evidence=args.evidence, evidence_check=args.evidence_check, holdout=holdout,
                   sampler=args.sampler)
    options.update(sampler_options(settings))
    options["structure_figures"] = None if detail == "all" else int(detail)
    n_proc = min(args.workers or available_cpus(), len(structures))
    target = Path(args.out if args.out else f"bayesfo-{Path(args.data).stem}")
    created = not target.exists()
    out = check_output_directory(target, directories=() if args.no_figures else ("figures",))
    load_libraries(formats or ())
    try:
        result = _compare(data, structures, out, n_proc, args.workers, formats, args.no_figures,
                          options)
    except BaseException:
        if created:  # a run that wrote nothing leaves no directory behind
            with contextlib.suppress(OSError):
                out.rmdir()
        raise
    if not args.quiet:
        if not data.units:
            print(_units_note(args.data, data.kind), file=sys.stderr)
        n_fit = result.data.n_frequencies
        held = "" if result.holdout is None else f" ({result.holdout.n_frequencies} more held out)"
        print(f"{data.label}: {n_fit} frequencies fitted{held}, kind {data.kind}; ranked by "
              "log-evidence ln Z (importance or bridge sampling; L: from a tempered ladder); "
              "P = posterior "
              "probability, equal prior odds; ok = posterior certified; fits = posterior "
              "predictive checks pass (small: a systematic misfit within 2° and 3.5 %; partly: "
              "pass, but the fitted noise swamps points the fit misses)")
        for line in ranking_lines(result.table()):
            print(line)
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
                hdi = ""
                if b["orders"]:
                    parts = [f"{o['symbol']} in [{o['hdi'][0]:.3f}, {o['hdi'][1]:.3f}]"
                             for o in b["orders"]]
                    parts[0] = parts[0].replace(" in ", f" of {b['parent']} in ", 1)
                    ones = [o["symbol"] for o in b["orders"] if o["hdi_includes_1"]]
                    hdi = (f"; {', '.join(parts)} (94 % HDI"
                           f"{'; includes 1: ' + ', '.join(ones) if ones else ''})")
                print(f"   {b['parent']:<14} vs {b['baseline']:<16} ln Z difference "
                      f"{d:+9.2f} ± {b['delta_log_evidence_err']:.2f}: {verdict}{hdi}")
        if result.holdout is not None:
            print("held out " + ", ".join(f"{w:.4g}" for w in result.holdout.omega) + " rad/s:")
            for row in result.table():
                if not row.get("error"):
                    print(f"   {row['structure']:<16} log predictive density {row['holdout_lpd']:10.2f}, "
                          f"RMSE {row['holdout_rmse']:.4g} (in-sample RMSE {row['rmse']:.4g})")
        if args.no_figures:
            print(f"wrote {out}/summary.json, ranking.csv and one NetCDF per structure")
        else:
            print(f"report: {out / 'report.html'} (figures in {out / 'figures'}; summary.json, "
                  "ranking.csv and one NetCDF per structure beside it)")
    return 0
