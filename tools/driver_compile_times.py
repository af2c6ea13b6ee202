"""First-compile time of the fixed-step particle driver's variants, each in a process with an empty cache.

What a first run of a scene (or a fresh clone's test suite) waits for: numba compiling
`rotframe.particles.drivers.run_fixed` for one combination of step family (free
splitting, RK4, the pendulum's sphere) and event watch. Each variant is timed in a fresh
process with its own empty ``NUMBA_CACHE_DIR``, so none profits from another::

    python tools/driver_compile_times.py

Run times are the bench's (``rotframe bench ensemble``); this measures compile time only.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: (model of tests/test_kernels_speed_invariance.py, method code, an event watched)
VARIANTS = [("steady free", 0, False), ("steady free", 0, True), ("steady free", 2, False),
            ("steady pendulum", 2, False), ("steady pendulum", 2, True)]

_ONE = r"""
import sys, time
import numpy as np
sys.path.insert(0, {tests!r})
import test_kernels_speed_invariance as T
model = T._models()[{name!r}]
events = np.array([[0.0, 2.0, 1e9, 0.0, 1.0]]) if {event!r} else None
start = time.perf_counter()
T._run_fixed(model, {method!r}, events)
print(time.perf_counter() - start)
"""


def compile_time(name: str, method: int, event: bool) -> float:
    """Seconds the first call of one driver variant takes in a fresh process with an empty numba cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(ROOT / "src"))
        code = _ONE.format(tests=str(ROOT / "tests"), name=name, method=method, event=event)
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
        return float(out.stdout.strip().splitlines()[-1])


def main() -> int:
    methods = {0: "rotation-splitting", 1: "rotation-splitting4", 2: "rk4"}
    for name, method, event in VARIANTS:
        seconds = compile_time(name, method, event)
        print(f"{name:16s} {methods[method]:20s} {'one event' if event else 'no event':10s} {seconds:6.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
