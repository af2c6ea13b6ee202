"""The inlined loop of a long run (`rotframe.problem.inlined`): the engine's loop with the problem's functions and the
model's parts compiled in gives the engine's numbers to the bit, for every kind of problem and method, and a run
switches to it between calls without changing a number.

The oracle is the engine's own loop (calls by address, the model read at run time), whose physics the other
suites check against closed forms and scipy: what is checked here is that the inlined copy is the same
computation, not a second one.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

import rotframe
from rotframe import forces
from rotframe.errors import ScenarioError
from rotframe.problem import inlined
from rotframe.problem.particles import Force, simulate_particles


def pull(t, r, v, k):
    return -k * r[0] + 0.1 * math.sin(t), -k * r[1], -k * r[2] - 0.05 * v[2]


def inertial_push(t, r, v):
    return 0.2, 0.0, 0.0  # a constant push in inertial axes: the frame's attitude is integrated (10 numbers)


def height(t, r, v, k):
    return r[2]


def crossing_x(t, r, v, k):
    return r[0] - 0.8


crossing_x.terminal = False
height.terminal = True
height.direction = -1


def omega_of(t):
    return np.array([0.1 * math.sin(0.3 * t), 0.05, 0.4 + 0.02 * t])


def omega_dot_of(t):
    return np.array([0.03 * math.cos(0.3 * t), 0.0, 0.02])


def origin_of(t):
    return np.array([0.0, 0.01 * t, 0.0])


R0 = np.array([[1.0, 0.5, 2.0], [0.3, -0.2, 1.0]])
V0 = np.array([[0.0, 0.4, 0.1], [0.2, 0.0, 0.0]])

CASES = {
    "dop853, a user force and events": dict(omega=[0.0, 0.2, 0.5], forces=[pull], params=(1.5,),
                                            events=[height, crossing_x], duration=20.0),
    "rk4, a varying frame and origin": dict(omega=omega_of, omega_dot=omega_dot_of, origin_acceleration=origin_of,
                                            forces=[pull], params=(1.5,), method="rk4", step=0.01, duration=5.0),
    "rotation-splitting4, the string and Coriolis alone": dict(
        omega=[0.0, 0.3, 0.5], forces=[forces.gravity([0.0, 0.0, -9.81]), forces.pendulum(3.0, [0.0, 0.0, 3.0])],
        frame_terms=("coriolis",), method="rotation-splitting4", step=0.01, duration=5.0,
        r0=[0.5, 0.0, 3.0 - math.sqrt(9.0 - 0.25)], v0=[0.0, 0.0, 0.0]),
    "dop853, a force in inertial axes (the attitude integrated)": dict(
        omega=[0.0, 0.0, 0.7], forces=[Force(inertial_push, axes="inertial"), forces.spring(2.0)], duration=10.0),
}


def run(case, inline):
    settings = dict(CASES[case])
    settings.setdefault("r0", R0)
    settings.setdefault("v0", V0)
    # compiled from the start: a cold cache's plain tier (rotframe.problem.tiers) runs the same steps in calls of its
    # own size, and each call's first evaluation counts in nfev (what this test compares besides the numbers)
    return simulate_particles(rtol=1e-10, samples=40, inline=inline, plain_tier=False, **settings)


def same_run(a, b):
    ta, tb = a.trajectory, b.trajectory
    assert np.array_equal(ta.times, tb.times)
    assert np.array_equal(ta.r, tb.r, equal_nan=True) and np.array_equal(ta.v, tb.v, equal_nan=True)
    assert ta.steps == tb.steps and ta.nfev == tb.nfev
    assert ta.event_times.keys() == tb.event_times.keys()
    for name in ta.event_times:
        for ea, eb in zip(ta.event_times[name], tb.event_times[name]):
            assert np.array_equal(ea, eb)
    if "frame_q" in ta.extras:
        assert np.array_equal(ta.extras["frame_q"], tb.extras["frame_q"])


@pytest.mark.parametrize("case", list(CASES))
def test_the_inlined_loop_gives_the_engines_numbers_to_the_bit(case):
    engine, inlined_run = run(case, False), run(case, True)
    same_run(engine, inlined_run)
    assert any("inlined loop" in note for note in inlined_run.notes)
    assert not any("inlined loop" in note for note in engine.notes)
    assert np.ptp(engine.trajectory.r[:, 0, 0]) > 1e-3  # the particle moved: the comparison compares something
    if "events" in CASES[case]:
        assert len(engine.trajectory.event_times["crossing_x"][0]) > 0  # the events fired


def test_the_models_parts_are_constants_of_their_own_cache_entry():
    """Two models of the same functions (one glue module) with other frame terms: each inlined loop is its own, in this
    process and in the disk cache (a loop loaded for the wrong model would take the other's terms)."""
    def spring_run(terms, inline):
        return simulate_particles(omega=[0.0, 0.3, 0.6], r0=R0, v0=V0, duration=10.0, forces=[pull], params=(1.5,),
                                  frame_terms=terms, rtol=1e-10, samples=20, inline=inline,
                                  plain_tier=False)  # as `run`: nfev is compared

    first = spring_run(("coriolis",), True)
    inlined._LOOPS.clear()  # the next one comes from the disk cache where it is there, or is compiled
    second = spring_run(("coriolis", "centrifugal"), True)
    same_run(first, spring_run(("coriolis",), False))
    same_run(second, spring_run(("coriolis", "centrifugal"), False))
    assert not np.array_equal(first.trajectory.r, second.trajectory.r)


def test_a_run_switches_between_calls_without_changing_a_number(monkeypatch):
    """The default (inline=None) switches once the run has measured its pace, where the work left is worth it: here
    at once (the thresholds set to zero), half-way through the engine's calls."""
    monkeypatch.setattr(inlined, "MEASURED_S", 0.0)
    monkeypatch.setattr(inlined, "WORTH_LOADING_S", 0.0)
    monkeypatch.setattr(inlined, "WORTH_COMPILING_S", 0.0)
    switched = run("rk4, a varying frame and origin", None)
    assert any("inlined loop" in note and "work left" in note for note in switched.notes)
    same_run(switched, run("rk4, a varying frame and origin", False))


def test_a_switch_mid_run_counts_as_compile_time(monkeypatch):
    """The time a run spends making its inlined loop after its first call is compile time, not integration."""
    for inline in (False, True):  # both loops made before: the run below compiles nothing
        run("rk4, a varying frame and origin", inline)
    made = inlined.inlined_loop

    def slow(*args, **kwargs):
        time.sleep(0.5)
        return made(*args, **kwargs)

    monkeypatch.setattr(inlined, "inlined_loop", slow)
    monkeypatch.setattr(inlined, "MEASURED_S", 0.0)
    monkeypatch.setattr(inlined, "WORTH_LOADING_S", 0.0)
    monkeypatch.setattr(inlined, "WORTH_COMPILING_S", 0.0)
    switched = run("rk4, a varying frame and origin", None)
    assert any("inlined loop" in note for note in switched.notes)
    assert switched.compile_s >= 0.5 > run("rk4, a varying frame and origin", False).compile_s


def test_a_short_run_stays_in_the_engines_loop():
    short = simulate_particles(omega=[0.0, 0.0, 0.5], r0=R0, v0=V0, duration=1.0, forces=[pull], params=(1.5,),
                               samples=5)
    assert not any("inlined loop" in note for note in short.notes)


@pytest.mark.parametrize("value", ["yes", 1, 0.0])
def test_inline_must_be_a_flag(value):
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=[0, 0, 1.0], r0=[1.0, 0.0, 0.0], v0=[0.0, 0.5, 0.0], duration=1.0, inline=value)
    msg = str(info.value)
    assert "\n" not in msg and "inline" in msg


def tilt(t, L, q, k):
    return -k * L[1], k * L[0], 0.01 * math.sin(t)


@pytest.mark.parametrize("method, torque", [("dop853", tilt), ("rk4", None)])
def test_a_bodys_inlined_loop_gives_the_engines_numbers_to_the_bit(method, torque):
    settings = dict(inertia=[1.0, 2.0, 3.0], L0=[0.1, 2.0, 0.3], q0=[0.0, 0.0, 0.0, 1.0], duration=20.0,
                    torque=torque, params=(0.2,) if torque else (), method=method, samples=30,
                    step=0.01 if method == "rk4" else None)
    engine, inlined_run = (rotframe.simulate_body(**settings, inline=flag) for flag in (False, True))
    assert np.array_equal(engine.trajectory.L, inlined_run.trajectory.L)
    assert np.array_equal(engine.trajectory.q, inlined_run.trajectory.q)
    assert np.ptp(engine.trajectory.L[:, 0]) > 1e-3
    assert any("inlined loop" in note for note in inlined_run.notes)


def test_inline_and_plain_python_are_refused_together_in_one_line():
    for call in (lambda: rotframe.simulate(omega=[0, 0, 1.0], r0=[1.0, 0.0, 0.0], v0=[0.0, 0.5, 0.0], duration=1.0,
                                           forces=[pull], params=(1.0,), jit=False, inline=True),
                 lambda: rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[0.1, 2.0, 0.3], q0=[0, 0, 0, 1.0],
                                                duration=1.0, jit=False, inline=True)):
        with pytest.raises(ScenarioError) as info:
            call()
        msg = str(info.value)
        assert "\n" not in msg and "inline=True" in msg and "jit=False" in msg
