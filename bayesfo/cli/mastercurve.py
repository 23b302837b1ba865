"""``bayesfo mastercurve``: time–temperature superposition of isotherms as one posterior."""

from __future__ import annotations

import json
import math
from pathlib import Path

from ..errors import InputError

#: The files of a directory that are read as isotherms (lab exports, RepTate's .osc and
#: .tts, spreadsheets).
DIRECTORY_SUFFIXES = (".csv", ".txt", ".tsv", ".dat", ".osc", ".tts", ".xls", ".xlsx")
#: Master structures ranked by default: a few seconds each on 20 isotherms.
DEFAULT_STRUCTURES = "zener,max-n2m1,fractional_zener_ll"


def add_parser(subparsers):
    """Register ``bayesfo mastercurve``."""
    from ._common import add_column_options

    p = subparsers.add_parser(
        "mastercurve", help="master curve of isotherms: shift factors, WLF/Arrhenius laws and "
                            "the master structure, in one posterior",
        description="Fit one master structure and every isotherm's shift log10 a_T jointly "
                    "(a certified posterior, as compare computes it), fit the WLF and "
                    "Arrhenius laws to the shifts, test whether superposition holds (van "
                    "Gurp–Palmen), and write summary.json, master.csv (the reduced data, which "
                    "'bayesfo compare' reads), the joint posterior (STRUCTURE.nc, which "
                    "'bayesfo predict' and 'bayesfo export' read), report.html, "
                    "figures/mastercurve.png, figures/residuals.png (each isotherm's misfit) "
                    "and figures/van_gurp_palmen.png.")
    p.add_argument("data", nargs="+", metavar="DATA",
                   help="files of isotherms: a lab export with several (TRIOS steps, a "
                        "temperature column, pyvisco), or one file per temperature (the "
                        "temperature from a '# temperature:' line or the name, e.g. Tp020C.csv), "
                        "or directories of such files")
    p.add_argument("--structures", default=DEFAULT_STRUCTURES, metavar="S,...",
                   help="master structures to rank by ln Z on the joint data (default "
                        f"{DEFAULT_STRUCTURES}; 'bayesfo structures' lists them), and "
                        "'spectrum': a discrete relaxation spectrum with a smoothness prior, "
                        "which needs no structure (slower: minutes on many isotherms)")
    p.add_argument("--temperatures", default=None, metavar="T1,T2,...",
                   help="the temperature [°C] of each file, in the order given (a directory's "
                        "files in name order), where the files do not say it; one file per "
                        "temperature")
    p.add_argument("--reference-temperature", type=float, default=None, metavar="T",
                   help="reference temperature [°C], an isotherm's (default: the middle one)")
    p.add_argument("--noise", default="auto",
                   choices=("auto", "relative_parts", "proportional", "constant", "known"),
                   help="noise model: auto (default: relative noise of each part, a "
                        "rheometer's, or noise proportional to |G*|, whichever the model-free "
                        "master's ln Z prefers; with --shifts joint, proportional), "
                        "relative_parts, proportional, constant, known (the data's sigma)")
    p.add_argument("--vertical", default="auto", choices=("auto", "none", "density", "free"),
                   help="vertical shift b_T: auto (default: the one of highest ln Z of the "
                        "model-free master among the three; with --shifts joint, none); none; "
                        "density: b_T = T_ref/T in kelvin (constant density); free: one "
                        "log10 b_T per isotherm")
    p.add_argument("--shifts", default="smooth", choices=("smooth", "joint"),
                   help="where the shifts come from: smooth (default: a model-free master, "
                        "smooth curves of ln G′ and ln G″ integrated out, so that no "
                        "structure's misfit moves them; the structures are then fitted to the "
                        "isotherms so shifted), joint (sampled with each master structure)")
    p.add_argument("--law", default="auto", choices=("auto", "free", "wlf", "arrhenius"),
                   help="horizontal shifts: auto (default: free shifts, then the best master "
                        "structure with the WLF and the Arrhenius law inside the joint "
                        "posterior, the highest ln Z kept), free (one log10 a_T per isotherm), "
                        "wlf or arrhenius (the law's parameters sampled)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--workers", type=int, default=0, metavar="N",
                   help="processes fitting the master structures, then the shift laws, side by "
                        "side (default 0: one per CPU; 1: one after the other here); the "
                        "numbers do not depend on it")
    add_column_options(p)
    p.add_argument("--out", default=None, metavar="DIR",
                   help="output directory (default bayesfo-mastercurve)")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.add_argument("--json", action="store_true", help="print summary.json's shift block")
    return p


def read_isotherm_files(paths, temperatures=None, columns=None) -> list[tuple]:
    """(FrequencyResponse, temperature) of every isotherm in ``paths`` (files, or directories
    of data files, :data:`DIRECTORY_SUFFIXES`); ``temperatures`` (°C, one per file in that order) where the files do not
    say them; ``columns`` (``{role: column}``, :func:`~bayesfo.data.columns_from_text`) for
    every file, as ``--columns`` of ``compare``."""
    from ..data import read_isotherms
    from ..data.temperature import temperature_of_file

    files = []
    for p in map(Path, paths):
        if p.is_dir():
            found = sorted(f for f in p.iterdir()
                           if f.is_file() and f.suffix.lower() in DIRECTORY_SUFFIXES)
            if not found:
                raise InputError(f"'{p}': a directory without data files ("
                                 + ", ".join(f"*{x}" for x in DIRECTORY_SUFFIXES) + ")")
            files.extend(found)
        elif p.is_file():
            files.append(p)
        else:
            raise InputError(f"'{p}': no such file or directory")
    if temperatures is not None and len(temperatures) != len(files):
        raise InputError(f"--temperatures gives {len(temperatures)} temperature(s) for "
                         f"{len(files)} file(s) ({', '.join(f.name for f in files)}): give one "
                         "per file, in that order")
    out = []
    for k, f in enumerate(files):
        sets = read_isotherms(f, columns=columns)
        if temperatures is not None:
            if len(sets) != 1:
                raise InputError(f"'{f}' holds {len(sets)} data sets: --temperatures gives "
                                 "one temperature per file (leave it out for a file that "
                                 "names its temperatures)")
            own = (sets[0].temperature if sets[0].temperature is not None
                   else temperature_of_file(f))
            if own is not None and not math.isclose(own, temperatures[k], abs_tol=1e-9):
                raise InputError(f"'{f}' says {own:g} °C, --temperatures gives "
                                 f"{temperatures[k]:g} °C for it: correct one of them")
            out.append((sets[0].data, temperatures[k]))
        elif len(sets) == 1 and sets[0].temperature is None:
            t = temperature_of_file(f)
            if t is None:
                raise InputError(f"'{f}': no temperature (give a '# temperature: 20 C' line, "
                                 "name the file by it, e.g. Tp020C.csv, or give "
                                 "--temperatures T1,T2,... for the files in order)")
            out.append((sets[0].data, t))
        else:
            for s in sets:
                if s.temperature is None:
                    raise InputError(f"'{f}', data set {s.label!r}: no temperature")
                out.append((s.data, s.temperature))
    return out


def run(args) -> int:
    from ..data import columns_from_text
    from ..options import parse_floats
    from ..outdir import check_output_directory
    from ..output import write_mastercurve
    from ..parallel import check_workers
    from ..tts import mastercurve
    from ..tts.joint import master_names
    from ._libraries import load_libraries

    check_workers(args.workers)
    structures = master_names(args.structures)  # an unknown name fails before reading
    temperatures = (parse_floats(args.temperatures, "--temperatures")
                    if args.temperatures is not None else None)
    isotherms = read_isotherm_files(args.data, temperatures, columns_from_text(args.columns))
    target = Path(args.out or "bayesfo-mastercurve")
    out = check_output_directory(target, directories=() if args.no_figures else ("figures",))
    load_libraries(() if args.no_figures else ("png",))
    mc = mastercurve(isotherms, structures, reference_temperature=args.reference_temperature,
                     noise=args.noise, vertical=args.vertical, law=args.law,
                     shifts=args.shifts, seed=args.seed, workers=args.workers)
    written = write_mastercurve(mc, out, figures=not args.no_figures)
    if args.json:
        summary = json.loads(written["summary.json"].read_text())
        print(json.dumps({k: summary[k] for k in ("shift_factors", "shift_law")}, indent=1,
                         ensure_ascii=False))
        return 0
    _print(mc, out)
    return 0


def _print(mc, out) -> None:
    smooth = mc.shifts_from == "smooth"
    print(f"{mc.data.label}: master structures ranked by ln Z "
          + ("on the isotherms at the model-free master's shifts" if smooth
             else "of the joint posterior"))
    for r in mc.ranking:
        z = "-" if r["log_evidence"] is None else (f"{r['log_evidence']:.2f} ± "
                                                    f"{r['log_evidence_err']:.2f}")
        p = "-" if r["probability"] is None else f"{r['probability']:.3f}"
        if r.get("dropped"):
            print(f"   {r['structure']:<22} dropped: {r['dropped']}")
            continue
        if r.get("log_evidence_upper") is not None:
            p = "-" if r["probability"] is None else f"≤ {r['probability']:.1e}"
            print(f"   {r['structure']:<22} ln Z "
                  f"{'≤ ' + format(r['log_evidence_upper'], '.2f'):>20}  P {p}  not sampled "
                  "(its best fit bounds ln Z)")
            continue
        print(f"   {r['structure']:<22} ln Z {z:>20}  P {p:>6}  "
              f"{'certified' if r['certified'] else 'NOT certified'} ({r['sampler']})")
    for title, evidence in (("vertical shifts", mc.vertical_evidence),
                            ("horizontal shifts", mc.law_evidence)):
        if not evidence:
            continue
        print(f"{title} ranked by ln Z "
              + ("of the model-free master" if smooth
                 else f"of {mc.structure} (free, or by a law inside the posterior)"))
        for how, r in sorted(evidence.items(),
                             key=lambda kv: -(kv[1]["log_evidence"]
                                              or kv[1].get("log_evidence_upper") or -math.inf)):
            if r.get("log_evidence_upper") is not None:  # not sampled: bounded from above
                print(f"   {how:<22} ln Z {'≤ ' + format(r['log_evidence_upper'], '.2f'):>20}  "
                      f"P ≤ {r['probability']:.1e}  not sampled (its best fit bounds ln Z)")
                continue
            z = "-" if r["log_evidence"] is None else (f"{r['log_evidence']:.2f} ± "
                                                        f"{r['log_evidence_err']:.2f}")
            p = "-" if r["probability"] is None else f"{r['probability']:.3f}"
            print(f"   {how:<22} ln Z {z:>20}  P {p:>6}  "
                  f"{'certified' if r['certified'] else 'NOT certified'} ({r['sampler']})")
    shifts = {"free": "", "wlf": " (WLF)", "arrhenius": " (Arrhenius)"}[mc.law]
    print(f"shift factors{shifts} "
          + ("of the model-free master" if smooth else f"of {mc.structure}")
          + f", T_ref = {mc.reference_temperature:g} °C:")
    vertical = mc.vertical != "none"
    print(f"{'T [°C]':>8} {'log10 a_T':>10} {'sd':>7} {'94 % HDI':>20}"
          + (f" {'log10 b_T':>10} {'sd':>7} {'94 % HDI':>20} ({mc.vertical})" if vertical
             else ""))
    gone = set((mc.shift_evidence or {}).get("undetermined") or [])
    for f in mc.shift_factors():
        line = f"{f['temperature']:8g}"
        for key in ("log10_aT", "log10_bT") if vertical else ("log10_aT",):
            # Rounded, then + 0.0: the reference's shift under a law, -1e-17 to rounding, is
            # printed as 0.000, not -0.000.
            a = {k: round(f[key][k], 3) + 0.0 for k in ("mean", "sd", "hdi_low", "hdi_high")}
            hdi = f"[{a['hdi_low']:.3f}, {a['hdi_high']:.3f}]"
            line += f" {a['mean']:10.3f} {a['sd']:7.3f} {hdi:>20}"
        if f["temperature"] in gone:
            line += "  not determined: slides along a featureless stretch"
        print(line)
    for name, law in mc.laws.items():
        text = ", ".join(f"{k} = {v['mean']:.4g} ± {v['sd']:.2g} {v['unit']}".rstrip()
                         for k, v in law["parameters"].items())
        untested = ("; as many constants as free shifts: not tested by them"
                    if law.get("dof", 1) <= 0 else "")
        prob = law.get("probability")
        prob = ("-" if prob is None else f"≤ {prob:.1e}" if law.get("probability_upper")
                else f"{prob:.3f}")
        left = law.get("left_out") or []
        left = (f"; fitted without {', '.join(f'{t:g}' for t in left)} °C (shift not "
                "determined)" if left else "")
        print(f"{name:>10}: {text}; probability {prob}{untested}{left}")
    from ..tts.validity import describe, describe_parts

    vgp = mc.tts_checks.get("van_gurp_palmen")
    if vgp is not None and vgp["valid"]:
        print(describe(vgp))  # a failing or untested test is among the notes
    parts = mc.tts_checks.get("shift_parts")
    if parts is not None and parts["consistent"]:
        print(describe_parts(parts))
    for n in mc.notes:
        print(f"note: {n}")
    _print_cautions(mc)
    print(f"wrote {out}/summary.json, master.csv, {mc.structure}.nc" + (
        "" if not (out / "figures").exists()
        else ", report.html and figures/mastercurve.png, figures/residuals.png, "
             "figures/van_gurp_palmen.png"))


def _print_cautions(mc) -> None:
    """What the report's verdict cautions about beyond the lines above: whether the master
    function describes the isotherms, and the overall answer on superposition where the tests
    part (``summary.json``'s ``tts_valid``)."""
    text = mc.misfit()
    if text:
        print(f"caution: {text}")
    vgp = mc.tts_checks.get("van_gurp_palmen") or {}
    if mc.tts_valid is False and vgp.get("valid"):
        print("superposition not established (tts_valid false in summary.json): the van "
              "Gurp–Palmen test passes, but the shifts of G′, G″ and tan δ disagree (the note "
              "above); --vertical free lets the isotherms shift vertically too")
