"""Physical parameters of a structure, with units derived from the data's units.

A card's parameters are the coefficients of its compliance J(s) = Σ b_k s^(β_k) / Σ a_k s^(α_k)
(the thesis' a, b, q) or, for the named rheology models, the physical parameters themselves
(moduli G_e, G_m [Pa], quasi-properties V, G, K [Pa·s^α], viscosities η [Pa·s], orders α, β, κ).
A *picture* maps the card's parameters to physical ones and back, declaratively in the card::

    [[physical]]
    name = "fractional_zener_ss"              # the picture's name, also an alias of the card
    network = "parallel(spring(G_e), series(spring(G_m), springpot(V, q)))"
    parameters = [{ name = "G_e", value = "1/b0", stress = 1, time = "0" }, ...]
    inverse = { b0 = "1/G_e", ... }           # the card's coefficients from the physical ones
    derived = [{ name = "tau", value = "(b1/b0)**(1/q)", stress = 0, time = "1" }]

``stress`` is the power of the stress unit and ``time`` the exponent of seconds (an expression
of the orders). A picture without ``parameters`` takes the card's parameters as physical ones;
their units then follow from the terms (:mod:`bayesfo.structures.scaling`). Exponent parameters
(orders) are physical parameters of every picture, without unit.

The names are keys (``summary.json``, ``ranking.csv``, ``--prior``) whatever the data; for
tensile data (:attr:`~bayesfo.data.FrequencyResponse.symbol` E, a DMA's E′, E″) figures, the
report and the terminal show the moduli in the tensile letter, E_e for G_e
(:func:`display_name`).

Units come from the data: for modulus data in Pa the stress unit is Pa; for compliance data in
1/Pa it is again Pa; for other units the inverse of the data's unit (``1/(µm/N)``); without
units, ``a.u.`` (modulus data without a unit: an arbitrary unit) or ``1/a.u.`` (compliance data, generic data). All functions take
the *unscaled* coefficients, as the posterior draws are reported (:meth:`Structure.to_physical`).

Examples
--------
>>> import numpy as np
>>> from bayesfo.structures import get_structure
>>> voigt = get_structure("voigt")
>>> phys = physical_parameters(voigt, {"a1": 0.5, "b0": 1e-3, "q": 0.4}, "modulus", "Pa")
>>> phys["G_e"], phys["c_q"]
((array(1000.), 'Pa'), (array(500.), 'Pa s^q'))
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .._io import show
from ..data.symbols import parameter_label
from ..errors import StructureError
from .expressions import Expr
from .network import Network

PICTURE_KEYS = {"name", "aliases", "title", "description", "network", "parameters", "inverse",
                "derived", "reference"}
PARAMETER_KEYS = {"name", "value", "stress", "time", "description"}


@dataclass(frozen=True)
class PhysicalParameter:
    """A physical quantity: its name, its value as an expression of the card's parameters, the
    power of the stress unit and the exponent of seconds in its unit."""

    name: str
    value: Expr
    stress: float
    time: Expr
    description: str = ""


@dataclass(frozen=True)
class Picture:
    """A physical reading of a structure's parameters (see the module docstring)."""

    name: str
    title: str = ""
    description: str = ""
    reference: str = ""
    network: Network | None = None
    parameters: tuple[PhysicalParameter, ...] = ()
    inverse: tuple[tuple[str, Expr], ...] = ()
    derived: tuple[PhysicalParameter, ...] = ()
    aliases: tuple[str, ...] = ()

    @property
    def identity(self) -> bool:
        """The card's parameters are the physical ones."""
        return not self.parameters

    def physical_values(self, structure, vals: dict) -> dict:
        """Physical parameters (and orders) from the card's parameter values ``vals``."""
        if self.identity:
            return vals
        out = dict(vals)
        for p in self.parameters:
            out[p.name] = p.value(vals)
        return out

    def describe(self) -> dict:
        return {"name": self.name, "title": self.title, "aliases": list(self.aliases),
                "network": self.network.text if self.network else "",
                "parameters": [p.name for p in self.parameters]}

    @classmethod
    def from_card(cls, spec, where: str, default_name: str) -> Picture:
        if not isinstance(spec, dict):
            raise StructureError(f"{where}: expected a table of keys")
        unknown = set(spec) - PICTURE_KEYS
        if unknown:
            raise StructureError(f"{where}: unknown key {show(str(sorted(unknown)[0]))}")
        name = spec.get("name", default_name)
        aliases = spec.get("aliases", [])
        if not isinstance(name, str) or not isinstance(aliases, list) or not all(
                isinstance(a, str) for a in aliases):
            raise StructureError(f"{where}: 'name' must be text and 'aliases' a list of text")
        for key in ("title", "description", "reference"):
            if not isinstance(spec.get(key, ""), str):
                raise StructureError(f"{where}: {key!r} must be text")
        network = spec.get("network")
        network = None if network is None else Network.parse(network, f"{where}, network")
        params = _parameter_list(spec.get("parameters", []), f"{where}, parameters")
        derived = _parameter_list(spec.get("derived", []), f"{where}, derived")
        inverse = spec.get("inverse", {})
        if not isinstance(inverse, dict):
            raise StructureError(f"{where}: 'inverse' must be a table of expressions")
        if bool(params) != bool(inverse):
            raise StructureError(f"{where}: 'parameters' and 'inverse' go together: the physical "
                                 "parameters from the card's and the card's back from them")
        inv = tuple((k, Expr.parse(v, f"{where}, inverse {show(str(k))}"))
                    for k, v in inverse.items())
        return cls(name, spec.get("title", ""), spec.get("description", ""),
                   spec.get("reference", ""), network, params, inv, derived, tuple(aliases))

    # ------------------------------------------------------------------ checks
    def check(self, structure, where: str) -> None:
        """Names, the round trip card ↔ physical and the network against the card's terms, at
        a few parameter sets inside the priors."""
        cards = set(structure.param_names) | set(structure.fixed)
        expo = set(structure.exponent_params)
        coefs = [n for n in structure.param_names if n not in expo]
        phys = {p.name for p in self.parameters} if not self.identity else set(coefs)
        for p in self.parameters + self.derived:
            if p.value.names - cards:
                raise StructureError(f"{where}: {p.name} = {p.value}: unknown parameter "
                                     f"{show(sorted(p.value.names - cards)[0])}")
            if p.time.names - expo:
                raise StructureError(f"{where}: the time exponent of {p.name} may only name "
                                     f"orders ({', '.join(sorted(expo)) or 'none'})")
        names = [p.name for p in self.parameters + self.derived] + sorted(expo)
        dup = {n for n in names if names.count(n) > 1} | ({p.name for p in self.derived} & cards)
        if dup:
            raise StructureError(f"{where}: the name {show(sorted(dup)[0])} is used twice")
        if not self.identity:
            if {k for k, _ in self.inverse} != set(coefs):
                raise StructureError(f"{where}: 'inverse' must give each coefficient of the card "
                                     f"({', '.join(coefs)}) from the physical parameters")
            for k, e in self.inverse:
                if e.names - phys - expo:
                    raise StructureError(f"{where}: inverse {k} = {e}: unknown name "
                                         f"{show(sorted(e.names - phys - expo)[0])}")
        if self.network is not None and self.network.names - phys - expo:
            raise StructureError(f"{where}: the network names {show(sorted(self.network.names - phys - expo)[0])}, "
                                 "which is not a physical parameter")
        theta = _check_points(structure)
        vals, _ = structure.values(theta)
        if not self.identity:
            back = _inverse_values(self, self.physical_values(structure, vals))
            for k in coefs:
                if not np.allclose(back[k], vals[k], rtol=1e-8, atol=0):
                    raise StructureError(f"{where}: 'inverse' does not invert 'parameters' for "
                                         f"{k} (card value {vals[k][0]:.6g}, round trip "
                                         f"{back[k][0]:.6g})")
        if self.network is not None:
            w = np.logspace(-3, 3, 13)
            j = structure.transfer(theta, w)
            g = self.network.modulus(self.physical_values(structure, vals), w)
            with np.errstate(all="ignore"):
                bad = ~np.isclose(j * g, 1.0, rtol=1e-8, atol=0)
            if bad.any():
                raise StructureError(f"{where}: the network {self.network.text!r} is not the "
                                     f"reciprocal of the card's compliance {structure.formula}")


def _parameter_list(spec, where: str) -> tuple[PhysicalParameter, ...]:
    if not isinstance(spec, list):
        raise StructureError(f"{where}: expected a list of tables")
    out = []
    for i, item in enumerate(spec):
        w = f"{where}, entry {i + 1}"
        if not isinstance(item, dict) or set(item) - PARAMETER_KEYS or "name" not in item \
                or "value" not in item:
            raise StructureError(f"{w}: expected {{ name = ..., value = ..., stress = ..., "
                                 "time = ... }")
        name, stress = item["name"], item.get("stress", 0)
        if not isinstance(name, str) or not name.isidentifier():
            raise StructureError(f"{w}: 'name' must be a name, got {name!r}")
        if isinstance(stress, bool) or not isinstance(stress, (int, float)) or abs(stress) > 6:
            raise StructureError(f"{w}: 'stress' must be a number from -6 to 6, got {stress!r}")
        out.append(PhysicalParameter(name, Expr.parse(item["value"], f"{w}, value"), float(stress),
                                     Expr.parse(item.get("time", "0"), f"{w}, time"),
                                     str(item.get("description", ""))))
    return tuple(out)


def _check_points(structure) -> np.ndarray:
    """Three parameter sets at inner quantiles of the priors, not on a symmetry line."""
    u = np.array([[0.31, 0.62, 0.44], [0.57, 0.36, 0.71], [0.68, 0.52, 0.27], [0.42, 0.75, 0.58],
                  [0.35, 0.46, 0.66], [0.61, 0.29, 0.49]])
    cols = [p.prior.ppf(u[i % len(u)]) for i, p in enumerate(structure.parameters)]
    return np.column_stack(cols) if cols else np.zeros((3, 0))


def _inverse_values(picture: Picture, phys: dict) -> dict:
    return {k: e(phys) for k, e in picture.inverse}


def display_name(name: str, symbol: str = "G") -> str:
    """A parameter's name as shown for data measured as ``symbol``: ``G_e`` → ``E_e`` for
    tensile data (:func:`bayesfo.data.symbols.parameter_label`); the key stays ``G_e``.

    Examples
    --------
    >>> display_name("G_m", "E"), display_name("G_m", "G"), display_name("c_q", "E")
    ('E_m', 'G_m', 'c_q')
    """
    return parameter_label(name, symbol)


# ---------------------------------------------------------------------------- units
def in_brackets(unit: str) -> str:
    """`` [unit]`` after a quantity's name, nothing without a unit. Data without a unit have
    the arbitrary unit ``a.u.`` (:func:`stress_unit`); the placeholder earlier versions stored
    for it (``[G]``, ``[J]``) is read as that, never shown as a unit of its own.

    Examples
    --------
    >>> in_brackets("Pa"), in_brackets("a.u."), in_brackets("[G]"), in_brackets("[G] s^q")
    (' [Pa]', ' [a.u.]', ' [a.u.]', ' [a.u. s^q]')
    >>> in_brackets("1/[J]"), in_brackets("")
    (' [1/a.u.]', '')
    """
    if not unit:
        return ""
    return f" [{_PLACEHOLDER.sub('a.u.', unit)}]"


#: The placeholder unit of data without one that earlier versions stored (in the data's letter).
_PLACEHOLDER = re.compile(r"\[[GJED]\]")


#: The unit of data that give none: an arbitrary unit.
ARBITRARY = "a.u."


def stress_unit(kind: str, unit: str = "") -> str:
    """The stress unit of the physical parameters for data of ``kind`` in ``unit``."""
    u = (unit or "").strip()
    if kind == "modulus":
        return u or ARBITRARY
    if not u:
        return f"1/{ARBITRARY}"
    if u.startswith("1/"):
        inner = u[2:].strip()
        return inner[1:-1] if inner.startswith("(") and inner.endswith(")") else inner
    return f"1/{parenthesized(u)}"


def parenthesized(u: str) -> str:
    """``u`` in parentheses where it is a compound unit (``(N/m)``), as it stands otherwise."""
    return f"({u})" if any(c in u for c in " /^*") else u


def _time_text(text: str) -> str:
    if text in ("0", "0.0", "-0"):
        return ""
    if text in ("1", "1.0"):
        return "s"
    if text.isidentifier() or text.replace(".", "", 1).isdigit():
        return f"s^{text}"
    return f"s^({text.replace(' ', '')})"


def format_unit(stress: float, time: str, stress_symbol: str) -> str:
    """A unit such as ``Pa s^alpha``, ``1/Pa``, ``s^q/Pa`` or ``s``; a stress symbol that is a
    reciprocal itself (``1/(m/N)`` of a generic transfer function in m/N) is inverted, not
    divided again (``m/N``, not ``1/(1/(m/N))``).

    Examples
    --------
    >>> format_unit(-1, "0", "1/(m/N)"), format_unit(1, "0", "1/(m/N)")
    ('m/N', '1/(m/N)')
    >>> format_unit(-1, "q", "1/a.u."), format_unit(1, "q", "Pa")
    ('a.u. s^q', 'Pa s^q')
    """
    if stress and stress_symbol.startswith("1/"):
        inner = stress_symbol[2:].strip()
        inner = inner[1:-1] if inner.startswith("(") and inner.endswith(")") else inner
        stress, stress_symbol = -stress, inner
    t = _time_text(str(time))
    p = abs(stress)
    if p == 0:
        return t
    s = stress_symbol if p == 1 else f"{parenthesized(stress_symbol)}^{p:g}"
    if stress > 0:
        return f"{parenthesized(s)} {t}" if t else s
    return f"{t or '1'}/{parenthesized(s)}"


def _linear_text(t0: float, coefs: dict) -> str:
    parts = []
    for x, k in coefs.items():
        parts.append(("-" if k < 0 else "+") + (x if abs(k) == 1 else f"{abs(k):g}*{x}"))
    if t0 or not parts:
        parts.append(f"{t0:+g}")
    text = "".join(parts)
    return text[1:] if text.startswith("+") else text


def _coefficient_unit(structure, name: str, symbol: str) -> str:
    plan = structure.scale_plan
    t0, coefs = plan.time_exponent(name)
    fixed = {k: float(v) for k, v in structure.fixed.items()}
    t0 += sum(k * fixed[x] for x, k in coefs.items() if x in fixed)
    coefs = {x: k for x, k in coefs.items() if x not in fixed}
    g = float(plan.g[plan.names.index(name)])
    return format_unit(g, _linear_text(t0, coefs), symbol)


def coefficient_units(structure, kind: str = "modulus", unit: str = "") -> dict[str, str]:
    """The unit of each free parameter of the card (``""`` for orders).

    Parameters
    ----------
    structure : Structure
    kind : {"modulus", "compliance", "generic"}
        The kind of the data.
    unit : str
        The data's unit (``FrequencyResponse.units``), e.g. ``"Pa"`` or ``"1/MPa"``.
    """
    symbol = stress_unit(kind, unit)
    expo = set(structure.exponent_params)
    return {n: "" if n in expo else _coefficient_unit(structure, n, symbol)
            for n in structure.param_names}


# ---------------------------------------------------------------------------- pictures
def pictures(structure) -> tuple[Picture, ...]:
    """The structure's pictures, the default first (an identity picture if none is declared)."""
    return structure.pictures or (Picture(structure.name),)


def picture_of(structure, name: str | None = None) -> Picture:
    """The picture called ``name`` (or with that alias); the default one for None."""
    options = pictures(structure)
    if name is None:
        return options[0]
    for p in options:
        if name == p.name or name in p.aliases:
            return p
    raise StructureError(f"structure '{structure.name}' has no picture {show(str(name))}; "
                         f"its pictures are {', '.join(p.name for p in options)}")


def _values(structure, coefficients) -> tuple[dict, tuple]:
    """``{name: array}`` of the card's parameters (fixed ones added) and the common shape."""
    if isinstance(coefficients, Mapping):
        missing = [n for n in structure.param_names if n not in coefficients]
        if missing:
            raise StructureError(f"structure '{structure.name}' needs {show(missing[0])} among "
                                 f"the coefficients ({', '.join(structure.param_names)})")
        arrays = [np.asarray(coefficients[n], dtype=float) for n in structure.param_names]
    else:
        theta = np.asarray(coefficients, dtype=float)
        if theta.ndim == 0 or theta.shape[-1] != structure.n_params:
            raise StructureError(f"structure '{structure.name}' takes {structure.n_params} "
                                 f"parameters ({', '.join(structure.param_names)}); got shape "
                                 f"{theta.shape}")
        arrays = [theta[..., i] for i in range(structure.n_params)]
    shape = np.broadcast_shapes(*(a.shape for a in arrays)) if arrays else ()
    vals = {n: np.broadcast_to(a, shape) for n, a in zip(structure.param_names, arrays)}
    for n, v in structure.fixed.items():
        vals[n] = np.full(shape, float(v))
    return vals, shape


def physical_units(structure, kind: str = "modulus", unit: str = "", *,
                   picture: str | None = None, derived: bool = True) -> dict[str, str]:
    """The unit of each physical parameter of a picture, in the order of
    :func:`physical_parameters`."""
    pic = picture_of(structure, picture)
    symbol = stress_unit(kind, unit)
    fixed = {k: float(v) for k, v in structure.fixed.items()}
    expo = [n for n in structure.param_names if n in set(structure.exponent_params)]
    if pic.identity:
        out = {n: u for n, u in coefficient_units(structure, kind, unit).items() if n not in expo}
    else:
        out = {p.name: format_unit(p.stress, p.time.substitute(fixed), symbol)
               for p in pic.parameters}
    out.update({n: "" for n in expo})
    if derived:
        out.update({p.name: format_unit(p.stress, p.time.substitute(fixed), symbol)
                    for p in _varying(structure, pic.derived)})
    return out


def _varying(structure, derived) -> list:
    """The derived quantities that depend on a free parameter: one of fixed parameters alone
    is a constant of the structure (the Maxwell's second springpot order β − α = 0 when both
    are fixed at 1), not something the data tell."""
    return [p for p in derived if not p.value.names <= set(structure.fixed)]


def _element_text(element) -> str:
    """What an element's coefficient is: "quasi-property of the springpot of order alpha"."""
    if element.kind == "springpot":
        return f"quasi-property of the springpot of order {element.order}"
    return {"spring": "modulus of the spring", "dashpot": "viscosity of the dashpot"}.get(
        element.kind, "")


def meanings(structure, picture: str | None = None) -> dict[str, str]:
    """What each physical parameter of a picture is, in words, in the order of
    :func:`physical_units`: the card's description of a modulus, quasi-property or derived
    quantity; for an order, the elements of the network whose order it is or enters
    ("order of the springpot c_beta; in the order beta - alpha of the springpot c_delta").
    Empty text where a parameter has neither."""
    pic = picture_of(structure, picture)
    elements = pic.network.elements() if pic.network is not None else []
    out = {}
    for name in physical_units(structure, "modulus", picture=picture):
        given = next((p.description for p in pic.parameters + pic.derived if p.name == name),
                     "")
        if given or name not in structure.exponent_params:
            element = next((e for e in elements if e.coefficient.text == name), None)
            out[name] = given or ("" if element is None else _element_text(element))
            continue
        parts = [f"order of the {e.kind} {e.coefficient}" if e.order.text == name
                 else f"in the order {e.order} of the {e.kind} {e.coefficient}"
                 for e in elements if e.order is not None and name in e.order.names]
        out[name] = "; ".join(parts)
    return out


def physical_dimensions(structure, coefficients, *, picture: str | None = None,
                        derived: bool = True) -> dict[str, tuple[float, np.ndarray]]:
    """``{name: (stress power, time exponent)}`` of each physical parameter, the time exponent
    evaluated at the orders of ``coefficients``: a quantity with dimensions (p, t) is
    multiplied by c^p·k^t when the stress unit grows by c and the time unit by k."""
    pic = picture_of(structure, picture)
    vals, shape = _values(structure, coefficients)
    expo = set(structure.exponent_params)
    out = {}
    if pic.identity:
        plan = structure.scale_plan
        for n in structure.param_names:
            if n not in expo:
                t0, coefs = plan.time_exponent(n)
                t = t0 + sum(k * vals[x] for x, k in coefs.items())
                out[n] = (float(plan.g[plan.names.index(n)]), np.broadcast_to(t, shape))
    else:
        out = {p.name: (p.stress, np.broadcast_to(p.time(vals), shape)) for p in pic.parameters}
    out.update({n: (0.0, np.zeros(shape)) for n in structure.param_names if n in expo})
    if derived:
        out.update({p.name: (p.stress, np.broadcast_to(p.time(vals), shape))
                    for p in _varying(structure, pic.derived)})
    return out


def physical_parameters(structure, coefficients, kind: str = "modulus", unit: str = "", *,
                        picture: str | None = None,
                        derived: bool = True) -> dict[str, tuple[np.ndarray, str]]:
    """Physical parameters with units from the card's (unscaled) coefficients.

    Parameters
    ----------
    structure : Structure
    coefficients : mapping of name → array_like, or array_like of shape (..., n_params)
        The card's free parameters in physical units (posterior draws as
        ``PosteriorResult.samples`` holds them), e.g. ``{"a1": draws_a1, "b0": ..., "q": ...}``.
    kind : {"modulus", "compliance", "generic"}
        The kind of the data; with ``unit`` it sets the units.
    unit : str
        The data's unit, e.g. ``"Pa"`` (modulus) or ``"1/Pa"`` (compliance).
    picture : str, optional
        A picture name or alias (e.g. ``"fractional_poynting_thomson"`` for ``zener``); the
        structure's default picture if omitted.
    derived : bool
        Include derived quantities such as relaxation times.

    Returns
    -------
    dict
        ``{name: (values, unit)}``: the physical parameters, then the orders, then the derived
        quantities; ``values`` has the shape of the coefficients.

    Raises
    ------
    StructureError
        For a missing coefficient or an unknown picture.
    """
    pic = picture_of(structure, picture)
    vals, _ = _values(structure, coefficients)
    units = physical_units(structure, kind, unit, picture=picture, derived=derived)
    phys = pic.physical_values(structure, vals)
    out = {}
    for name, u in units.items():
        expr = next((p.value for p in pic.derived if p.name == name), None)
        value = expr(vals) if expr is not None else phys[name]
        out[name] = (np.asarray(value, dtype=float), u)
    return out


def coefficients_from_physical(structure, physical: Mapping, *,
                               picture: str | None = None) -> dict[str, np.ndarray]:
    """The card's free parameters from physical ones: the inverse of
    :func:`physical_parameters` (units as that function reports them).

    Parameters
    ----------
    structure : Structure
    physical : mapping of name → array_like
        The physical parameters of the picture and the orders (derived quantities are not
        needed).
    picture : str, optional
        As for :func:`physical_parameters`.
    """
    pic = picture_of(structure, picture)
    expo = set(structure.exponent_params)
    needed = ([n for n in structure.param_names if n not in expo] if pic.identity
              else [p.name for p in pic.parameters]) + [n for n in structure.param_names
                                                        if n in expo]
    missing = [n for n in needed if n not in physical]
    if missing:
        raise StructureError(f"picture '{pic.name}' of structure '{structure.name}' needs "
                             f"{show(missing[0])} ({', '.join(needed)})")
    vals = {n: np.asarray(physical[n], dtype=float) for n in needed}
    vals.update({n: float(v) for n, v in structure.fixed.items()})
    if pic.identity:
        return {n: vals[n] for n in structure.param_names}
    back = _inverse_values(pic, vals)
    return {n: np.asarray(back[n] if n in back else vals[n], dtype=float)
            for n in structure.param_names}


def parameter_forms(structure, coefficients, kind: str, unit: str = "") -> tuple[dict, dict]:
    """``(natural, other)``: the parameters in the form natural to the data's kind and in the
    other form, each ``{name: (values, unit)}``. For modulus data the natural form is the
    default picture (moduli, quasi-properties, orders, derived times); for compliance and
    generic data it is the card's own coefficients. For cards written in physical parameters
    the two forms hold the same parameters."""
    vals, _ = _values(structure, coefficients)
    units = coefficient_units(structure, kind, unit)
    own = {n: (np.asarray(vals[n], dtype=float), units[n]) for n in structure.param_names}
    phys = physical_parameters(structure, coefficients, kind, unit)
    return (phys, own) if kind == "modulus" else (own, phys)
