"""The ``bayesfo`` command line.

Exit status 0 on success, 2 on bad input (one line on stderr naming the file, column, row or
argument), 1 on an internal error.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import warnings
from pathlib import Path

import numpy as np

from . import __version__, batch
from .errors import InputError, OutputError


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit status 2."""

    def error(self, message):
        raise InputError(f"{message} (see '{self.prog} --help')")


DEFAULT_STRUCTURES = "voigt,zener,maxwell,voigt-int,zener-int,maxwell-int"


def _add_data_options(p):
    p.add_argument("data", metavar="DATA", help="CSV file with omega|freq and the response columns")
    p.add_argument("--kind", choices=("compliance", "modulus", "generic"),
                   help="what the response is (default: the file's '# kind:' line, else generic)")
    p.add_argument("--reciprocal", action="store_true",
                   help="use 1/G of the data (sigma propagated)")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="bayesfo",
        description="Uncertainty-aware model choice for fractional-order transfer functions.",
    )
    parser.add_argument("--version", action="version", version=f"bayesfo {__version__}")
    parser.add_argument("--models", action="append", default=[], metavar="PATH",
                        help="extra structure card (.toml) or directory of cards; repeatable")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("inspect", help="read and check a data file; show what it holds")
    _add_data_options(p)
    p.add_argument("--structures", default=None,
                   help="comma list of structures to check the data against (e.g. voigt,zener,max3)")
    p.add_argument("--holdout", default=None, metavar="W1,W2",
                   help="angular frequencies [rad/s] to hold out for validation")
    p.add_argument("--json", action="store_true", help="print JSON")

    p = sub.add_parser("compare", help="posteriors and criteria of several structures on one data set")
    _add_data_options(p)
    p.add_argument("--structures", default=DEFAULT_STRUCTURES,
                   help=f"comma list, with shortcuts maxN and all (default {DEFAULT_STRUCTURES})")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="output directory (default: bayesfo-<data name>)")
    p.add_argument("--noise", default="auto", choices=("auto", "known", "constant", "proportional"),
                   help="noise model (default: known if the data give sigma, else relative or constant)")
    p.add_argument("--prior", action="append", default=[], metavar="NAME=TYPE:A:B",
                   help="override a prior, e.g. q=uniform:0.2:1 or sigma_rel=log-uniform:1e-4:0.1")
    p.add_argument("--seed", type=batch.seed_argument, default=0)
    p.add_argument("--holdout", default=None, metavar="W1,W2",
                   help="angular frequencies [rad/s] left out of the fit for validation")
    p.add_argument("--evidence", default="auto", choices=batch.EVIDENCE_ROUTES,
                   help="ln Z by bridge sampling from the emcee draws (bridge) or from a tempered "
                        "ladder (ladder); auto: the ladder where the posterior did not converge")
    p.add_argument("--evidence-check", action="store_true",
                   help="also compute ln Z by dynesty nested sampling and flag disagreements")
    p.add_argument("--workers", type=int, default=0, metavar="N",
                   help="processes running structures side by side and then drawing the figures "
                        "(default 0: one per CPU); the numbers do not depend on it")
    p.add_argument("--no-figures", action="store_true",
                   help="skip the figures and report.html (faster; summary, table and NetCDF only)")
    p.add_argument("--quiet", action="store_true", help="no progress bar or table")

    p = sub.add_parser("identify", help="deterministic fit of one structure (methods 1-5 or optimisation)")
    _add_data_options(p)
    p.add_argument("--structure", required=True,
                   help="structure name (e.g. zener, max-n2m1) or a list/shortcut such as max3 "
                        "for the max-order loop")
    p.add_argument("--method", default="opt", choices=("1", "2", "3", "4", "5", "opt"),
                   help="linear method of thesis Table 3.1, or global optimisation (default)")
    p.add_argument("--q", type=float, default=None,
                   help="fix the commensurate order (default: q-grid scan / optimised)")
    p.add_argument("--seed", type=batch.seed_argument, default=0, help="seed of the optimiser's random starts")
    p.add_argument("--json", action="store_true", help="print JSON")

    p = sub.add_parser("simulate", help="thesis Monte Carlo studies beside the printed tables")
    p.add_argument("study", metavar="STUDY", help="table-3.2, table-a.1, table-a.3, table-3.4, table-a.5, table-a.7, figure-3.2")
    p.add_argument("--runs", type=int, default=None, help="noisy realisations (default: as in the thesis)")
    p.add_argument("--seed", type=batch.seed_argument, default=0)
    p.add_argument("--figure", metavar="FILE", help="figure-3.2: write the RMSE surface (.png, .pdf)")
    p.add_argument("--json", action="store_true", help="print JSON")

    p = sub.add_parser("structures", help="list the available structures with priors")
    p.add_argument("--json", action="store_true", help="print JSON")

    p = sub.add_parser("extract", help="sine records (one per frequency) -> frequency response CSV")
    p.add_argument("records", nargs="+", metavar="RECORD",
                   help="CSV with time,input,output[,series] and '# omega:' or '# freq:'")
    p.add_argument("--out", required=True, metavar="FILE.csv", help="output CSV")
    p.add_argument("--kind", choices=("compliance", "modulus", "generic"), default="generic")
    p.add_argument("--harmonics", type=int, default=5, help="highest harmonic reported (default 5)")
    p.add_argument("--threshold", type=float, default=0.05,
                   help="harmonic ratio above which a record is flagged as nonlinear (default 0.05)")
    batch.add_parser(sub)
    return parser


def _read(args):
    from .data import read_csv

    data = read_csv(args.data, kind=args.kind)
    if args.reciprocal:
        data = data.reciprocal()
    return data


def _library(args):
    from .structures import default_library, load_library

    return load_library(extra=args.models) if args.models else default_library()


def _parse_floats(text: str, option: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"{option} takes comma-separated numbers, got {text!r}") from None


def cmd_inspect(args) -> int:
    from .structures import resolve_structures

    data = _read(args)
    info = data.to_dict()
    info.update(
        omega_ref=data.omega_ref,
        g_ref=data.g_ref,
        magnitude_min=float(data.magnitude.min()),
        magnitude_max=float(data.magnitude.max()),
    )
    if args.holdout:
        train, test = data.split(_parse_floats(args.holdout, "--holdout"))
        info["holdout"] = test.omega.tolist()
        data = train
    if args.structures:
        structures = resolve_structures(args.structures, _library(args))
        for s in structures:
            s.check_data(data)
        info["structures"] = {s.name: s.n_params for s in structures}
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    print(f"{info['name']}: {info['n_frequencies']} frequencies, "
          f"{info['omega_min']:.4g} to {info['omega_max']:.4g} rad/s, kind {info['kind']}"
          + (f", units {info['units']}" if info["units"] else ""))
    print(f"|G| from {info['magnitude_min']:.4g} to {info['magnitude_max']:.4g}; "
          f"scaling omega_ref = {info['omega_ref']:.4g} rad/s, g_ref = {info['g_ref']:.4g}")
    print("sigma: " + ("given per point" if info["has_sigma"] else "not given (estimated when fitting)"))
    bad = info["dissipation_violations"]
    if bad:
        print(f"warning: {len(bad)} point(s) with negative loss, impossible for a passive "
              f"{info['kind']}: omega = " + ", ".join(f"{w:.4g}" for w in bad) + " rad/s")
    for note in info["notes"]:
        print(f"note: {note}")
    if "holdout" in info:
        print("held out: " + ", ".join(f"{w:.4g}" for w in info["holdout"]) + " rad/s")
    if "structures" in info:
        print("structures (parameters): "
              + ", ".join(f"{k} ({v})" for k, v in info["structures"].items()))
    return 0


def cmd_structures(args) -> int:
    library = _library(args)
    if args.json:
        print(json.dumps([s.describe() for s in library.values()], indent=2))
        return 0
    width = max(len(n) for n in library)
    for s in library.values():
        priors = ", ".join(f"{p.name}~{p.prior.describe()}" for p in s.parameters)
        print(f"{s.name:<{width}}  {s.formula}")
        print(f"{'':<{width}}  priors: {priors}")
    return 0


def cmd_extract(args) -> int:
    from .timeseries import extract_frequency_response, write_extraction

    if args.harmonics < 2:
        raise InputError(f"--harmonics must be at least 2, got {args.harmonics}")
    if not args.threshold > 0:
        raise InputError(f"--threshold must be positive, got {args.threshold}")
    fr, analyses = extract_frequency_response(
        args.records, kind=args.kind, n_harmonics=args.harmonics,
        nonlinearity_threshold=args.threshold,
    )
    write_extraction(args.out, fr, analyses)
    print(f"{'omega [rad/s]':>14} {'gain':>12} {'phase [deg]':>12} {'THD':>8}  linear")
    for a in analyses:
        print(f"{a.omega:14.6g} {a.gain:12.6g} {a.phase_deg:12.4f} {a.thd_output:8.4f}  "
              + ("no" if a.nonlinear else "yes"))
    print(f"wrote {args.out}")
    return 0


def _parse_priors(specs) -> dict:
    from .priors import prior_from_dict

    out = {}
    for spec in specs:
        name, _, rest = spec.partition("=")
        parts = rest.split(":")
        if not name or len(parts) != 3:
            raise InputError(f"--prior takes NAME=TYPE:A:B (e.g. q=uniform:0.2:1), got {spec!r}")
        kind, a, b = parts
        keys = ("mu", "sd") if kind == "normal" else ("low", "high")
        try:
            values = {keys[0]: float(a), keys[1]: float(b)}
        except ValueError:
            raise InputError(f"--prior {spec!r}: the bounds must be numbers") from None
        if name.strip() in out:
            raise InputError(f"--prior {spec!r}: a prior for '{name.strip()}' is already given; "
                             "give one --prior per parameter")
        out[name.strip()] = prior_from_dict({"prior": kind, **values}, f"--prior {spec!r}")
    return out


def _num(x, fmt: str = ".2f") -> str:
    """A number for the terminal table; '-' for one that is undefined (its reason is among
    the warnings)."""
    return format(x, fmt) if x is not None and np.isfinite(x) else "-"


def cmd_compare(args) -> int:
    from .compare import available_cpus, compare, process_pool, write_outputs
    from .outdir import check_output_directory
    from .structures import resolve_structures

    data = _read(args)
    structures = resolve_structures(args.structures, _library(args))
    priors = _parse_priors(args.prior)
    known = {p for s in structures for p in s.param_names} | {"sigma", "sigma_rel"}
    unknown = [k for k in priors if k not in known]
    if unknown:
        raise InputError(f"--prior names '{unknown[0]}', which no selected structure has")
    out = check_output_directory(args.out if args.out else f"bayesfo-{Path(args.data).stem}")
    progress = not args.quiet and sys.stderr.isatty()
    holdout = _parse_floats(args.holdout, "--holdout") if args.holdout else None
    options = dict(noise=args.noise, seed=args.seed, priors=priors, progress=progress,
                   evidence=args.evidence, evidence_check=args.evidence_check, holdout=holdout)
    if args.workers < 0:
        raise InputError(f"--workers must be 0 (one per CPU) or a positive number, got {args.workers}")
    n_proc = min(args.workers or available_cpus(), len(structures))
    if n_proc > 1:
        # One pool for the structures and then the figures: its processes have the libraries
        # loaded by the time they draw.
        with process_pool(n_proc) as pool:
            result = compare(data, structures, pool=pool, **options)
            write_outputs(result, out, figures=not args.no_figures, pool=pool)
    else:
        result = compare(data, structures, workers=1, **options)
        write_outputs(result, out, figures=not args.no_figures)
    if not args.quiet:
        n_fit = result.data.n_frequencies
        held = "" if result.holdout is None else f" ({result.holdout.n_frequencies} more held out)"
        print(f"{data.label}: {n_fit} frequencies fitted{held}, kind {data.kind}; ranked by "
              "log-evidence ln Z (bridge sampling; L: from a tempered ladder); P = posterior probability, equal prior odds")
        print(f"{'#':>2} {'structure':<16} {'k':>2} {'ln Z':>18} {'dlnZ':>8} {'P':>6} "
              f"{'elpd_loo':>10} {'BIC':>10} {'q (sd)':>16} {'R-hat':>6} {'ok':>3}")
        for row in result.table():
            if row.get("error"):
                print(f"{'-':>2} {row['structure']:<16} {row['n_params']:>2}  skipped: {row['error']}")
                continue
            q = "" if row["q_mean"] is None else f"{row['q_mean']:.3f} ({row['q_sd']:.3f})"
            if row["log_evidence"] is None:
                z = dz = p = "-"
            else:
                z = f"{row['log_evidence']:.2f} ± {row['log_evidence_err']:.2f}"
                z += " L" if row["evidence_method"] == "ladder" else "  "
                dz = f"{row['delta_log_evidence']:.2f}"
                p = f"{row['posterior_probability']:.3f}"
            print(f"{row['rank']:>2} {row['structure']:<16} {row['n_params']:>2} {z:>18} {dz:>8} "
                  f"{p:>6} {_num(row['loo']):>10} {_num(row['bic']):>10} {q:>16} "
                  f"{_num(row['rhat_max'], '.3f'):>6} {'yes' if row['converged'] else 'NO':>3}")
        pairs = result.baselines()
        if pairs:
            print("integer baselines (q = 1) against their fractional parents:")
            for b in pairs:
                if b["delta_log_evidence"] is None:
                    continue
                d = b["delta_log_evidence"]
                verdict = "fractional order favoured" if d > 0 else "integer order favoured"
                hdi = ""
                if b["order"] is not None:
                    lo, hi = b["order_hdi"]
                    hdi = (f"; {b['order']} of {b['parent']} in [{lo:.3f}, {hi:.3f}] (94 % HDI"
                           f"{', includes 1' if b['order_hdi_includes_1'] else ''})")
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


def cmd_identify(args) -> int:
    from .identify import identify

    from .structures import resolve_structures

    data = _read(args)
    structures = resolve_structures(args.structure, _library(args))
    if len(structures) > 1:
        return _identify_loop(args, data, structures)
    structure = structures[0]
    result = identify(data, structure, method=args.method, q=args.q, seed=args.seed)
    if args.json:
        print(json.dumps(result, indent=2))
        return 0
    print(f"{result['structure']} by method {result['method']} on {data.label}: "
          f"{structure.formula}")
    for name, value in result["parameters"].items():
        print(f"  {name:>6} = {value:.6g}")
    print(f"  RMSE = {result['rmse']:.4g} (eq. 3.23), stable: {'yes' if result['stable'] else 'no'}")
    if result.get("rejected_unstable_q"):
        print(f"  q values rejected as unstable: {len(result['rejected_unstable_q'])} of the grid")
    return 0


def _identify_loop(args, data, structures) -> int:
    """The max-order loop of thesis §4.3.2: every member, and the one with the lowest RMSE."""
    from .identify import identify

    results, skipped = [], {}
    for s in structures:
        try:
            results.append(identify(data, s, method=args.method, q=args.q, seed=args.seed))
        except InputError as exc:
            skipped[s.name] = str(exc)
    if not results:
        raise InputError("; ".join(f"{k}: {v}" for k, v in skipped.items()))
    best = min(results, key=lambda r: r["rmse"])["structure"]
    if args.json:
        print(json.dumps({"structures": results, "skipped": skipped, "best_by_rmse": best}, indent=2))
        return 0
    print(f"{'structure':<16} {'q':>6} {'RMSE':>11}  stable")
    for r in results:
        q = "" if r["q"] is None else f"{r['q']:.3f}"
        print(f"{r['structure']:<16} {q:>6} {r['rmse']:>11.4g}  {'yes' if r['stable'] else 'no'}")
    for name, why in skipped.items():
        print(f"{name:<16} skipped: {why}")
    print(f"lowest RMSE: {best} (the thesis' choice; it favours the largest members: "
          "compare them with `bayesfo compare` for a penalised ranking)")
    return 0


def cmd_simulate(args) -> int:
    from .studies import rmse_surface, run_study

    if args.study == "figure-3.2":
        runs = 1 if args.runs is None else args.runs
        if runs < 1:
            raise InputError(f"--runs must be at least 1, got {runs}")
        surface = rmse_surface(runs=runs, seed=args.seed)
        if args.figure:
            from .plotting import plot_rmse_surface, save_figure

            mesh = plot_rmse_surface(surface)
            save_figure(mesh.axes.figure, args.figure)
        if args.json:
            print(json.dumps(surface))
        else:
            z = np.asarray(surface["rmse"])
            for s_, row in zip(surface["sigma"], z):
                k = int(np.argmin(row))
                print(f"sigma = {s_:.4f}: minimum RMSE {row[k]:.4g} at q = {surface['q'][k]:.2f}")
            if args.figure:
                print(f"wrote {args.figure}")
        return 0
    if args.figure:
        raise InputError("--figure applies to figure-3.2 only")
    result = run_study(args.study, runs=args.runs, seed=args.seed)
    if args.json:
        print(json.dumps(result, indent=2))
        return 0
    print(f"{result['study']}: {result['runs']} runs, seed {result['seed']} (thesis values in brackets)")
    for key, row in result["methods"].items():
        th = result["thesis"].get(key, {})
        print(f"method {key}")
        for field in ("mean_a", "var_a", "mean_b", "var_b", "mean_q", "var_q", "rmse_spec",
                      "var_rmse_spec", "rmse_noise", "var_rmse_noise"):
            ours = np.atleast_1d(row[field])
            text = " ".join(f"{v:.4g}" for v in ours)
            if field in th:
                text += "   [" + " ".join(f"{v:.4g}" for v in np.atleast_1d(th[field])) + "]"
            print(f"  {field:<15} {text}")
    return 0


COMMANDS = {
    "batch": batch.cmd_batch,
    "compare": cmd_compare,
    "inspect": cmd_inspect,
    "structures": cmd_structures,
    "extract": cmd_extract,
    "identify": cmd_identify,
    "simulate": cmd_simulate,
}


def _one_line_warning(message, category, filename, lineno, file=None, line=None):
    print(f"bayesfo: warning: {message}", file=sys.stderr)


class Terminated(BaseException):
    """SIGTERM arrived: unwinds like Ctrl-C, so that outputs are left as they were and worker
    processes are ended."""


def _on_sigterm(signum, frame):
    raise Terminated


def main(argv=None) -> int:
    """Run the command line; returns the exit status."""
    import signal
    import threading

    parser = build_parser()
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        args = parser.parse_args(argv)
        if args.command is None:
            parser.print_help()
            return 2
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.showwarning = _one_line_warning
            return COMMANDS[args.command](args)
    except InputError as exc:
        print(f"bayesfo: error: {exc}", file=sys.stderr)
        return 2
    except OutputError as exc:
        print(f"bayesfo: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("bayesfo: interrupted (no output is left half-written)",
              file=sys.stderr)
        return 130
    except Terminated:
        print("bayesfo: terminated (no output is left half-written)",
              file=sys.stderr)
        return 143
    except Exception as exc:  # the contract: exit 1 on internal errors, no traceback by default
        if os.environ.get("BAYESFO_DEBUG"):
            raise
        print(f"bayesfo: internal error: {type(exc).__name__}: {exc} "
              "(set BAYESFO_DEBUG=1 for a traceback)", file=sys.stderr)
        return 1
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
