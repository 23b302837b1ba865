"""Structures derived from another: the integer-order baseline (orders → 1), a structure with
some parameters fixed, and the inverted (reciprocal) variant; and the test whether an integer
baseline is a model of its own or a degenerate one."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .._io import show
from ..errors import StructureError
from .structure import Structure
from .terms import Inequality


def integer_variant(s: Structure) -> Structure:
    """The integer-order baseline: every exponent parameter fixed to 1."""
    expo = set(s.exponent_params)
    if not expo:
        raise StructureError(f"structure '{s.name}' has no exponent parameter to fix")
    params = tuple(p for p in s.parameters if p.name not in expo)
    fixed = dict(s.fixed) | {name: 1.0 for name in expo}
    constraints = tuple(
        c for c in s.constraints if not (isinstance(c, Inequality) and c.names <= expo)
    )
    return replace(
        s, name=f"{s.name}-int", parameters=params, fixed=fixed, constraints=constraints,
        integer=True, title=f"{s.title} (integer order)", aliases=(),
    )


def fix_parameters(s: Structure, values: dict[str, float]) -> Structure:
    """A copy of ``s`` with some exponent parameters fixed (e.g. ``{"q": 0.5}``)."""
    unknown = [k for k in values if k not in s.param_names]
    if unknown:
        raise StructureError(
            f"structure '{s.name}' has no free parameter {show(str(unknown[0]))}; "
            f"its free parameters are {', '.join(s.param_names)}"
        )
    # Coefficients change with the internal scaling of ω and G; only exponents are unit-free.
    coef = [k for k in values if k not in s.exponent_params]
    if coef:
        raise StructureError(
            f"only exponent parameters ({', '.join(s.exponent_params) or 'none'}) can be fixed "
            f"in structure '{s.name}', not {show(str(coef[0]))}"
        )
    for k, v in values.items():
        if not s.priors[k].contains(v):
            raise StructureError(
                f"{k} = {v:g} is outside the prior {s.priors[k].describe()} of structure '{s.name}'"
            )
    params = tuple(p for p in s.parameters if p.name not in values)
    fixed = dict(s.fixed) | {k: float(v) for k, v in values.items()}
    return replace(s, parameters=params, fixed=fixed)


def inverted_variant(s: Structure) -> Structure:
    """The reciprocal transfer function (numerator and denominator swapped)."""
    expo = set(s.exponent_params)
    constraints = tuple(
        c for c in s.constraints if not isinstance(c, Inequality) or c.names <= expo
    )
    # The pictures describe the material of the card, not its reciprocal.
    return replace(
        s, name=f"{s.name}-inv", numerator=s.denominator, denominator=s.numerator,
        constraints=constraints, inverted=True, title=f"{s.title} (inverted)", pictures=(),
        aliases=(),
    )


# ---------------------------------------------------------------------------- degeneracy
#: Relative singular value below which a direction of the parameter space does not change the
#: response (central differences are good to ~1e-10 relative).
RANK_TOL = 1e-6


def identifiable_rank(s: Structure) -> int | None:
    """How many parameter directions change the response: the largest rank of the Jacobian
    of G(jω)/|G(jω)| (real and imaginary parts, ω from 1e-6 to 1e6) with respect to the free
    parameters, over a few parameter sets inside the priors. None if it cannot be computed
    (non-finite responses)."""
    if s.n_params == 0:
        return 0
    w = np.logspace(-6, 6, 121)
    quantiles = ([0.31, 0.62, 0.44, 0.57, 0.36, 0.71, 0.68], [0.55, 0.3, 0.66, 0.41, 0.72, 0.48,
                 0.35], [0.67, 0.47, 0.33, 0.7, 0.52, 0.39, 0.6])
    best = None
    with np.errstate(all="ignore"):
        for u in quantiles:
            theta = np.array([p.prior.ppf(u[i % len(u)]) for i, p in enumerate(s.parameters)],
                             dtype=float)
            step = 1e-5 * np.maximum(np.abs(theta), 1e-3)
            sets = [theta]
            for i in range(s.n_params):
                for sign in (1.0, -1.0):
                    t = theta.copy()
                    t[i] += sign * step[i]
                    sets.append(t)
            g = s.transfer(np.array(sets), w)
            if not np.all(np.isfinite(g)) or np.any(g[0] == 0):
                continue
            d = (g[1::2] - g[2::2]) / (2 * step[:, None]) / g[0]
            jac = np.concatenate([d.real, d.imag], axis=1) * np.maximum(np.abs(theta), 1e-3)[:, None]
            if not np.all(np.isfinite(jac)):
                continue
            sv = np.linalg.svd(jac, compute_uv=False)
            rank = int(np.sum(sv > RANK_TOL * sv.max())) if sv.max() > 0 else 0
            best = rank if best is None else max(best, rank)
    return best


def integer_is_degenerate(base: Structure, integer: Structure) -> bool:
    """True when fixing the orders to 1 loses more identifiable directions than orders fixed,
    e.g. two springpots in parallel becoming ``1/(V s + G s)``: the baseline would then be a
    smaller model with redundant parameters, not a model of its own."""
    r_base, r_int = identifiable_rank(base), identifiable_rank(integer)
    if r_base is None or r_int is None:
        return False
    return r_int < r_base - (base.n_params - integer.n_params)
