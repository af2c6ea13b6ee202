"""The house rules of docs/architecture.md, checked on the source tree.

- no import cycle between modules;
- imports point down the layers (frames/errors/limits/validation < numerics < particles, rigid <
  earth, analytic < scenes < app), and particles and rigid do not import each other;
- no module imports another module's private (``_name``) names;
- no module is much over 600 lines unless it is listed below with the reason.

Imports are read with ``ast`` (every ``import`` anywhere in a module, including those inside
functions), so a lazy import counts like any other.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = SRC / "rotframe"

#: layer of each top-level part of the package (lower imports nothing higher)
LAYERS = {
    "errors": 0, "limits": 0, "validation": 0, "units": 0, "frames": 0, "files": 0, "method_registry": 0,
    "numerics": 1,
    "particles": 2, "rigid": 2,
    "earth": 3, "analytic": 3, "problem": 3, "forces": 3, "events": 3, "torques": 3,
    "scenes": 4,
    "app": 5, "__main__": 5,
}
#: parts of one layer that must not import each other
APART = {frozenset({"particles", "rigid"})}
MAX_LINES = 620
#: modules allowed to be longer, and why (one concept each)
LONG_MODULES: dict[str, str] = {}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


MODULES = _modules()


def _imports(name: str, path: Path):
    """(target module, imported name or None) for every rotframe import in the module."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target == "rotframe" or target.startswith("rotframe."):
                for alias in node.names:
                    full = f"{target}.{alias.name}"
                    yield (full, None) if full in MODULES else (target, alias.name)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("rotframe"):
                    yield alias.name, None


EDGES = {name: sorted({t for t, _ in _imports(name, path) if t != name}) for name, path in MODULES.items()}


def _part(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def test_the_module_table_is_complete():
    missing = sorted({_part(m) for m in MODULES if _part(m)} - set(LAYERS))
    assert not missing, f"parts of the package with no layer in LAYERS: {missing}"


def test_no_import_cycle():
    graph = defaultdict(set)
    for source, targets in EDGES.items():
        graph[source] |= {t for t in targets if t in MODULES}
    index, low, stack, on_stack, cycles = {}, {}, [], set(), []

    def visit(v):  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for v in sorted(MODULES):
        if v not in index:
            visit(v)
    assert not cycles, f"import cycles: {cycles}"


def test_imports_point_down():
    upward = []
    for source, targets in EDGES.items():
        a = _part(source)
        if a is None:  # the package's own __init__ loads by name only
            continue
        for target in targets:
            b = _part(target)
            if b is None or a == b:
                continue
            if LAYERS[b] > LAYERS[a] or frozenset({a, b}) in APART:
                upward.append(f"{source} -> {target}")
    assert not upward, "imports against the layers:\n" + "\n".join(upward)


def test_no_module_imports_private_names_of_another():
    private = [f"{name} imports {target}.{imported}" for name, path in MODULES.items()
               for target, imported in _imports(name, path)
               if imported and imported.startswith("_") and not imported.startswith("__") and target != name]
    private += [f"{name} imports {target}" for name, targets in EDGES.items() for target in targets
                if any(p.startswith("_") and not p.startswith("__") for p in target.split("."))]
    assert not private, "\n".join(private)


@pytest.mark.parametrize("name", sorted(MODULES))
def test_modules_are_small(name):
    lines = len(MODULES[name].read_text().splitlines())
    if name in LONG_MODULES:
        return
    assert lines <= MAX_LINES, f"{name}: {lines} lines (split it by concept, or list it in LONG_MODULES with why)"


def test_a_planted_upward_import_is_caught(tmp_path):
    """The checker itself: an import from app in a particle module is reported."""
    global EDGES
    saved = EDGES
    try:
        EDGES = dict(saved)
        EDGES["rotframe.particles.forces"] = [*saved["rotframe.particles.forces"], "rotframe.app.cli"]
        with pytest.raises(AssertionError, match="particles.forces -> rotframe.app.cli"):
            test_imports_point_down()
    finally:
        EDGES = saved


def test_every_package_ships_in_the_wheel():
    """pyproject.toml lists its packages by name (scenarios/ is mapped in): a new folder must be listed."""
    import tomllib

    listed = set(tomllib.loads((SRC.parent / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {_module_name(p.parent / "__init__.py") for p in PACKAGE.rglob("__init__.py")}
    assert found <= listed, f"packages missing from pyproject.toml: {sorted(found - listed)}"
