"""A problem's numbers do not depend on where the pacer cuts the compiled calls.

The pacer sizes each compiled call in time (`rotframe.problem.pacing`), so where a call ends
depends on the machine's speed. The engine keeps everything a step needs in its arrays, and the
one DOP853 loop ends a call only after an accepted step (`rotframe.numerics.dop853_loop`,
``budget``): a run cut after every step must give the samples, event records and step counts of
a run in one call, to the bit. Under DOP853 (a frame from a table, whose knots are stops; a
terminal and a non-terminal event) and under RK4 and a splitting.
"""

from __future__ import annotations

import numpy as np
import pytest

import rotframe
from rotframe.problem import pacing


def wind(t, r, v):
    return 0.1 * np.sin(t), 0.0, -9.81


def ground(t, r, v):
    return r[2]


ground.direction, ground.terminal = -1, True


def cross_x(t, r, v):
    return r[0] - 0.3


def _run(method):
    tk = np.linspace(0.0, 6.0, 7)
    omega = (tk, np.column_stack([0.01 * np.sin(tk), 0.02 + 0.0 * tk, 0.05 + 0.01 * tk]))
    v0 = np.array([[8.0, 0.0, 20.0], [15.0, 1.0, 12.0], [3.0, -2.0, 25.0]])
    step = {} if method == "dop853" else {"step": 0.01}
    res = rotframe.simulate(omega=omega, r0=np.zeros((3, 3)), v0=v0, duration=6.0, forces=[wind],
                            events=[ground, cross_x], method=method, samples=25, **step)
    return res


@pytest.mark.parametrize("method", ["dop853", "rk4", "rotation-splitting4"])
def test_a_run_cut_after_every_step_is_the_run_in_one_call(method, monkeypatch):
    whole = _run(method)

    class OneStepPacer(pacing.Pacer):
        def start(self):
            super().start()
            return 1

    from rotframe.problem import particles

    monkeypatch.setattr(particles, "Pacer", OneStepPacer)
    cut = _run(method)
    assert np.array_equal(whole.trajectory.r, cut.trajectory.r)
    assert np.array_equal(whole.trajectory.v, cut.trajectory.v)
    steps = whole.to_dict()["steps"]
    assert steps == cut.to_dict()["steps"] and steps > 10
    for label in ("ground", "cross_x"):
        a, b = whole.trajectory.event_times[label], cut.trajectory.event_times[label]
        assert all(np.array_equal(x, y) for x, y in zip(a, b)) and len(a) == len(b)
    assert sum(len(np.ravel(t)) for t in whole.trajectory.event_times["ground"]) == 3  # every shot lands
