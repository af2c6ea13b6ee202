"""How long a problem of your own takes to start: the start-up rows of ``rotframe.simulate`` (issue 32).

Four rows, each timed in a new process of its own, around the ``simulate`` call alone (numpy,
numba, scipy and rotframe imported before the clock starts, so what is counted is compiling and
running, as the goals are stated beyond imports):

- ``first problem ever``: numba's cache and rotframe's driver cache both empty (a fresh machine).
  The run is short: the engine's loop is not compiled yet, and the run is answered by its
  plain-Python remake (`rotframe.problem.tiers`), the problem's own functions compiled;
- ``first problem ever, long``: the caches empty again, the same problem run 100 times as long
  (1,000 s): seen to be long after its first plain call, it compiles the engine's loop, its
  trajectory tier (`rotframe.problem.dop853_split.trajectory_tier`: the trajectory and the right-hand
  side, the loop over the particle Python);
- ``new problem``: the caches filled by that long run, the force a new function (its fingerprint
  is new, so nothing of it is cached);
- ``changed force``: in the process of the new problem, the force edited once more (a notebook
  cell run again) and the problem run again.

The problem is a particle on a spring in a steadily rotating frame, 10 s, DOP853: the problem
diffrax's first jit-compiled Dopri8 solve was measured on (0.8 s beyond imports, issue 32). The
goals are those of issue 32: 3 s for the first problem ever (both of its rows), 0.5 s and 0.3 s.
A force's constant is drawn anew for every measurement, so no run finds the previous one's driver.

Beside them, where jax and diffrax are installed (``pip install 'rotframe[bench]'``), diffrax
on the same problem in a new process of its own, numpy, jax and diffrax imported before the
clock (`diffrax_startup_rows`): its first ``jax.jit``-compiled Dopri8 solve (``diffeqsolve``, a
PID controller, the same tolerances and sample times; jax's compilation cache is off by default,
so this is both its "first problem ever" and its "new problem"), and in the same process the
force edited and solved again (its "changed force": a new function, traced and compiled anew).
"""

from __future__ import annotations

import json
import math
import os
import random
import subprocess
import sys
import tempfile

__all__ = ["problem_startup_rows", "diffrax_startup_rows", "PROBLEM_STARTUP_GOALS", "SHORT_S", "LONG_S"]

#: Goals of issue 32 (s, beyond imports): the first problem ever (short or long), a new problem, a changed force.
PROBLEM_STARTUP_GOALS = {"first problem ever": 3.0, "first problem ever, long": 3.0, "new problem": 0.5,
                         "changed force": 0.3}
#: the spans of the short problem (diffrax's too) and of the long one (s)
SHORT_S = 10.0
LONG_S = 1000.0

# argv: a JSON list of [spring constant, span]; prints each run's wall time and whether the plain tier ran it
_CHILD = r'''
import json, sys, time
import numpy, numba, scipy.linalg  # imported before the clock: the rows count what follows
from rotframe.problem.particles import simulate_particles

def timed(k, span):
    source = f"def spring(t, r, v):\n    return -{k!r} * r[0], -{k!r} * r[1], -{k!r} * r[2]\n"
    space = {}
    exec(compile(source, f"<force {k!r}>", "exec"), space)  # a new function, as an edited cell makes
    t0 = time.perf_counter()
    run = simulate_particles(omega=[0.0, 0.0, 0.5], r0=[1.0, 0.0, 0.0], v0=[0.0, 1.0, 0.0], duration=span,
                             forces=[space["spring"]], samples=10)
    wall = time.perf_counter() - t0
    return {"wall": wall, "tier": next((n for n in run.notes if "plain-Python remake" in n), "")}

print(json.dumps([timed(k, span) for k, span in json.loads(sys.argv[1])]))
'''


_DIFFRAX_CHILD = r'''
import json, sys, time
import numpy as np
import jax
jax.config.update("jax_enable_x64", True)
jax.config.update("jax_platforms", "cpu")
import jax.numpy as jnp
import diffrax  # imported before the clock: the rows count what follows

W = 0.5  # the frame's rate about z (rad/s), as rotframe.simulate's omega=[0, 0, 0.5]
RTOL = 1e-10  # rotframe's default; atol = rtol * the state's scale (1 here), as rotframe scales it

def timed(k):
    source = (f"def field(t, y, args):\n"
              f"    x, yy, z, vx, vy, vz = y[0], y[1], y[2], y[3], y[4], y[5]\n"
              f"    ax = -{k!r} * x + 2.0 * W * vy + W * W * x\n"
              f"    ay = -{k!r} * yy - 2.0 * W * vx + W * W * yy\n"
              f"    az = -{k!r} * z\n"
              f"    return jnp.stack([vx, vy, vz, ax, ay, az])\n")
    space = {"jnp": jnp, "W": W}
    exec(compile(source, f"<force {k!r}>", "exec"), space)  # a new function, as an edited cell makes
    t0 = time.perf_counter()
    term = diffrax.ODETerm(space["field"])

    @jax.jit
    def solve(y0):
        return diffrax.diffeqsolve(term, diffrax.Dopri8(), t0=0.0, t1=10.0, dt0=None, y0=y0,
                                   stepsize_controller=diffrax.PIDController(rtol=RTOL, atol=RTOL),
                                   saveat=diffrax.SaveAt(ts=jnp.linspace(0.0, 10.0, 11)), max_steps=1_000_000).ys

    ys = np.asarray(solve(jnp.array([1.0, 0.0, 0.0, 0.0, 1.0, 0.0])).block_until_ready())
    return time.perf_counter() - t0, ys

first, ys1 = timed(float(sys.argv[1]))
changed, _ = timed(float(sys.argv[2]))
print(json.dumps({"first": first, "changed": changed, "r_end": ys1[-1, :3].tolist(),
                  "versions": f"jax {jax.__version__}, diffrax {diffrax.__version__}"}))
'''


def diffrax_startup_rows(constants=None):
    """diffrax's start-up on the problem of `problem_startup_rows`, in a new process (module docstring).

    Two rows, or one row saying why there are none where jax or diffrax is not installed.
    """
    import importlib.util

    missing = [name for name in ("jax", "diffrax") if importlib.util.find_spec(name) is None]
    base = {"scenario": "startup", "method": "diffrax Dopri8 (jax.jit of the whole solve)", "run": "diffrax",
            "error": math.nan, "error_kind": "start-up", "nfev": 0, "family": "peer"}
    if missing:
        return [dict(base, setting="first solve in a process", wall_s=math.nan,
                     note=f"not measured: {', '.join(missing)} not installed (pip install 'rotframe[bench]')")]
    rng = random.Random()
    k1, k2 = constants or (1.0 + rng.random(), 1.0 + rng.random())
    res = subprocess.run([sys.executable, "-c", _DIFFRAX_CHILD, repr(k1), repr(k2)], capture_output=True, text=True,
                         timeout=600)
    if res.returncode != 0:
        tail = (res.stderr.strip().splitlines() or ["no output"])[-1]
        return [dict(base, setting="first solve in a process", wall_s=math.nan, note=f"not measured: {tail}")]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    note = (f"{out['versions']}; numpy, jax and diffrax imported before the clock; the same problem, tolerances "
            "and samples as rotframe's rows")
    return [dict(base, setting="first solve in a process", wall_s=out["first"], beyond_imports_s=out["first"],
                 note=note + " (jax's compilation cache off, its default: every new process compiles anew)"),
            dict(base, setting="changed force", wall_s=out["changed"], beyond_imports_s=out["changed"],
                 note=note + " (the force a new function in the same process: traced and compiled anew)")]


def _child(env, runs):
    """The runs ``[(spring constant, span), ...]`` in one new process with the environment ``env``: each one's
    ``{"wall": s, "tier": the note of the plain tier, or ""}``."""
    res = subprocess.run([sys.executable, "-c", _CHILD, json.dumps(runs)], env=env, capture_output=True, text=True,
                         check=True, timeout=600)
    return json.loads(res.stdout.strip().splitlines()[-1])


def _how(setting, tier):
    if setting == "first problem ever":
        return ("answered by the engine's plain-Python remake, its loop not compiled yet (rotframe.problem.tiers)"
                if "short enough" in tier else "the engine's loop compiled in the run")
    if setting == "first problem ever, long":
        if "its trajectories alone" in tier:
            return (f"{LONG_S:g} s of the same problem: its first plain call, then the engine's loop compiled, its "
                    "trajectory tier (rotframe.problem.dop853_split.trajectory_tier)")
        return (f"{LONG_S:g} s of the same problem: its first plain call, then the engine's loop compiled"
                if "then the loop compiled" in tier else "the engine's loop compiled in the run")
    if tier:
        return "the plain tier ran it (the engine's loop was not in the cache)"
    return ("the engine's loop loaded from numba's cache (the loop the long run compiled)"
            if setting == "new problem" else
            "the engine's loop as the new problem loaded it, the force's glue compiled anew")


def problem_startup_rows():
    """The four start-up rows of a problem of your own (`PROBLEM_STARTUP_GOALS`), timed in new processes."""
    rng = random.Random()
    constants = [1.0 + rng.random() for _ in range(6)]
    with (tempfile.TemporaryDirectory() as numba_cache, tempfile.TemporaryDirectory() as drivers,
          tempfile.TemporaryDirectory() as numba_cache_2, tempfile.TemporaryDirectory() as drivers_2):
        env = dict(os.environ, NUMBA_CACHE_DIR=numba_cache, ROTFRAME_CACHE_DIR=drivers)
        first, = _child(env, [(constants[0], SHORT_S)])  # everything empty: the first problem ever
        env = dict(os.environ, NUMBA_CACHE_DIR=numba_cache_2, ROTFRAME_CACHE_DIR=drivers_2)
        long, = _child(env, [(constants[1], LONG_S)])  # everything empty again, a run that compiles the loop
        again, changed = _child(env, [(constants[2], SHORT_S), (constants[3], SHORT_S)])  # a new force, an edit
    runs = {"first problem ever": first, "first problem ever, long": long, "new problem": again,
            "changed force": changed}
    rows = []
    for setting, run in runs.items():
        goal = PROBLEM_STARTUP_GOALS[setting]
        wall = run["wall"]
        rows.append({"scenario": "startup", "method": "rotframe.simulate (a spring in a rotating frame, DOP853)",
                     "setting": setting, "run": "simulate", "wall_s": wall, "error": math.nan,
                     "error_kind": "start-up", "nfev": 0, "import_s": 0.0, "beyond_imports_s": wall,
                     "goal_s": goal, "goal_met": bool(wall <= goal),
                     "note": f"{_how(setting, run['tier'])}; the simulate call alone, numpy, numba, scipy and rotframe "
                             "imported; goals of issue 32 (diffrax's rows beside: its first jit solve of the same "
                             "problem)"})
    return rows + diffrax_startup_rows((constants[4], constants[5]))
