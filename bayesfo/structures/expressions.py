"""Arithmetic expressions in the cards: the physical parameters of a structure as functions of
its coefficients (``"(a1*b0 - b1)/b0**2"``), their inverses, unit exponents (``"beta - alpha"``)
and the arguments of a mechanical network.

Only numbers, parameter names, ``+ - * / **`` and parentheses are allowed; expressions are
parsed once, checked, and evaluated on arrays of parameter sets.
"""

from __future__ import annotations

import ast
import math
import operator
from dataclasses import dataclass, field

import numpy as np

from .._io import show
from ..errors import StructureError

_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
           ast.Div: operator.truediv, ast.Pow: operator.pow}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos}

#: Longest expression text accepted (a card's expressions are a few dozen characters).
MAX_EXPRESSION = 400


def _check(node, where: str, text: str) -> None:
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        _check(node.left, where, text)
        _check(node.right, where, text)
    elif isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
        _check(node.operand, where, text)
    elif isinstance(node, ast.Name):
        if node.id.lower() in ("nan", "inf", "infinity"):
            raise StructureError(f"{where}: {show(node.id)} in {show(text, 80)} is not a name")
    elif isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)) \
                or not math.isfinite(node.value):
            raise StructureError(f"{where}: {show(text, 80)} holds {node.value!r}; only finite "
                                 "numbers, names, + - * / ** and parentheses are allowed")
    else:
        raise StructureError(f"{where}: cannot read {show(text, 80)}; only finite numbers, "
                             "names, + - * / ** and parentheses are allowed")


@dataclass(frozen=True)
class Expr:
    """A checked arithmetic expression of parameter names."""

    text: str
    tree: ast.AST = field(repr=False, compare=False)
    names: frozenset = field(compare=False)

    @classmethod
    def parse(cls, text, where: str) -> Expr:
        if isinstance(text, bool) or not isinstance(text, (str, int, float)):
            raise StructureError(f"{where}: expected an expression as text, got {text!r}")
        text = str(text).strip()
        if not text or len(text) > MAX_EXPRESSION:
            raise StructureError(f"{where}: expected an expression of 1 to {MAX_EXPRESSION} "
                                 f"characters, got {show(text, 80)}")
        try:
            tree = ast.parse(text, mode="eval").body
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            raise StructureError(f"{where}: cannot read {show(text, 80)}; write an expression "
                                 "such as '(a1*b0 - b1)/b0**2'") from None
        try:
            _check(tree, where, text)
        except RecursionError:
            raise StructureError(f"{where}: {show(text, 80)} is nested too deeply") from None
        names = frozenset(n.id for n in ast.walk(tree) if isinstance(n, ast.Name))
        return cls(text, tree, names)

    def __call__(self, values) -> np.ndarray:
        """The value for ``{name: array}`` (arrays broadcast); errors become NaN or inf."""
        with np.errstate(all="ignore"):
            return np.asarray(self._eval(self.tree, values), dtype=float)

    def _eval(self, node, values):
        if isinstance(node, ast.BinOp):
            # numpy scalars and arrays: overflow and division by zero give inf, not errors
            left, right = self._eval(node.left, values), self._eval(node.right, values)
            return _BINARY[type(node.op)](left, right)
        if isinstance(node, ast.UnaryOp):
            return _UNARY[type(node.op)](self._eval(node.operand, values))
        if isinstance(node, ast.Name):
            return np.asarray(values[node.id], dtype=float)
        return np.float64(node.value)

    def substitute(self, fixed: dict) -> str:
        """The text with the names in ``fixed`` replaced by their values (a number when no
        name is left)."""
        if self.names <= set(fixed):
            return f"{float(self({k: float(v) for k, v in fixed.items()})):g}"
        if not self.names & set(fixed):
            return self.text

        class _Sub(ast.NodeTransformer):
            def visit_Name(self, node):
                if node.id in fixed:
                    return ast.copy_location(ast.Constant(float(fixed[node.id])), node)
                return node

        return ast.unparse(_Sub().visit(ast.parse(self.text, mode="eval")))

    def __str__(self) -> str:
        return self.text
