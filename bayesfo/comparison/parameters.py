"""The parameters of a structure's posterior in the forms a user reads: units derived from the
data's kind and unit, and the physical parameters of the structure's picture (moduli,
quasi-properties, times, orders) beside the card's coefficients, each summarised and judged
whether the data determine it (:func:`not_determined`)."""

from __future__ import annotations

import math

import numpy as np

from ..inference.results import HDI_PROB
from ..structures import coefficient_units, parameter_forms, picture_of

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
    from ..inference._arviz import arviz

    x = np.asarray(values, dtype=float).ravel()
    x = x[~np.isnan(x)]
    out = {"unit": unit}
    if x.size < 2:
        return out | dict.fromkeys(("mean", "sd", "hdi_low", "hdi_high", "median"), math.nan) \
            | {"map": float(map_value)}
    finite = bool(np.all(np.isfinite(x)))
    lo, hi = arviz().hdi(x, hdi_prob=HDI_PROB)
    # Finite draws can still overflow the moments (a time b1**(1/alpha) near alpha = 0 reaches
    # 1e200): those moments are undefined too.
    with np.errstate(over="ignore", invalid="ignore"):
        mean, sd = (float(x.mean()), float(x.std(ddof=1))) if finite else (math.nan, math.nan)
    return out | {"mean": mean if math.isfinite(mean) and math.isfinite(sd) else math.nan,
                  "sd": sd if math.isfinite(sd) else math.nan,
                  "hdi_low": float(lo), "hdi_high": float(hi), "median": float(np.median(x)),
                  "map": float(map_value)}


#: A quantity with a unit is not determined by the data when its HDI spans more than this many
#: decades (:func:`not_determined`).
UNDETERMINED_DECADES = 2.0


def not_determined(summary: dict) -> str | None:
    """Why the data do not determine the quantity of ``summary`` (:func:`summarise_draws`), or
    None where they do.

    Only quantities with a unit are judged here: moduli, quasi-properties, times, the card's
    coefficients, σ. Such a quantity is positive, so its 94 % HDI is read on a log scale: it is
    not determined when the HDI spans more than :data:`UNDETERMINED_DECADES` decades (a factor of
    100), or runs to 0 or to infinity (draws that underflow or overflow, as a time
    (b1/a1)^(1/α) does when the order α runs into its prior bound at 0).

    The threshold is a judgement: a quantity known only to within more than a factor of 100
    has no order of magnitude that the data fix. It lies in the gap seen on real data (the
    default structures on the 20 °C isotherm of the 3M 468MP adhesive and on pyRheo's chia
    gel): the quantities the data fix had HDIs of 0.01 to 1.6 decades, those of structures
    with more freedom than the data need 2.1 decades or more, or ran to 0 (a Zener reduced
    to a Voigt: G_m 2.1–2.5 and τ 2.9–5.3 decades; the fractional Maxwell's c_β, c_δ 3.3–4.0
    decades, its τ and E from 0 to 1e38–1e72; the integer Maxwell on the gel, whose time
    lies beyond the lowest frequency: c_β and τ 2.2 decades). A quantity near the threshold
    can fall on either side from one seed to another. Pure numbers (orders, ``sigma_rel``)
    are judged against their prior instead (``poorly_determined``: the HDI covers more than
    half of the prior range). A quantity whose HDI reaches below 0 is a signed one and is
    not judged.
    """
    if not summary.get("unit"):
        return None
    lo, hi = summary.get("hdi_low"), summary.get("hdi_high")
    if lo is None or hi is None or math.isnan(lo) or math.isnan(hi) or lo < 0:
        return None
    percent = f"{100 * HDI_PROB:g} %"
    if lo == 0 or math.isinf(hi):
        return (f"its {percent} HDI runs from {_bound(lo)} to {_bound(hi)}"
                if hi > 0 else None)
    decades = math.log10(hi) - math.log10(lo)
    if decades > UNDETERMINED_DECADES:
        return f"its {percent} HDI spans {decades:.1f} decades"
    return None


def _bound(x: float) -> str:
    return "infinity" if math.isinf(x) else "0" if x == 0 else f"{x:.3g}"


def with_determination(block: dict, poorly_determined=None) -> dict:
    """``block`` (``{name: summary}``) with ``not_determined`` (bool) and
    ``not_determined_reason`` (:func:`not_determined`, None where determined) in each summary,
    and ``poorly_determined`` copied from ``poorly_determined`` (``{name: bool}`` of the
    sampled parameters) for the names it holds."""
    poorly_determined = poorly_determined or {}
    out = {}
    for name, s in block.items():
        reason = not_determined(s)
        out[name] = dict(s) | {"not_determined": reason is not None,
                               "not_determined_reason": reason}
        if name in poorly_determined:
            out[name]["poorly_determined"] = bool(poorly_determined[name])
    return out


def physical_forms(structure, draws: dict, map_values: dict, kind: str, units: str = "",
                   poorly_determined=None) -> dict:
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

    def block(form, at):
        return with_determination({n: summarise_draws(v, at[n][0], u)
                                   for n, (v, u) in form.items()}, poorly_determined)

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
    of :func:`physical_forms` (undefined values are left out), ``(not determined)`` or
    ``(poorly determined)`` after a value the data do not fix."""
    parts = []
    for name, s in (block or {}).items():
        v = s.get(key)
        if v is None or not math.isfinite(v):
            continue
        flag = (" (not determined)" if s.get("not_determined")
                else " (poorly determined)" if s.get("poorly_determined") else "")
        parts.append(f"{name}={v:.4g}" + (f" {s['unit']}" if s.get("unit") else "") + flag)
    return "; ".join(parts)
