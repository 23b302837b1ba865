"""The parameters of a structure's posterior in the forms a user reads: units derived from the
data's kind and unit, and the physical parameters of the structure's picture (moduli,
quasi-properties, times, orders) beside the card's coefficients, each summarised and judged
whether the data determine it (:func:`not_determined`)."""

from __future__ import annotations

import math

import numpy as np

from ..inference import hdi
from ..inference.results import HDI_PROB
from ..predictions.prony import EXTRAPOLATED
from ..structures import coefficient_units, parameter_forms, picture_of
from ..structures.physical import stress_unit

#: Noise parameters sampled with a structure: ``sigma`` has the data's unit, ``sigma_rel`` none.
NOISE_UNITS = {"sigma": "data", "sigma_rel": ""}


def parameter_units(structure, names, kind: str, units: str = "") -> dict[str, str]:
    """The unit of each sampled parameter: the card's coefficients from the data's ``kind``
    and ``units`` (:func:`~bayesfo.structures.coefficient_units`; ``""`` for orders), ``sigma``
    in the data's unit and ``sigma_rel`` without one.

    Examples
    --------
    >>> from bayesfo.structures import get_structure
    >>> parameter_units(get_structure("voigt"), ("a1", "b0", "q", "sigma"), "modulus", "Pa")
    {'a1': 's^q', 'b0': '1/Pa', 'q': '', 'sigma': 'Pa'}
    """
    own = coefficient_units(structure, kind, units)
    out = {}
    for n in names:
        if n in own:
            out[n] = own[n]
        elif n in NOISE_UNITS:
            out[n] = (units or "") if NOISE_UNITS[n] == "data" else NOISE_UNITS[n]
        else:
            out[n] = ""
    return out


def summarise_draws(values, map_value, unit: str) -> dict:
    """``{unit, mean, sd, hdi_low, hdi_high, median, map}`` of the draws of one quantity, as
    the posterior summarises its parameters (94 % HDI by arviz). A draw at ±inf (an order at
    its bound makes a time overflow) leaves mean and sd undefined (NaN, null in JSON); the HDI
    and the median are those of all draws."""
    x = np.asarray(values, dtype=float).ravel()
    x = x[~np.isnan(x)]
    out = {"unit": unit}
    if x.size < 2:
        return out | dict.fromkeys(("mean", "sd", "hdi_low", "hdi_high", "median"), math.nan) \
            | {"map": float(map_value)}
    finite = bool(np.all(np.isfinite(x)))
    lo, hi = hdi(x, HDI_PROB)
    # Finite draws can still overflow the moments (a time b1**(1/alpha) near alpha = 0 reaches
    # 1e200): those moments are undefined too.
    with np.errstate(over="ignore", invalid="ignore"):
        mean, sd = (float(x.mean()), float(x.std(ddof=1))) if finite else (math.nan, math.nan)
    return out | {"mean": mean if math.isfinite(mean) and math.isfinite(sd) else math.nan,
                  "sd": sd if math.isfinite(sd) else math.nan,
                  "hdi_low": float(lo), "hdi_high": float(hi), "median": float(np.median(x)),
                  "map": float(map_value)}


#: A quantity with a unit is not determined by the data when the 94 % HDI of its decimal
#: logarithm spans more than this many decades (:func:`not_determined`).
UNDETERMINED_DECADES = 2.0


def not_determined(summary: dict, draws=None) -> str | None:
    """Why the data do not determine the quantity of ``summary`` (:func:`summarise_draws`), or
    None where they do.

    Parameters
    ----------
    summary : dict
        The quantity's summary: its ``unit`` and, where ``draws`` are not given, its
        ``hdi_low`` and ``hdi_high``.
    draws : array_like, optional
        The quantity's posterior draws. Where given (as they are for every summary a comparison
        writes), a positive quantity is judged on the HDI of ``log10(draws)``; without them,
        on ``log10`` of the HDI's ends.

    Returns
    -------
    str or None
        The reason, in words (``"its 94 % HDI on a log scale spans 2.8 decades"``), or None.

    Notes
    -----
    Only quantities with a unit are judged here: moduli, quasi-properties, times, the card's
    coefficients, σ. Pure numbers (orders, ``sigma_rel``) are judged against their prior
    instead (``poorly_determined``: the HDI covers more than half of the prior range).

    *Positive quantities* (all draws ≥ 0; a draw at 0 or infinity is one that underflowed or
    overflowed, as a time (b1/a1)^(1/α) does when the order α runs into its prior bound at 0)
    are judged on a log scale: not determined when the 94 % HDI of ``log10(draws)`` spans more
    than :data:`UNDETERMINED_DECADES` decades (a factor of 100), or runs to 0 or infinity.
    The HDI is taken of the logarithms, not read off the HDI of the values, so that a quantity
    and its reciprocal (b0 and G_e = 1/b0) get the same verdict: the HDI of the values leans
    towards small values and spans more decades than that of the logarithms (for a lognormal
    posterior with a log-scale HDI 1.50 decades wide, the values' HDI spans 1.98). The
    ``hdi_low``/``hdi_high`` of the summary stay the HDI of the values.

    *Signed quantities* (some draws below 0): not determined when the HDI of the values reaches
    0 or across it (the data do not fix even the sign); otherwise, the sign being fixed, the
    draws of that sign are judged as a positive quantity on their magnitudes. Draws that are
    all ≤ 0 are judged on their magnitudes.

    *Undefined draws*: a quantity that is NaN (undefined, e.g. a time of a negative ratio) at
    more than 6 % of the draws, the share outside a 94 % HDI, has no 94 % HDI and is not
    determined; so is one with fewer than two defined draws. Without draws, an HDI that is
    NaN is likewise not determined. Fewer NaN draws are left out.

    The threshold is a judgement: a quantity known only to within more than a factor of 100
    has no order of magnitude that the data fix. It lies in a gap between the spans of the
    quantities with units on real data: the undetermined ones (a Zener reduced to a Voigt, a
    fractional Maxwell whose order ran to 0) above it, the rest below, some of which the HDIs
    of the values would have put above it (BENCHMARKS.md, "Measurements behind design
    choices"). A quantity near the threshold can fall on either side from one seed to another.
    A quantity bounded by the data on one side only is judged by how far its posterior spreads
    on the log scale, which its prior shapes: a coefficient under a uniform prior that the data
    bound only from above has most of its draws within a decade or two of that bound.
    """
    if not summary.get("unit"):
        return None
    percent = f"{100 * HDI_PROB:g} %"
    if draws is None:
        return _judged_on_summary(summary, percent)
    x = np.asarray(draws, dtype=float).ravel()
    defined = x[~np.isnan(x)]
    share = 1.0 - defined.size / x.size if x.size else 1.0
    if defined.size < 2 or share > 1.0 - HDI_PROB:
        return f"it is undefined at {100 * share:.0f} % of the draws"
    if np.any(defined < 0):
        if np.all(defined <= 0):
            defined = -defined
        else:
            lo, hi = (float(v) for v in _hdi(defined))
            if lo <= 0 <= hi:
                return (f"its {percent} HDI runs from {_bound(lo)} to {_bound(hi)}, across 0: "
                        "the data do not fix its sign")
            defined = np.abs(defined[defined > 0] if lo > 0 else defined[defined < 0])
    return _judged(*_log_hdi(defined), percent)


def _log_hdi(x) -> tuple[float, float, float]:
    """The HDI of ``log10(x)`` (x ≥ 0) as values, 0 or infinity where a draw underflowed or
    overflowed, and its width in decades (infinite then)."""
    with np.errstate(divide="ignore"):
        lo, hi = (float(v) for v in _hdi(np.log10(x)))
    return (10.0 ** lo if math.isfinite(lo) else (0.0 if lo < 0 else math.inf),
            10.0 ** hi if math.isfinite(hi) else (0.0 if hi < 0 else math.inf),
            hi - lo if math.isfinite(lo) and math.isfinite(hi) else math.inf)


def log_scale_hdi(summary: dict, draws) -> tuple[float, float] | None:
    """The 94 % HDI of a positive quantity with a unit taken on a log scale, as values
    (``10**`` the ends of the HDI of ``log10(draws)``): the interval that
    :func:`not_determined` judges, which reports show in place of the HDI of the values (that
    one leans towards small values). None for a pure number, a quantity with draws below 0,
    undefined (NaN) draws, or no draws."""
    judged = _positive_log_hdi(summary, draws)
    return None if judged is None else judged[:2]


def _positive_log_hdi(summary: dict, draws) -> tuple[float, float, float] | None:
    """:func:`_log_hdi` of the draws of a positive quantity with a unit; None otherwise (see
    :func:`log_scale_hdi`)."""
    if not summary.get("unit") or draws is None:
        return None
    x = np.asarray(draws, dtype=float).ravel()
    if x.size < 2 or np.isnan(x).any() or np.any(x < 0):
        return None
    return _log_hdi(x)


def shown_hdi(summary: dict) -> tuple[float, float]:
    """The interval a report shows for a quantity summarised by :func:`with_determination`:
    the HDI on a log scale where there is one (:func:`log_scale_hdi`), else the HDI of the
    values."""
    if summary.get("hdi_log_low") is not None and summary.get("hdi_log_high") is not None:
        return summary["hdi_log_low"], summary["hdi_log_high"]
    return summary.get("hdi_low"), summary.get("hdi_high")


def _hdi(x):
    with np.errstate(invalid="ignore"):  # inf - inf among the candidate widths
        return hdi(x, HDI_PROB)


def _judged_on_summary(summary: dict, percent: str) -> str | None:
    """:func:`not_determined` from the ends of the HDI of the values alone (no draws)."""
    lo, hi = summary.get("hdi_low"), summary.get("hdi_high")
    if lo is None or hi is None or math.isnan(lo) or math.isnan(hi):
        return f"its {percent} HDI is undefined"
    if lo <= 0 <= hi and lo < 0:
        return (f"its {percent} HDI runs from {_bound(lo)} to {_bound(hi)}, across 0: the "
                "data do not fix its sign")
    lo, hi = sorted((abs(lo), abs(hi)))
    with np.errstate(divide="ignore"):
        decades = float(np.log10(hi) - np.log10(lo)) if 0 < lo and hi < math.inf else math.inf
    return _judged(lo, hi, decades, percent)


def _judged(lo: float, hi: float, decades: float, percent: str) -> str | None:
    if lo == 0 or math.isinf(hi):
        return f"its {percent} HDI runs from {_bound(lo)} to {_bound(hi)}"
    if decades > UNDETERMINED_DECADES:
        return f"its {percent} HDI on a log scale spans {decades:.1f} decades"
    return None


def _bound(x: float) -> str:
    return ("infinity" if x == math.inf else "-infinity" if x == -math.inf
            else "0" if x == 0 else f"{x:.3g}")


def with_determination(block: dict, poorly_determined=None, draws=None, limited=None) -> dict:
    """``block`` (``{name: summary}``) with ``not_determined`` (bool) and
    ``not_determined_reason`` (:func:`not_determined`, None where determined) in each summary,
    and ``poorly_determined`` copied from ``poorly_determined`` (``{name: bool}`` of the
    sampled parameters) for the names it holds. ``draws`` (``{name: draws}``) are the draws
    each quantity is judged on (:func:`not_determined`); a name without them is judged on its
    summary's HDI. ``limited`` (``{name: reason}``, :func:`limit_reasons`): quantities whose
    posterior a prior bound ends, not determined for that reason where not already for
    another."""
    poorly_determined = poorly_determined or {}
    draws = draws or {}
    limited = limited or {}
    out = {}
    percent = f"{100 * HDI_PROB:g} %"
    for name, s in block.items():
        # A positive quantity with a unit: its log-scale HDI, computed once, is both what is
        # shown and what is judged (as not_determined judges it).
        judged = _positive_log_hdi(s, draws.get(name))
        reason = (not_determined(s, draws.get(name)) if judged is None
                  else _judged(*judged, percent)) or limited.get(name)
        out[name] = dict(s) | {"not_determined": reason is not None,
                               "not_determined_reason": reason}
        if judged is not None:
            out[name]["hdi_log_low"], out[name]["hdi_log_high"] = judged[:2]
        if name in poorly_determined:
            out[name]["poorly_determined"] = bool(poorly_determined[name])
    return out


#: A quantity of the picture follows a coefficient whose posterior a prior bound ends where
#: their rank correlation over the draws is at least this (:func:`physical_forms`): G_e = 1/b0
#: follows b0 wholly (1.0), while a modulus a1/b1 of two coefficients that run to their bounds
#: together along a ridge is fixed by the data (|rho| under 0.1 on the adhesive at -10 °C).
FOLLOWS = 0.5


def prior_limited(structure, summary: dict) -> dict:
    """``{name: side}`` (``"lower"`` or ``"upper"``) of the sampled parameters whose posterior
    a prior bound ends (``ParameterSummary.at_prior_bound``): every parameter but the orders,
    whose bounds (0 and 1) are the structure's own (an order at 0 is an element that vanishes).
    A coefficient's prior is a range as wide as the data's scale allows (log-uniform over eight
    decades of the scaled problem): a posterior that runs into it is one the data leave open on
    that side, whose HDI the prior alone sets (a zero-shear viscosity at the prior's top)."""
    orders = set(structure.exponent_params)
    side = {"low": "lower", "high": "upper"}
    return {n: side[s.at_prior_bound] for n, s in summary.items()
            if getattr(s, "at_prior_bound", "") and n not in orders}


def limit_reasons(limited: dict) -> dict:
    """``{name: reason}`` of :func:`prior_limited`'s parameters, as ``not_determined_reason``
    gives it."""
    return {n: f"its posterior runs to the prior's {side} bound, {_WIDEN.format(n)}"
            for n, side in limited.items()}


_WIDEN = "which the prior, not the data, sets (--prior {}=... widens it, on the scaled problem)"


def _following(structure, form: dict, draws: dict, limited: dict) -> dict:
    """``{name: reason}`` of the quantities of ``form`` (``{name: (values, unit)}``) that follow
    a parameter of ``limited`` (:func:`prior_limited`): one their expression names, with a
    rank correlation over the draws of at least :data:`FOLLOWS`."""
    if not limited or not structure.pictures:
        return {}
    pic = picture_of(structure)
    expressions = {p.name: p.value for p in (*pic.parameters, *pic.derived)}

    def ranks(x):
        return np.argsort(np.argsort(np.asarray(x, float).ravel()))

    out = {}
    for name, (values, _) in form.items():
        if name in limited or name not in expressions:
            continue
        for n in sorted(expressions[name].names & set(limited)):
            v, c = np.asarray(values, float).ravel(), np.asarray(draws[n], float).ravel()
            ok = np.isfinite(v) & np.isfinite(c)
            if ok.sum() < 10 or np.ptp(v[ok]) == 0:
                continue
            rho = float(np.corrcoef(ranks(v[ok]), ranks(c[ok]))[0, 1])
            if abs(rho) >= FOLLOWS:
                out[name] = (f"it follows {n} (rank correlation {rho:+.2f}), whose posterior "
                             f"runs to the prior's {limited[n]} bound, {_WIDEN.format(n)}")
                break
    return out


def extrapolated(block: dict, data) -> dict[str, str]:
    """``{name: flag}`` of the quantities of ``block`` (``{name: summary}``) that the model
    extrapolates, however narrow their 94 % HDI: a time whose HDI lies wholly outside the times
    ``data`` cover (1/ω_max to 1/ω_min), and, for modulus data, a modulus whose HDI lies
    wholly above :data:`~bayesfo.predictions.prony.EXTRAPOLATED` times the largest measured
    |G*| (a plateau beyond the highest frequency). Quantities not determined are left out."""
    t_lo, t_hi = 1.0 / float(np.max(data.omega)), 1.0 / float(np.min(data.omega))
    modulus = stress_unit("modulus", data.units or "") if data.kind == "modulus" else None
    top = float(np.max(np.abs(data.response)))
    out = {}
    for name, s in block.items():
        lo, hi = s.get("hdi_low"), s.get("hdi_high")
        if (s.get("not_determined") or lo is None or hi is None
                or not (math.isfinite(lo) and math.isfinite(hi))):
            continue
        if s.get("unit") == "s" and (hi < t_lo or lo > t_hi):
            out[name] = (f"beyond the data window (t = 1/ω from {t_lo:.3g} to {t_hi:.3g} s): "
                         "the model's extrapolation")
        elif modulus is not None and s.get("unit") == modulus and lo > EXTRAPOLATED * top:
            out[name] = (f"above every measured |{data.symbol}*| (at most {top:.3g}): the "
                         "model's extrapolation past the highest frequency")
    return out


def physical_forms(structure, draws: dict, map_values: dict, kind: str, units: str = "",
                   poorly_determined=None, limited=None) -> dict:
    """The parameters of ``structure`` in both forms, summarised, with units.

    Parameters
    ----------
    structure : Structure
    draws : dict
        ``{name: draws}`` of the structure's free parameters in physical (unscaled) units, as
        ``PosteriorResult.samples`` holds them.
    map_values : dict
        ``{name: value}`` of the draw of highest posterior density.
    kind, units : str
        The data's kind and unit.
    poorly_determined : dict, optional
        ``{name: bool}`` of the sampled parameters (``ParameterSummary.poorly_determined``),
        copied into the summaries of the same names.
    limited : dict, optional
        ``{name: side}`` of the sampled parameters whose posterior a prior bound ends
        (:func:`prior_limited`): they, and the quantities that follow one of them, are not
        determined for that reason.

    Returns
    -------
    dict
        ``natural_form``: ``"physical"`` for modulus data, ``"coefficients"`` for compliance
        and generic data and for structures without a picture; ``picture``: the name of the structure's default picture (None for
        structures without one: inverted variants, the max-order family); ``physical``:
        ``{name: summary}`` of the physical parameters (moduli, quasi-properties, orders, derived
        times; the card's coefficients for a structure without a picture); ``other``: the form
        not natural to the data (the card's coefficients for modulus data, the physical
        parameters otherwise; None for a structure without a picture); ``coefficient_units``.
        Each summary is that of :func:`summarise_draws`, with ``not_determined`` and
        ``not_determined_reason`` (:func:`with_determination`).
    """
    natural, other = parameter_forms(structure, draws, kind, units)
    at_map = parameter_forms(structure, map_values, kind, units)
    modulus = kind == "modulus"
    physical, coefficients = (natural, other) if modulus else (other, natural)
    map_physical, map_coefficients = (at_map if modulus else at_map[::-1])

    limited = limited or {}

    def block(form, at):
        return with_determination({n: summarise_draws(v, at[n][0], u)
                                   for n, (v, u) in form.items()}, poorly_determined,
                                  draws={n: v for n, (v, _) in form.items()},
                                  limited=limit_reasons(limited)
                                  | _following(structure, form, draws, limited))

    has_picture = bool(structure.pictures)
    phys = block(physical, map_physical) if has_picture else block(coefficients, map_coefficients)
    coefs = block(coefficients, map_coefficients)
    return {"natural_form": "physical" if modulus and has_picture else "coefficients",
            "picture": picture_of(structure).name if has_picture else None,
            "physical": phys,
            "other": None if not has_picture else (coefs if modulus else phys),
            "coefficient_units": {n: u for n, (_, u) in coefficients.items()}}


def physical_text(block: dict, key: str = "median") -> str:
    """``"G_e=1.2e+05 Pa; c_q=3.4e+04 Pa s^q; q=0.57"``: one value of each parameter of a block
    of :func:`physical_forms` (undefined values are left out). The text is ``name=value unit``
    and nothing else (scripts parse it); whether the data determine a value is in the block's
    flags (:func:`flagged_names`)."""
    parts = []
    for name, s in (block or {}).items():
        v = s.get(key)
        if v is None or not math.isfinite(v):
            continue
        parts.append(f"{name}={v:.4g}" + (f" {s['unit']}" if s.get("unit") else ""))
    return "; ".join(parts)


def flagged_names(block: dict, flag: str = "not_determined") -> list[str]:
    """The names in ``block`` (``{name: summary}``) whose summary has ``flag`` set
    (``"not_determined"`` or ``"poorly_determined"``), in the block's order."""
    return [name for name, s in (block or {}).items() if s.get(flag)]


def natural_block(record: dict) -> dict:
    """The parameters of a structure's ``summary.json`` record in the form natural to the data:
    ``parameters_physical`` where ``natural_form`` is ``"physical"``, else ``parameters`` (the
    card's coefficients and the noise, as sampled). The terminal, the verdict and the
    ``not_determined`` column of ``ranking.csv`` name the parameters of this form."""
    if record.get("natural_form") == "physical" and record.get("parameters_physical"):
        return record["parameters_physical"]
    return record.get("parameters") or {}
