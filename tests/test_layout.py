"""The package's layout: no import cycle among lmcr's modules, and the library never imports Prefect.

Imports are read from the source (ast), not executed: module-level and function-level imports both
count, those under `if TYPE_CHECKING:` do not (they never run)."""

from __future__ import annotations

import ast
from pathlib import Path

LMCR = Path(__file__).resolve().parent.parent / "lmcr"


def module_name(path: Path, root: Path = LMCR) -> str:
    """'lmcr.a.b' for lmcr/a/b.py, 'lmcr.a' for lmcr/a/__init__.py."""
    parts = [root.name, *path.relative_to(root).with_suffix("").parts]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    """The ids of the nodes under `if TYPE_CHECKING:` (or `typing.TYPE_CHECKING`)."""
    skipped = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skipped |= {id(sub) for stmt in node.body for sub in ast.walk(stmt)}
    return skipped


def imported_names(source: str, name: str, is_package: bool) -> set[str]:
    """Every dotted name a module's imports may load (`from a import b` gives a and a.b), relative
    imports resolved against `name`."""
    tree = ast.parse(source)
    skipped = _type_checking_nodes(tree)
    package = name if is_package else name.rpartition(".")[0]
    names = set()
    for node in ast.walk(tree):
        if id(node) in skipped:
            continue
        if isinstance(node, ast.Import):
            names |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                stem = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*stem, *([node.module] if node.module else [])])
            names |= {base, *(f"{base}.{alias.name}" for alias in node.names)}
    return names


def import_graph(root: Path = LMCR) -> dict[str, set[str]]:
    """Module -> the lmcr modules it imports (a name resolved to its longest module prefix)."""
    paths = {module_name(p, root): p for p in root.rglob("*.py")}
    graph = {}
    for name, path in paths.items():
        targets = set()
        for imported in imported_names(path.read_text(encoding="utf-8"), name, path.name == "__init__.py"):
            while imported and imported not in paths:
                imported = imported.rpartition(".")[0]
            if imported and imported != name:
                targets.add(imported)
        graph[name] = targets
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = _pop_component(stack, on_stack, node)
                    if len(component) > 1:
                        found.append(sorted(component))
            elif child not in index:
                index[child] = low[child] = len(index)
                stack.append(child)
                on_stack.add(child)
                work.append((child, iter(sorted(graph[child]))))
            elif child in on_stack:
                low[node] = min(low[node], index[child])
    return found


def _pop_component(stack: list[str], on_stack: set[str], root: str) -> list[str]:
    """Tarjan's step for a component's root: the nodes above it on the stack, and itself, off the stack."""
    component = []
    while not component or component[-1] != root:
        component.append(stack.pop())
        on_stack.discard(component[-1])
    return component


def test_the_checker_finds_a_cycle_and_skips_type_checking_imports(tmp_path):
    root = tmp_path / "lmcr"
    (root / "sub").mkdir(parents=True)
    (root / "__init__.py").write_text('"""p"""\n')
    (root / "sub" / "__init__.py").write_text('"""p"""\n')
    (root / "a.py").write_text("from lmcr.sub import b\n")
    (root / "sub" / "b.py").write_text("def f():\n    from . import c\n")
    (root / "sub" / "c.py").write_text("import lmcr.a\n")
    (root / "d.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import lmcr.a\n")
    graph = import_graph(root)
    assert graph["lmcr.sub.b"] == {"lmcr.sub", "lmcr.sub.c"} and graph["lmcr.d"] == set()
    assert cycles(graph) == [["lmcr.a", "lmcr.sub.b", "lmcr.sub.c"]]


def test_no_import_cycle_among_lmcr_modules():
    assert cycles(import_graph()) == []


def test_the_library_never_imports_prefect():
    users = sorted(
        name
        for name, path in ((module_name(p), p) for p in LMCR.rglob("*.py"))
        if any(
            n == "prefect" or n.startswith("prefect.")
            for n in imported_names(path.read_text(encoding="utf-8"), name, path.name == "__init__.py")
        )
    )
    assert users == []
