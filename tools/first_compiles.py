"""What a first run compiles, function by function: numba's compile events, with every cache empty.

Runs ``rotframe ARGS...`` (a scene's run) in a new process with empty numba and rotframe caches
and prints each compiled function's own seconds (its callees' compiles taken out), largest
first, and the top-level compiles. How the first-compile figures of docs/architecture.md (the
Foucault row) and of the closing notes were measured::

    python tools/first_compiles.py run foucault --no-record --json
    python tools/first_compiles.py run tumbling-ball --no-record --json

The times include numba's own start in a process (some 0.3 s at the first compile).
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile

_CHILD = r'''
import collections, sys, time
from numba.core import event
records, stack = [], []

class Listener(event.Listener):
    def on_start(self, e):
        stack.append([time.perf_counter(), 0.0])

    def on_end(self, e):
        start, inner = stack.pop()
        took = time.perf_counter() - start
        if stack:
            stack[-1][1] += took
        func = getattr(e.data.get("dispatcher"), "py_func", None)
        records.append((took - inner, took, len(stack), getattr(func, "__qualname__", "?")))

event.register("numba:compile", Listener())
from rotframe.app.cli import main
t0 = time.perf_counter()
try:
    main(sys.argv[1:])
except SystemExit:
    pass
wall = time.perf_counter() - t0
own = collections.defaultdict(float)
for self_s, _, _, name in records:
    own[name] += self_s
print(f"run {wall:.2f} s, compiles {sum(r[1] for r in records if r[2] == 0):.2f} s", file=sys.stderr)
for name, s in sorted(own.items(), key=lambda kv: -kv[1])[:20]:
    print(f"  {s:6.3f} s  {name}", file=sys.stderr)
print("top level: " + ", ".join(f"{name} {took:.2f} s" for _, took, depth, name in records if depth == 0),
      file=sys.stderr)
'''


def main(argv):
    with tempfile.TemporaryDirectory() as empty:
        env = dict(os.environ, NUMBA_CACHE_DIR=os.path.join(empty, "numba"),
                   ROTFRAME_CACHE_DIR=os.path.join(empty, "rotframe"))
        done = subprocess.run([sys.executable, "-c", _CHILD, *argv], env=env, stdout=subprocess.DEVNULL)
    return done.returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
