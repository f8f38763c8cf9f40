"""The package's modules import one another without a circle, deferred imports included."""

import ast
from pathlib import Path

import networkx as nx

import qrrt_circuits

ROOT = Path(qrrt_circuits.__file__).resolve().parent
PACKAGE = "qrrt_circuits"


def _modules() -> dict[str, Path]:
    found = {}
    for path in ROOT.rglob("*.py"):
        parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join(parts)] = path
    return found


def _type_checking(node: ast.AST) -> bool:
    return isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)


def _imports(tree: ast.AST) -> list[ast.ImportFrom | ast.Import]:
    """Every import statement of a module, deferred ones included, except under TYPE_CHECKING."""
    out = []
    stack = [tree]
    while stack:
        node = stack.pop()
        for child in ast.iter_child_nodes(node):
            if _type_checking(child):
                stack.extend(child.orelse)
                continue
            if isinstance(child, ast.Import | ast.ImportFrom):
                out.append(child)
            stack.append(child)
    return out


def import_graph() -> nx.DiGraph:
    """Module -> the package's modules it imports (``from p import name`` counts as importing the
    submodule p.name where that is a module, else p)."""
    modules = _modules()
    graph = nx.DiGraph()
    graph.add_nodes_from(modules)
    for name, path in modules.items():
        is_package = path.name == "__init__.py"
        base = name.split(".") if is_package else name.split(".")[:-1]
        for node in _imports(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            else:
                if node.level:
                    prefix = base[:len(base) - node.level + 1]
                    source = ".".join(prefix + ([node.module] if node.module else []))
                else:
                    source = node.module or ""
                targets = [f"{source}.{alias.name}" if f"{source}.{alias.name}" in modules else source
                           for alias in node.names]
            for target in targets:
                while target and target not in modules:
                    target = target.rpartition(".")[0]
                if target.startswith(PACKAGE) and target != name and target in modules:
                    graph.add_edge(name, target)
    return graph


def test_no_import_circle():
    graph = import_graph()
    # a package's __init__ re-exports its submodules: edges from a package to its own submodules
    # are its re-exports, not dependencies of the submodules on the package
    circles = [cycle for cycle in nx.simple_cycles(graph)]
    assert not circles, f"{len(circles)} import circles, e.g. {sorted(circles, key=len)[:3]}"


#: the package's layers, bottom first: a module imports only from its own layer or the layers below
#: (``docs/DESIGN.md``, "Layers"); the package's root modules are the top layer
LAYERS = (
    {"_support"},
    {"probability"},
    {"world", "reachability"},
    {"problems"},
    {"search", "hardware"},
    {"coherent"},
    {"planners"},
    {"execution", "registry", "plotting"},
    {"adapters", "experiments"},
    {"cli", "(root)"},
)
#: imports against the layer order that remain, each named: (importing module, imported module)
LAYER_EXCEPTIONS = {
    # the process pools' warm-up builds the experiments' default world (and its exact check) once per
    # worker ...
    ("qrrt_circuits._support.worker_warmup", "qrrt_circuits.experiments"),
    ("qrrt_circuits._support.worker_warmup", "qrrt_circuits.experiments.worlds"),
    # ... and loads the kernels of the problem families' plans
    ("qrrt_circuits._support.worker_warmup", "qrrt_circuits.experiments.problems"),
    # the OMPL planner adapter reads the package version for OMPL's planner name
    ("qrrt_circuits.adapters.ompl_planning", "qrrt_circuits"),
}


def layer_of(module: str) -> str:
    """A module's layer name: its first package below ``qrrt_circuits``, or "(root)"."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "(root)"


def test_layers_are_declared_for_every_package():
    declared = set().union(*LAYERS)
    assert {layer_of(module) for module in import_graph().nodes} <= declared


def test_imports_look_one_way():
    """Every import goes to the module's own layer or one below it, but the named exceptions."""
    rank = {name: index for index, names in enumerate(LAYERS) for name in names}
    upward = {(a, b) for a, b in import_graph().edges() if rank[layer_of(b)] > rank[layer_of(a)]}
    assert upward <= LAYER_EXCEPTIONS, f"imports against the layer order: {sorted(upward - LAYER_EXCEPTIONS)}"
    assert LAYER_EXCEPTIONS <= upward, f"exceptions that no longer occur: {sorted(LAYER_EXCEPTIONS - upward)}"


#: private names a module of one layer takes from another layer, each named: (module, name)
PRIVATE_EXCEPTIONS: set[tuple[str, str]] = set()


def test_no_private_name_crosses_a_layer():
    """No module imports a ``_``-prefixed name from a module of another layer, nor calls a
    ``_``-prefixed method that only another layer defines (on anything but self, cls or super())."""
    modules = _modules()
    defined: dict[str, set[str]] = {}  # private method name -> the layers that define it
    trees = {name: ast.parse(path.read_text()) for name, path in modules.items()}
    for name, tree in trees.items():
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and _private(node.name):
                defined.setdefault(node.name, set()).add(layer_of(name))
    found = set()
    for name, tree in trees.items():
        own = layer_of(name)
        outside = {alias.asname or alias.name.split(".")[0] for node in ast.walk(tree) if isinstance(node, ast.Import)
                   for alias in node.names if not alias.name.startswith(PACKAGE)}  # os, sys, numpy, ...
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                for alias in node.names:
                    if _private(alias.name) and layer_of(node.module) != own:
                        found.add((name, alias.name))
            if isinstance(node, ast.ImportFrom) and node.level:
                base = name.split(".") if modules[name].name == "__init__.py" else name.split(".")[:-1]
                source = base[:len(base) - node.level + 1] + ([node.module] if node.module else [])
                for alias in node.names:
                    if _private(alias.name) and layer_of(".".join(source)) != own:
                        found.add((name, alias.name))
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and _private(node.func.attr)
                    and not _is_self(node.func.value) and own not in defined.get(node.func.attr, {own})
                    and not (isinstance(node.func.value, ast.Name) and node.func.value.id in outside)):
                found.add((name, node.func.attr))
    assert found <= PRIVATE_EXCEPTIONS, f"private names across layers: {sorted(found - PRIVATE_EXCEPTIONS)}"


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _is_self(node: ast.AST) -> bool:
    return (isinstance(node, ast.Name) and node.id in ("self", "cls")) or (
        isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "super")
