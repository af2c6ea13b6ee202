"""diffrax's start-up rows beside rotframe's (`rotframe.app.bench.problem_startup.diffrax_startup_rows`).

Without jax or diffrax (CI installs neither) the row says so and carries no number. With them, the
child's problem must be rotframe's start-up problem itself: its end position agrees with
`rotframe.simulate`'s to the tolerance both use (a row that timed another problem would compare
nothing).
"""

from __future__ import annotations

import importlib.util
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from rotframe.app.bench import problem_startup


def test_without_diffrax_the_row_says_why_and_has_no_number(monkeypatch):
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name in ("jax", "diffrax") else real(name, *a))
    rows = problem_startup.diffrax_startup_rows()
    assert len(rows) == 1
    assert math.isnan(rows[0]["wall_s"])
    assert "not installed" in rows[0]["note"] and "rotframe[bench]" in rows[0]["note"]


def test_the_diffrax_child_solves_rotframes_start_up_problem():
    pytest.importorskip("diffrax")
    k = 1.5
    res = subprocess.run([sys.executable, "-c", problem_startup._DIFFRAX_CHILD, repr(k), repr(k + 0.1)],
                         capture_output=True, text=True, timeout=600, check=True)
    out = json.loads(res.stdout.strip().splitlines()[-1])
    from rotframe.problem.particles import simulate_particles

    def spring(t, r, v):
        return -k * r[0], -k * r[1], -k * r[2]

    ours = simulate_particles(omega=[0.0, 0.0, 0.5], r0=[1.0, 0.0, 0.0], v0=[0.0, 1.0, 0.0], duration=10.0,
                              forces=[spring], samples=10)
    np.testing.assert_allclose(out["r_end"], np.asarray(ours.trajectory.r)[-1, 0], rtol=0, atol=1e-8)
    assert out["first"] > 0 and out["changed"] > 0
