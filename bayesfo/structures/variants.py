"""Structures derived from another: the integer-order baseline (q = 1), a structure with some
parameters fixed, and the inverted (reciprocal) variant."""

from __future__ import annotations

from dataclasses import replace

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
        integer=True, title=f"{s.title} (integer order)",
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
    return replace(
        s, name=f"{s.name}-inv", numerator=s.denominator, denominator=s.numerator,
        constraints=constraints, inverted=True,
        title=f"{s.title} (inverted)",
    )

