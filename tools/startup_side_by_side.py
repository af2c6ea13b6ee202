"""First runs of two source trees side by side, every cache empty: how the README's trajectory-tier figures were made.

For each tree, alternately, in new processes with empty numba and rotframe caches:

* ``short``: the start-up bench's first problem ever (10 s of the spring: the plain tier answers it) in caches of
  its own;
* ``long``: the start-up bench's first problem ever, long (`rotframe.app.bench.problem_startup`: 1,000 s of a spring
  in a rotating frame, DOP853, the ``simulate`` call alone);
* ``new``: then a new problem in the caches that run left (10 s, another spring constant);
* each scene named (default ``cr3bp``): ``python -m rotframe run NAME --no-record`` in caches of its own (wall time,
  imports included).

Usage, with the tree before checked out beside this one::

    git worktree add /tmp/old <rev>
    python tools/startup_side_by_side.py /tmp/old/src src 3
    python tools/startup_side_by_side.py /tmp/old/src src 3 foucault,tumbling-ball,cr3bp

Runs on one machine drift (its speed changes by tens of percent over minutes), so compare the ratios of runs made
in pairs (each pair's order by chance), never numbers from different days.
"""
from __future__ import annotations

import os
import random
import statistics
import subprocess
import sys
import tempfile
import time


def _simulate(src, cache, drivers, k, span):
    """The start-up bench's own child run (`rotframe.app.bench.problem_startup`) of the tree ``src``: its wall time."""
    from rotframe.app.bench.problem_startup import _child

    env = dict(os.environ, PYTHONPATH=os.path.abspath(src), NUMBA_CACHE_DIR=cache, ROTFRAME_CACHE_DIR=drivers)
    return _child(env, [(k, span)])[0]["wall"]


def _scene(src, name):
    with (tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as drivers,
          tempfile.TemporaryDirectory() as folder):
        env = dict(os.environ, PYTHONPATH=os.path.abspath(src), NUMBA_CACHE_DIR=cache, ROTFRAME_CACHE_DIR=drivers)
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "rotframe", "run", name, "--no-record"], env=env, cwd=folder,
                       capture_output=True, text=True, check=True, timeout=600)
        return time.perf_counter() - t0


def main(old, new, reps, scenes=("cr3bp",)):
    trees = {"before": old, "after": new}
    rows = {tree: {"short": [], "long": [], "new": [], **{name: [] for name in scenes}} for tree in trees}
    for _ in range(reps):
        order = list(trees.items())
        random.shuffle(order)  # which tree runs first in a pair, by chance: the machine's drift falls on both
        for tree, src in order:
            with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as drivers:
                rows[tree]["short"].append(_simulate(src, cache, drivers, 1.0 + random.random(), 10.0))
            with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as drivers:
                rows[tree]["long"].append(_simulate(src, cache, drivers, 1.0 + random.random(), 1000.0))
                rows[tree]["new"].append(_simulate(src, cache, drivers, 1.0 + random.random(), 10.0))
            for name in scenes:
                rows[tree][name].append(_scene(src, name))
            print(tree, {key: round(v[-1], 2) for key, v in rows[tree].items()}, flush=True)
    for key in rows["after"]:
        b, a = (statistics.median(rows[tree][key]) for tree in trees)
        ratios = [x / y for x, y in zip(rows["after"][key], rows["before"][key])]
        print(f"{key:13s} median before {b:.2f} s, after {a:.2f} s; after / before in each pair: median "
              f"{statistics.median(ratios):.2f}, {min(ratios):.2f} to {max(ratios):.2f}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 3,
         tuple(sys.argv[4].split(",")) if len(sys.argv) > 4 else ("cr3bp",))
