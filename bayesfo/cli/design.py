"""``bayesfo design``: the frequencies to measure next to settle a comparison's model choice."""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import InputError


def add_parser(subparsers):
    """Register ``bayesfo design``."""
    p = subparsers.add_parser(
        "design", help="where to measure next: the frequencies that would best tell the "
                       "structures of a comparison apart",
        description="Score candidate frequencies in the instrument window by the expected "
                    "information about which structure is right (the mutual information "
                    "between the structure and one more measurement, under each structure's "
                    "posterior predictive and the current model probabilities), propose the "
                    "best points, and state what they would do to the leading structures' log "
                    "Bayes factor. Where every structure considered fails the posterior "
                    "predictive checks, it says so and proposes instead the frequencies that "
                    "best determine the best ranked structure's parameters together.")
    p.add_argument("directory", metavar="DIR", help="output directory of bayesfo compare")
    p.add_argument("--window", metavar="WMIN,WMAX", default=None,
                   help="the instrument's frequency window [rad/s] (default: the data's, a "
                        "decade wider on each side)")
    p.add_argument("--points", type=int, default=3, metavar="N",
                   help="how many frequencies to propose (default 3)")
    p.add_argument("--structures", default=None, metavar="S,...",
                   help="the structures to tell apart (default: those that could still win)")
    p.add_argument("--cost", default="uniform", choices=("uniform", "low-frequency"),
                   help="low-frequency: choose by information per second of measuring time "
                        "(10 s plus three periods per point)")
    p.add_argument("--parameter", metavar="NAME", default=None,
                   help="instead of the model choice, the frequencies that best determine this "
                        "parameter (e.g. alpha) of the best ranked structure, or of the one "
                        "--structures names")
    p.add_argument("--figure", metavar="FILE.png", default=None,
                   help="draw the predictions over the window with the proposed points")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--json", action="store_true", help="print the design as JSON")
    return p


def run(args) -> int:
    import numpy as np

    from ..comparison import load
    from ..options import parse_floats
    from ..planning import design
    from ..tts import MasterCurve

    window = None
    if args.window is not None:
        window = parse_floats(args.window, "--window")
        if len(window) != 2:
            raise InputError(f"--window takes WMIN,WMAX, got {args.window!r}")
    figure = None
    if args.figure is not None:
        figure = Path(args.figure)
        if figure.suffix.lower().lstrip(".") not in ("png", "pdf", "svg"):
            raise InputError(f"--figure {args.figure}: give a .png, .pdf or .svg file name")
        if not figure.parent.is_dir():
            raise InputError(f"--figure {args.figure}: directory '{figure.parent}' does not "
                             "exist")
        if figure.is_dir():
            raise InputError(f"--figure {args.figure}: is a directory; give a file name in "
                             "it (e.g. design.png)")
    result = load(args.directory, models=getattr(args, "models", ()) or ())
    if isinstance(result, MasterCurve):
        raise InputError(f"'{args.directory}' holds a master curve: design chooses frequencies "
                         "between structures of a comparison; run it on a bayesfo compare "
                         "directory (e.g. of the master curve's master.csv)")
    structures = None if args.structures is None else [
        s.strip() for s in args.structures.split(",") if s.strip()]
    if args.parameter is not None:
        return _parameter(result, args, window, structures)
    from ..planning import all_inadequate

    failing = all_inadequate(result, structures)
    if failing:
        why = None if figure is None else _unwritable(figure)
        if why is not None:
            raise InputError(f"--figure '{args.figure}': cannot be written ({why}); give a "
                             "file in a writable folder")
        if args.figure is not None:
            raise InputError(f"--figure draws the design of the model choice, and every "
                             f"structure considered ({', '.join(failing)}) fails the posterior "
                             "predictive checks; leave it out (design then plans for the best "
                             "one's parameters)")
        note = (f"every structure considered ({', '.join(failing)}) fails the posterior "
                "predictive checks: points that tell them apart would choose among "
                "descriptions that all miss the data, so these are the frequencies that best "
                f"determine the parameters of the best ranked, {failing[0]}, together (a "
                "structure that describes the data is wanted first)")
        return _parameter(result, args, window, [failing[0]], notes=(note,))
    try:
        plan = design(result, window=window, points=args.points, structures=structures,
                      cost=args.cost, seed=args.seed)
    except np.linalg.LinAlgError as exc:
        raise InputError(f"the design's linear algebra failed ({exc}): the predictions over "
                         "the window are degenerate; give a narrower --window or other "
                         "--structures") from None
    if figure is not None:
        from .._io import write_error
        from ..plotting.design import plot_design
        from ..plotting.output import save_figure

        try:
            save_figure(plot_design(result, plan, seed=args.seed).figure, figure, close=True,
                        named=True)
        except OSError as exc:
            raise InputError(f"--figure '{args.figure}': cannot be written "
                             f"({write_error(figure, exc)}); give a file in a writable "
                             "folder") from None
    if args.json:
        print(json.dumps(plan.to_dict(), indent=1))
        return 0
    _print(plan, figure)
    return 0


def _unwritable(path: Path) -> str | None:
    """Why no file can be written at ``path`` (None where one can): a file made there and
    removed again, or an existing one opened for appending and left as it was."""
    from .._io import write_error

    try:
        if path.exists():
            with open(path, "ab"):
                pass
        else:
            with open(path, "xb"):
                pass
            path.unlink()
    except OSError as exc:
        return write_error(path, exc)
    return None


def _print(plan, figure) -> None:
    names = ", ".join(f"{n} (P {p:.3f})" for n, p in zip(plan.structures, plan.probabilities,
                                                           strict=True))
    print(f"telling apart {names}: {plan.entropy:.3f} nats of information still missing")
    print(f"window {plan.window[0]:.4g}-{plan.window[1]:.4g} rad/s; proposed measurements "
          + ("(by information per second of measuring time)" if plan.cost == "low-frequency"
             else "(by information)") + ":")
    print(f"{'#':>3} {'omega [rad/s]':>14} {'gain [nats]':>12} {'total [nats]':>13} "
          f"{'time [s]':>9}")
    for i, p in enumerate(plan.proposed):
        print(f"{i + 1:>3} {p['omega']:14.4g} {p['gain']:12.3f} {p['information']:13.3f} "
              f"{p['seconds']:9.0f}")
    total = plan.proposed[-1]["information"]
    others = ", ".join(f"{k} {v:.3f}" for k, v in plan.alternatives.items())
    print(f"{plan.asked} point(s) by rules of thumb give: {others} nats (proposed: "
          f"{total:.3f})")
    a, b = plan.leading
    print(f"{a} against {b}: ln B now {plan.log_bayes_factor:+.2f}; expected change "
          f"{plan.expected_change[a]:+.2f} if {a} is right, {plan.expected_change[b]:+.2f} if "
          f"{b} is; decisive afterwards (|ln B| > 4.6) with probability {plan.p_decisive:.2f}")
    for n in plan.notes:
        print(f"note: {n}")
    if figure is not None:
        print(f"wrote {figure}")


def _parameter(result, args, window, structures, notes=()) -> int:
    """``--parameter``: the frequencies that best determine one parameter (or, without it, all
    parameters of the one structure together, with the ``notes`` that say why)."""
    import numpy as np

    from ..planning import design_parameter

    if structures is not None and len(structures) != 1:
        raise InputError("--parameter takes one structure: give --structures S with one name")
    if args.figure is not None:
        raise InputError("--figure draws the design of the model choice; leave it out with "
                         "--parameter")
    try:
        plan = design_parameter(result, args.parameter,
                                structure=structures[0] if structures else None, window=window,
                                points=args.points, cost=args.cost, seed=args.seed,
                                notes=notes)
    except np.linalg.LinAlgError as exc:
        raise InputError(f"the design's linear algebra failed ({exc}): the predictions over "
                         "the window are degenerate; give a narrower --window") from None
    if args.json:
        print(json.dumps(plan.to_dict(), indent=1))
        return 0
    for n in plan.notes:
        print(f"note: {n}")
    if isinstance(plan.sd_now, dict):
        print(f"all parameters of {plan.structure}; posterior sd now: "
              + ", ".join(f"{k} {v:.4g}" for k, v in plan.sd_now.items()))
    else:
        print(f"{plan.parameter} of {plan.structure}: posterior sd now {plan.sd_now:.4g}")
    print(f"window {plan.window[0]:.4g}-{plan.window[1]:.4g} rad/s; proposed measurements:")
    print(f"{'#':>3} {'omega [rad/s]':>14} {'gain [nats]':>12} {'sd after':>11} {'time [s]':>9}")
    for i, p in enumerate(plan.proposed):
        after = p["sd_after"]
        shown = (", ".join(f"{k} {v:.3g}" for k, v in after.items()) if isinstance(after, dict)
                 else f"{after:11.4g}")
        print(f"{i + 1:>3} {p['omega']:14.4g} {p['gain']:12.3f} {shown} {p['seconds']:9.0f}")
    return 0
