"""A loop compiled for a system's functions loads from numba's disk cache in the next process.

numba keys a closure's cache entry by a pickle of its cells, and a numba function pickles with a
random id of its process: a loop that held its system's functions in a closure was compiled again
in every process (the heavy top's DOP853 loop: 2.2 s each run). The loops now read them as globals
of a copy (`rotframe.numerics.compiled.bound`). Each case runs twice in fresh processes sharing a
cache; the second compiles nothing. The old tree fails the rigid body's case.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

_SCRIPT = """
import sys
from numba.core import event
import numpy as np

names = []


class Listener(event.Listener):
    def on_start(self, ev):
        names.append(ev.data["dispatcher"].py_func.__qualname__)

    def on_end(self, ev):
        pass


case = sys.argv[1]
import rotframe
import rotframe.numerics.compile_apart
rotframe.numerics.compile_apart.spare_core = lambda: False  # every compile in this process, where it is seen
event.register("numba:compile", Listener())
if case == "rigid":  # the rigid body's DOP853 loop, an entry point called from Python
    from rotframe.rigid.adaptive import rigid_dop853
    rigid_dop853([1.0, 2.0, 3.0], [0.1, 1.0, 0.1], [0.0, 0.0, 0.0, 1.0], np.linspace(0.0, 1.0, 5))
elif case == "problem":  # your own problem's DOP853 variant with events, and a body's
    import rotframe.problem.tiers
    rotframe.problem.tiers.PLAIN_PARTICLES = 0  # compiled from the first run: no plain tier, the compile is the test
    def ground(t, r, v):
        return r[2] + 1.0
    ground.terminal = True
    rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=[1.0, 0.0, 0.0], v0=[0.0, 1.0, 0.0], duration=1.0,
                      forces=[lambda t, r, v: (0.0, 0.0, -9.81)], events=[ground], samples=4)
    rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[0.1, 1.0, 0.1], q0=[0, 0, 0, 1], duration=1.0, samples=4)
print("COMPILED " + " ".join(names))
"""


@pytest.mark.parametrize("case", ["rigid", "problem"])
def test_a_second_process_compiles_no_loop(tmp_path, case):
    script = tmp_path / "run.py"
    script.write_text(_SCRIPT)
    env = dict(os.environ, ROTFRAME_CACHE_DIR=str(tmp_path / "problems"), NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    compiled = []
    for _ in range(2):
        proc = subprocess.run([sys.executable, str(script), case], capture_output=True, text=True, env=env,
                              timeout=600)
        assert proc.returncode == 0, proc.stderr[-2000:]
        line = [ln for ln in proc.stdout.splitlines() if ln.startswith("COMPILED")][-1]
        compiled.append(line.split()[1:])
    first, second = compiled
    assert any(name.startswith("dop853_trajectory_") or name.startswith("advance_") for name in first), first
    assert second == [], second
