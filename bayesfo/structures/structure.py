"""A structure: the transfer function of a card with its parameters and priors, evaluated
vectorised over parameter sets, with its constraints (stability, dissipation, inequalities)
and the scaling between physical units and the scaled problem."""

from __future__ import annotations

from contextlib import nullcontext
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from .._io import show
from ..errors import StructureError
from ..priors import Prior
from . import passivity
from .parameters import Parameter, Parametrised, in_prior_support  # noqa: F401
from .passivity import commensurate_passive, side_stable, springpot_sum_passive
from .response import (
    commensurate_response,
    dissipation_grid,
    is_dissipative,
    matignon_stable,
    power_ratio,
)
from .scaling import ScalePlan, Scaling, scale_plan
from .terms import Inequality, Term


@dataclass(frozen=True, eq=False)
class Structure(Parametrised):
    """A transfer-function structure with priors and constraints.

    Build structures from cards (:func:`load_library`, :func:`get_structure`) rather than by
    hand. Arrays of parameters have shape ``(n_params,)`` or ``(n_sets, n_params)`` with the
    columns in the order of :attr:`param_names`; the results then have shape ``(n_freq,)`` or
    ``(n_sets, n_freq)``.

    Examples
    --------
    >>> import numpy as np
    >>> from bayesfo.structures import get_structure
    >>> voigt = get_structure("voigt")
    >>> voigt.param_names
    ('a1', 'b0', 'q')
    >>> g = voigt.transfer([1.0, 2.0, 0.5], np.array([1.0]))
    >>> bool(np.isclose(g[0], 2.0 / (1 + np.sqrt(1j))))
    True
    """

    name: str
    numerator: tuple[Term, ...]
    denominator: tuple[Term, ...]
    parameters: tuple[Parameter, ...]
    fixed: dict = field(default_factory=dict)
    constraints: tuple = ()
    title: str = ""
    description: str = ""
    reference: str = ""
    family: str = ""
    inverted: bool = False
    integer: bool = False
    degrees: tuple[int, int] | None = None  # (n, m) of A and B before any inversion
    card: str = ""
    #: Physical pictures (:class:`~bayesfo.structures.physical.Picture`), the default first;
    #: empty for inverted variants, whose reciprocal is not the material of the card.
    pictures: tuple = ()
    #: Other names of the structure (e.g. ``fractional_kelvin_voigt_s`` for ``voigt``).
    aliases: tuple[str, ...] = ()
    #: The integer-order baseline when it is another structure of the library (``maxwell-int``
    #: for the fractional Maxwell gel), rather than a generated ``-int`` variant.
    baseline: str = ""

    def __post_init__(self):
        self._validate()

    # ------------------------------------------------------------------ introspection
    @property
    def priors(self) -> dict[str, Prior]:
        return {p.name: p.prior for p in self.parameters}

    @property
    def exponent_params(self) -> tuple[str, ...]:
        """Parameters in the exponents (free or fixed)."""
        names = {p for t in self.numerator + self.denominator for p in t.exponent.params}
        return tuple(sorted(names))

    @cached_property
    def commensurate_order(self) -> str | None:
        """The name of q when numerator and denominator are polynomials in λ = s^q, else None."""
        p = _polynomial_order(self.numerator + self.denominator)
        return p if p != "" else None

    @property
    def formula(self) -> str:
        """The transfer function as text, e.g. ``b0 / (1 + a1 s^q)``."""

        def side(terms, below=False):
            fixed = [Term(t.coef, t.exponent.substitute(self.fixed)) for t in terms]
            text = " + ".join(str(t) for t in fixed)
            product = below and len(terms[0].factors) > 1
            return f"({text})" if len(terms) > 1 or product else text

        return f"{side(self.numerator)} / {side(self.denominator, below=True)}"

    def describe(self) -> dict:
        """Plain-Python description (name, formula, priors, constraints) for reports."""
        out = {
            "name": self.name,
            "family": self.family,
            "formula": self.formula,
            "inverted": self.inverted,
            "integer": self.integer,
            "n_params": self.n_params,
            "parameters": {p.name: p.prior.to_dict() for p in self.parameters},
            "fixed": dict(self.fixed),
            "constraints": [c if isinstance(c, str) else c.text for c in self.constraints],
            "title": self.title,
            "reference": self.reference,
        }
        if self.aliases:
            out["aliases"] = list(self.aliases)
        if self.pictures:
            out["pictures"] = [p.describe() for p in self.pictures]
            if self.modulus_formula is not None:
                out["modulus_formula"] = self.modulus_formula
        return out

    @property
    def modulus_formula(self) -> str | None:
        """G*(s) in the physical parameters of the default picture (``G_e + c_q s^q`` for the
        fractional Voigt), with the orders this variant fixes written as their values; None for
        a structure without a mechanical network (inverted variants, the max-order family).
        :attr:`formula` is the card's compliance J(s)."""
        network = self.pictures[0].network if self.pictures else None
        return None if network is None else network.modulus_text(dict(self.fixed))

    def with_picture(self, name: str) -> Structure:
        """A copy whose default picture (the physical parameters it reports) is the one called
        ``name`` or with that alias; the model, its parameters and its priors are unchanged."""
        for i, p in enumerate(self.pictures):
            if name == p.name or name in p.aliases:
                if i == 0:
                    return self
                return replace(self, pictures=(p,) + self.pictures[:i] + self.pictures[i + 1:])
        raise StructureError(f"structure '{self.name}' has no picture {show(str(name))}; its "
                             f"pictures are {', '.join(p.name for p in self.pictures) or 'none'}")

    def with_priors(self, priors: dict[str, Prior]) -> Structure:
        """A copy with some priors replaced (``{name: Prior}``)."""
        unknown = [k for k in priors if k not in self.param_names]
        if unknown:
            raise StructureError(
                f"structure '{self.name}' has no parameter {show(str(unknown[0]))}; "
                f"its parameters are {', '.join(self.param_names)}"
            )
        params = tuple(
            replace(p, prior=priors[p.name]) if p.name in priors else p for p in self.parameters
        )
        return replace(self, parameters=params)

    def check_data(self, data) -> None:
        """Raise :class:`~bayesfo.errors.InputError` if ``data`` has fewer points than parameters."""
        data.check_enough_points(self.n_params, f"structure '{self.name}'")

    # ------------------------------------------------------------------ evaluation
    def values(self, theta) -> tuple[dict[str, np.ndarray], bool]:
        """Map ``theta`` to ``{name: column}`` including fixed parameters; flag a single set."""
        theta = np.asarray(theta, dtype=float)
        single = theta.ndim == 1
        theta2 = np.atleast_2d(theta)
        if theta2.ndim != 2 or theta2.shape[1] != self.n_params:
            raise StructureError(
                f"structure '{self.name}' takes {self.n_params} parameters "
                f"({', '.join(self.param_names)}); got an array of shape {theta.shape}"
            )
        vals = {name: theta2[:, i] for i, name in enumerate(self.param_names)}
        for name, v in self.fixed.items():
            vals[name] = np.full(theta2.shape[0], float(v))
        return vals, single

    def _side_arrays(self, terms, vals, n_sets):
        """Coefficients and exponents of a side, each of shape (n_sets, n_terms)."""
        coef = np.empty((n_sets, len(terms)))
        expo = np.empty((n_sets, len(terms)))
        with np.errstate(all="ignore"):
            for i, t in enumerate(terms):
                coef[:, i] = t.coefficient(vals, n_sets)
                expo[:, i] = t.exponent.value(vals)
        return coef, expo

    def _polynomial(self, terms, vals, n_sets):
        """Ascending coefficients of a side that is a polynomial in λ = s^q."""
        for side, plan in self._polynomial_plans:
            if side is terms:
                break
        else:
            plan = _polynomial_plan(terms)
        out = np.zeros((n_sets, plan[0] + 1))
        # The floating-point guard only where coefficients are computed or added (arithmetic
        # that may overflow); a coefficient that is one parameter is its column as it is.
        with np.errstate(all="ignore") if plan[2] else nullcontext():
            for degree, name, t in plan[1]:
                out[:, degree] += vals[name] if name is not None else t.coefficient(vals, n_sets)
        return out

    @cached_property
    def _polynomial_plans(self) -> tuple:
        """(side, plan) per side: its degree and each term's (degree, parameter or None, term).
        The sides themselves, matched by identity, not their ``id()``: a structure pickled to
        a worker process brings the plans along, and there the sides are new objects whose
        ``id()`` could equal the other side's former one (pickling keeps the identity of the
        side and of its entry here)."""
        return tuple((side, _polynomial_plan(side)) for side in (self.numerator, self.denominator))

    def polynomials(self, theta):
        """Pseudo-polynomial coefficients of a commensurate structure.

        Returns
        -------
        den, num : ndarray, shapes (n_sets, n+1) and (n_sets, m+1)
            Ascending coefficients of A(λ) (denominator) and B(λ) (numerator), λ = s^q.
        q : ndarray, shape (n_sets,)
        """
        p = self.commensurate_order
        if p is None:
            raise StructureError(f"structure '{self.name}' is not of commensurate order")
        vals, _ = self.values(theta)
        n_sets = next(iter(vals.values())).shape[0] if vals else 1
        return (
            self._polynomial(self.denominator, vals, n_sets),
            self._polynomial(self.numerator, vals, n_sets),
            vals[p],
        )

    def transfer(self, theta, omega) -> np.ndarray:
        """The transfer function as written in the card (with inversion for ``-inv``).

        Parameters
        ----------
        theta : array_like, shape (n_params,) or (n_sets, n_params)
        omega : array_like, shape (n_freq,)
            Angular frequencies, in the units matching ``theta`` (scaled or physical).

        Returns
        -------
        ndarray of complex, shape (n_freq,) or (n_sets, n_freq)
        """
        omega = np.asarray(omega, dtype=float)
        vals, single = self.values(theta)
        n_sets = np.atleast_2d(np.asarray(theta, float)).shape[0]
        p = self.commensurate_order
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            if p is not None:
                out = commensurate_response(
                    omega,
                    self._polynomial(self.denominator, vals, n_sets),
                    self._polynomial(self.numerator, vals, n_sets),
                    vals[p],
                )
            else:
                nc, ne = self._side_arrays(self.numerator, vals, n_sets)
                dc, de = self._side_arrays(self.denominator, vals, n_sets)
                out = power_ratio(omega, nc, ne, dc, de)
        return out[0] if single else out

    def laplace(self, theta, s, *, per_set: bool = False) -> np.ndarray:
        """The transfer function as written in the card at complex ``s`` (any shape), with the
        fractional powers on their principal branch (cut along the negative real axis).

        With ``per_set``, row i of ``s`` (shape ``(n_sets, ...)``) belongs to parameter set i
        alone (e.g. frequencies shifted by each set's own factor).

        Returns
        -------
        ndarray of complex, shape ``s.shape`` (one set, or ``per_set``) or ``(n_sets, *s.shape)``
        """
        s = np.asarray(s, dtype=complex)
        vals, single = self.values(theta)
        n_sets = np.atleast_2d(np.asarray(theta, float)).shape[0]
        log_s = np.log(s)
        if per_set:
            if s.ndim == 0 or s.shape[0] != n_sets:
                raise StructureError(f"laplace(per_set=True) takes one row of s per parameter "
                                     f"set: {n_sets} sets, s of shape {s.shape}")
            shape, out_shape, single = (n_sets,) + (1,) * (s.ndim - 1), s.shape, False
        else:
            shape, out_shape = (n_sets,) + (1,) * s.ndim, (n_sets, *s.shape)
        powers = {}  # s^e once per distinct exponent column (s^q on both sides, s^0, s^1)

        def power(e):
            key = e.tobytes()
            if key not in powers:
                powers[key] = (1.0 if not e.any() else s if np.all(e == 1.0)
                               else np.exp(e.reshape(shape) * log_s))
            return powers[key]

        sides = []
        with np.errstate(all="ignore"):
            for terms in (self.numerator, self.denominator):
                coef, expo = self._side_arrays(terms, vals, n_sets)
                total = np.zeros(out_shape, dtype=complex)
                for k in range(coef.shape[1]):
                    total += coef[:, k].reshape(shape) * power(expo[:, k])
                sides.append(total)
            out = sides[0] / sides[1]
        return out[0] if single else out

    def power_terms(self, theta) -> tuple[list[tuple[float, float]], list[tuple[float, float]]]:
        """(coefficient, exponent) pairs of numerator and denominator for one parameter set,
        as :func:`bayesfo.timeseries.timedomain.simulate` takes them."""
        theta = np.asarray(theta, dtype=float)
        if theta.ndim != 1:
            raise StructureError(f"power_terms takes one parameter set, got shape {theta.shape}")
        nc, ne, dc, de = self.power_arrays(theta)
        return ([(float(c), float(e)) for c, e in zip(nc[0], ne[0])],
                [(float(c), float(e)) for c, e in zip(dc[0], de[0])])

    def power_arrays(self, theta) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Coefficients and exponents of the numerator's and the denominator's terms for each
        parameter set: (num_coef, num_exp, den_coef, den_exp), each (n_sets, terms of its side)."""
        vals, _ = self.values(theta)
        n_sets = np.atleast_2d(np.asarray(theta, float)).shape[0]
        return (*self._side_arrays(self.numerator, vals, n_sets),
                *self._side_arrays(self.denominator, vals, n_sets))

    def equilibrium_modulus(self, theta) -> np.ndarray:
        """G_e = lim 1/C(s) as s → 0 for each parameter set (physical units): the ratio of
        the lowest-order terms of the compliance's denominator and numerator; 0 where the
        denominator's lowest power of s is the higher (a liquid), inf where it is the lower."""
        nc, ne, dc, de = self.power_arrays(np.atleast_2d(np.asarray(theta, float)))

        def lowest(coef, expo):  # the lowest power of s with a coefficient, and its coefficient
            expo = np.where(coef != 0, expo, np.inf)
            low = np.min(expo, axis=1)
            return low, np.sum(np.where(expo == low[:, None], coef, 0.0), axis=1)

        (en, cn), (ed, cd) = lowest(nc, ne), lowest(dc, de)
        with np.errstate(all="ignore"):
            return np.where(ed > en, 0.0, np.where(ed < en, np.inf, cd / cn))

    def response(self, theta, omega, kind: str = "compliance") -> np.ndarray:
        """The response compared with data of ``kind``: the transfer function, or its reciprocal
        for modulus data (cards describe compliances)."""
        g = self.transfer(theta, omega)
        if kind == "modulus":
            with np.errstate(divide="ignore", invalid="ignore"):
                return 1.0 / g
        return g

    # ------------------------------------------------------------------ constraints
    def stable(self, theta, kind: str = "generic") -> np.ndarray:
        """Stability of the poles, and for materials of the zeros.

        The poles (roots of the denominator) are always tested. For compliance and modulus data
        the zeros are tested too: a passive material has a compliance whose reciprocal, the
        modulus, is again a stable response, so a root of the numerator in the unstable region
        is as unphysical as a pole there. Roots at s = 0 (integrators) are accepted. A side that
        is a polynomial in one λ = s^p is tested with Matignon's theorem (thesis Theorem 3); any
        other side with the conditions of :mod:`bayesfo.structures.passivity` (a positive sum of
        springpots with exponents spanning less than 2; integer exponents; else the argument
        principle on the imaginary axis).
        """
        if self.commensurate_order is not None:
            ok = self._stable_polynomials(*self.polynomials(theta), kind)
            return ok[0] if np.ndim(theta) != 2 else ok
        vals, single = self.values(theta)
        n_sets = np.atleast_2d(np.asarray(theta, float)).shape[0]
        ok = np.ones(n_sets, dtype=bool)
        sides = [self.denominator] + ([self.numerator] if kind in ("compliance", "modulus") else [])
        for terms in sides:
            p = _polynomial_order(terms)
            if p == "":
                continue  # a constant, without roots
            if p is not None:
                poly = self._polynomial(terms, vals, n_sets)
                ok &= matignon_stable(poly, vals[p], allow_integrator=True)
            elif ok.any():
                rows = np.flatnonzero(ok)
                coef, expo = self._side_arrays(terms, {k: v[rows] for k, v in vals.items()},
                                               rows.size)
                ok[rows] = side_stable(coef, expo)
        return ok[0] if single else ok

    def _stable_polynomials(self, den, num, q, kind: str) -> np.ndarray:
        """:meth:`stable` of a commensurate structure from its polynomials
        (:meth:`polynomials`): Matignon's theorem on each side that is not a constant, in one
        call when both sides have the same degree."""
        den_roots, num_roots = self._sides_with_roots
        polys = ([den] if den_roots else []) + (
            [num] if num_roots and kind in ("compliance", "modulus") else [])
        n = q.shape[0]
        if not polys:
            return np.ones(n, dtype=bool)
        if len(polys) == 2 and polys[0].shape[1] == polys[1].shape[1]:
            both = matignon_stable(np.concatenate(polys), np.concatenate([q, q]),
                                   allow_integrator=True)
            return both[:n] & both[n:]
        ok = np.ones(n, dtype=bool)
        for poly in polys:
            ok &= matignon_stable(poly, q, allow_integrator=True)
        return ok

    def passive(self, theta, kind: str, omega_grid) -> np.ndarray:
        """Dissipation ≥ 0 of the response compared with ``kind`` data, at every ω > 0.

        Commensurate structures (N(λ)/D(λ), λ = s^q) are decided exactly, at every frequency,
        without ``omega_grid``: with x = ω^q, Im G(jω) has the sign of the dissipation
        polynomial P(x) = Σ_k Σ_l n_k d_l x^(k+l) sin((k − l) qπ/2), and a compliance (and its
        reciprocal, a modulus) dissipates iff P(x) ≤ 0 for every x > 0, decided by the sign
        pattern of P's coefficients and its values at the positive roots of P′
        (:func:`~bayesfo.structures.passivity.commensurate_passive`, relative rounding
        tolerance 1e-12). Degree ≤ 1 on both sides is the closed form of this rule:
        Im[(b0 + b1 λ)/(a0 + a1 λ)] = (b1 a0 − b0 a1) Im λ / |A|², and Im λ > 0 for
        0 < q < 2, so the structure dissipates iff b1 a0 ≤ b0 a1 (q outside (0, 2) is left to
        the other constraints). Other structures: parameter sets that satisfy an exact
        sufficient condition (springpots in series or in parallel; a declared network with
        positive coefficients and orders in [0, 1]; see :mod:`bayesfo.structures.passivity`)
        are passive at every frequency, and the rest are checked on ``omega_grid``.
        Non-finite parameters are not passive.
        """
        theta2 = np.atleast_2d(np.asarray(theta, float))
        single = np.ndim(theta) != 2
        if kind == "generic":
            ok = np.ones(theta2.shape[0], dtype=bool)
        elif self._passive_by_polynomials:
            ok = self._passive_polynomials(*self.polynomials(theta2), theta2)
        else:
            ok = self._exactly_passive(theta2)
            rest = np.flatnonzero(~ok)
            if rest.size:
                ok[rest] = is_dissipative(self.response(theta2[rest], omega_grid, kind), kind)
        return ok[0] if single else ok

    @property
    def _passive_by_polynomials(self) -> bool:
        """Commensurate, with dissipation decided from the polynomials
        (:meth:`_passive_polynomials`): always for degree ≤ 1, else where
        ``passivity.EXACT_COMMENSURATE``."""
        return self.commensurate_order is not None and (self._first_degree
                                                        or passivity.EXACT_COMMENSURATE)

    def _passive_polynomials(self, den, num, q, theta2) -> np.ndarray:
        """:meth:`passive` of a commensurate structure from its polynomials
        (:meth:`polynomials`) at the parameter sets ``theta2``: the closed form of degree ≤ 1,
        else :func:`~bayesfo.structures.passivity.commensurate_passive`."""
        if self._first_degree:
            d1 = den[:, 1] if den.shape[1] > 1 else 0.0
            n1 = num[:, 1] if num.shape[1] > 1 else 0.0
            lhs, rhs = n1 * den[:, 0], num[:, 0] * d1
            scale = np.abs(lhs) + np.abs(rhs)
            ok = (lhs <= rhs + 1e-12 * scale) | ~((q > 0) & (q < 2))
            return ok & np.all(np.isfinite(theta2), axis=1)
        return commensurate_passive(den, num, q) & np.all(np.isfinite(theta2), axis=1)

    def _exactly_passive(self, theta2) -> np.ndarray:
        """Rows passive by an exact sufficient condition (the others may be passive too)."""
        vals, _ = self.values(theta2)
        n = theta2.shape[0]
        ok = np.zeros(n, dtype=bool)
        if self.pictures and self.pictures[0].network is not None:
            ok |= self.pictures[0].network.positive(self.pictures[0].physical_values(self, vals))
        if not ok.all():  # the second condition only where the first leaves rows undecided
            sums = springpot_sum_passive(self._side_arrays(self.numerator, vals, n),
                                         self._side_arrays(self.denominator, vals, n))
            if sums is not None:
                ok |= sums
        return ok & np.all(np.isfinite(theta2), axis=1)

    @cached_property
    def _sides_with_roots(self) -> tuple[bool, bool]:
        """Whether the denominator and the numerator are polynomials that are not constants."""
        return (_polynomial_order(self.denominator) != "",
                _polynomial_order(self.numerator) != "")

    @cached_property
    def _constraint_plan(self) -> tuple[tuple, frozenset]:
        """The card's inequalities and the names of its other constraints (``stable``,
        ``passive``), sorted once: :meth:`constraints_hold` runs thousands of times per
        tempered ladder on batches of tens of rows, where its fixed cost counts."""
        return (tuple(c for c in self.constraints if isinstance(c, Inequality)),
                frozenset(c for c in self.constraints if isinstance(c, str)))

    @cached_property
    def _first_degree(self) -> bool:
        """Commensurate with numerator and denominator of degree ≤ 1 in λ = s^q."""
        if self.commensurate_order is None:
            return False
        return all(_degree(t) <= 1 for t in self.numerator + self.denominator)

    def admissible(self, theta, kind: str, omega_grid=None) -> np.ndarray:
        """All declared constraints and prior supports at once: the support of the posterior.

        Parameters
        ----------
        theta : array_like, shape (n_params,) or (n_sets, n_params)
        kind : {"compliance", "modulus", "generic"}
        omega_grid : array_like, optional
            The dense grid of the dissipation check, in the units of ``theta``
            (default :func:`~bayesfo.structures.response.dissipation_grid` around ω = 1).
        """
        theta = np.asarray(theta, dtype=float)
        ok = np.atleast_1d(self.in_support(theta)).copy()
        ok &= self.constraints_hold(theta, kind, omega_grid, where=ok)
        return ok[0] if theta.ndim == 1 else ok

    def constraints_hold(self, theta, kind: str, omega_grid=None, where=None) -> np.ndarray:
        """The card's constraints (inequalities, ``stable``, ``passive``) without the prior
        ranges; rows where ``where`` is false are skipped (returned false)."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        ok = np.ones(theta.shape[0], dtype=bool) if where is None else np.array(where, dtype=bool)
        inequalities, names = self._constraint_plan
        if inequalities:
            vals, _ = self.values(theta)
            for c in inequalities:
                ok &= c.holds(vals)
        elif theta.shape[1] != self.n_params:
            self.values(theta)  # raises the error of a wrong shape
        if "stable" in names and self._passive_by_polynomials and ok.any():
            # The polynomials once for both checks (all rows: no copy of theta).
            rows = np.flatnonzero(ok)
            kept = theta if rows.size == ok.size else theta[rows]
            den, num, q = self.polynomials(kept)
            stable = self._stable_polynomials(den, num, q, kind)
            ok[rows] = stable
            if "passive" in names and kind != "generic" and stable.any():
                keep = np.flatnonzero(stable)
                ok[rows[keep]] = self._passive_polynomials(den[keep], num[keep], q[keep],
                                                           kept[keep])
            return ok
        if "stable" in names and ok.any():
            rows = np.flatnonzero(ok)
            ok[rows] = self.stable(theta[rows], kind)
        if "passive" in names and kind != "generic" and ok.any():
            grid = dissipation_grid(1.0, 1.0) if omega_grid is None else omega_grid
            rows = np.flatnonzero(ok)
            ok[rows] = self.passive(theta[rows], kind, grid)
        return ok

    # ------------------------------------------------------------------ units
    @cached_property
    def scale_plan(self) -> ScalePlan:
        """The units of the coefficients (:mod:`bayesfo.structures.scaling`)."""
        return scale_plan(self)

    def to_scaled(self, theta, scaling: Scaling) -> np.ndarray:
        """Physical parameters → parameters of the scaled problem (ω/ω_ref, G/g_ref)."""
        theta = np.asarray(theta, float)
        theta2 = np.atleast_2d(theta)
        vals, _ = self.values(theta2)
        out = theta2 * self.scale_plan.factors(theta2, vals, scaling)
        return out[0] if theta.ndim == 1 else out

    def to_physical(self, theta, scaling: Scaling) -> np.ndarray:
        """Parameters of the scaled problem → physical parameters (exponents are unchanged)."""
        theta = np.asarray(theta, float)
        theta2 = np.atleast_2d(theta)
        vals, _ = self.values(theta2)
        out = theta2 / self.scale_plan.factors(theta2, vals, scaling)
        return out[0] if theta.ndim == 1 else out

    # ------------------------------------------------------------------ checks
    def _validate(self):
        where = f"structure '{self.name}'" + (f" (card {self.card})" if self.card else "")
        if not self.numerator or not self.denominator:
            raise StructureError(f"{where}: numerator and denominator need at least one term")
        terms = self.numerator + self.denominator
        for side in (self.numerator, self.denominator):
            seen = set()
            for t in side:
                key = (tuple(sorted(t.factors)), t.exponent)
                if t.is_free and key in seen:
                    raise StructureError(f"{where}: the term '{t}' appears twice in one side")
                seen.add(key)
        coef_names = {f for t in terms for f in t.factors}
        expo_names = set(self.exponent_params)
        both = coef_names & expo_names
        if both:
            raise StructureError(f"{where}: parameter '{sorted(both)[0]}' is used both as a "
                                 "coefficient and in an exponent")
        used = coef_names | expo_names
        declared = set(self.param_names) | set(self.fixed)
        missing = used - declared
        if missing:
            raise StructureError(f"{where}: parameter '{sorted(missing)[0]}' has no prior")
        unused = set(self.param_names) - used
        if unused:
            raise StructureError(f"{where}: parameter {show(sorted(unused)[0])} does not appear in the formula")
        for t in terms:
            if not t.is_free and (t.exponent.coefs or t.exponent.constant != 0):
                raise StructureError(
                    f"{where}: a constant coefficient is only allowed on s^0, got term '{t}'"
                )
        for c in self.constraints:
            if isinstance(c, Inequality):
                unknown = c.names - declared
                if unknown:
                    raise StructureError(
                        f"{where}: constraint '{c.text}' names unknown parameter '{sorted(unknown)[0]}'"
                    )
            elif c not in ("stable", "passive"):
                raise StructureError(
                    f"{where}: unknown constraint {c!r}; use 'stable', 'passive' or an inequality"
                )
        _ = self.scale_plan  # units of the coefficients: raises for a card that cannot be scaled


def _polynomial_plan(terms) -> tuple:
    """(degree, ((degree, name or None, term), ...), computed) of a side that is a polynomial in
    λ: name is the parameter when the term's coefficient is one parameter, else None; computed
    where a coefficient is computed or two terms add to one (arithmetic that may overflow),
    false where each coefficient is one parameter's column, copied into zeros."""
    rows = tuple((_degree(t), t.coef if t.is_free and len(t.factors) == 1 else None, t)
                 for t in terms)
    degrees = [d for d, _, _ in rows]
    computed = any(name is None for _, name, _ in rows) or len(set(degrees)) < len(degrees)
    return max(degrees), rows, computed


def _degree(t: Term) -> int:
    """k of a term c·s^(k q) of a polynomial side (0 for a constant exponent)."""
    one = t.exponent.single
    return int(round(one[1])) if one else 0


def _polynomial_order(terms) -> str | None:
    """The exponent parameter p if all terms are c·s^{k p} (k integer ≥ 0) or constants.

    Returns "" for constant-only sides and None if the terms are not a polynomial in s^p.
    """
    params = set()
    for t in terms:
        e = t.exponent
        if not e.coefs:
            if e.constant != 0:
                return None
            continue
        one = e.single
        if one is None or one[1] < 0 or one[1] != round(one[1]):
            return None
        params.add(one[0])
    if len(params) > 1:
        return None
    return params.pop() if params else ""
