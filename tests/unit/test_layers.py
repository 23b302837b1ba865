"""The package's layers: no import cycle, at module level or through the imports inside
functions, and every layer imports only the layers before it (docs/architecture.md)."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).parents[2] / "bayesfo"

#: The layers in the order of the data flow; a layer may import those before it. The
#: infrastructure modules come first; ``cli`` is last and nothing imports it. ``predictions``
#: works on any posterior's draws and comes before ``comparison``, whose results call it.
LAYERS = (
    ("errors", "_io", "_signals", "_text", "priors", "parallel", "outdir"),
    ("data",),
    ("structures", "models"),
    ("identify", "timeseries", "studies"),
    ("options",),
    ("inference",),
    ("predictions",),
    ("comparison", "tts"),
    ("planning",),
    ("plotting",),
    ("output",),
    ("batch",),
    ("cli",),
)


def _modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _imports(modules: dict[str, Path]) -> dict[str, set[str]]:
    """Module -> the package modules it imports, anywhere in its body: at module level and
    inside functions. Not counted: the imports under ``if TYPE_CHECKING:`` and those of a
    module's ``__getattr__`` (the package face's names loaded on first use)."""
    edges = {}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        found = set()
        todo = [ast.parse(path.read_text())]
        while todo:
            node = todo.pop()
            if isinstance(node, ast.If) and getattr(node.test, "id", "") == "TYPE_CHECKING":
                todo.extend(node.orelse)
                continue
            if isinstance(node, ast.FunctionDef) and node.name == "__getattr__":
                continue
            todo.extend(ast.iter_child_nodes(node))
            targets = []
            if isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(up + ([node.module] if node.module else []))
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base
                           for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            for target in targets:
                while target and target not in modules and "." in target:
                    target = target.rpartition(".")[0]
                if target in modules and target != name and target != "bayesfo":
                    found.add(target)
        edges[name] = found
    return edges


MODULES = _modules()
EDGES = _imports(MODULES)


def _top(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def test_no_module_imports_itself_through_others():
    """Tarjan's strongly connected components of the module graph: every one is a single
    module."""
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in EDGES[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for v in EDGES:
        if v not in index:
            visit(v)
    assert cycles == []


def test_every_layer_imports_only_the_layers_before_it():
    rank = {name: k for k, layer in enumerate(LAYERS) for name in layer}
    listed = set(rank) | {""}
    found = {_top(m) for m in MODULES}
    assert found <= listed, f"modules in no layer: {sorted(found - listed)}"
    upward = []
    for module, targets in EDGES.items():
        top = _top(module)
        if top == "":
            continue
        for target in targets:
            other = _top(target)
            if other != top and rank[other] > rank[top]:
                upward.append(f"{module} ({top}) imports {target} ({other})")
    assert upward == []


#: Most imports of the package's own modules inside functions, outside the package face
#: (``bayesfo/__init__.py``, which loads its names on first use) and the command line (which
#: imports the computing modules when a command runs). The rest load at the top of their
#: module; those left inside functions each load libraries that their module does not (scipy's
#: optimisers, ArviZ, matplotlib for figures), or are in the master-curve modules being
#: rewritten (tts.joint, tts.conditional, tts.smooth_posterior, tts.shifts: 30 of them). The
#: goal is under 40.
MAX_FUNCTION_LEVEL_IMPORTS = 66


def _lazy_allowed(module: str) -> bool:
    return module == "bayesfo" or module == "bayesfo.cli" or module.startswith("bayesfo.cli.")


def _inside_functions():
    """(module, line, the module imported) of every import of a package module inside a
    function, and (module, name imported, from) of every private name or private module
    imported from another top-level package (``bayesfo.inference._arviz`` from
    ``bayesfo.tts``; the root's ``_io``, ``_text`` and ``_signals`` are modules of every
    layer, their private names are not)."""
    inside, private = [], []
    for name, path in MODULES.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]

        def visit(node, in_function):
            for child in ast.iter_child_nodes(node):
                function = in_function or isinstance(child, (ast.FunctionDef,
                                                             ast.AsyncFunctionDef))
                if isinstance(child, ast.If) and getattr(child.test, "id", "") == "TYPE_CHECKING":
                    continue
                if isinstance(child, ast.ImportFrom) and (child.level or (child.module or "")
                                                          .startswith("bayesfo")):
                    base = child.module or ""
                    if child.level:
                        up = package.split(".")[: len(package.split(".")) - child.level + 1]
                        base = ".".join(up + ([child.module] if child.module else []))
                    if in_function and not _lazy_allowed(name):
                        inside.append((name, child.lineno, base))
                    other = _top(base)
                    if other and other != _top(name):
                        for alias in child.names:
                            hidden = alias.name.startswith("_") and not alias.name.startswith("__")
                            if hidden or any(p.startswith("_") for p in base.split(".")[2:]):
                                private.append((name, f"{base}.{alias.name}"))
                visit(child, function)

        visit(ast.parse(path.read_text()), False)
    return inside, private


INSIDE, PRIVATE = _inside_functions()


def test_the_package_modules_are_imported_at_the_top_of_a_module():
    assert len(INSIDE) <= MAX_FUNCTION_LEVEL_IMPORTS, sorted(INSIDE)


def test_no_private_name_is_imported_from_another_package():
    assert PRIVATE == []
