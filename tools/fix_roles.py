"""Convert Sphinx roles in docstrings to Markdown that mkdocstrings renders.

mkdocstrings renders docstrings as Markdown, so ``:class:`Result``` prints literally. This
script rewrites every ``:class:``, ``:func:``, ``:meth:``, ``:mod:``, ``:data:``, ``:attr:``,
``:exc:``, ``:obj:`` and ``:const:`` role under ``src/rotframe`` to

- ``[`Result`][rotframe.app.api.Result]`` (an autorefs cross-reference) when the object it
  names is rendered somewhere in the API reference, and
- ``` `Result` ``` (plain code) when it is not, so that ``mkdocs build --strict`` never meets
  an unresolved reference.

Which objects are rendered is read from the built site itself (the ``id="rotframe...."``
anchors that mkdocstrings writes), so the script first builds the docs into a temporary
folder. A role's target is found the way Sphinx would look for it: in the module (and the
class) whose docstring holds it, then as an absolute dotted path, then among the module's
package siblings. The object found is matched to a rendered anchor by identity, so a name
re-exported elsewhere (``rotframe.earth.parse_angle``) still links to where it is shown.

Run from the repository root (idempotent; rerun it after merging branches)::

    PYTHONPATH=src python tools/fix_roles.py            # rewrite in place
    PYTHONPATH=src python tools/fix_roles.py --check    # exit 1 if any role is left
"""

from __future__ import annotations

import argparse
import ast
import importlib
import re
import subprocess
import sys
import tempfile
import types
from pathlib import Path

ROLE = re.compile(r":(?:py:)?(class|func|meth|mod|data|attr|exc|obj|const):`([^`\n]+)`")
ANCHOR = re.compile(r'id="(rotframe\.[A-Za-z0-9_.]+)"')


def rendered_anchors(root: Path) -> list[str]:
    """Build the docs into a temporary folder and return the rotframe anchors found."""
    with tempfile.TemporaryDirectory() as site:
        subprocess.run(
            [sys.executable, "-m", "mkdocs", "build", "--site-dir", site, "--quiet"],
            cwd=root, check=True,
        )
        found: set[str] = set()
        for page in Path(site).rglob("*.html"):
            found.update(ANCHOR.findall(page.read_text(encoding="utf-8")))
    return sorted(found)


def _key(obj):
    """Identity key for objects whose identity is stable (modules, classes, callables)."""
    obj = getattr(obj, "__func__", obj)
    if isinstance(obj, (types.ModuleType, type, types.FunctionType, property)) or callable(obj):
        return id(obj)
    return None


def _lookup(path: str):
    """Import the longest module prefix of ``path`` and walk the rest as attributes."""
    parts = path.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except Exception:
            continue
        try:
            for name in parts[cut:]:
                obj = getattr(obj, name)
        except Exception:
            return None
        return obj
    return None


def _walk(obj, parts):
    try:
        for name in parts:
            obj = getattr(obj, name)
    except Exception:
        return None
    return obj


def _fits(obj, kind: str) -> bool:
    """Whether the object found is of the kind the role names (a module for :mod:, ...)."""
    if kind == "mod":
        return isinstance(obj, types.ModuleType)
    if kind in ("class", "exc"):
        return isinstance(obj, type)
    if kind in ("func", "meth"):
        return callable(obj) and not isinstance(obj, (type, types.ModuleType))
    return not isinstance(obj, types.ModuleType)


class Resolver:
    def __init__(self, anchors: list[str]):
        self.anchors = set(anchors)
        self.by_identity: dict[int, str] = {}
        self._keep = []
        for anchor in anchors:
            obj = _lookup(anchor)
            key = _key(obj) if obj is not None else None
            if key is None:
                continue
            self._keep.append(obj)  # keep alive so ids stay unique
            best = self.by_identity.get(key)
            home = getattr(getattr(obj, "__func__", obj), "__module__", None)
            # prefer the anchor on the object's own module page; else the shortest path
            if best is None or (home and anchor.startswith(home + ".") and not best.startswith(home + ".")):
                self.by_identity[key] = anchor

    def target(self, name: str, module: str, klass: str | None, kind: str = "obj") -> str | None:
        parts = name.split(".")
        mod = importlib.import_module(module)
        package = module.rsplit(".", 1)[0] if "." in module else module
        tries = []  # (object, dotted path it was found under)
        if klass:
            cls = _walk(mod, klass.split("."))
            if cls is not None:
                tries.append((_walk(cls, parts), f"{module}.{klass}.{name}"))
        if kind not in ("attr", "meth") or "." in name:
            tries.append((_walk(mod, parts), f"{module}.{name}"))
            tries.append((_lookup(name), name))
        if kind == "mod":
            tries.append((_lookup(f"{package}.{name}"), f"{package}.{name}"))
            tries.append((_lookup(f"rotframe.{name}"), f"rotframe.{name}"))
        for obj, path in tries:
            if obj is None or not _fits(obj, kind):
                continue
            key = _key(obj)
            if key is not None and key in self.by_identity:
                return self.by_identity[key]
            if path in self.anchors:
                return path
        return None


def enclosing_classes(source: str) -> dict[int, str]:
    """Map each line number inside a class body to the class's dotted name."""
    out: dict[int, str] = {}

    def visit(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.ClassDef):
                name = f"{prefix}.{child.name}" if prefix else child.name
                for line in range(child.lineno, (child.end_lineno or child.lineno) + 1):
                    out[line] = name
                visit(child, name)
            elif isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                visit(child, prefix)

    visit(ast.parse(source), "")
    return out


def module_name(path: Path, src: Path) -> str:
    rel = path.relative_to(src).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def convert(path: Path, src: Path, resolver: Resolver) -> tuple[str, int, int]:
    text = path.read_text(encoding="utf-8")
    if not ROLE.search(text):
        return text, 0, 0
    module = module_name(path, src)
    classes = enclosing_classes(text)
    linked = plain = 0
    out_lines = []
    for number, line in enumerate(text.splitlines(keepends=True), start=1):
        def repl(match):
            nonlocal linked, plain
            raw = match.group(2).strip()
            title = None
            explicit = re.fullmatch(r"(.+?)\s*<([^<>]+)>", raw)
            if explicit:
                title, raw = explicit.group(1), explicit.group(2)
            kind = match.group(1)
            name = raw.lstrip("~!.").rstrip("()")
            shown = title or (name.rsplit(".", 1)[-1] if raw.startswith("~") else raw.lstrip("!"))
            anchor = resolver.target(name, module, classes.get(number), kind)
            if anchor is None:
                plain += 1
                return f"`{shown}`"
            linked += 1
            return f"[`{shown}`][{anchor}]"

        out_lines.append(ROLE.sub(repl, line))
    return "".join(out_lines), linked, plain


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="only report; exit 1 if any role is left")
    args = parser.parse_args(argv)
    root = Path(__file__).resolve().parents[1]
    src = root / "src"
    files = sorted((src / "rotframe").rglob("*.py"))
    if args.check:
        left = [(f, n) for f in files for n, line in enumerate(f.read_text().splitlines(), 1) if ROLE.search(line)]
        for f, n in left:
            print(f"{f.relative_to(root)}:{n}: Sphinx role")
        return 1 if left else 0
    sys.path.insert(0, str(src))
    resolver = Resolver(rendered_anchors(root))
    total_linked = total_plain = 0
    for path in files:
        new, linked, plain = convert(path, src, resolver)
        if linked or plain:
            path.write_text(new, encoding="utf-8")
            total_linked += linked
            total_plain += plain
    print(f"{total_linked} roles became links, {total_plain} became plain code")
    return 0


if __name__ == "__main__":
    sys.exit(main())
