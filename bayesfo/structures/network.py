"""Mechanical networks: the picture of a named model as springs, dashpots and springpots in
series and in parallel, e.g. ``parallel(spring(G_e), series(spring(G_m), springpot(V, alpha)))``.

A network is evaluated as a modulus, element by element (spring G: G; dashpot η: η s;
springpot (V, α): V s^α), with moduli adding in parallel and compliances adding in series. It
serves two purposes: an independent check of a card's compliance terms, and the exact
passivity condition of series–parallel networks of springpots:

    If every element has a positive coefficient and an order in [0, 1], the modulus G(jω) of
    the network lies in the closed first quadrant (G' ≥ 0, G'' ≥ 0) at every ω > 0, and the
    compliance 1/G in the closed fourth quadrant; for Re s > 0 neither G(s) nor 1/G(s) is zero
    or infinite. The network is passive and stable (poles only at s = 0: flow).

Proof sketch: a springpot V s^α with V > 0, 0 ≤ α ≤ 1 has arg in [0, α·arg s] ⊂ [0, arg s] for
0 ≤ arg s ≤ π/2 (and the mirror image below the real axis). The closed cone C(φ) = {z: 0 ≤ arg z
≤ φ}, φ < π, is closed under addition (parallel) and under z ↦ 1/(1/z1 + 1/z2) (series: 1/z maps
C(φ) onto its mirror image, which is again a convex cone). With s = jω, φ = π/2. References:
Schiessel, Metzler, Blumen & Nonnenmacher, J. Phys. A 28 (1995) 6567; Bagley & Torvik,
J. Rheol. 27 (1983) 201 (positive coefficients and orders in [0, 1] for thermodynamic
admissibility).
"""

from __future__ import annotations

import ast
from dataclasses import dataclass

import numpy as np

from .._io import show
from ..errors import StructureError
from .expressions import MAX_EXPRESSION, Expr
from .response import jw_power

ELEMENTS = {"spring": 1, "dashpot": 1, "springpot": 2}
COMBINATIONS = ("series", "parallel")
SYMBOLS = {"series": " — ", "parallel": " ∥ "}


@dataclass(frozen=True)
class Element:
    """One element: ``kind`` (spring, dashpot, springpot), its coefficient and order."""

    kind: str
    coefficient: Expr
    order: Expr | None = None

    def order_value(self, values):
        if self.kind == "spring":
            return 0.0
        if self.kind == "dashpot":
            return 1.0
        return self.order(values)

    def __str__(self) -> str:
        if self.kind == "springpot":
            return f"springpot({self.coefficient}, {self.order})"
        return f"{self.kind}({self.coefficient})"


@dataclass(frozen=True)
class Network:
    """A series–parallel network of elements, parsed from text."""

    text: str
    tree: tuple  # ("series" | "parallel", (children...)) or an Element

    @classmethod
    def parse(cls, text, where: str) -> Network:
        if not isinstance(text, str) or not text.strip() or len(text) > 4 * MAX_EXPRESSION:
            raise StructureError(f"{where}: 'network' must be text such as "
                                 f"'series(spring(G_m), springpot(V, alpha))', got {text!r}")
        try:
            node = ast.parse(text.strip(), mode="eval").body
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            raise StructureError(f"{where}: cannot read the network {show(text, 80)}") from None
        try:
            return cls(text.strip(), cls._build(node, where, text))
        except RecursionError:
            raise StructureError(f"{where}: the network is nested too deeply") from None

    @classmethod
    def _build(cls, node, where: str, text: str):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)) or node.keywords:
            raise StructureError(
                f"{where}: cannot read the network {show(text, 80)}: use spring(G), "
                "dashpot(eta), springpot(V, alpha), series(...) and parallel(...)"
            )
        name = node.func.id
        if name in COMBINATIONS:
            if len(node.args) < 2:
                raise StructureError(f"{where}: {name}(...) in the network needs two or more parts")
            return (name, tuple(cls._build(a, where, text) for a in node.args))
        if name not in ELEMENTS:
            raise StructureError(
                f"{where}: unknown network element {show(name)}; known: "
                f"{', '.join([*ELEMENTS, *COMBINATIONS])}"
            )
        if len(node.args) != ELEMENTS[name]:
            raise StructureError(f"{where}: {name}(...) takes {ELEMENTS[name]} argument(s)")
        args = [Expr.parse(ast.unparse(a), where) for a in node.args]
        return Element(name, args[0], args[1] if len(args) > 1 else None)

    # ------------------------------------------------------------------ introspection
    def elements(self) -> list[Element]:
        out, stack = [], [self.tree]
        while stack:
            t = stack.pop()
            if isinstance(t, Element):
                out.append(t)
            else:
                stack.extend(reversed(t[1]))
        return out

    @property
    def names(self) -> set[str]:
        out = set()
        for e in self.elements():
            out |= e.coefficient.names | (e.order.names if e.order else set())
        return out

    def picture(self) -> str:
        """The network in symbols, e.g. ``G_e ∥ (G_m — V,alpha)``."""

        def show_tree(t, top=False):
            if isinstance(t, Element):
                if t.kind == "springpot":
                    return f"springpot({t.coefficient}, {t.order})"
                return f"{t.kind} {t.coefficient}"
            inner = SYMBOLS[t[0]].join(show_tree(c) for c in t[1])
            return inner if top else f"({inner})"

        return show_tree(self.tree, top=True)

    def modulus_text(self, fixed: dict | None = None) -> str:
        """G*(s) of the network in symbols: moduli add in parallel, compliances in series,
        e.g. ``G_e + c_q s^q`` or ``G_e + 1/(1/G_m + 1/(c_q s^q))``; an order that ``fixed``
        (``{name: value}``, e.g. an integer variant's orders at 1) determines is written as
        its value (``c_q s`` for q = 1, a spring's modulus for order 0).

        Examples
        --------
        >>> Network.parse("parallel(spring(G_e), springpot(c_q, q))", "x").modulus_text()
        'G_e + c_q s^q'
        >>> Network.parse("series(springpot(c_beta, beta), springpot(c_delta, beta - alpha))",
        ...               "x").modulus_text()
        '1/(1/(c_beta s^beta) + 1/(c_delta s^(beta - alpha)))'
        """

        def power(order) -> str:
            text = order.substitute(fixed or {})
            try:
                value = float(text)
            except ValueError:  # an order left free
                return f"s^{text}" if text.replace("_", "").isalnum() else f"s^({text})"
            return "" if value == 0 else "s" if value == 1 else f"s^{value:g}"

        def modulus(t) -> str:
            if isinstance(t, Element):
                if t.kind == "spring":
                    return str(t.coefficient)
                if t.kind == "dashpot":
                    return f"{t.coefficient} s"
                return f"{t.coefficient} {power(t.order)}".rstrip()
            if t[0] == "parallel":
                return " + ".join(modulus(c) for c in t[1])
            return "1/(" + " + ".join(compliance(c) for c in t[1]) + ")"

        def compliance(t) -> str:
            if isinstance(t, Element):
                inner = modulus(t)
                return f"1/{inner}" if " " not in inner else f"1/({inner})"
            if t[0] == "series":
                return " + ".join(compliance(c) for c in t[1])
            return f"1/({modulus(t)})"

        return modulus(self.tree)

    # ------------------------------------------------------------------ evaluation
    def modulus(self, values, omega) -> np.ndarray:
        """G(jω) of the network, shape (n_sets, n_freq) for ``values`` of shape (n_sets,)."""
        omega = np.asarray(omega, dtype=float)

        def ev(t):
            if isinstance(t, Element):
                c = np.atleast_1d(t.coefficient(values))[:, None]
                return c * jw_power(omega, np.atleast_1d(t.order_value(values))[:, None])
            parts = [ev(c) for c in t[1]]
            if t[0] == "parallel":
                return sum(parts)
            return 1.0 / sum(1.0 / p for p in parts)

        with np.errstate(all="ignore"):
            return ev(self.tree)

    def positive(self, values) -> np.ndarray:
        """Rows where every coefficient is positive and finite and every order lies in [0, 1]:
        the sufficient condition for passivity and stability stated in the module docstring."""
        ok = True
        with np.errstate(invalid="ignore"):
            for e in self.elements():
                c = e.coefficient(values)
                ok = ok & np.isfinite(c) & (c > 0)
                if e.kind == "springpot":
                    q = e.order(values)
                    ok = ok & (q >= 0) & (q <= 1)
        return np.asarray(ok, dtype=bool)
