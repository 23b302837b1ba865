"""The parameters of a structure's posterior in the forms a user reads: units derived from the
data's kind and unit, and the physical parameters of the structure's picture (moduli,
quasi-properties, times, orders) beside the card's coefficients, each summarised."""

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


def physical_forms(structure, draws: dict, map_values: dict, kind: str, units: str = "") -> dict:
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
        Each summary is that of :func:`summarise_draws`.
    """
    natural, other = parameter_forms(structure, draws, kind, units)
    at_map = parameter_forms(structure, map_values, kind, units)
    modulus = kind == "modulus"
    physical, coefficients = (natural, other) if modulus else (other, natural)
    map_physical, map_coefficients = (at_map if modulus else at_map[::-1])

    def block(form, at):
        return {n: summarise_draws(v, at[n][0], u) for n, (v, u) in form.items()}

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
    of :func:`physical_forms` (undefined values are left out)."""
    parts = []
    for name, s in (block or {}).items():
        v = s.get(key)
        if v is None or not math.isfinite(v):
            continue
        parts.append(f"{name}={v:.4g}" + (f" {s['unit']}" if s.get("unit") else ""))
    return "; ".join(parts)
