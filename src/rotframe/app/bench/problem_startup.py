"""How long a problem of your own takes to start: the start-up rows of ``rotframe.simulate`` (issue 32).

Three rows, each timed in a new process of its own, around the ``simulate`` call alone (numpy,
numba, scipy and rotframe imported before the clock starts, so what is counted is compiling and
running, as the goals are stated beyond imports):

- ``first problem ever``: numba's cache and rotframe's driver cache both empty (a fresh machine);
- ``new problem``: the caches filled by an earlier problem, the force a new function (its
  fingerprint is new, so nothing of it is cached);
- ``changed force``: in the process of the new problem, the force edited once more (a notebook
  cell run again) and the problem run again.

The problem is a particle on a spring in a steadily rotating frame, 10 s, DOP853: the problem
diffrax's first jit-compiled Dopri8 solve was measured on (0.8 s beyond imports, issue 32). The
goals are those of issue 32: 3 s, 0.5 s and 0.3 s. A force's constant is drawn anew for every
measurement, so no run finds the previous one's driver.
"""

from __future__ import annotations

import json
import math
import os
import random
import subprocess
import sys
import tempfile

__all__ = ["problem_startup_rows", "PROBLEM_STARTUP_GOALS"]

#: Goals of issue 32 (s, beyond imports): the first problem ever, a new problem, a changed force.
PROBLEM_STARTUP_GOALS = {"first problem ever": 3.0, "new problem": 0.5, "changed force": 0.3}

_CHILD = r'''
import json, sys, time
import numpy, numba, scipy.linalg  # imported before the clock: the rows count what follows
from rotframe.problem.particles import simulate_particles

def timed(k):
    source = f"def spring(t, r, v):\n    return -{k!r} * r[0], -{k!r} * r[1], -{k!r} * r[2]\n"
    space = {}
    exec(compile(source, f"<force {k!r}>", "exec"), space)  # a new function, as an edited cell makes
    t0 = time.perf_counter()
    simulate_particles(omega=[0.0, 0.0, 0.5], r0=[1.0, 0.0, 0.0], v0=[0.0, 1.0, 0.0], duration=10.0,
                       forces=[space["spring"]], samples=10)
    return time.perf_counter() - t0

first = timed(float(sys.argv[1]))
changed = timed(float(sys.argv[2]))
print(json.dumps({"first": first, "changed": changed}))
'''


def _child(env, k1, k2):
    res = subprocess.run([sys.executable, "-c", _CHILD, repr(k1), repr(k2)], env=env, capture_output=True,
                         text=True, check=True, timeout=600)
    return json.loads(res.stdout.strip().splitlines()[-1])


def problem_startup_rows():
    """The three start-up rows of a problem of your own (`PROBLEM_STARTUP_GOALS`), timed in new processes."""
    rng = random.Random()
    constants = [1.0 + rng.random() for _ in range(6)]
    with tempfile.TemporaryDirectory() as numba_cache, tempfile.TemporaryDirectory() as drivers:
        env = dict(os.environ, NUMBA_CACHE_DIR=numba_cache, ROTFRAME_CACHE_DIR=drivers)
        first = _child(env, constants[0], constants[1])["first"]  # everything empty: the first problem ever
        again = _child(env, constants[2], constants[3])  # caches filled; a new force, then an edited one
    times = {"first problem ever": first, "new problem": again["first"], "changed force": again["changed"]}
    rows = []
    for setting, wall in times.items():
        goal = PROBLEM_STARTUP_GOALS[setting]
        rows.append({"scenario": "startup", "method": "rotframe.simulate (a spring in a rotating frame, DOP853)",
                     "setting": setting, "run": "simulate", "wall_s": wall, "error": math.nan,
                     "error_kind": "start-up", "nfev": 0, "import_s": 0.0, "beyond_imports_s": wall,
                     "goal_s": goal, "goal_met": bool(wall <= goal),
                     "note": "the simulate call alone, numpy, numba, scipy and rotframe imported; goals of issue 32 "
                             "(diffrax's first jit solve of this problem: 0.8 s)"})
    return rows
