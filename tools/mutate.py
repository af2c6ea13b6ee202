#!/usr/bin/env python
"""Small mutation tester for rotframe's physics: plant one operator mutation at a time, run tests.

mutmut and cosmic-ray rewrite functions into Python trampolines, which numba's
``@njit`` kernels cannot compile; this script instead mutates a copy of ``src/``
and runs a chosen test subset against it, each mutant compiled by numba (its own
cache). ``--no-jit`` runs them with ``NUMBA_DISABLE_JIT=1`` instead, which once
saved the compiles; rotframe no longer imports so (a kernel for compiled code
only, `rotframe.numerics.compiled.jit_internal`, needs numba's dispatcher), so
every mutant would be an error.

Mutations, inside the chosen functions only:

* ``+`` <-> ``-`` and ``*`` -> ``/`` in binary operations and ``+=`` <-> ``-=``;
* a dropped factor: ``a * b`` -> ``a`` and -> ``b``;
* a sign flip: ``-x`` -> ``x``;
* a changed constant: a number ``c`` -> ``-c`` and, for ``c`` not 0 or 1, ``2 c``;
* a dropped assignment component: ``x = expr`` -> ``x = 0.0`` (for float targets).

A mutant is *killed* when the tests fail (or run past ``--timeout``), *survived* when
they pass. Usage (from the repository root)::

    python tools/mutate.py                         # default targets and tests
    python tools/mutate.py --target src/rotframe/particles/forces.py:drag_coefficients,position_acceleration \\
        --tests "tests/test_i11b_forces.py -k 'not projectile'" -j 2

Prints one line per mutant and the score; exits 1 when any mutant survived
and ``--strict`` is given.
"""

from __future__ import annotations

import argparse
import ast
import copy
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

DEFAULT_TARGETS = ["src/rotframe/particles/forces.py:_forces_of_position,_frame_terms_of_position,state_acceleration,"
                   "drag_coefficients,string_normal",
                   "src/rotframe/particles/accelerations.py:altitude_gravity,central_gravity,air_density,drag_rate,"
                   "centrifugal,coriolis_about_axis,string_tension"]
DEFAULT_TESTS = "tests/test_i11b_forces.py -k 'not projectile'"


class _Collector(ast.NodeVisitor):
    """Lists every mutation site of a function as (node path, kind, description)."""

    def __init__(self):
        self.sites = []

    def generic_visit(self, node):
        line = getattr(node, "lineno", None)
        if isinstance(node, ast.BinOp):
            if isinstance(node.op, ast.Add):
                self.sites.append((node, "op", ast.Sub(), f"line {line}: + -> -"))
            elif isinstance(node.op, ast.Sub):
                self.sites.append((node, "op", ast.Add(), f"line {line}: - -> +"))
            elif isinstance(node.op, ast.Mult):
                self.sites.append((node, "op", ast.Div(), f"line {line}: * -> /"))
                self.sites.append((node, "left", None, f"line {line}: a * b -> a"))
                self.sites.append((node, "right", None, f"line {line}: a * b -> b"))
            elif isinstance(node.op, ast.Div):
                self.sites.append((node, "op", ast.Mult(), f"line {line}: / -> *"))
            elif isinstance(node.op, ast.Pow):
                self.sites.append((node, "left", None, f"line {line}: a ** b -> a"))
        elif isinstance(node, ast.AugAssign):
            if isinstance(node.op, ast.Add):
                self.sites.append((node, "op", ast.Sub(), f"line {line}: += -> -="))
            elif isinstance(node.op, ast.Sub):
                self.sites.append((node, "op", ast.Add(), f"line {line}: -= -> +="))
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            self.sites.append((node, "unneg", None, f"line {line}: -x -> x"))
        elif isinstance(node, ast.Constant) and isinstance(node.value, float) and node.value != 0.0:
            self.sites.append((node, "neg", None, f"line {line}: {node.value!r} -> {-node.value!r}"))
            if node.value not in (0.0, 1.0):
                self.sites.append((node, "double", None, f"line {line}: {node.value!r} -> {2 * node.value!r}"))
        elif isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name) \
                and isinstance(node.value, ast.BinOp):
            self.sites.append((node, "zero", None, f"line {line}: {node.targets[0].id} = ... -> 0.0"))
        super().generic_visit(node)


def _apply(func, index):
    """A deep copy of the function node with mutation ``index`` applied; and its description."""
    func = copy.deepcopy(func)
    c = _Collector()
    c.visit(func)
    node, kind, arg, desc = c.sites[index]
    if kind == "op":
        node.op = arg
    elif kind in ("left", "right", "unneg"):
        repl = node.left if kind == "left" else node.right if kind == "right" else node.operand
        _replace(func, node, repl)
    elif kind == "neg":
        node.value = -node.value
    elif kind == "double":
        node.value = 2 * node.value
    elif kind == "zero":
        node.value = ast.Constant(0.0)
    return func, desc


def _replace(tree, old, new):
    for parent in ast.walk(tree):
        for field, value in ast.iter_fields(parent):
            if value is old:
                setattr(parent, field, new)
                return
            if isinstance(value, list):
                for i, item in enumerate(value):
                    if item is old:
                        value[i] = new
                        return
    raise RuntimeError("node not found")


def _mutants(path, names):
    """Yield (mutated file text, description) for every site in the named functions of ``path``."""
    text = (ROOT / path).read_text()
    lines = text.splitlines(keepends=True)
    tree = ast.parse(text)
    for func in tree.body:
        if not isinstance(func, ast.FunctionDef) or func.name not in names:
            if isinstance(func, ast.ClassDef):
                for sub in func.body:
                    if isinstance(sub, ast.FunctionDef) and sub.name in names:
                        yield from _function_mutants(lines, sub, path)
            continue
        yield from _function_mutants(lines, func, path)


def _function_mutants(lines, func, path):
    c = _Collector()
    c.visit(func)
    start = func.lineno - 1  # the def line (decorators stay above it)
    end = func.end_lineno
    indent = " " * func.col_offset
    for i in range(len(c.sites)):
        mutated, desc = _apply(func, i)
        mutated.decorator_list = []
        body = ast.unparse(mutated)
        body = "".join(indent + ln + "\n" for ln in body.splitlines())
        yield "".join(lines[:start]) + body + "".join(lines[end:]), f"{path}:{func.name} {desc}"


def _run(src_copy, tests, timeout, jit):
    env = dict(os.environ, PYTHONPATH=str(src_copy), PYTHONDONTWRITEBYTECODE="1")
    if not jit:
        env["NUMBA_DISABLE_JIT"] = "1"
    # -n 0: in one process, so that -x's first failure exits 1 (under pytest-xdist, the suite's default, it exits 2,
    # which read as an error here: every killed mutant was reported so)
    cmd = [sys.executable, "-m", "pytest", "-q", "-x", "-n", "0", "-p", "no:cacheprovider", *shlex.split(tests)]
    try:
        proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "killed (timeout)"
    if proc.returncode == 0:
        return "survived"
    if proc.returncode == 1:
        return "killed"
    return f"error (pytest exit {proc.returncode})"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--target", action="append", help="FILE:func1,func2 (repeatable)")
    ap.add_argument("--tests", default=DEFAULT_TESTS, help="pytest arguments (one string)")
    ap.add_argument("-j", "--jobs", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=600.0)
    ap.add_argument("--no-jit", dest="jit", action="store_false",
                    help="NUMBA_DISABLE_JIT=1 (rotframe does not import so: see the module docstring)")
    ap.add_argument("--list", action="store_true", help="list the mutants and exit")
    ap.add_argument("--sample", type=int, default=0, help="run only N mutants drawn at random (seed 0)")
    ap.add_argument("--strict", action="store_true", help="exit 1 when a mutant survives")
    args = ap.parse_args(argv)
    targets = args.target or DEFAULT_TARGETS
    jobs = []
    for t in targets:
        path, _, names = t.partition(":")
        jobs.extend((path, text, desc) for text, desc in _mutants(path, set(names.split(","))))
    seen, unique = set(), []
    for job in jobs:  # two mutations that give the same file are one mutant
        if job[1] not in seen:
            seen.add(job[1])
            unique.append(job)
    jobs = unique
    if args.sample and args.sample < len(jobs):
        import random

        jobs = random.Random(0).sample(jobs, args.sample)
    if args.list:
        for _, _, desc in jobs:
            print(desc)
        print(f"{len(jobs)} mutants")
        return 0

    tmp = Path(tempfile.mkdtemp(prefix="rotframe-mutate-"))

    def one(k):
        path, text, desc = jobs[k]
        work = tmp / f"m{k}"
        shutil.copytree(ROOT / "src", work, ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
        (work / Path(path).relative_to("src")).write_text(text)
        verdict = _run(work, args.tests, args.timeout, args.jit)
        shutil.rmtree(work, ignore_errors=True)
        print(f"{verdict:>18}  {desc}", flush=True)
        return verdict

    try:
        with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            verdicts = list(pool.map(one, range(len(jobs))))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    killed = sum(v.startswith("killed") for v in verdicts)
    errors = sum(v.startswith("error") for v in verdicts)
    survived = sum(v == "survived" for v in verdicts)
    scored = killed + survived
    print(f"mutation score: {killed}/{scored} killed ({100.0 * killed / max(scored, 1):.1f} %), "
          f"{survived} survived, {errors} errors (not scored)")
    return 1 if (args.strict and survived) else 0


if __name__ == "__main__":
    sys.exit(main())
