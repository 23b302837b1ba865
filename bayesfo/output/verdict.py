"""The verdict of a comparison in plain language: which structure the data support, by how
much (Kass & Raftery's verbal scale of the Bayes factor), whether the information criteria and
the posterior predictive checks agree, how well the fractional order is determined, which
posteriors are not certified, how the noise model was chosen, and the winner's physical
parameters with units (naming instead of valuing those the data do not determine).

:func:`verdict` returns the sentences, each with a flag that marks a caution; the report
(:mod:`bayesfo.output.report`) renders them as its first section, and scripts can print them.

References
----------
Kass, R. E. & Raftery, A. E. (1995). Bayes factors. *J. Am. Stat. Assoc.* 90, 773–795 (the
verbal scale of the evidence).
"""

from __future__ import annotations

import math

from ..comparison.parameters import UNDETERMINED_DECADES, flagged_names, shown_hdi
from ..comparison.steps import BOUND_METHOD, NOISE_DECISIVE
from ..comparison.table import CRITERIA, ORDER_SYMBOLS, order_parameters
from ..data.symbols import in_symbol, parameter_label
from ..inference.bound import BOUND_MARGIN
from ..options import VERY_STRONG

#: Kass & Raftery (1995) on ln B (their 2 ln B thresholds 2, 6, 10, halved).
EVIDENCE_SCALE = ((1.0, "not worth more than a bare mention"), (3.0, "positive"),
                  (VERY_STRONG, "strong"), (math.inf, "very strong"))
HDI_PERCENT = 94

def _finite(x) -> bool:
    if x is None or isinstance(x, (bool, str)):
        return False
    try:
        return math.isfinite(float(x))
    except (TypeError, ValueError):
        return False



def _prob(p) -> str:
    if not _finite(p):
        return "–"
    return "< 0.001" if p < 0.001 else f"{p:.3f}"


def _bayes_factor(d: float) -> str:
    if d < 30:
        return f"{math.exp(d):.3g}"
    return f"about 10^{d / math.log(10):.0f}"


def _strength(d: float) -> str:
    return next(label for bound, label in EVIDENCE_SCALE if d < bound)


def _orders(result) -> list:
    """``(name, summary)`` of every fractional order of a result's posterior."""
    summary = result.posterior.summary
    return [(p, summary[p]) for p in order_parameters(summary)]


def _digits(sd: float) -> int:
    """Decimals that show a value to the second significant digit of its standard deviation."""
    if not _finite(sd) or sd <= 0:
        return 3
    return min(8, max(0, 1 - math.floor(math.log10(sd))))


def _sentence(text: str) -> str:
    return text if text.endswith(".") else text + "."


def _adequacy_sentences(comparison, rows) -> list[tuple[str, bool]]:
    """Whether the best-supported structure, and any candidate, describes the data (posterior
    predictive checks, :mod:`bayesfo.inference.adequacy`)."""
    checked = [(r["structure"], comparison[r["structure"]].adequacy) for r in rows]
    checked = [(n, a) for n, a in checked if a is not None]
    if not checked:
        return []
    name, best = checked[0]
    level = f"{100 * best.level:g} %"
    if not any(a.adequate for _, a in checked):
        small = [n for n, a in checked if a.misfit_small]
        reason = f" {name}: {_sentence(best.reasons[0])}" if best.reasons else ""
        if best.misfit_small:
            # The best one misses by little: said first, not after "none describes".
            text = (f"No candidate passes the posterior predictive checks at the {level} level, "
                    f"but the best supported, {name}, misses the data by little (within 2° in "
                    "phase and 3.5 % in magnitude): systematically, so its numbers describe "
                    f"the data up to that.{reason}")
            others = [n for n in small if n != name]
            if others:
                text += f" The misfit is as small for {_join(others)}."
            return [(text.rstrip(), True)]
        text = ("None of the candidates describes these data: every structure fails the "
                f"posterior predictive checks at the {level} level, so the ranking says only "
                f"which misfits least.{reason}")
        if small:
            text += (f" The misfit is small (within 2° in phase and 3.5 % in magnitude) for "
                     f"{_join(small)}.")
        return [(text.rstrip(), True)]
    if best.adequate and best.misfit_masked:
        return [(f"{name} passes its posterior predictive checks at the {level} level, but "
                 f"{best.caution} (its {best.noise} noise model treats them as noise; if they "
                 "are more precise than that, the pass does not extend to them).", True)]
    if best.adequate:
        return [(f"{name} describes the data: its posterior predictive checks pass at the "
                 f"{level} level (largest misfit {best.max_phase_error_deg:.1f}° in phase, "
                 f"{100 * (10 ** best.max_log10_magnitude_error - 1):.1f} % in magnitude).",
                 False)]
    good = [n for n, a in checked if a.adequate]
    text = (f"{name} is best supported but does not describe the data: "
            f"{_sentence(best.reasons[0] if best.reasons else best.summary)}")
    text += f" Structures that pass the checks: {_join(good)}."
    return [(text, True)]


def verdict(comparison) -> list[tuple[str, bool]]:
    """The plain-language verdict, as sentences ``(text, flagged)``.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison

    Returns
    -------
    list of (str, bool)
        Sentences in reading order, whether the structures describe the data first, then the
        evidence; ``flagged`` marks cautions (no convergence, poorly
        determined order, parameters the data do not determine, an evidence difference within
        its error).
    """
    table = [r for r in comparison.table() if r.get("rank") is not None]
    # Structures the evidence bound left out have no posterior: the sentences on posteriors
    # are of the sampled ones, and one sentence says which were left out and why.
    rows = [r for r in table if r.get("sampled", True)]
    bounded = [r for r in table if not r.get("sampled", True)]
    failed = [r for r in comparison.results if r.error is not None]
    out: list[tuple[str, bool]] = [(f"Data: {w.split(': ', 1)[1]}.", True)
                                   for w in comparison.data_warnings]
    kk = comparison.data.kramers_kronig()
    if kk is not None and not kk.consistent and not any(
            kk.describe() in w for w in comparison.data_warnings):
        out.append((f"Data: {kk.describe()}.", True))
    if not rows:
        return out + [("No structure could be run on these data.", True)]
    best = rows[0]
    name = best["structure"]
    result = comparison[name]
    # Whether the structures describe the data comes first: a decisive ranking of structures
    # that all misfit says only which misfits least.
    out.extend(_adequacy_sentences(comparison, rows))
    if best["log_evidence"] is None:
        out.append((f"No structure has a log-evidence; ranked by PSIS-LOO, {name} comes first.",
                    True))
    elif len(rows) == 1:
        out.append((f"Only one structure was run: {name}, with ln Z = "
                    f"{best['log_evidence']:.2f} ± {best['log_evidence_err']:.2f}.", False))
    else:
        second = rows[1]
        n = len(rows)
        if second["log_evidence"] is None:
            out.append((f"{name} has the highest log-evidence (ln Z = "
                        f"{best['log_evidence']:.2f}); {second['structure']} has none.", False))
        else:
            d = best["log_evidence"] - second["log_evidence"]
            err = math.hypot(best["log_evidence_err"] or 0.0, second["log_evidence_err"] or 0.0)
            out.append((
                f"{name} is the best-supported structure: its log-evidence exceeds that of the "
                f"runner-up, {second['structure']}, by Δln Z = {d:.2f} ± {err:.2f} (Bayes "
                f"factor {_bayes_factor(d)}; on the Kass–Raftery scale the evidence is "
                f"{_strength(d)}). Its posterior probability among the {n} structures compared is "
                f"{_prob(best['posterior_probability'])} (equal prior odds unless others were "
                "given).", False))
            if d < 2 * err:
                out.append((f"The difference from {second['structure']} is within twice its "
                            "estimation error: the evidence does not separate the two.", True))
    if bounded:
        listed = _join([f"{r['structure']} (ln Z ≤ {r['log_evidence_bound']:.2f})"
                        for r in bounded])
        out.append((f"Not sampled: {listed}: the best fit of each (the global optimiser's "
                    "maximum log-likelihood, an upper bound of ln Z under any normalised prior) "
                    f"lies more than {BOUND_MARGIN:g} nats below the log-evidence of {name}, so "
                    f"its posterior probability is below e^-{BOUND_MARGIN:g}; they have no "
                    "PSIS-LOO, WAIC or posterior figures (--sample all samples them).", False))
    if len(rows) > 1:
        agree = [c for c in CRITERIA if best.get(f"rank_{c}") == 1]
        disagree = {}
        for c in CRITERIA:
            if c not in agree:
                top = next((r["structure"] for r in rows if r.get(f"rank_{c}") == 1), None)
                disagree.setdefault(top, []).append(CRITERIA[c])
        if not disagree:
            out.append(("The information criteria agree: PSIS-LOO, WAIC, AIC and BIC all rank "
                        f"{name} first.", False))
        else:
            parts = [f"{_join(crit)} prefer{'s' if len(crit) == 1 else ''} {other}"
                     for other, crit in disagree.items()]
            lead = (f"{_join([CRITERIA[c] for c in agree])} also rank {name} first, but "
                    if agree else "The information criteria disagree with the evidence: ")
            out.append((lead + "; ".join(parts) + ".", False))
    orders = _orders(result)
    if orders:
        values = []
        for p, s in orders:
            digits = _digits(s.sd)
            values.append(f"{ORDER_SYMBOLS[p]} = {s.mean:.{digits}f} (sd {s.sd:.2g}, "
                          f"{HDI_PERCENT} % HDI {s.hdi_low:.{digits}f}–{s.hdi_high:.{digits}f})")
        text = (f"The fractional order{'s' if len(orders) > 1 else ''} of {name} "
                f"{'are' if len(orders) > 1 else 'is'} {_join(values)}.")
        poor = [ORDER_SYMBOLS[p] for p, s in orders if s.poorly_determined]
        if poor:
            out.append((text + f" {_join(poor)} {'is' if len(poor) == 1 else 'are'} poorly "
                        f"determined: {'its' if len(poor) == 1 else 'their'} {HDI_PERCENT} % "
                        "HDI covers more than half of the prior range.", True))
        else:
            out.append((text, False))
        for p, s in orders:
            if s.multimodal:
                out.append((f"The posterior of {ORDER_SYMBOLS[p]} has several separated modes.",
                            True))
    elif result.structure.integer:
        out.append((f"{name} is an integer-order structure (its exponents are fixed at 1).",
                    False))
    out.extend(_physical_sentence(name, result, skip={p for p, _ in orders}))
    out.extend(_noise_sentences(name, result))
    poor = [f"{r['structure']} ({', '.join(symbols)})" for r in rows[1:]
            if (symbols := [ORDER_SYMBOLS[p] for p, s in _orders(comparison[r["structure"]])
                            if s.poorly_determined])]
    if poor:
        out.append(("Fractional orders poorly determined (HDI wider than half the prior "
                    f"range): {'; '.join(poor)}.", True))
    undecided = [text for r in rows[1:]
                 if (text := _undecided_noise(r["structure"], comparison[r["structure"]]))]
    if undecided:
        out.append(("Exponents that depend on a noise model the evidence does not decide "
                     f"({HDI_PERCENT} % intervals under each; state σ per point or choose the "
                     f"noise model with --noise): {'; '.join(undecided)}.", True))
    # Every ranked structure, the winner first, named as the terminal names them (the form
    # natural to the data), whether or not a sentence above gave its values.
    vague = [f"{r['structure']} ({', '.join(names)})" for r in rows
             if (names := _undetermined(comparison[r["structure"]]))]
    if vague:
        out.append((f"Parameters that the data do not determine ({HDI_PERCENT} % HDI over more "
                    f"than {UNDETERMINED_DECADES:g} decades on a log scale, reaching 0 or "
                    "infinity, or undefined; their numbers are not estimates): "
                    f"{'; '.join(vague)}.", True))
    if not best["converged"]:
        post = result.posterior
        out.append((f"Caution: the posterior of {name} did not converge (R-hat "
                    f"{post.rhat_max:.3f}, ESS {post.ess_min:.0f}); its log-evidence and the "
                    "ranking that rests on it are unreliable. Try a longer run (--max-steps "
                    "40000), more walkers (--walkers) or a narrower prior (--prior).", True))
        conv = next((r for r in rows if r["converged"]), None)
        if conv is not None and conv["log_evidence"] is not None and best["log_evidence"] is not None:
            out.append((f"The best-supported structure whose posterior converged is "
                        f"{conv['structure']} (Δln Z = {conv['log_evidence'] - best['log_evidence']:.2f}"
                        f" to {name}, posterior probability {_prob(conv['posterior_probability'])}).",
                        True))
    others = [r["structure"] for r in rows[1:] if not r["converged"]]
    if others:
        out.append((f"Posteriors that did not converge: {', '.join(others)}.", True))
    if comparison.holdout is not None:
        scored = [r for r in rows if _finite(r.get("holdout_lpd"))]
        if scored:
            top = max(scored, key=lambda r: r["holdout_lpd"])
            out.append((f"On the {comparison.holdout.n_frequencies} held-out frequencies, "
                        f"{top['structure']} predicts best (log predictive density "
                        f"{top['holdout_lpd']:.2f}).", False))
    if failed:
        out.append(("Could not be run: " + "; ".join(f"{r.name} ({r.error})" for r in failed)
                    + ".", True))
    return out


def _undetermined(result) -> list[str]:
    """The parameters of ``result``, in the form natural to the data, that the data do not
    determine (:func:`~bayesfo.comparison.parameters.not_determined`): the names the terminal
    lists beneath the ranking."""
    if getattr(result, "posterior", None) is None:
        return []
    symbol = getattr(result, "data_symbol", "G")
    return [parameter_label(n, symbol) for n in flagged_names(result.natural_parameters)]


def _physical_sentence(name, result, skip=None) -> list[tuple[str, bool]]:
    """The winner's physical parameters: posterior median and 94 % HDI with units; those the
    data do not determine are named with the reason instead of a value."""
    phys = getattr(result, "physical", None)
    if not phys or phys["picture"] is None:
        return []
    parts, vague = [], []
    symbol = getattr(result, "data_symbol", "G")
    for key, s in phys["physical"].items():
        if skip is not None and key in skip:
            continue
        p = parameter_label(key, symbol)  # E_e for G_e of tensile data
        if s.get("not_determined"):  # before the value: an undefined median is named too
            vague.append(f"{p} ({s['not_determined_reason']})")
            continue
        if not _finite(s.get("median")):
            continue
        unit = f" {in_symbol(s['unit'], symbol)}" if s["unit"] else ""
        lo, hi = shown_hdi(s)
        hdi = f" ({lo:.3g}–{hi:.3g})" if _finite(lo) and _finite(hi) else ""
        parts.append(f"{p} = {s['median']:.3g}{unit}{hdi}")
    out = []
    picture = "" if phys["picture"] == name else f" ({phys['picture']})"
    if parts:
        out.append((f"In physical parameters{picture}, {name} has {_join(parts)} "
                    f"(posterior medians, {HDI_PERCENT} % HDI in brackets).", False))
    if vague:
        out.append((f"The data do not determine {_join(vague)} of {name}: "
                    + ("its value is not an estimate." if len(vague) == 1
                       else "their values are not estimates."), True))
    return out


def _join(items) -> str:
    items = list(items)
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _undecided_noise(name, result) -> str:
    """``"zener (q 0.236–0.259 under constant noise, 0.463–0.549 under proportional;
    probability 0.891 for constant)"`` where the structure's exponents depend on the noise
    model and the evidence does not decide it; empty otherwise."""
    record = result.criteria.noise_models
    if not record or not record.get("sensitive"):
        return ""
    chosen, models = record["chosen"], record["models"]
    p = models[chosen]["probability"]
    if p is None or p >= NOISE_DECISIVE or not _contested(record):
        return ""
    names = [chosen, *(n for n in _plausible(models) if n != chosen)]
    parts = [f"{ORDER_SYMBOLS.get(param, param)} " + ", ".join(
        f"{models[n]['hdi'][param][0]:.3g}–{models[n]['hdi'][param][1]:.3g} under {n}"
        + (" noise" if i == 0 else "") for i, n in enumerate(names) if param in models[n]["hdi"])
        for param in _contested(record)]
    return f"{name} ({'; '.join(parts)}; probability {p:.3f} for {chosen})"


def _plausible(models) -> list[str]:
    """The noise models the evidence has not excluded (probability of at least
    1 − NOISE_DECISIVE, or none stated)."""
    return [n for n, m in models.items()
            if m["probability"] is None or m["probability"] >= 1.0 - NOISE_DECISIVE]


def _contested(record) -> list[str]:
    """The exponents whose intervals part among the noise models the evidence has not excluded
    (records written before ``contested_parameters`` existed: every sensitive one)."""
    return record.get("contested_parameters", record["sensitive_parameters"])


def _noise_sentences(name, result) -> list[tuple[str, bool]]:
    """How the winner's noise model was chosen, and whether its exponents depend on it."""
    record = result.criteria.noise_models
    if not record:
        return []
    chosen = record["chosen"]
    models = record["models"]
    p = models[chosen]["probability"]
    others = [n for n in models if n != chosen]
    # Against an upper bound of the other's ln Z, the probability is a lower bound.
    least = "at least " if any(models[n].get("evidence_method") == BOUND_METHOD
                               for n in others) else ""
    text = (f"Noise model of {name}: {chosen}, chosen by evidence over "
            f"{_join(others)} noise"
            + (f" (probability {least}{p:.3f})." if p is not None else "."))
    if "marginal" in record:
        text += (" Its ln Z in the ranking is averaged over the noise models (equal prior "
                 "weights), as every structure's is.")
    if not record["sensitive"]:
        return [(text, False)]
    parts = []
    decided = (p is not None and p >= NOISE_DECISIVE) or not _contested(record)
    shown = [chosen, *(n for n in (others if decided else _plausible(models)) if n != chosen)]
    for param in record["sensitive_parameters"] if decided else _contested(record):
        spans = [f"{models[n]['hdi'][param][0]:.3g}–{models[n]['hdi'][param][1]:.3g} under {n} "
                 "noise" for n in shown if param in models[n]["hdi"]]
        parts.append(f"{param} {'; '.join(spans)}")
    excluded = [n for n in others if n not in _plausible(models)]
    if decided and (p is None or p < NOISE_DECISIVE) and excluded:
        # The intervals part only under models the evidence excludes.
        return [(text + f" Its exponents differ only under {_join(excluded)} noise "
                 f"({HDI_PERCENT} % intervals that do not overlap: {'; '.join(parts)}), which "
                 f"the evidence excludes (probability below {1 - NOISE_DECISIVE:.2f}).", False)]
    text += (f" Its exponents depend on the noise model ({HDI_PERCENT} % intervals that do not "
             f"overlap: {'; '.join(parts)})"
             + ("; the evidence decides between them." if decided else
                "; the evidence does not decide between them, so state σ per point or choose "
                "the noise model (--noise) from what you know of the instrument."))
    return [(text, not decided)]
