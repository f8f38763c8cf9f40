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
