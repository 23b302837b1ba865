"""Model structures, declared as cards in ``bayesfo/models/*.toml`` and evaluated vectorised.

A :class:`Structure` is a transfer function written as a ratio of power terms,
``Σ c_i s^{e_i} / Σ d_j s^{f_j}``, whose coefficients and exponents are parameters or constants,
together with the priors of its free parameters and its constraints. It is something you
evaluate: ``structure.response(theta, omega, kind)`` returns complex values of shape
``(n_sets, n_freq)`` for ``theta`` of shape ``(n_sets, n_params)``, and the same function serves
least squares, MCMC and plotting.

Cards
-----
A card describes one structure (or a family of them) as the **compliance** of a material, as the
thesis does (§2.4.2); for modulus data the same material is compared through the reciprocal. A
single-structure card::

    name = "voigt"
    title = "Fractional Voigt model"
    numerator = [["b0", "0"]]                  # [coefficient, exponent] pairs
    denominator = [[1, "0"], ["a1", "q"]]      # exponents: "0", "q", "2*q", "alpha", 1, ...
    constraints = ["stable", "passive"]        # and inequalities such as "alpha <= beta"
    [parameters]                               # priors on the scaled data, in this order
    a1 = { prior = "log-uniform", low = 1e-4, high = 1e4 }
    b0 = { prior = "log-uniform", low = 1e-4, high = 1e4 }
    q  = { prior = "uniform", low = 0, high = 1 }

Coefficients may be products of parameters (``"G_e*c_alpha"``) and exponents sums
(``"alpha+1"``, ``"kappa+beta"``), so that the named rheology models (springpot, fractional
Kelvin–Voigt, Maxwell gel and liquid, Zener solid–liquid and liquid–liquid, Jeffreys, Burgers;
``docs/models.md``) are written in their physical parameters. Further card keys: ``aliases``
(other names, e.g. RheoJAX's and pyRheo's), ``physical`` (pictures: the mechanical network and
the map between the card's coefficients and physical parameters, :mod:`.physical`),
``inverted = false`` (no ``-inv`` variant) and ``integer`` (see below).

A family card has ``family = "max-order"`` and ``n_max``; its members are the commensurate
structures ``B(λ)/A(λ)`` with ``A = 1 + a1 λ + … + an λ^n`` and ``B = b0 + … + bm λ^m`` for
n = 1..n_max, m = 0..n, and parameter tables may use the patterns ``"a*"`` and ``"b*"``.

Variants are generated, never written by hand: ``NAME-int`` fixes every exponent parameter to 1
(the integer-order baseline) and ``NAME-inv`` is the reciprocal transfer function (for
integrator-like data such as a hydraulic dashpot, thesis §4.3.4). Inverted max-order members
run over m = 1..n_max, n = 0..m. ``NAME-int`` is not generated where it is degenerate (two
springpots in parallel become ``1/((c_alpha + c_beta) s)``: the rank of the response's
Jacobian drops by more than the orders fixed), and a card may name another structure as its
baseline (``integer = "maxwell-int"``), which then answers to ``NAME-int``.

Constraints
-----------
``stable``
    No pole (and for compliance and modulus data no zero: the reciprocal of a passive material
    response is a stable response too) in the closed right half plane. A side that is a
    polynomial in λ = s^p for one exponent parameter p is tested by Matignon's theorem (thesis
    Theorem 3); other sides by the conditions of :mod:`.passivity` (a positive sum of springpots
    with exponents spanning less than 2 has no such zero; integer exponents: Matignon with
    q = 1; otherwise the argument principle). A root at s = 0 is an integrator (Maxwell
    compliance, dashpot), not an instability, and is accepted.
``passive``
    Dissipation ≥ 0 of the response compared with the data (Im J ≤ 0 for a compliance,
    Im G ≥ 0 for a modulus; nothing for generic data), at every frequency. Exact for
    commensurate structures N(λ)/D(λ), λ = s^q: the dissipation polynomial
    P(x) = Σ n_k d_l x^(k+l) sin((k − l) qπ/2) must be ≤ 0 for every x = ω^q > 0, decided by
    the signs of its coefficients and its values at the positive roots of P′
    (:func:`.passivity.commensurate_passive`). Other structures: exact where a sufficient
    condition holds (sums of springpots in series or in parallel; a network with positive
    coefficients and orders in [0, 1], :mod:`.network`), otherwise on a dense grid reaching
    decades beyond the data.
inequalities
    ``lhs <= rhs`` (or ``<``, ``>=``, ``>``), each side a product of parameter names and numbers.
    They must be invariant under the internal scaling (compare exponents with exponents, or
    products with the same units); inverted variants keep only those between exponent
    parameters, because coefficient orderings are statements about the parent material.

Scaling and units
-----------------
Parameters are sampled and optimised on scaled data, ω̃ = ω/ω_ref and G̃ = G/g_ref (see
:class:`Scaling`), and reported in physical units through :meth:`Structure.to_physical`. The
unit of every coefficient follows from the terms (:mod:`.scaling`); :mod:`.physical` reports the
physical parameters with units derived from the data's units
(:func:`physical_parameters`, :func:`coefficient_units`, :func:`parameter_forms`).
"""

from .cards import (
                    CARD_KEYS,
                    MODEL_PATH_ENV,
                    N_MAX_DEFAULT,
                    Library,
                    card_paths,
                    default_library,
                    get_structure,
                    list_structures,
                    load_library,
                    picture_for,
                    resolve_structures,
                    structures_from_card,
)
from .physical import (
                    Picture,
                    coefficient_units,
                    coefficients_from_physical,
                    meanings,
                    parameter_forms,
                    physical_dimensions,
                    physical_parameters,
                    physical_units,
                    picture_of,
                    stress_unit,
)
from .scaling import Scaling
from .structure import Parameter, Structure
from .terms import MAX_DEGREE, Exponent, Inequality, Term
from .variants import fix_parameters, integer_variant, inverted_variant

__all__ = ["CARD_KEYS", "MAX_DEGREE", "MODEL_PATH_ENV", "N_MAX_DEFAULT", "Exponent", "Inequality",
           "Library", "Parameter", "Picture", "Scaling", "Structure", "Term", "card_paths",
           "coefficient_units", "coefficients_from_physical", "default_library",
           "fix_parameters", "get_structure", "integer_variant", "inverted_variant", "list_structures",
           "load_library", "meanings", "parameter_forms", "physical_dimensions", "physical_parameters", "physical_units",
           "picture_for", "picture_of", "resolve_structures", "stress_unit",
           "structures_from_card"]
