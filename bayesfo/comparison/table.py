"""The ranking table: one row per structure from its ``summary.json`` record
(:func:`ranking_rows`, :data:`RANKING_FIELDS`, the columns of ``ranking.csv``), shared by
:meth:`~bayesfo.comparison.Comparison.table` and ``bayesfo batch``, which builds its tables
from stored runs."""

from __future__ import annotations

import math

from .._text import number  # noqa: F401  (the comparison's table writes its numbers)
from ..inference.bound import BOUND_REASON
from .parameters import flagged_names, natural_block, physical_text

#: The parameters that name a structure's fractional order, in order of preference: the
#: commensurate order ``q``; ``beta`` (the generalised Maxwell model's order; the lower order
#: of two springpots in parallel); ``alpha`` (the one springpot of the fractional Maxwell gel
#: and liquid, the Zener solid–liquid and the springpot itself).
ORDER_PARAMS = ("q", "beta", "alpha")
#: The symbols in text of every parameter that is a fractional order (the cards' exponents).
ORDER_SYMBOLS = {"q": "q", "alpha": "α", "beta": "β", "delta": "δ", "kappa": "κ", "gamma": "γ"}
#: The criteria besides the evidence that the ranking table ranks by, as the attributes of
#: :class:`~bayesfo.comparison.Criteria`: +1 where higher is better (elpd), -1 where lower is.
CRITERIA_DIRECTION = {"loo": 1, "waic": 1, "aic": -1, "aicc": -1, "bic": -1}
#: Those of them that the verdict and the figures name.
CRITERIA = {"loo": "PSIS-LOO", "waic": "WAIC", "aic": "AIC", "bic": "BIC"}


def order_parameter(parameters) -> str | None:
    """The name of the fractional order among ``parameters`` (names or a dict by name), the
    first of :data:`ORDER_PARAMS` present, else None."""
    return next((k for k in ORDER_PARAMS if k in parameters), None)


def order_parameters(parameters) -> list[str]:
    """Every fractional order among ``parameters`` (names or a dict by name), in their order:
    a two-springpot model has two (α and β), the Zener liquid–liquid three."""
    return [k for k in parameters if k in ORDER_SYMBOLS]


def orders_text(parameters: dict, digits: int = 3) -> str:
    """Every fractional order of a structure record's ``parameters`` (``summary.json`` form)
    by its symbol, as the posterior mean and 94 % HDI: ``"α 0.589 [0.586–0.592]; β 0.128
    [0.121–0.135]"`` (no commas: one CSV cell readable without quoting); empty where the
    structure has none."""
    parts = []
    for k in order_parameters(parameters):
        p = parameters[k] or {}
        mean, lo, hi = p.get("mean"), p.get("hdi_low"), p.get("hdi_high")
        if mean is None:
            continue
        text = f"{ORDER_SYMBOLS[k]} {mean:.{digits}f}"
        if lo is not None and hi is not None:
            text += f" [{lo:.{digits}f}–{hi:.{digits}f}]"
        parts.append(text)
    return "; ".join(parts)


def _finite_or_none(value) -> bool:
    return value is not None and math.isfinite(value)


def ranking_rows(structures, ranking) -> list[dict]:
    """The rows of the ranking table (:data:`RANKING_FIELDS`), one per structure, best first
    and structures that could not be run last: the one definition of a ranking row, used by
    :meth:`Comparison.table` and by ``bayesfo batch`` (from a stored ``summary.json``).

    Parameters
    ----------
    structures : sequence of dict
        Each structure's record as ``summary.json`` holds it (:meth:`StructureResult.to_dict`,
        in the order the structures were run). Missing entries are None in the row; a number
        that is None (JSON's null for NaN or infinity) ranks last, like NaN.
    ranking : sequence of str
        The structure names, best first (:attr:`Comparison.ranking`).

    Returns
    -------
    list of dict
        Failed structures: ``rank`` None, ``structure``, ``n_params``, ``error``.
    """
    order = {n: i for i, n in enumerate(ranking)}
    ok = [s for s in structures if "error" not in s]
    loos = [s.get("loo") for s in ok if _finite_or_none(s.get("loo"))]
    best_loo = max(loos, default=math.nan)
    best_z = max((s["log_evidence"] for s in ok if s.get("log_evidence") is not None),
                 default=math.nan)
    ranks = {}
    for crit, better in CRITERIA_DIRECTION.items():
        # An undefined criterion (NaN, with its reason among the warnings) ranks last.
        ordered = sorted(ok, key=lambda s, c=crit, g=-better: (
            not _finite_or_none(s.get(c)), g * s[c] if _finite_or_none(s.get(c)) else 0))
        ranks[crit] = {s["name"]: i + 1 for i, s in enumerate(ordered)}
    rows = []
    for s in sorted(structures, key=lambda s: order.get(s["name"], len(order))):
        name = s["name"]
        if "error" in s:
            rows.append({"rank": None, "structure": name, "n_params": s.get("n_params"),
                         "error": s["error"]})
            continue
        params = s.get("parameters") or {}
        q_name = order_parameter(params)
        q = params[q_name] if q_name is not None else None
        log_z = s.get("log_evidence")
        loo = s.get("loo")
        adequacy = s.get("adequacy")
        if adequacy is None:
            fits = None
        else:
            fits = (("partly" if adequacy.get("misfit_masked") else "yes")
                    if adequacy.get("adequate")
                    else "small" if adequacy.get("misfit_small") else "no")
        p_values = None if adequacy is None else [
            math.nan if v is None else v for v in adequacy.get("p_values", {}).values()]
        rows.append({
            "rank": order[name] + 1 if name in order else None, "structure": name,
            "n_params": s.get("n_params"), "parent": s.get("parent"), "log_evidence": log_z,
            "log_evidence_err": s.get("log_evidence_err"),
            "evidence_method": s.get("evidence_method"),
            "delta_log_evidence": None if log_z is None else log_z - best_z,
            "bayes_factor": None if log_z is None else math.exp(log_z - best_z),
            "posterior_probability": s.get("posterior_probability"),
            "evidence_agree": s.get("evidence_agree"),
            **{f"rank_{k}": v[name] for k, v in ranks.items()},
            "loo": loo, "loo_se": s.get("loo_se"),
            "delta_loo": None if loo is None else loo - best_loo,
            "delta_loo_se": s.get("delta_loo_se"),
            "waic": s.get("waic"), "aic": s.get("aic"), "aicc": s.get("aicc"),
            "bic": s.get("bic"), "max_log_likelihood": s.get("max_log_likelihood"),
            "rmse": s.get("rmse"),
            "holdout_lpd": s.get("holdout_lpd"), "holdout_rmse": s.get("holdout_rmse"),
            "q_mean": None if q is None else q.get("mean"),
            "q_sd": None if q is None else q.get("sd"),
            "pareto_k_max": s.get("pareto_k_max"), "rhat_max": s.get("rhat_max"),
            "ess_min": s.get("ess_min"), "converged": s.get("converged"),
            "sampler": s.get("sampler"), "fits": fits,
            "adequate": None if adequacy is None else adequacy.get("adequate"),
            "adequacy_p_min": None if not p_values else min(p_values),
            "max_phase_error_deg": None if adequacy is None
            else adequacy.get("max_phase_error_deg"),
            "max_log10_magnitude_error": None if adequacy is None
            else adequacy.get("max_log10_magnitude_error"),
            "error": "",
            # Posterior medians of the physical parameters, with units, as one text cell.
            "physical_parameters": physical_text(s.get("parameters_physical")),
            # Every fractional order by its symbol (q_mean and q_sd hold only the first).
            "orders": "" if s.get("integer") else orders_text(natural_block(s)),
            # The parameters (in the form natural to the data) that the data do not determine,
            # and those whose HDI covers more than half of their prior range.
            "not_determined": "; ".join(flagged_names(natural_block(s))),
            "poorly_determined": "; ".join(flagged_names(natural_block(s),
                                                         "poorly_determined")),
            # Left out by the evidence bound (sampled false): ln Z and P are at most these.
            "sampled": s.get("sampled", True),
            "log_evidence_bound": s.get("log_evidence_bound"),
            "delta_log_evidence_bound": None if s.get("log_evidence_bound") is None
            else s["log_evidence_bound"] - best_z,
            "posterior_probability_bound": s.get("posterior_probability_bound"),
        })
    return rows


RANKING_FIELDS = ("rank", "structure", "parent", "n_params", "log_evidence", "log_evidence_err",
                  "evidence_method", "delta_log_evidence", "bayes_factor", "posterior_probability", "evidence_agree",
                  "loo", "loo_se", "delta_loo", "rank_loo", "waic", "rank_waic", "aic", "rank_aic",
                  "aicc", "rank_aicc", "bic", "rank_bic", "max_log_likelihood", "rmse",
                  "holdout_lpd", "holdout_rmse", "q_mean",
                  "q_sd", "pareto_k_max", "rhat_max", "ess_min", "converged", "sampler",
                  "fits", "adequate", "adequacy_p_min", "max_phase_error_deg",
                  "max_log10_magnitude_error", "error", "physical_parameters", "delta_loo_se",
                  "not_determined", "poorly_determined", "orders", "sampled",
                  "log_evidence_bound", "delta_log_evidence_bound", "posterior_probability_bound")



def order_means(row: dict) -> str:
    """The posterior means of every fractional order of a ranking row, by symbol
    (``"α 0.589 β 0.128"``), from its ``orders`` cell."""
    return " ".join(part.split(" [")[0] for part in (row.get("orders") or "").split("; ")
                    if part)


#: The ranking in text: (header, minimum width, cell of a ranked row). The structure's name is
#: left-aligned, every other column right-aligned; a column is as wide as its widest cell.
TEXT_COLUMNS = (
    ("#", 2, lambda r: str(r["rank"])),
    ("structure", 16, lambda r: r["structure"]),
    ("k", 2, lambda r: str(r["n_params"])),
    ("ln Z", 18, lambda r: (f"≤ {number(r['log_evidence_bound'])}   "
                            if r.get("log_evidence_bound") is not None else "-")
     if r["log_evidence"] is None else
     f"{number(r['log_evidence'])} ± {number(r['log_evidence_err'])}"
     + (" L" if r["evidence_method"] == "ladder" else "  ")),
    ("dlnZ", 8, lambda r: (f"≤ {number(r['delta_log_evidence_bound'])}"
                           if r.get("delta_log_evidence_bound") is not None else "-")
     if r["log_evidence"] is None else number(r["delta_log_evidence"])),
    ("P", 6, lambda r: (f"≤ {r['posterior_probability_bound']:.0e}"
                        if r.get("posterior_probability_bound") is not None else "-")
     if r["log_evidence"] is None else number(r["posterior_probability"], ".3f")),
    ("elpd_loo", 10, lambda r: number(r["loo"])),
    ("BIC", 10, lambda r: number(r["bic"])),
    ("orders (mean)", 13, order_means),
    ("R-hat", 6, lambda r: number(r["rhat_max"], ".3f")),
    ("ok", 3, lambda r: "yes" if r["converged"] else "-" if r.get("sampled") is False
     else "NO"),
    ("fits", 6, lambda r: (r["fits"] or "-").replace("no", "NO")),
)


def ranking_lines(rows: list[dict]) -> list[str]:
    """The ranking table in text (``bayesfo compare`` prints it; :meth:`Comparison.summary`
    too): a header and a line per structure of :func:`ranking_rows`, the ranked ones first and
    each one that failed with its reason; columns as wide as their widest cell, so that a huge
    ln Z keeps the table aligned."""
    ranked = [r for r in rows if not r.get("error")]
    cells = [[cell(r) for _, _, cell in TEXT_COLUMNS] for r in ranked]
    widths = [max([minimum, len(header)] + [len(c[k]) for c in cells])
              for k, (header, minimum, _) in enumerate(TEXT_COLUMNS)]
    widths[1] = max([widths[1]] + [len(r["structure"]) for r in rows])

    def line(values):
        return " ".join(f"{v:<{w}}" if k == 1 else f"{v:>{w}}"
                        for k, (v, w) in enumerate(zip(values, widths, strict=True)))

    lines = [line([header for header, _, _ in TEXT_COLUMNS]), *map(line, cells)]
    if any(r.get("sampled") is False for r in ranked):
        lines.append(f"≤: {BOUND_REASON} (ln Z ≤ max ln L); no PSIS-LOO, WAIC or posterior "
                     "figures; --sample all samples it")
    for r in rows:
        if r.get("error"):
            lines.append(f"{'-':>{widths[0]}} {r['structure']:<{widths[1]}} "
                         f"{r['n_params']:>{widths[2]}}  failed: {r['error']}")
    return lines
