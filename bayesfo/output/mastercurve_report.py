"""The report of a master curve (``bayesfo mastercurve``): one self-contained HTML document with
a verdict in words, the isotherms, the master functions ranked, the shift factors, the shift
laws and the figures."""

from __future__ import annotations

import math
from pathlib import Path

from .. import __version__
from .._io import atomic_write_text
from ..comparison.table import number
from ..tts.validity import describe, describe_parts
from .report import CSS, _e, _figures_section, _num

#: Captions of the master curve's figures.
CAPTIONS = {
    "mastercurve": "Storage and loss parts of every isotherm at its posterior mean shift, "
                   "coloured by temperature, with the master function's posterior median and "
                   "94 % band; right: log10 a_T against temperature (94 % HDI) with the WLF "
                   "and Arrhenius laws.",
    "residuals": "Relative residuals of the storage and loss parts of every isotherm under the "
                 "joint fit (each posterior draw's own shifts), against the reduced frequency, "
                 "coloured by temperature; right: each isotherm's rms relative residual, with "
                 "the level above which an isotherm is named as missed.",
    "van_gurp_palmen": "Loss angle against the magnitude of every isotherm, without any shift: "
                       "the isotherms of a thermorheologically simple material fall on one "
                       "curve.",
}
_LAW_NAMES = {"free": "free shifts", "wlf": "the WLF law", "arrhenius": "the Arrhenius law"}


def mastercurve_verdict(mc) -> list[tuple[str, bool]]:
    """Sentences in reading order, each with whether it is a caution: is superposition valid,
    does the master function describe every isotherm, which master function and which shift
    law the evidence supports, and whether the posterior is certified."""
    out: list[tuple[str, bool]] = []
    vgp = mc.tts_checks.get("van_gurp_palmen")
    if vgp is not None:
        text = describe(vgp)
        out.append((text[0].upper() + text[1:] + ".", vgp["valid"] is not True))
    parts = mc.tts_checks.get("shift_parts")
    if parts is not None and parts["consistent"] is not None:
        text = describe_parts(parts)
        out.append((text[0].upper() + text[1:] + ".",
                    not parts["consistent"] and mc.vertical == "none"))
    text = mc.misfit()
    if text:
        out.append((text, True))
    if mc.shifts_from == "smooth":
        out.append(("The shifts come from a model-free master (smooth curves of ln G′ and ln G″ "
                    "against log10 a_T ω, integrated out): no structure's misfit moves them; "
                    "the master functions below are fitted to the isotherms so shifted.", False))
        gone = mc.shift_evidence.get("undetermined") or []
        if gone:
            out.append(("The data do not fix the shift of the isotherm(s) at "
                        + ", ".join(f"{t:g}" for t in gone) + " °C (a featureless stretch of "
                        "the master curve); the shift laws are fitted without them.", True))
    vev = mc.vertical_evidence
    if vev:
        order = sorted((k for k in vev if vev[k]["log_evidence"] is not None),
                       key=lambda k: -vev[k]["log_evidence"])
        if len(order) > 1:
            names = {"none": "no vertical shift", "density": "the density correction "
                     "b_T = T_ref/T", "free": "free vertical shifts"}
            out.append((f"Vertical shifts: {names[order[0]]} (ln Z "
                        f"{vev[order[0]]['log_evidence'] - vev[order[1]]['log_evidence']:.1f} "
                        f"above {names[order[1]]}).", False))
    ranked = [r for r in mc.ranking if r.get("log_evidence") is not None]
    if len(ranked) > 1:
        gap = ranked[0]["log_evidence"] - ranked[1]["log_evidence"]
        out.append((f"Of {len(ranked)} master functions, {ranked[0]['structure']} has the "
                    f"highest ln Z ({ranked[0]['log_evidence']:.2f}), {gap:.1f} above "
                    f"{ranked[1]['structure']}: probability {ranked[0]['probability']:.3f}.",
                    False))
    elif ranked:
        out.append((f"One master function, {ranked[0]['structure']}: ln Z = "
                    f"{ranked[0]['log_evidence']:.2f}.", False))
    aside = [r for r in mc.ranking if r.get("log_evidence_upper") is not None]
    if ranked and aside:
        out.append((", ".join(r["structure"] for r in aside)
                    + f" {'was' if len(aside) == 1 else 'were'} not sampled: the best fit "
                    f"bounds ln Z at least "
                    f"{ranked[0]['log_evidence'] - max(r['log_evidence_upper'] for r in aside):.0f}"
                    f" below {ranked[0]['structure']}'s.", False))
    ev = mc.law_evidence
    if ev:
        order = sorted(ev, key=lambda k: -(ev[k]["log_evidence"] if ev[k]["log_evidence"]
                                           is not None else ev[k].get("log_evidence_upper")
                                           or -math.inf))
        top, second = order[0], order[1]
        z1, z2 = ev[top]["log_evidence"], ev[second]["log_evidence"]
        upper = ev[second].get("log_evidence_upper")
        gap = (f"ln Z {z1 - z2:.1f} above {_LAW_NAMES[second]}" if z2 is not None else
               f"ln Z at least {z1 - upper:.1f} above {_LAW_NAMES[second]}, whose best fit "
               "bounds its ln Z" if upper is not None else
               f"{_LAW_NAMES[second]} gave no certified ln Z")
        if top == "free":
            out.append((f"The shifts follow neither shift law over all isotherms: free shifts "
                        f"are supported ({gap}).", True))
        else:
            out.append((f"The shifts follow {_LAW_NAMES[top]} ({gap}); its parameters were "
                        "sampled with the master function.", False))
    else:
        law = mc.shift_law()
        chi2 = mc.laws[law["name"]]["chi2_per_dof"]
        preferred = (f"Of the two laws fitted to the shifts, {_LAW_NAMES[law['name']]} is "
                     f"preferred (probability {law['probabilities'][law['name']]:.3f})")
        if mc.laws[law["name"]].get("dof", 1) <= 0:
            out.append((f"{preferred}, but with as many constants as free shifts it passes "
                        "through them: the shifts cannot test it (more isotherms would).", True))
        else:
            out.append((f"{preferred}; it misses them by χ²/dof {chi2:.3g}.", chi2 > 4.0))
    if not mc.posterior.converged:
        out.append((f"The {'joint ' if mc.shifts_from == 'joint' else ''}posterior of "
                    f"{mc.structure} is not certified: "
                    f"{'; '.join(mc.posterior.messages)}.", True))
    return out


def _isotherms_table(mc) -> str:
    fit = mc.tts_checks.get("isotherm_fit", {})
    rms = dict(zip(fit.get("temperatures", []), fit.get("rms_relative", []), strict=False))
    rows = "".join(
        f"<tr><td>{t:g}</td><td class='text'>{_e(d.label)}</td><td>{d.n_frequencies}</td>"
        f"<td>{d.omega.min():.3g}–{d.omega.max():.3g}</td>"
        f"<td>{_num(100 * rms[t], '.2f') if t in rms else '–'}</td></tr>"
        for t, d in zip(mc.temperatures, mc.isotherms, strict=True))
    return ("<table><tr><th>T [°C]</th><th class='text'>isotherm</th><th>points</th>"
            "<th>ω [rad/s]</th><th>residual rms [%]</th></tr>" + rows + "</table>")


def _ranking_table(mc) -> str:
    rows = "".join(
        f"<tr><td class='text'>{_e(r['structure'])}</td><td>{_law_log_z(r)}</td>"
        f"<td>{_num(r['log_evidence_err'])}</td><td>{_num(r['probability'], '.3f')}</td>"
        f"<td class='text'>{'yes' if r['certified'] else 'NO'} ({_e(r['sampler'])}"
        f"{': ' + _e(r['dropped']) if r.get('dropped') else ''})</td></tr>"
        for r in mc.ranking)
    return ("<table><tr><th class='text'>master function</th><th>ln Z</th><th>± err</th>"
            "<th>probability</th><th class='text'>certified</th></tr>" + rows + "</table>")


def _shifts_table(mc) -> str:
    vertical = mc.vertical != "none"
    head = ("<tr><th>T [°C]</th><th>log10 a_T</th><th>sd</th><th>94 % HDI</th>"
            + ("<th>log10 b_T</th><th>sd</th>" if vertical else "") + "</tr>")
    rows = []
    for f in mc.shift_factors():
        a, b = f["log10_aT"], f["log10_bT"]
        n = {k: number(v, ".3f") for k, v in a.items()}  # no "-0.000" at the reference
        m = {k: number(v, ".3f") for k, v in b.items()}
        rows.append(f"<tr><td>{f['temperature']:g}</td><td>{n['mean']}</td>"
                    f"<td>{n['sd']}</td><td>[{n['hdi_low']}, {n['hdi_high']}]</td>"
                    + (f"<td>{m['mean']}</td><td>{m['sd']}</td>" if vertical else "")
                    + "</tr>")
    return "<table>" + head + "".join(rows) + "</table>"


def _law_log_z(evidence: dict) -> str:
    """A law's ln Z in the table: the estimate, or '≤ bound' for a law not sampled."""
    if evidence.get("log_evidence") is None and evidence.get("log_evidence_upper") is not None:
        return f"≤ {_num(evidence['log_evidence_upper'])} (not sampled)"
    return _num(evidence.get("log_evidence"))


def _chi2(law: dict) -> str:
    """χ²/dof of a law, or why there is none (no free shift to spare)."""
    if law.get("dof", 1) <= 0:
        return "– (as many constants as shifts)"
    return f"{law['chi2_per_dof']:.3g}"


def _laws_table(mc) -> str:
    rows = []
    for name, law in mc.laws.items():
        params = "; ".join(f"{k} = {v['mean']:.4g} [{v['hdi_low']:.4g}, {v['hdi_high']:.4g}]"
                           f" {v['unit']}".rstrip() for k, v in law["parameters"].items())
        evidence = mc.law_evidence.get(name, {})
        rows.append(f"<tr><td class='text'>{_e(_LAW_NAMES[name])}</td>"
                    f"<td class='text'>{_e(params)}</td><td>{_chi2(law)}</td>"
                    f"<td>{_num(law['probability'], '.3f')}</td>"
                    f"<td>{_law_log_z(evidence)}</td></tr>")
    if "free" in mc.law_evidence:
        rows.append(f"<tr><td class='text'>free shifts</td><td class='text'>one per isotherm"
                    f"</td><td>–</td><td>–</td>"
                    f"<td>{_num(mc.law_evidence['free']['log_evidence'])}</td></tr>")
    return ("<table><tr><th class='text'>law</th><th class='text'>parameters (mean, 94 % HDI)"
            "</th><th>χ²/dof against the shifts</th><th>probability (BIC)</th>"
            "<th>ln Z inside the posterior</th></tr>" + "".join(rows) + "</table>")


def render_mastercurve_report(mc, figures: dict | None = None) -> str:
    """The report of a master curve as one self-contained HTML document (figures embedded from
    their PNG files, ``{name: path}``)."""
    title = f"bayesfo master curve: {mc.data.label}"
    sentences = "".join(f"<p class='flag'>{_e(t)}</p>" if flagged else f"<p>{_e(t)}</p>"
                        for t, flagged in mastercurve_verdict(mc))
    notes = "".join(f"<li>{_e(n)}</li>" for n in mc.notes)
    shifts = {"free": "one free log10 a_T per isotherm", "wlf": "the WLF law's",
              "arrhenius": "the Arrhenius law's"}[mc.law]
    sections = [
        f"<div class='verdict' id='verdict'>{sentences}</div>",
        f"<h2 id='isotherms'>Isotherms</h2><p>{len(mc.temperatures)} isotherms, reference "
        f"{mc.reference_temperature:g} °C; residual: each isotherm's relative rms residual "
        f"under the fit of the master structure.</p>{_isotherms_table(mc)}",
        f"<h2 id='ranking'>Master functions</h2>{_ranking_table(mc)}",
        f"<h2 id='shifts'>Shift factors of {_e(mc.structure)}</h2><p>Shifts: {_e(shifts)}; "
        f"vertical: {_e(mc.vertical)}.</p>{_shifts_table(mc)}",
        f"<h2 id='laws'>Shift laws</h2>{_laws_table(mc)}",
    ]
    if notes:
        sections.append(f"<h2 id='notes'>Notes</h2><ul>{notes}</ul>")
    if figures:
        sections.append(f"<h2 id='figures'>Figures</h2>"
                        f"{_figures_section(figures, captions=CAPTIONS)}")
    return (
        "<!DOCTYPE html>\n<html lang='en'>\n<head>\n<meta charset='utf-8'>\n"
        "<meta name='viewport' content='width=device-width, initial-scale=1'>\n"
        f"<title>{_e(title)}</title>\n<style>{CSS}</style>\n</head>\n<body>\n"
        f"<h1>{_e(title)}</h1>\n<p class='small'>bayesfo {_e(__version__)}.</p>\n"
        + "\n".join(sections) + "\n</body>\n</html>\n")


def write_mastercurve_report(mc, out_dir, figures: dict | None = None) -> Path:
    """Write ``report.html`` of a master curve into ``out_dir`` atomically."""
    return atomic_write_text(Path(out_dir) / "report.html", render_mastercurve_report(mc, figures))
