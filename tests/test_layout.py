"""The package's layout rules: no module-level import cycle, short modules and functions, and device
code apart from host code. Read from the source with ``ast``: nothing under test is imported."""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

from helpers import ROOT

MAX_MODULE_LINES = 600
"""A module has fewer lines than this."""
MAX_FUNCTION_LINES = 120
"""A function, method, ``@wp.kernel`` or ``@wp.func`` has fewer lines than this (decorators aside)."""
TREES = {"warpcaustics": ROOT / "warpcaustics", "warpcaustics.kernels": ROOT / "kernels"}
"""Package name -> folder: ``kernels/`` is installed as ``warpcaustics.kernels`` (pyproject's package-dir)."""
WARP_HOST_CALLS = {
    "launch", "launch_tiled",  # launches
    "array", "zeros", "zeros_like", "empty", "empty_like", "full", "full_like", "ones", "ones_like",
    "clone", "copy", "from_numpy",  # allocations and copies
}
"""``wp.*`` calls that belong in host code: kernels/ declares, warpcaustics/ launches and allocates."""


@cache
def modules() -> dict[str, Path]:
    """Every module of the package by dotted name (a package by its ``__init__.py``)."""
    out = {}
    for package, folder in TREES.items():
        for path in sorted(folder.rglob("*.py")):
            parts = path.relative_to(folder).with_suffix("").parts
            if parts[-1] == "__init__":
                parts = parts[:-1]
            name = ".".join((package, *parts))
            if name.startswith("warpcaustics.kernels") and package == "warpcaustics":
                continue  # not a folder of warpcaustics/ (kernels/ is mapped in its place)
            out[name] = path
    return out


@cache
def parse(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _module_level_imports(body: list[ast.stmt]):
    """The import statements that run when the module is imported: at the top level and inside
    top-level ``if``/``try``/``with`` blocks and class bodies, not in functions, and not under
    ``if TYPE_CHECKING:`` (which never runs)."""
    for node in body:
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, ast.If):
            if not _is_type_checking(node.test):
                yield from _module_level_imports(node.body)
            yield from _module_level_imports(node.orelse)
        elif isinstance(node, ast.Try) or type(node).__name__ == "TryStar":
            yield from _module_level_imports(node.body)
            for handler in node.handlers:
                yield from _module_level_imports(handler.body)
            yield from _module_level_imports(node.orelse)
            yield from _module_level_imports(node.finalbody)
        elif isinstance(node, (ast.With, ast.ClassDef)):
            yield from _module_level_imports(node.body)


def _ancestors(name: str) -> list[str]:
    parts = name.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def import_edges(name: str) -> set[str]:
    """The package's modules that importing ``name`` imports directly (module-level imports only).

    ``from a.b import c`` imports ``a.b.c`` where that is a module, else ``a.b``; importing a module
    also imports its parent packages' ``__init__``, except ``name``'s own ancestors: Python has
    imported those before ``name`` runs, so they add no edge (a package's ``__init__`` importing its
    submodules, which import their siblings, is no cycle). An explicit ``from a import x`` of a
    name defined in the package ``a`` always counts, ancestor or not.
    """
    known = modules()
    is_package = known[name].name == "__init__.py"
    package = name if is_package else name.rpartition(".")[0]
    targets = set()
    for node in _module_level_imports(parse(known[name]).body):
        if isinstance(node, ast.Import):
            found = [alias.name for alias in node.names]
        else:
            base = node.module or ""
            if node.level:  # relative: from the importing module's package, one level up per extra dot
                parts = package.split(".")
                base = ".".join([*parts[: len(parts) - node.level + 1], *([base] if base else [])])
            found = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names]
        for target in found:
            if target in known:
                targets.add(target)
            targets.update(a for a in _ancestors(target) if a in known and a not in _ancestors(name))
    targets.discard(name)
    return targets


def strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components of ``graph`` (iterative: no recursion limit)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                components.append(sorted(component))
    return components


def _cycle(graph: dict[str, set[str]], component: list[str]) -> list[str]:
    """One cycle through the component's first module, for the failure message."""
    members = set(component)
    start = component[0]
    paths = {start: [start]}
    frontier = [start]
    while frontier:
        node = frontier.pop(0)
        for child in sorted(graph[node] & members):
            if child == start:
                return [*paths[node], start]
            if child not in paths:
                paths[child] = [*paths[node], child]
                frontier.append(child)
    return component


def _relative(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def test_strongly_connected_finds_a_cycle_and_only_cycles():
    """The cycle check itself: a → b → c → a is one component, d (imported by a) stands alone."""
    graph = {"a": {"b", "d"}, "b": {"c"}, "c": {"a"}, "d": set()}
    assert sorted(strongly_connected(graph)) == [["a", "b", "c"], ["d"]]
    assert _cycle(graph, ["a", "b", "c"]) == ["a", "b", "c", "a"]


def test_no_module_level_import_cycle():
    """No module of warpcaustics (kernels included) imports itself again through others at import time."""
    graph = {name: import_edges(name) for name in modules()}
    assert len(graph) > 20 and "warpcaustics.kernels.geometry" in graph  # the tree was found
    cycles = [" -> ".join(_cycle(graph, c)) for c in strongly_connected(graph) if len(c) > 1]
    assert cycles == [], "module-level import cycles:\n" + "\n".join(cycles)


def test_modules_are_short():
    """Every module in warpcaustics/ and kernels/ has fewer than MAX_MODULE_LINES lines."""
    long = {}
    for path in modules().values():
        lines = len(path.read_text(encoding="utf-8").splitlines())
        if lines >= MAX_MODULE_LINES:
            long[_relative(path)] = lines
    assert long == {}, f"modules of {MAX_MODULE_LINES} lines or more: {long}"


def test_functions_are_short():
    """Every function, method, @wp.kernel and @wp.func has fewer than MAX_FUNCTION_LINES lines."""
    long = {}
    for path in modules().values():
        for node in ast.walk(parse(path)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines >= MAX_FUNCTION_LINES:
                    long[f"{_relative(path)}:{node.lineno} {node.name}"] = lines
    assert long == {}, f"functions of {MAX_FUNCTION_LINES} lines or more: {long}"


def _host_code(tree: ast.Module) -> list[str]:
    """What in a kernels/ module is host code: numpy imports, Warp launches and allocations."""
    warp_names = {"wp"}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name == "warp":
                    warp_names.add(alias.asname or "warp")
                if alias.name.split(".")[0] == "numpy":
                    found.append(f"{node.lineno}: import {alias.name}")
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            if node.module.split(".")[0] == "numpy":
                found.append(f"{node.lineno}: from {node.module} import")
            if node.module == "warp":
                found += [f"{node.lineno}: from warp import {a.name}" for a in node.names
                          if a.name in WARP_HOST_CALLS]
    # A kernel's or struct's ``wp.array(dtype=...)`` annotation declares a type, it allocates nothing.
    annotations = [n.annotation for n in ast.walk(tree) if isinstance(n, (ast.arg, ast.AnnAssign))]
    annotations += [n.returns for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)]
    in_annotation = {id(n) for a in annotations if a is not None for n in ast.walk(a)}
    for node in ast.walk(tree):
        func = node.func if isinstance(node, ast.Call) and id(node) not in in_annotation else None
        if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
                and func.value.id in warp_names and func.attr in WARP_HOST_CALLS):
            found.append(f"{node.lineno}: {func.value.id}.{func.attr}(...)")
    return found


def test_host_code_never_inside_kernels():
    """kernels/ holds device code only: no numpy import, no wp.launch, no wp.array/zeros/empty (or
    other) allocation; those belong to the host classes in warpcaustics/."""
    found = {}
    for name, path in modules().items():
        if name.startswith("warpcaustics.kernels"):
            if host := _host_code(parse(path)):
                found[_relative(path)] = host
    assert found == {}, f"host code in kernels/: {found}"


def test_host_code_check_sees_launches_allocations_and_numpy():
    """The kernels/ check itself flags a launch, an allocation and numpy, and lets a kernel's array
    annotations and wp.* device built-ins through."""
    source = (
        "import numpy as np\nimport warp as wp\n"
        "@wp.kernel\ndef k(a: wp.array(dtype=float)):\n    a[wp.tid()] = wp.max(1.0, 2.0)\n"
        "def host(n):\n    x = wp.zeros(n, dtype=float)\n    wp.launch(k, dim=n, inputs=[x])\n"
    )
    found = _host_code(ast.parse(source))
    assert sorted(found) == ["1: import numpy", "7: wp.zeros(...)", "8: wp.launch(...)"]
