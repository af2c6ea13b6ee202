"""First-run time of the particle drivers with and without an event, each in a process with an empty cache.

What a first run with a ground event waits for, beside the same run without it: numba compiling
`rotframe.particles.drivers.run_fixed_events` or `run_dop853_events` (a kernel of their own, so
that a run with events compiles no event-free loop). Each case runs in a fresh process with its
own empty ``NUMBA_CACHE_DIR`` and reports the process's CPU seconds (imports included), which a
busy machine disturbs less than wall time::

    python tools/event_compile_times.py            # this tree
    PYTHONPATH=/path/to/other/src python tools/event_compile_times.py   # another tree, to compare

Interleave two trees' runs on a shared machine.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile

_ONE = r"""
import sys
import numpy as np
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.particles.trajectory import Event

method, event = sys.argv[1], sys.argv[2] == "event"
terms = ("gravity", "coriolis", "centrifugal") + (("quadratic-drag",) if method == "dop853" else ())
model = ParticleModel(terms, omega=OmegaSchedule.constant([0.0, 4e-5, 5e-5]), g=np.array([0.0, 0.0, -9.81]),
                      k_quadratic=1e-4)
n = 64 if method == "dop853" else 1
r0 = np.zeros((n, 3))
v0 = np.tile([300.0, 10.0, 300.0], (n, 1)) * np.linspace(0.5, 1.0, n)[:, None]
step = {} if method == "dop853" else {"step": 0.01}
integrate_particles(model, r0, v0, 60.0, method=method, samples=600,
                    events=[Event("ground", "r", 2, 0.0, -1, True)] if event else (), **step)
"""

CASES = [(method, event) for method in ("dop853", "rotation-splitting", "rk4") for event in ("none", "event")]


def cpu_seconds(method: str, event: str) -> float:
    """CPU seconds (user + system) of one fresh process running one case with an empty numba cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([sys.executable, "-c", _ONE, method, event], env=env, check=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> int:
    for method, event in CASES:
        label = "ground event" if event == "event" else "no event"
        print(f"{method:20s} {label:12s} {cpu_seconds(method, event):6.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
