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
