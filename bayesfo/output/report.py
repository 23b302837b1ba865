"""A self-contained HTML report of a comparison: the page a person reads first.

From top to bottom: a plain-language verdict (:func:`bayesfo.output.verdict.verdict`: which structure
wins, by how much, whether the information criteria agree, how well the fractional order is
determined, what did not converge; the winner's physical parameters), the data, the ranking
table, the priors, the parameter summaries with units (the physical form and the card's
coefficients, the form natural to the data first), warnings and convergence, and the figures with one-line captions.
PNG figures are embedded as base64 data URIs and the style sheet is inline, so the file needs
nothing else to be read or mailed. All text from data, files and results is escaped.

The report speaks in the letters of the data (:attr:`bayesfo.data.FrequencyResponse.symbol`):
for tensile data (a DMA's E′, E″) the data section says "tensile modulus E* = E′ + iE″", and
the formulas, parameter names (E_e for the card's G_e, :mod:`bayesfo.data.symbols`) and captions
say E and D where they say G and J for shear data.

This module does not draw: it takes the figure files written by
:func:`bayesfo.plotting.write_figures`, so it needs no plotting library.
"""

from __future__ import annotations

import base64
import html
from pathlib import Path

from .. import __version__
from .._io import atomic_write_text
from ..comparison.parameters import UNDETERMINED_DECADES, extrapolated, shown_hdi
from ..comparison.table import number
from ..data.symbols import describe, in_symbol, mode, parameter_label
from ..errors import InputError
from ..inference.bound import BOUND_MARGIN, BOUND_REASON
from ..options import LEADING_STRUCTURES, VERY_STRONG
from ..plotting.captions import file_stem
from ..structures import picture_of
from ..structures.physical import in_brackets, meanings
from .verdict import (  # noqa: F401  (_bayes_factor, _strength: re-exported for the tests)
    HDI_PERCENT,
    _bayes_factor,
    _finite,
    _join,
    _prob,
    _strength,
    verdict,
)

CSS = """
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; color: #1a1a1a;
       max-width: 62rem; margin: 2rem auto; padding: 0 1rem; line-height: 1.45; }
h1 { font-size: 1.5rem; margin-bottom: 0.2rem; } h2 { font-size: 1.2rem; margin-top: 2rem;
     border-bottom: 1px solid #ccc; } h3 { font-size: 1.0rem; margin-bottom: 0.3rem; }
.verdict { background: #f3f7fb; border-left: 4px solid #0072B2; padding: 0.6rem 1rem; }
.verdict p { margin: 0.4rem 0; }
.flag { color: #b00000; font-weight: 600; }
table { border-collapse: collapse; margin: 0.5rem 0 1rem; font-size: 0.88rem; }
th, td { border: 1px solid #d0d0d0; padding: 0.2rem 0.5rem; text-align: right; }
th { background: #f0f0f0; } td.text, th.text { text-align: left; }
tr.failed td { color: #777; }
figure { margin: 1.2rem 0; } figure img { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption { font-size: 0.9rem; color: #333; }
.small { font-size: 0.85rem; color: #555; }
"""

CAPTIONS = {
    "ranking": "Log-evidence (top) and information criteria (bottom) relative to the best "
               "structure, in nats, higher is better; posterior probabilities on the right; red "
               "labels: posterior not converged.",
    "bode": "Magnitude and phase of the data (± 1 sd where σ is known) with each structure's "
            "posterior median response (line) and its 50 % and 90 % credible bands.",
    "moduli": "Storage and loss parts and the loss tangent of the data with each structure's "
              "posterior median and its 50 % and 90 % credible bands.",
    "time_functions": "Relaxation modulus G(t) and creep compliance J(t) of each structure "
                      "with credible bands; shaded: beyond the measured window.",
    "nyquist": "The same in the complex plane: posterior median curve and single posterior "
               "draws (thin lines).",
    "residuals": "Residuals of the data from the posterior median prediction, real and "
                 "imaginary parts, normalised by the noise (or relative to |G|).",
    "q_posteriors": "Posterior density of the fractional order per structure (best on top), "
                    "with the prior (dashed), the 94 % HDI (bar) and the mean (tick).",
}


def _e(x) -> str:
    return html.escape(str(x), quote=True)


def _num(x, fmt: str = ".2f") -> str:
    return number(x, fmt, missing="–")


def _cell(x, fmt: str = ".2f", text: str | None = None, cls: str = "") -> str:
    """A numeric table cell; ``data-value`` carries the full-precision number."""
    attr = f' data-value="{_e(repr(float(x)))}"' if _finite(x) else ""
    c = f' class="{cls}"' if cls else ""
    return f"<td{c}{attr}>{_e(text if text is not None else _num(x, fmt))}</td>"


def _text_cell(x, cls: str = "text") -> str:
    return f'<td class="{cls}">{_e(x)}</td>'


def _noise(comparison) -> list[tuple[str, str]]:
    seen = []
    chosen: dict[str, list[str]] = {}
    for r in comparison.results:
        if r.posterior is None:
            continue
        if r.criteria.noise_models:
            chosen.setdefault(r.posterior.noise, []).append(r.name)
        elif (r.posterior.noise, r.posterior.noise_reason) not in seen:
            seen.append((r.posterior.noise, r.posterior.noise_reason))
    # Say what relative_parts means, whether asked for or chosen by evidence.
    parts = ("relative errors σ_rel of the real and imaginary parts separately, the cost that "
             "pyRheo and RheoJAX minimise")
    seen = [(n, f"{why} ({parts})" if n == "relative_parts" else why) for n, why in seen]
    if chosen:
        seen.append(("by evidence per structure", "; ".join(
            f"{noise} for {_join(names)}" + (f" ({parts})" if noise == "relative_parts" else "")
            for noise, names in chosen.items())))
    return seen


def _symbol(comparison) -> str:
    """The letter of the data's measured quantity (G when the data do not say)."""
    return getattr(comparison.data, "symbol", "G")


def _data_section(comparison) -> str:
    d = comparison.data
    rows = [
        ("name", d.label), ("source", d.source or "(not from a file)"), ("kind", d.kind)]
    quantity = describe(_symbol(comparison), d.kind)
    if quantity and mode(_symbol(comparison)) == "tensile":  # shear, the default, is not said
        rows.append(("quantity", quantity))
    rows += [
        ("units", d.units or "(not given)"), ("frequencies", str(d.n_frequencies)),
        ("ω range", f"{d.omega.min():.4g} – {d.omega.max():.4g} rad/s"),
        ("σ per point", "given by the data" if d.sigma is not None else "not given"),
    ]
    for noise, reason in _noise(comparison):
        rows.append(("noise model", f"{noise}: {reason}"))
    if comparison.holdout is not None:
        rows.append(("held out", ", ".join(f"{w:.4g}" for w in comparison.holdout.omega)
                     + " rad/s (not used in the fit)"))
    rows.append(("seed", str(comparison.seed)))
    for note in getattr(d, "notes", ()):
        rows.append(("note", note))
    body = "".join(f'<tr><th class="text">{_e(k)}</th>{_text_cell(v)}</tr>' for k, v in rows)
    return f"<table>{body}</table>"


RANKING_COLUMNS = (
    # (key, header, format)
    ("log_evidence", "ln Z", ".2f"), ("log_evidence_err", "± err", ".2f"),
    ("delta_log_evidence", "Δln Z", ".2f"), ("posterior_probability", "P", None),
    ("loo", "elpd LOO", ".2f"), ("loo_se", "± se", ".2f"),
    ("aic", "AIC", ".2f"), ("bic", "BIC", ".2f"), ("rmse", "RMSE", ".3g"),
    ("pareto_k_max", "Pareto k max", ".2f"), ("rhat_max", "R-hat", ".3f"),
    ("ess_min", "ESS min", ".0f"),
)


def _ranking_table(comparison) -> str:
    holdout = comparison.holdout is not None
    cols = list(RANKING_COLUMNS)
    if holdout:
        cols.insert(9, ("holdout_lpd", "held-out lpd", ".2f"))
    data = comparison.data
    unit = in_symbol(data.units or {"modulus": "[G]", "compliance": "[J]"}.get(data.kind, ""),
                     _symbol(comparison))
    head = ('<tr><th>#</th><th class="text">structure</th><th>k</th>'
            + "".join(f"<th>{_e(h + (in_brackets(unit) if k == 'rmse' else ''))}</th>"
                      for k, h, _ in cols)
            + '<th class="text">orders</th><th class="text">converged</th>'
            '<th class="text">fits</th></tr>')
    body = []
    for row in comparison.table():
        name = row["structure"]
        if row.get("rank") is None:
            body.append(f'<tr class="failed" id="row-{_e(name)}"><td>–</td>{_text_cell(name)}'
                        f'<td>{row["n_params"]}</td><td class="text" colspan="{len(cols) + 3}">'
                        f'failed: {_e(row.get("error"))}</td></tr>')
            continue
        cells = [f'<td>{row["rank"]}</td>', _text_cell(name), f'<td>{row["n_params"]}</td>']
        sampled = row.get("sampled", True)
        for key, _, fmt in cols:
            v = row.get(key)
            bound = {"log_evidence": "log_evidence_bound",
                     "delta_log_evidence": "delta_log_evidence_bound",
                     "posterior_probability": "posterior_probability_bound"}.get(key)
            if not sampled and bound is not None and row.get(bound) is not None:
                # Left out by the evidence bound: ln Z and P are at most these.
                b = row[bound]
                cells.append(_cell(b, text="≤ " + (f"{b:.0e}" if key == "posterior_probability"
                                                   else _num(b, fmt))))
            elif key == "posterior_probability":
                cells.append(_cell(v, text=_prob(v)))
            elif key == "log_evidence" and _finite(v) and row.get("evidence_method") == "ladder":
                cells.append(_cell(v, text=f"{_num(v, fmt)} L"))
            elif key == "rhat_max" and _finite(v) and not row["converged"]:
                cells.append(_cell(v, fmt, cls="flag"))
            else:
                cells.append(_cell(v, fmt))
        cells.append(_text_cell(row.get("orders") or "–"))
        ok = row["converged"]
        if not sampled:
            cells.append('<td class="text">not sampled</td>')
        else:
            cells.append(f'<td class="text{"" if ok else " flag"}">{"yes" if ok else "NO"}</td>')
        fits = row.get("fits")  # the posterior predictive checks, as the terminal says them
        cells.append(f'<td class="text{" flag" if fits == "no" else ""}">'
                     f'{_e((fits or "–").replace("no", "NO"))}</td>')
        body.append(f'<tr id="row-{_e(name)}">' + "".join(cells) + "</tr>")
    note = ("<p class='small'>Ranked by ln Z (from the certified importance weights where "
            "they gave the posterior, else bridge sampling from the emcee draws, or the "
            "particles of a tempered ladder, marked L); Δln Z to the best; P: posterior "
            "model probability; elpd: expected log pointwise predictive density (higher is "
            "better) with the standard error of each estimate, by PSIS-LOO, whose Pareto k "
            "says where it is unreliable (WAIC, which estimates the same without a diagnostic "
            "of its own, is in ranking.csv and summary.json); AIC and BIC: lower is better; "
            "RMSE at the posterior mode (thesis eq. (3.23)), in the data's unit; orders: each "
            "fractional order by its symbol, posterior mean and 94 % HDI; fits: whether the "
            "posterior predictive checks pass (small: a systematic misfit within 2° and "
            "3.5 %; partly: they pass, but the fitted noise swamps points the fit misses).</p>")
    if any(not r.get("sampled", True) for r in comparison.table() if r.get("rank")):
        note += (f"<p class='small'>≤: {_e(BOUND_REASON)}. Its maximum log-likelihood (the "
                 "global optimiser's, under every noise model) is an upper bound of ln Z under "
                 f"any normalised prior and lies more than {BOUND_MARGIN:g} nats below the "
                 "leader's certified ln Z, so its posterior probability is below "
                 f"e^-{BOUND_MARGIN:g}; AIC, AICc, BIC and RMSE are those of that best fit; it "
                 "has no PSIS-LOO, WAIC, posterior or figures. <code>--sample all</code> "
                 "samples it.</p>")
    return f"<table>{head}{''.join(body)}</table>{note}"


def _families(comparison) -> str:
    fams = comparison.families()
    if not fams:
        return ""
    rows = "".join(
        f"<tr>{_text_cell(f['family'])}{_text_cell(', '.join(f['members']))}"
        f"{_cell(f['log_evidence'])}{_cell(f['log_evidence_err'])}"
        f"{_cell(f['posterior_probability'], text=_prob(f['posterior_probability']))}</tr>"
        for f in fams)
    return ("<h3>Families</h3><p class='small'>Evidence of each family with several members, "
            "equal prior weight on its members.</p><table><tr><th class='text'>family</th>"
            "<th class='text'>members</th><th>ln Z</th><th>± err</th><th>P</th></tr>"
            f"{rows}</table>")


def _names_note(symbol: str) -> str:
    """For tensile data: the moduli shown as E_e are keyed G_e in the files and options."""
    if parameter_label("G_e", symbol) == "G_e":
        return ""
    return (" The moduli are named by the letter of the data, E for a tensile modulus (E_e, "
            "E_m); summary.json, ranking.csv, the NetCDF files and --prior name them as the "
            "structure's card does (G_e, G_m).")


def _priors_section(comparison) -> str:
    symbol = _symbol(comparison)
    parts = []
    for name in comparison.ranking:
        r = comparison[name]
        rows = []
        for name, prior in (r.criteria.priors or {}).items():
            kind = prior.get("prior", "?")
            if "low" in prior:
                desc = f"[{prior['low']:.4g}, {prior['high']:.4g}]"
            elif "mu" in prior:
                desc = f"mean {prior['mu']:.4g}, sd {prior['sd']:.4g}"
            else:
                desc = ", ".join(f"{k} = {v}" for k, v in prior.items() if k != "prior")
            rows.append(f"<tr>{_text_cell(parameter_label(name, symbol))}{_text_cell(kind)}"
                        f"{_text_cell(desc)}</tr>")
        scale = ""
        if r.fit is not None and getattr(r.fit, "scaling", None) is not None:
            sc = r.fit.scaling
            scale = (f" Scaled data: ω/ω_ref, G/g_ref with ω_ref = {sc.omega_ref:.4g} rad/s, "
                     f"g_ref = {sc.g_ref:.4g}"
                     + (" (structure compared with the reciprocal of the data)"
                        if sc.reciprocal else "") + ".")
        formula = f"J(s) = {r.structure.formula}"
        if comparison.data.kind == "modulus" and r.structure.modulus_formula is not None:
            formula = (f"G*(s) = {r.structure.modulus_formula}, sampled as the card's "
                       f"compliance {formula}")
        parts.append(f"<h3>{_e(r.name)}</h3><p class='small'>{_e(in_symbol(formula, symbol))}."
                     f"{_e(in_symbol(scale, symbol))}</p><table><tr><th class='text'>parameter</th>"
                     f"<th class='text'>prior</th><th class='text'>range</th></tr>"
                     f"{''.join(rows)}</table>")
    return ("<p class='small'>Coefficient priors apply on the scaled data (so that they mean "
            "the same for any units); exponents are unscaled. Every structure is also "
            "restricted to stable, dissipative parameters (and its card's inequalities)."
            f"{_e(_names_note(symbol))}</p>" + "".join(parts))


def _parameters_section(comparison) -> str:
    symbol = _symbol(comparison)
    parts = []
    for name in comparison.ranking:
        r = comparison[name]
        units = getattr(r, "units", {}) or {}
        judged = r.sampled_parameters
        rows = []
        if r.posterior is None:  # left out by the evidence bound: no posterior
            continue
        for p, s in r.posterior.summary.items():
            flags = _flags(judged.get(p, {})) + (["multimodal"] if s.multimodal else [])
            rows.append(
                f"<tr>{_text_cell(parameter_label(p, symbol))}"
                f"{_text_cell(in_symbol(units.get(p, ''), symbol))}{_cell(s.mean, '.4g')}"
                f"{_cell(s.sd, '.3g')}"
                + "".join(_cell(v, '.4g') for v in shown_hdi(
                    judged.get(p, {"hdi_low": s.hdi_low, "hdi_high": s.hdi_high})))
                + f"{_cell(s.median, '.4g')}{_cell(s.map, '.4g')}"
                f"<td class='text{' flag' if flags else ''}'>{_e(', '.join(flags))}</td></tr>")
        sampled = (f"<table>{_PARAMETER_HEAD}<th class='text'>flags</th></tr>{''.join(rows)}"
                   "</table>")
        phys = getattr(r, "physical", None)
        if phys is None or phys["picture"] is None:
            parts.append(f"<h3>{_e(name)}</h3>{sampled}")
            continue
        physical = _physical_table(phys["physical"], symbol,
                                   meanings(r.structure, phys["picture"]),
                                   extrapolated(phys["physical"], comparison.data))
        picture = _picture_text(r.structure, phys["picture"], symbol)
        compliance = _e(in_symbol(r.structure.formula, symbol))
        if phys["natural_form"] == "physical":
            parts.append(f"<h3>{_e(name)}</h3><p class='small'>Physical parameters ({picture}):"
                         f"</p>{physical}<p class='small'>As sampled: the card's coefficients "
                         f"(compliance {compliance}) and the noise:</p>{sampled}")
        else:
            parts.append(f"<h3>{_e(name)}</h3><p class='small'>As sampled: the card's "
                         f"coefficients (compliance {compliance}) and the noise:"
                         f"</p>{sampled}<p class='small'>Physical parameters ({picture}):</p>"
                         f"{physical}")
    intro = in_symbol(
        "Each structure's parameters are given in the form natural to the data first (modulus "
        "data: moduli G [stress], quasi-properties c [stress·s^order], orders and times "
        "τ [s]; compliance data: the card's coefficients a, b and orders), then in the "
        "other form.", symbol) + _names_note(symbol)
    return (f"<p class='small'>Posterior summaries in physical units, the units derived from "
            f"the data's; HDI: {HDI_PERCENT} % highest-density interval; MAP: the draw of "
            "highest posterior density (for a physical parameter, its value at that draw). "
            "For a positive quantity with a unit the HDI shown is taken on a log scale (of "
            "the logarithms of the draws, so that a quantity and its reciprocal agree; "
            "summary.json holds it as hdi_log_low/hdi_log_high beside the HDI of the values). "
            "'Poorly determined': the HDI covers more than half of the prior range. 'Not "
            f"determined': that log-scale HDI spans more "
            f"than {UNDETERMINED_DECADES:g} decades or runs to 0 or infinity (for a signed "
            "quantity: reaches across 0), or the quantity is undefined at more draws than the "
            "HDI leaves out, so the data do not fix even its order of magnitude and its numbers "
            f"are not estimates. {_e(intro)}</p>" + "".join(parts))


_PARAMETER_HEAD = ("<tr><th class='text'>parameter</th><th class='text'>unit</th><th>mean</th>"
                   "<th>sd</th><th>HDI low</th><th>HDI high</th><th>median</th><th>MAP</th>")


def _flags(s: dict) -> list[str]:
    """'not determined: …' and 'poorly determined', those that apply, for one summary (of
    :func:`~bayesfo.comparison.parameters.with_determination`)."""
    return ([f"not determined: {s['not_determined_reason']}"] if s.get("not_determined")
            else []) + (["poorly determined"] if s.get("poorly_determined") else [])


def _physical_table(block: dict, symbol: str = "G", meaning: dict | None = None,
                    beyond: dict | None = None) -> str:
    """The physical parameters' summaries, with what each is (``meaning``, from
    :func:`~bayesfo.structures.physical.meanings`) in a last column where given, and the flags
    of ``beyond`` (:func:`~bayesfo.comparison.parameters.extrapolated`) beside their own."""
    rows = []
    for p, s in block.items():
        flags = _flags(s) + ([beyond[p]] if beyond and p in beyond else [])
        rows.append(
            f"<tr>{_text_cell(parameter_label(p, symbol))}"
            f"{_text_cell(in_symbol(s['unit'], symbol))}"
            f"{_cell(s['mean'], '.4g')}"
            f"{_cell(s['sd'], '.3g')}" + "".join(_cell(v, '.4g') for v in shown_hdi(s))
            + f"{_cell(s['median'], '.4g')}{_cell(s['map'], '.4g')}"
            f"<td class='text{' flag' if flags else ''}'>{_e(', '.join(flags))}</td>"
            + (_text_cell(in_symbol((meaning or {}).get(p, ''), symbol)) if meaning else "")
            + "</tr>")
    head = _PARAMETER_HEAD + "<th class='text'>flags</th>" + (
        "<th class='text'>meaning</th>" if meaning else "")
    return f"<table>{head}</tr>{''.join(rows)}</table>"


def _picture_text(structure, picture: str, symbol: str = "G") -> str:
    """The picture's name, title and mechanical network, escaped; the network's moduli and
    G*(s) in the letters of data measured as ``symbol`` (E_e and E*(s) for tensile data)."""
    pic = picture_of(structure, picture)
    text = pic.name + (f", {pic.title}" if pic.title else "")
    if pic.network is not None:
        text += in_symbol(f"; network {pic.network.text}, G*(s) = "
                          f"{pic.network.modulus_text(dict(structure.fixed))}", symbol)
    if structure.fixed:
        text += " with " + ", ".join(f"{k} = {float(v):g}" for k, v in structure.fixed.items())
    return _e(text)


def _diagnostics_section(comparison) -> str:
    items = []
    for r in comparison.results:
        if r.error is not None:
            items.append(f"<li><b>{_e(r.name)}</b>: <span class='flag'>failed</span>: "
                         f"{_e(r.error)}</li>")
            continue
        post = r.posterior
        if post is None:
            bound = r.criteria.bound or {}
            items.append(f"<li><b>{_e(r.name)}</b>: not sampled: ln Z ≤ "
                         f"{_num(bound.get('log_evidence_bound'))} (max ln L from the "
                         f"{_e(bound.get('source', 'optimiser'))})</li>")
            continue
        status = ("converged" if post.converged
                  else "<span class='flag'>not converged</span>")
        tau = max(post.tau) if len(post.tau) else float("nan")
        if getattr(post, "sampler", "emcee") == "ladder":
            how = (f"{post.n_walkers} independent tempered-ladder runs × "
                   f"{post.samples.shape[0] // post.n_walkers} particles (R-hat and ESS across "
                   "the runs)")
        elif getattr(post, "sampler", "emcee") == "importance":
            info = r.criteria.importance or {}
            how = (f"importance sampling from {info.get('n_modes', '?')} optimum(s), "
                   f"{info.get('n_proposals', 0):,} proposal draws, Pareto k̂ "
                   f"{_num(info.get('k_hat'), '.2f')} (certified below 0.7), ESS of the weights")
            widest = info.get("widest") or {}
            if widest.get("parameter"):
                how += (f"; every fractional order determined (the widest, "
                        f"{widest['parameter']}, spans {100 * widest['share_of_prior']:.0f} % of "
                        "its prior range)")
            probe = info.get("probe") or {}
            if probe.get("skipped"):
                how += f"; ridge probe not run ({_e(probe['skipped'])})"
            elif probe:
                how += (f"; ridge probe: {probe.get('points', 0)} profile points, "
                        f"{_num(100 * probe.get('missed', 0.0), '.1f')} % of the posterior "
                        "beyond the proposal's reach")
                if probe.get("ridge"):
                    how += (f" (after widening it along a ridge in {_e(probe['ridge'])}, where "
                            f"the first proposal missed an estimated "
                            f"{_num(100 * probe.get('covered', 0.0), '.0f')} %)")
            found = info.get("configurations")
            if found is not None and found.get("skipped"):
                how += (f"; configurations where an element vanishes not searched "
                        f"({_e(found['skipped'])})")
            elif found is not None:
                vanishing = found.get("vanishing") or []
                how += ("; configurations where an element vanishes: "
                        + (f"{_e(', '.join(vanishing))}, "
                           f"{_num(100 * found.get('missed', 0.0), '.1f')} % of the posterior "
                           "beyond the draws' reach" if vanishing else "none"))
            rounds = info.get("k_hat_rounds") or []
            if len(rounds) > 1:
                how += (f"; {len(rounds)} rounds of importance sampling (k̂ "
                        + " → ".join(_num(k, ".2f") for k in rounds) + ")")
            if info.get("ladder_outside") is not None:
                how += (f"; the tempered ladder run for ln Z put "
                        f"{_num(100 * info['ladder_outside'], '.1f')} % of its particles outside "
                        "the range of the draws")
        else:
            how = (f"{post.n_walkers} walkers × {post.n_steps} steps, τ max "
                   f"{_num(tau, '.0f')}, acceptance {_num(post.acceptance, '.2f')}")
        line = (f"<b>{_e(r.name)}</b>: {status}; R-hat {_num(post.rhat_max, '.3f')}, ESS bulk "
                f"{_num(post.ess_bulk_min, '.0f')}, tail {_num(post.ess_tail_min, '.0f')}, "
                f"{how}")
        if r.criteria.evidence_agree is False:
            line += "; <span class='flag'>the two ln Z estimates (default and nested) disagree</span>"
        ev = r.criteria.evidence
        if ev is not None and ev.method == "ladder":
            line += (f"; ln Z from a tempered ladder ({ev.n_likelihood:,} likelihood evaluations, "
                     f"{ev.seconds:.1f} s)")
        notes = list(post.messages) + [w for w in r.criteria.warnings
                                       if w not in post.messages]
        if notes:
            line += "<ul>" + "".join(f"<li class='flag'>{_e(m)}</li>" for m in notes) + "</ul>"
        items.append(f"<li>{line}</li>")
    return f"<ul>{''.join(items)}</ul>"


def _caption(name: str, comparison=None) -> str:
    """The caption of a figure: what it shows for this comparison (:mod:`bayesfo.plotting.captions`),
    else the generic text."""
    if comparison is not None:
        from ..plotting.captions import figure_caption

        text = figure_caption(name, comparison)
        if text:
            return text
    if name in CAPTIONS:
        return CAPTIONS[name] if comparison is None else in_symbol(CAPTIONS[name],
                                                                   _symbol(comparison))
    kind, _, structure = name.partition("_")
    if kind == "corner":
        return (f"Posterior of {structure}: marginal and pairwise distributions (log10 of "
                "parameters with a log-uniform prior; contours hold 50 % and 90 %), with the "
                "posterior mode and the least-squares optimum.")
    if kind == "trace":
        return (f"Walker traces of {structure} after burn-in; whether they converged is stated "
                "under 'Warnings and convergence'.")
    return name


def _paths(value) -> list[Path]:
    if isinstance(value, (str, Path)):
        return [Path(value)]
    return [Path(v) for v in value]


def _figures_section(figures: dict, comparison=None, captions: dict | None = None) -> str:
    """The figures' PNG files embedded with their captions (``captions``, else a comparison's
    own)."""
    parts = []
    for name, value in figures.items():
        paths = _paths(value)
        png = next((p for p in paths if p.suffix.lower() == ".png"), None)
        caption = captions.get(name, name) if captions is not None else _caption(name, comparison)
        if png is None:
            parts.append(f"<p class='small'>{_e(name)}: {_e(caption)} (not embedded: written as "
                         f"{_e(', '.join(p.name for p in paths))})</p>")
            continue
        try:
            data = png.read_bytes()
        except OSError as exc:
            raise InputError(f"argument 'figures': cannot read figure '{name}' from "
                             f"'{png}': {exc.strerror}") from None
        uri = "data:image/png;base64," + base64.b64encode(data).decode("ascii")
        parts.append(f"<figure id='fig-{_e(name)}'><img src='{uri}' alt='{_e(caption)}'>"
                     f"<figcaption><b>{_e(name)}</b>: {_e(caption)}</figcaption></figure>")
    return "".join(parts)


def _without_corner(figures: dict, comparison) -> str:
    """A note naming the structures that have no corner figure among ``figures``, if any."""
    # Structures left out by the evidence bound have no posterior to draw (the table says so).
    unsampled = {r.name for r in comparison.results if getattr(r, "posterior", True) is None}
    missing = [n for n in comparison.ranking if f"corner_{file_stem(n)}" not in figures
               and n not in unsampled]
    if not missing:
        return ""
    return (f"<p class='small'>No corner figure of {_e(', '.join(missing))}: by default only "
            f"the leading structures get one (of the best {LEADING_STRUCTURES}, those the "
            f"evidence does not rule out, ln Z within {VERY_STRONG:g} of the best, and each "
            "structure an information criterion ranks first); "
            "<code>--structure-figures all</code> draws every one.</p>")


def render_report(comparison, figures: dict | None = None) -> str:
    """The report of a comparison as one self-contained HTML document.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    figures : dict, optional
        ``{figure name: path or list of paths}``, e.g. the result of
        :func:`bayesfo.plotting.write_figures`; the PNG of each is embedded (figures without
        a PNG are listed by file name). Names such as ``bode`` or ``corner_<structure>`` get
        their captions.

    Returns
    -------
    str
        The HTML text.

    Raises
    ------
    InputError
        If a figure file cannot be read.

    Examples
    --------
    >>> text = render_report(comparison)                    # doctest: +SKIP
    >>> "report" in text                                     # doctest: +SKIP
    True
    """
    title = f"bayesfo: which structure do the data '{comparison.data.label}' support?"
    sentences = "".join(f"<p class='flag'>{_e(t)}</p>" if flagged else f"<p>{_e(t)}</p>"
                        for t, flagged in verdict(comparison))
    # What a reader looks for first comes first: the verdict, the ranking, the figures; the
    # numbers behind them (parameters, priors, diagnostics) after.
    sections = [
        f"<div class='verdict' id='verdict'>{sentences}</div>",
        f"<h2 id='data'>Data</h2>{_data_section(comparison)}",
        f"<h2 id='ranking'>Ranking</h2>{_ranking_table(comparison)}{_families(comparison)}",
    ]
    if figures:
        sections.append(f"<h2 id='figures'>Figures</h2>{_figures_section(figures, comparison)}"
                        f"{_without_corner(figures, comparison)}")
    sections += [
        f"<h2 id='parameters'>Parameters</h2>{_parameters_section(comparison)}",
        f"<h2 id='priors'>Priors</h2>{_priors_section(comparison)}",
        f"<h2 id='diagnostics'>Warnings and convergence</h2>{_diagnostics_section(comparison)}",
    ]
    return (
        "<!DOCTYPE html>\n<html lang='en'>\n<head>\n<meta charset='utf-8'>\n"
        "<meta name='viewport' content='width=device-width, initial-scale=1'>\n"
        f"<title>{_e(title)}</title>\n<style>{CSS}</style>\n</head>\n<body>\n"
        f"<h1>{_e(title)}</h1>\n<p class='small'>bayesfo {_e(__version__)}, seed "
        f"{_e(comparison.seed)}, ranked by {_e(comparison.ranked_by.replace('_', ' '))}"
        + (f"; {_e(comparison.noise_note)}" if getattr(comparison, "noise_note", None) else "")
        + ".</p>\n"
        + "\n".join(sections) + "\n</body>\n</html>\n"
    )


def write_report(comparison, out_dir, figures: dict | None = None) -> Path:
    """Write ``report.html`` (see :func:`render_report`) into ``out_dir`` atomically.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    out_dir : str or path-like
        Directory, created when missing.
    figures : dict, optional
        As for :func:`render_report`.

    Returns
    -------
    Path
        The path of the report.
    """
    text = render_report(comparison, figures)
    return atomic_write_text(Path(out_dir) / "report.html", text)
