"""The long-time modulus G_e = lim G(t) as t → ∞ of a compared model: 0 for a model that
relaxes fully (a liquid), exact from the lowest powers of s in its compliance. The Prony export
takes G∞ from it (:func:`~bayesfo.predictions.prony.prony_series`)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .draws import Draws


def long_time_modulus(result, *, structure: str | None = None, average: str | None = None,
                      seed: int = 0) -> np.ndarray:
    """The long-time modulus G_e = lim G(t) as t → ∞ of each draw that
    :func:`~bayesfo.predictions.functions.predict` takes with the same arguments (a master
    curve's at its reference temperature), or of ``result`` given as :class:`Draws`: 0 for a
    draw that relaxes fully (a liquid). Exact, from the lowest powers of s in the compliance
    (:func:`equilibrium_modulus`), not from G(t) at a large t: a springpot of small order
    relaxes too slowly for any finite t to tell.

    Examples
    --------
    >>> import bayesfo as bf
    >>> result = bf.compare(bf.read("examples/data/adhesive_468mp/Tp020C.csv"), "maxwell")  # doctest: +SKIP
    >>> float(np.median(long_time_modulus(result)))  # doctest: +SKIP
    0.0
    """
    if result.data.kind not in ("modulus", "compliance"):
        raise InputError(f"long_time_modulus: the data are a {result.data.kind} transfer "
                         "function; material functions follow from modulus or compliance "
                         "data only")
    if structure is not None and average is not None:
        raise InputError("long_time_modulus: give a structure or an average, not both")
    draws = (result if isinstance(result, Draws)
             else result.draws(structure=structure, average=average, seed=seed))
    g = np.concatenate([equilibrium_modulus(s, theta) for _, s, theta in draws.parts
                        if theta.shape[0]])
    return g if draws.log_b is None else g / 10.0 ** draws.log_b


def equilibrium_modulus(structure, theta) -> np.ndarray:
    """G_e = lim 1/C(s) as s → 0 for each parameter set of ``theta`` (physical units), by the
    master's own ``equilibrium_modulus`` (a relaxation spectrum's is its G_e); of a structure,
    the ratio of the lowest-order terms of the compliance's denominator and numerator. 0 where
    the denominator's lowest power of s is the higher (the model relaxes fully: a liquid);
    inf where it is the lower (a compliance that vanishes at long times).

    Examples
    --------
    A Zener solid, C(s) = (b0 + b1 s^q)/(1 + a1 s^q), relaxes to 1/b0; a fractional Maxwell
    model, C(s) = (1 + b1 s^α)/(a1 s^β), relaxes fully:

    >>> from bayesfo.structures import get_structure
    >>> equilibrium_modulus(get_structure("zener"), [[2.0, 0.5, 0.1, 0.4]])
    array([2.])
    >>> equilibrium_modulus(get_structure("maxwell"), [[1e3, 2.0, 0.3, 0.8]])
    array([0.])
    """
    return np.asarray(structure.equilibrium_modulus(theta), float)
