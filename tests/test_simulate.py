"""``rotframe.simulate``: a user's particle problem against oracles written here, independently.

Every oracle below is built in this file from scipy (``solve_ivp``, ``Rotation``) or a closed
form; none calls rotframe's frame, driver or stepping code. The user functions are defined at
module level and reused across tests, so that the number of distinct generated drivers (each a
numba compile of some 10 to 20 s here) stays small; they share the default on-disk cache
(``$ROTFRAME_CACHE_DIR``), except the cross-process test, which uses fresh folders.

Tolerances: rotframe runs at ``rtol=1e-12`` unless said otherwise. DOP853's global error over
the few dozen steps of these runs is a small multiple of rtol times the state's scale, so the
frame tests allow 1e-9 of the scale; the scipy oracles run at ``rtol=1e-13``.
"""

from __future__ import annotations

import functools
import json
import math
import os
import subprocess
import sys
import textwrap

import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import rotframe
from rotframe.errors import IntegrationError, RotframeError, ScenarioError
from raising_force import raise_after_one_second

RTOL = 1e-12


# ---------------------------------------------------------------------------------------------
# user functions shared by the tests (module level: one compile each, reused across tests)
# ---------------------------------------------------------------------------------------------

def omega_fn(t):
    """A frame turning about a moving axis (rad/s, frame axes)."""
    return np.array([0.4 * np.sin(0.7 * t), 0.3 * np.cos(0.5 * t), 1.0 + 0.05 * t])


def omega_dot_fn(t):
    return np.array([0.28 * np.cos(0.7 * t), -0.15 * np.sin(0.5 * t), 0.05])


def spring(t, r, v, k):
    return -k * r[0], -k * r[1], -k * r[2]


def spring_potential(t, r, k):
    return 0.5 * k * (r[0] * r[0] + r[1] * r[1] + r[2] * r[2])


SPRING = rotframe.Force(spring, potential=spring_potential)

#: the frame's rate in the user-written fictitious force (a global array: numba freezes it)
W_USER = np.array([0.3, -0.2, 0.9])


def user_fictitious(t, r, v, k):
    """-2 w x v - w x (w x r), written out by the user (w = W_USER)."""
    w = W_USER
    cx = w[1] * v[2] - w[2] * v[1]
    cy = w[2] * v[0] - w[0] * v[2]
    cz = w[0] * v[1] - w[1] * v[0]
    ux = w[1] * r[2] - w[2] * r[1]
    uy = w[2] * r[0] - w[0] * r[2]
    uz = w[0] * r[1] - w[1] * r[0]
    fx = w[1] * uz - w[2] * uy
    fy = w[2] * ux - w[0] * uz
    fz = w[0] * uy - w[1] * ux
    return -2.0 * cx - fx, -2.0 * cy - fy, -2.0 * cz - fz


def x_spring_and_gravity(t, r, v, k, g):
    """A spring along x and uniform gravity along -z."""
    return -k * r[0], 0.0, -g


def ground(t, r, v, k, g):
    return r[2]


ground.terminal = True
ground.direction = -1


def x_any(t, r, v, k, g):
    return r[0]


def x_up(t, r, v, k, g):
    return r[0]


x_up.direction = 1


def x_down(t, r, v, k, g):
    return r[0]


x_down.direction = -1


def inertial_push(t, r, v, gx, gy, gz):
    return gx, gy, gz


INERTIAL_PUSH = rotframe.Force(inertial_push, axes="inertial")


# ---------------------------------------------------------------------------------------------
# oracles (scipy and closed forms, nothing of rotframe)
# ---------------------------------------------------------------------------------------------

def _hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def attitude_oracle(omega_of_t, times):
    """R(t), frame components -> inertial components, from R' = R [omega]x (omega in frame axes), R(0) = I."""
    def rhs(t, y):
        return (y.reshape(3, 3) @ _hat(omega_of_t(t))).ravel()

    sol = solve_ivp(rhs, (times[0], times[-1]), np.eye(3).ravel(), method="DOP853", rtol=1e-13, atol=1e-15,
                    t_eval=times)
    assert sol.success
    return sol.y.T.reshape(-1, 3, 3)


def inertial_line_in_frame(R, times, r0, v0, w0):
    """The free particle's inertial straight line, seen in frame axes: R(t)^T (r0 + (v0 + w0 x r0) t)."""
    v_in = v0 + np.cross(w0, r0)
    line = r0[None, :] + times[:, None] * v_in[None, :]
    return np.einsum("nji,nj->ni", R, line)


R0 = np.array([1.0, 0.5, -0.3])
V0 = np.array([0.2, -0.1, 0.3])
DURATION = 8.0


def _omega_numpy(t):
    return np.array([0.4 * math.sin(0.7 * t), 0.3 * math.cos(0.5 * t), 1.0 + 0.05 * t])


@functools.lru_cache(maxsize=None)
def _line(duration, samples):
    times = np.linspace(0.0, duration, samples + 1)
    R = attitude_oracle(_omega_numpy, times)
    return times, inertial_line_in_frame(R, times, R0, V0, _omega_numpy(0.0))


@pytest.fixture(scope="module")
def line_oracle():
    return _line(DURATION, 80)


def _scale():
    return float(np.linalg.norm(R0) + np.linalg.norm(V0 + np.cross(_omega_numpy(0.0), R0)) * DURATION)


# ---------------------------------------------------------------------------------------------
# 1. the inertial straight line seen from a frame turning about a moving axis
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("duration", [DURATION, 100.0])
@pytest.mark.parametrize("form", ["derived", "given"])
def test_moving_axis_callable(form, duration):
    """omega(t) as a function, omega' derived (4th-order difference) or given: error ~ rtol x scale.

    Over 100 s (omega_z grows to 6 rad/s, some 55 turns) the error is still DOP853's, some 1e-10 of the
    scale: the derived omega' must not lose accuracy late in a run (a difference step growing with t did).
    """
    times, expected = _line(duration, 80)
    kwargs = {"omega_dot": omega_dot_fn} if form == "given" else {}
    res = rotframe.simulate(omega=omega_fn, r0=R0, v0=V0, duration=duration, rtol=RTOL, samples=80, **kwargs)
    np.testing.assert_array_equal(res.trajectory.times, times)
    scale = np.max(np.abs(expected))
    err = np.max(np.abs(res.trajectory.r[:, 0] - expected))
    assert err < 1e-9 * scale, err / scale
    assert res.complete and res.warnings == []


def test_moving_axis_table(line_oracle):
    """omega as a table every 5 ms (a cubic spline): the spline's error in omega' is ~h^3 |omega''''| / 24
    ~ 1e-9 rad/s^2, which moves the particle by ~1e-8 of the scale over 8 s; allowed 1e-7."""
    times, expected = line_oracle
    tt = np.linspace(0.0, DURATION, 1601)
    table = (tt, np.array([_omega_numpy(t) for t in tt]))
    res = rotframe.simulate(omega=table, r0=R0, v0=V0, duration=DURATION, rtol=RTOL, samples=80)
    err = np.max(np.abs(res.trajectory.r[:, 0] - expected))
    assert err < 1e-7 * _scale(), err


def test_moving_axis_table_coarse_is_visibly_worse(line_oracle):
    """The same frame from a table every 0.5 s: the error grows as the spline's (the table is really used)."""
    times, expected = line_oracle
    tt = np.linspace(0.0, DURATION, 17)
    table = (tt, np.array([_omega_numpy(t) for t in tt]))
    res = rotframe.simulate(omega=table, r0=R0, v0=V0, duration=DURATION, rtol=RTOL, samples=80)
    err = np.max(np.abs(res.trajectory.r[:, 0] - expected))
    assert 1e-6 * _scale() < err < 1e-1 * _scale(), err


# ---------------------------------------------------------------------------------------------
# 2. a user-written Coriolis (and centrifugal) term against the built-in one
# ---------------------------------------------------------------------------------------------

def test_user_coriolis_equals_builtin():
    r0 = np.array([0.7, -0.4, 0.2])
    v0 = np.array([0.1, 0.5, -0.3])
    builtin = rotframe.simulate(omega=W_USER, r0=r0, v0=v0, duration=12.0, forces=[SPRING], params=(2.0,),
                                rtol=RTOL, samples=60)
    user = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=r0, v0=v0, duration=12.0, forces=[SPRING, user_fictitious],
                             params=(2.0,), rtol=RTOL, samples=60)
    a = np.concatenate([builtin.trajectory.r, builtin.trajectory.v], axis=-1)
    b = np.concatenate([user.trajectory.r, user.trajectory.v], axis=-1)
    scale = np.max(np.abs(a))
    assert np.max(np.abs(a - b)) <= 1e-12 * scale, np.max(np.abs(a - b)) / scale


def test_rotating_spring_against_closed_form():
    """The same built-in run against the inertial ellipse turned into frame axes by exp(-t w^) (scipy)."""
    k = 2.0
    r0 = np.array([0.7, -0.4, 0.2])
    v0 = np.array([0.1, 0.5, -0.3])
    res = rotframe.simulate(omega=W_USER, r0=r0, v0=v0, duration=12.0, forces=[SPRING], params=(k,), rtol=RTOL,
                            samples=60)
    t = res.trajectory.times
    s = math.sqrt(k)
    v_in = v0 + np.cross(W_USER, r0)
    r_in = np.cos(s * t)[:, None] * r0 + (np.sin(s * t) / s)[:, None] * v_in
    v_in_t = -s * np.sin(s * t)[:, None] * r0 + np.cos(s * t)[:, None] * v_in
    turn = Rotation.from_rotvec(-t[:, None] * W_USER[None, :])
    r_frame = turn.apply(r_in)
    v_frame = turn.apply(v_in_t) - np.cross(W_USER, r_frame)
    assert np.max(np.abs(res.trajectory.r[:, 0] - r_frame)) < 1e-9
    assert np.max(np.abs(res.trajectory.v[:, 0] - v_frame)) < 1e-9


# ---------------------------------------------------------------------------------------------
# 3. an accelerating origin
# ---------------------------------------------------------------------------------------------

def test_accelerating_origin_free_particle():
    """Non-rotating frame, origin accelerating at a0: r = r0 + v0 t - a0 t^2 / 2 (DOP853 is exact on a
    quadratic: round-off)."""
    a0 = np.array([0.3, -1.2, 9.81])
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=R0, v0=V0, duration=3.0, origin_acceleration=a0,
                            rtol=RTOL, samples=30)
    t = res.trajectory.times[:, None]
    expected = R0 + V0 * t - 0.5 * a0 * t * t
    assert np.max(np.abs(res.trajectory.r[:, 0] - expected)) < 1e-12 * np.max(np.abs(expected))
    assert np.max(np.abs(res.trajectory.v[:, 0] - (V0 - a0 * t))) < 1e-12 * np.max(np.abs(a0)) * 3.0


# ---------------------------------------------------------------------------------------------
# 4. events
# ---------------------------------------------------------------------------------------------

def test_dropped_ball_terminal_event():
    """A ball dropped from h lands at sqrt(2 h / g): located to round-off; samples after it hold the landing."""
    h, g = 10.0, 9.81
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=[0.0, 0.0, h], v0=[0.0, 0.0, 0.0], duration=3.0,
                            forces=[x_spring_and_gravity], params=(0.0, g),
                            events=[ground, x_any, x_up, x_down], rtol=RTOL, samples=30)
    t_land = math.sqrt(2 * h / g)
    ev = res.trajectory.event_times["ground"]
    assert len(ev) == 1 and len(ev[0]) == 1
    assert abs(ev[0][0] - t_land) < 1e-12 * t_land, ev[0][0] - t_land
    for name in ("x_any", "x_up", "x_down"):
        assert len(res.trajectory.event_times[name][0]) == 0
    traj = res.trajectory
    after = traj.times > t_land
    assert np.any(after)
    landing = traj.r[np.flatnonzero(after)[0], 0]
    assert abs(landing[2]) < 1e-12 * h
    np.testing.assert_array_equal(traj.r[after, 0], np.repeat(landing[None, :], after.sum(), axis=0))
    np.testing.assert_array_equal(traj.v[after, 0], np.repeat(traj.v[np.flatnonzero(after)[0], 0][None, :],
                                                             after.sum(), axis=0))
    assert abs(traj.v[np.flatnonzero(after)[0], 0, 2] + g * t_land) < 1e-12 * g * t_land
    # before the landing, the parabola
    before = ~after
    np.testing.assert_allclose(traj.r[before, 0, 2], h - 0.5 * g * traj.times[before] ** 2, rtol=0, atol=1e-12 * h)


def test_oscillator_crossings_with_direction():
    """x = cos t crosses 0 at pi/2 + k pi: all of them (direction 0), the rising and the falling ones apart."""
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=[1.0, 0.0, 1.0], v0=[0.0, 0.0, 0.0], duration=20.0,
                            forces=[x_spring_and_gravity], params=(1.0, 0.0),
                            events=[ground, x_any, x_up, x_down], rtol=RTOL, samples=40)
    zeros = np.pi / 2 + np.pi * np.arange(7)
    zeros = zeros[zeros < 20.0]
    got = np.asarray(res.trajectory.event_times["x_any"][0])
    assert got.shape == zeros.shape
    assert np.max(np.abs(got - zeros)) < 1e-9
    np.testing.assert_allclose(res.trajectory.event_times["x_down"][0], zeros[0::2], rtol=0, atol=1e-9)
    np.testing.assert_allclose(res.trajectory.event_times["x_up"][0], zeros[1::2], rtol=0, atol=1e-9)
    assert len(res.trajectory.event_times["ground"][0]) == 0
    assert res.complete
    # the run went on to the end (non-terminal events): the last sample is cos(20)
    assert abs(res.trajectory.r[-1, 0, 0] - math.cos(20.0)) < 1e-9


# ---------------------------------------------------------------------------------------------
# 5. energy and the Jacobi integral
# ---------------------------------------------------------------------------------------------

def test_energy_drift_inertial():
    r0 = np.array([1.0, 0.2, -0.5])
    v0 = np.array([0.0, 1.1, 0.3])
    k = 3.0
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=r0, v0=v0, duration=20.0, forces=[SPRING], params=(k,),
                            rtol=RTOL, samples=200)
    assert "energy_rel_drift" in res.diagnostics and "jacobi_rel_drift" not in res.diagnostics
    r, v = res.trajectory.r[:, 0], res.trajectory.v[:, 0]
    E = 0.5 * np.sum(v * v, axis=1) + 0.5 * k * np.sum(r * r, axis=1)
    mine = np.max(np.abs(E - E[0])) / abs(E[0])
    assert mine < 1e-10
    assert abs(res.diagnostics["energy_rel_drift"] - mine) < 1e-14


def test_jacobi_drift_rotating(tmp_path):
    w = np.array([0.0, 0.0, 0.5])
    k = 1.0
    r0 = np.array([1.0, 0.0, 0.2])
    v0 = np.array([0.0, 0.3, 0.0])
    res = rotframe.simulate(omega=w, r0=r0, v0=v0, duration=40.0, forces=[SPRING], params=(k,), rtol=RTOL,
                            samples=400)
    assert "jacobi_rel_drift" in res.diagnostics and "energy_rel_drift" not in res.diagnostics
    r, v = res.trajectory.r[:, 0], res.trajectory.v[:, 0]
    wxr = np.cross(w, r)
    C = 0.5 * np.sum(v * v, axis=1) + 0.5 * k * np.sum(r * r, axis=1) - 0.5 * np.sum(wxr * wxr, axis=1)
    mine = np.max(np.abs(C - C[0])) / abs(C[0])
    assert mine < 1e-10
    assert abs(res.diagnostics["jacobi_rel_drift"] - mine) < 1e-14
    # the plain energy in the rotating frame is NOT conserved here (the test would see a wrong integral)
    E = 0.5 * np.sum(v * v, axis=1) + 0.5 * k * np.sum(r * r, axis=1)
    assert np.max(np.abs(E - E[0])) / abs(E[0]) > 1e-3


# ---------------------------------------------------------------------------------------------
# 6. a force given in inertial axes
# ---------------------------------------------------------------------------------------------

def test_inertial_axes_force():
    """Constant inertial acceleration g_in in a frame turning at w: the inertial parabola turned by exp(-t w^)."""
    w = np.array([0.2, -0.5, 1.1])
    g_in = np.array([0.4, -0.3, -9.81])
    r0 = np.array([2.0, 1.0, 0.5])
    v0 = np.array([0.3, 0.0, 4.0])
    res = rotframe.simulate(omega=w, r0=r0, v0=v0, duration=6.0, forces=[INERTIAL_PUSH], params=tuple(g_in),
                            rtol=RTOL, samples=60)
    t = res.trajectory.times
    v_in0 = v0 + np.cross(w, r0)
    r_in = r0 + t[:, None] * v_in0 + 0.5 * t[:, None] ** 2 * g_in
    expected = Rotation.from_rotvec(-t[:, None] * w[None, :]).apply(r_in)
    scale = np.max(np.abs(r_in))
    err = np.max(np.abs(res.trajectory.r[:, 0] - expected))
    assert err < 1e-9 * scale, err / scale


# ---------------------------------------------------------------------------------------------
# 7. bad input
# ---------------------------------------------------------------------------------------------

def bad_shape(t, r, v):
    return 1.0, 2.0


def nan_at_start(t, r, v):
    return math.nan, 0.0, 0.0


def raiser(t, r, v):
    raise RuntimeError("boom")


def nan_after_one_second(t, r, v):
    if t > 1.0:
        return np.nan, 0.0, 0.0
    return -r[0], -r[1], -r[2]


class _Knob:
    scale = 2.0


KNOB = _Knob()


def uncompilable(t, r, v):
    """numba cannot type a Python object's attribute."""
    return -KNOB.scale * r[0], -KNOB.scale * r[1], -KNOB.scale * r[2]


def _one_line(exc):
    text = str(exc)
    assert "\n" not in text, text
    return text


def test_force_wrong_shape():
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=[0, 0, 1.0], r0=R0, v0=V0, duration=1.0, forces=[bad_shape])
    msg = _one_line(info.value)
    assert "bad_shape" in msg and "forces[0]" in msg and "(2,)" in msg


def test_force_nan_at_start():
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=[0, 0, 1.0], r0=R0, v0=V0, duration=1.0, forces=[nan_at_start])
    msg = _one_line(info.value)
    assert "nan_at_start" in msg and "not finite" in msg


def test_force_raises():
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=[0, 0, 1.0], r0=R0, v0=V0, duration=1.0, forces=[raiser])
    msg = _one_line(info.value)
    assert "raiser" in msg and "RuntimeError" in msg and "boom" in msg
    assert "t = 0" in msg and "r = " in msg and "v = " in msg


def test_force_becomes_nan_later_keeps_partial():
    with pytest.raises(IntegrationError) as info:
        rotframe.simulate(omega=[0, 0, 1.0], r0=R0, v0=V0, duration=3.0, forces=[nan_after_one_second],
                          samples=30)
    exc = info.value
    msg = _one_line(exc)
    assert "nan_after_one_second" in msg and "non-finite" in msg
    assert 0.9 <= exc.t_reached <= 1.1
    assert exc.partial is not None and not exc.partial.complete  # a Result, as rotframe.run's
    part = exc.partial.trajectory
    assert 0.9 <= part.times[-1] <= 1.0 + 1e-12
    assert np.all(np.isfinite(part.r)) and np.all(np.isfinite(part.v))
    assert part.r.shape == (part.times.size, 1, 3)


@pytest.mark.parametrize("inline", [False, True])
def test_force_raises_later_gives_time_and_state(inline):
    """A force that raises inside the compiled run: one line naming it, with the time and the state of the step,
    in the engine's loop (the call by address flags it) and in the inlined loop (the exception ends the call, which
    is replayed a step at a time to find the step)."""
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=[0, 0, 1.0], r0=R0, v0=V0, duration=3.0, forces=[raise_after_one_second],
                          samples=30, inline=inline)
    exc = info.value
    msg = _one_line(exc)
    assert "raise_after_one_second" in msg and "ValueError" in msg and "too late" in msg
    assert "r = [" in msg and "v = [" in msg
    t_step = float(re.search(r"in the step from t = ([-+0-9.e]+) s", msg).group(1))
    assert 0.0 < t_step <= 1.0  # the step that raised began before the force's limit
    times = exc.partial.trajectory.times
    assert times[-1] <= t_step < times[-1] + 0.1  # every sample before that step is kept (one each 0.1 s)
    assert np.all(np.isfinite(exc.partial.trajectory.r))


def test_omega_table_not_increasing():
    tt = np.array([0.0, 1.0, 1.0, 2.0])
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=(tt, np.ones((4, 3))), r0=R0, v0=V0, duration=1.0)
    msg = _one_line(info.value)
    assert "omega" in msg and "increase" in msg


def test_omega_table_too_short_for_the_run():
    tt = np.linspace(0.0, 1.0, 5)
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=(tt, np.ones((5, 3))), r0=R0, v0=V0, duration=2.0)
    assert "omega" in _one_line(info.value)


def test_omega_particle_result_refused():
    particle = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=[0.0, 0.0, 10.0], v0=[0.0, 0.0, 0.0], duration=1.0,
                                 forces=[x_spring_and_gravity], params=(0.0, 9.81),
                                 events=[ground, x_any, x_up, x_down], samples=4)
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=particle, r0=R0, v0=V0, duration=1.0)
    msg = _one_line(info.value)
    assert "omega" in msg and "attitude" in msg


def test_uncompilable_force_one_line_then_plain_python():
    with pytest.raises(RotframeError) as info:
        rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=R0, v0=V0, duration=1.0, forces=[uncompilable], samples=4)
    msg = _one_line(info.value)
    assert "numba" in msg and "jit=False" in msg and "uncompilable" in msg
    res = rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=R0, v0=V0, duration=1.0, forces=[uncompilable], samples=4,
                            rtol=1e-8, jit=False)
    assert any("slow" in w for w in res.warnings), res.warnings
    # plain Python gives the physics: a spring of k = 2 seen from a frame turning at 0.5 rad/s about z
    w = np.array([0.0, 0.0, 0.5])
    t = res.trajectory.times
    s = math.sqrt(2.0)
    v_in = V0 + np.cross(w, R0)
    r_in = np.cos(s * t)[:, None] * R0 + (np.sin(s * t) / s)[:, None] * v_in
    expected = Rotation.from_rotvec(-t[:, None] * w[None, :]).apply(r_in)
    assert np.max(np.abs(res.trajectory.r[:, 0] - expected)) < 1e-6


def _pull_star(t, r, v, *p):
    return -p[0] * r[0], -p[0] * r[1], -p[1] * r[2]


def _pull(t, r, v, k, kz):
    return -k * r[0], -k * r[1], -kz * r[2]


def _crossing_star(t, r, v, *p):
    return r[0] - 0.5 * p[0] / 2.0


def test_functions_of_star_args_run_compiled_as_their_spelled_out_twins():
    """A force, an event and a torque written with *params give the numbers of the same functions with their
    parameters spelled out, compiled (numba's inliner refuses *args with no message: they compile on their own)."""
    kw = dict(omega=[0.0, 0.0, 0.5], r0=R0, v0=V0, duration=3.0, params=(2.0, 0.5), samples=6)
    star = rotframe.simulate(forces=[_pull_star], events=[_crossing_star], **kw)
    spelled = rotframe.simulate(forces=[_pull], events=[lambda t, r, v, k, kz: r[0] - 0.5 * k / 2.0], **kw)
    assert not star.warnings
    np.testing.assert_array_equal(star.trajectory.r, spelled.trajectory.r)
    [a], [b] = star.trajectory.event_times.values(), spelled.trajectory.event_times.values()
    assert a[0].size >= 1
    np.testing.assert_array_equal(a[0], b[0])

    def torque_star(t, L, q, *p):
        return p[0] * L[1], 0.0, 0.0

    def torque(t, L, q, c):
        return c * L[1], 0.0, 0.0

    body = dict(inertia=[1.0, 2.0, 3.0], L0=[0.1, 1.0, 0.1], q0=[0, 0, 0, 1], duration=2.0, samples=4, params=(0.3,))
    np.testing.assert_array_equal(rotframe.simulate_body(torque=torque_star, **body).trajectory.L,
                                  rotframe.simulate_body(torque=torque, **body).trajectory.L)


def test_functions_of_keywords_are_refused_in_one_line():
    def pull(t, r, v, **options):
        return -r[0], -r[1], -r[2]

    with pytest.raises(RotframeError) as info:
        rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=R0, v0=V0, duration=1.0, forces=[pull], samples=4)
    msg = _one_line(info.value)
    assert "forces[0]" in msg and "**keywords" in msg and "jit=False" in msg
    res = rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=R0, v0=V0, duration=1.0, forces=[pull], samples=4, jit=False)
    assert np.all(np.isfinite(res.trajectory.r))


def test_bad_method_and_arguments_name_the_key():
    with pytest.raises(ScenarioError, match="method"):
        rotframe.simulate(omega=[0, 0, 1.0], r0=R0, v0=V0, duration=1.0, method="euler")
    with pytest.raises(ScenarioError, match="r0"):
        rotframe.simulate(omega=[0, 0, 1.0], r0=[1.0, 2.0], v0=V0, duration=1.0)
    with pytest.raises(ScenarioError, match="omega"):
        rotframe.simulate(omega=[0, 0, math.nan], r0=R0, v0=V0, duration=1.0)
    with pytest.raises(ScenarioError, match="duration"):
        rotframe.simulate(omega=[0, 0, 1.0], r0=R0, v0=V0, duration=-1.0)


# ---------------------------------------------------------------------------------------------
# 8. a second process compiles nothing
# ---------------------------------------------------------------------------------------------

_CACHE_SCRIPT = textwrap.dedent('''
    import json, sys
    import numpy as np
    import rotframe
    import rotframe.numerics.compile_apart
    rotframe.numerics.compile_apart.spare_core = lambda: False  # every compile in this process, where it is counted

    def drag(t, r, v, c):
        return -c * v[0], -c * v[1], -c * v[2]

    res = rotframe.simulate(omega=[0.0, 0.0, 1.0], r0=[1.0, 0.0, 0.0], v0=[0.0, 1.0, 0.0], duration=2.0,
                            forces=[drag], params=(0.1,), samples=8)
    mods = [m for name, m in sys.modules.items() if name.startswith("rotframe_particle_problem_")]
    assert len(mods) == 1, mods
    from rotframe.problem import engine
    # the problem's own glue (with the user's force inside) and the engine that steps it
    from rotframe.problem.signatures import PARTICLE
    stats = [mods[0].terms.stats, engine.variant(PARTICLE, "dop853", False).stats]
    print(json.dumps({"hits": [sum(s.cache_hits.values()) for s in stats],
                      "misses": [sum(s.cache_misses.values()) for s in stats],
                      "r": res.trajectory.r[-1, 0].tolist()}))
''')


def test_second_process_compiles_nothing(tmp_path):
    script = tmp_path / "user_problem.py"
    script.write_text(_CACHE_SCRIPT)
    env = dict(os.environ, ROTFRAME_CACHE_DIR=str(tmp_path / "problems"), NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    outs = []
    for _ in range(2):
        proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, timeout=600)
        assert proc.returncode == 0, proc.stderr[-2000:]
        outs.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    first, second = outs
    assert min(first["misses"]) >= 1 and max(first["hits"]) == 0
    assert max(second["misses"]) == 0 and min(second["hits"]) >= 1
    assert second["r"] == first["r"]
    assert list((tmp_path / "problems").glob("rotframe_particle_problem_*.py"))


# ---------------------------------------------------------------------------------------------
# 9. many particles: each as if alone, bitwise; independent of the thread count
# ---------------------------------------------------------------------------------------------

def test_many_particles_bitwise_and_thread_independent(monkeypatch):
    """N particles of very different scales: each particle's numbers are those of its run alone, bitwise
    (its own tolerance scale, its own steps), and do not depend on the thread count (blocks of 256
    particles here, so that several run on threads)."""
    from rotframe.particles import threads as particle_threads
    from rotframe.particles.ensemble import threads_scope

    monkeypatch.setattr(particle_threads, "BLOCK", 256)

    rng = np.random.default_rng(7)
    N = 600
    r0 = rng.normal(size=(N, 3)) * np.exp(rng.uniform(-5, 4, size=(N, 1)))
    v0 = rng.normal(size=(N, 3)) * np.exp(rng.uniform(-5, 2, size=(N, 1)))
    r0[3] = 0.0
    kw = dict(omega=W_USER, duration=3.0, forces=[SPRING], params=(2.0,), rtol=1e-10, samples=12)
    runs = {}
    for threads in (1, 2):
        with threads_scope(threads):
            runs[threads] = rotframe.simulate(r0=r0, v0=v0, **kw)
    together = runs[1]
    np.testing.assert_array_equal(runs[2].trajectory.r, together.trajectory.r)
    np.testing.assert_array_equal(runs[2].trajectory.v, together.trajectory.v)
    assert together.trajectory.r.shape == (13, N, 3)
    for i in (0, 1, 2, 3, 511, 512, N - 1):
        alone = rotframe.simulate(r0=r0[i], v0=v0[i], **kw)
        np.testing.assert_array_equal(alone.trajectory.r[:, 0], together.trajectory.r[:, i])
        np.testing.assert_array_equal(alone.trajectory.v[:, 0], together.trajectory.v[:, i])


# ---------------------------------------------------------------------------------------------
# 12. the Result's surface
# ---------------------------------------------------------------------------------------------

def test_result_surface(tmp_path):
    res = rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=[[1.0, 0.0, 0.2], [0.5, 0.5, 0.0]],
                            v0=[[0.0, 0.3, 0.0], [0.1, 0.0, 0.0]], duration=5.0, forces=[SPRING], params=(1.0,),
                            method="DOP853", rtol=1e-10, samples=20)
    assert isinstance(res, rotframe.Result)
    assert res.method == "dop853"
    assert res.trajectory.r.shape == (21, 2, 3) and res.trajectory.v.shape == (21, 2, 3)
    lower = rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=[[1.0, 0.0, 0.2], [0.5, 0.5, 0.0]],
                              v0=[[0.0, 0.3, 0.0], [0.1, 0.0, 0.0]], duration=5.0, forces=[SPRING], params=(1.0,),
                              method="dop853", rtol=1e-10, samples=20)
    np.testing.assert_array_equal(lower.trajectory.r, res.trajectory.r)
    rk4 = rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=[1.0, 0.0, 0.2], v0=[0.0, 0.3, 0.0], duration=5.0,
                            forces=[SPRING], params=(1.0,), method="RK4", step=1e-3, samples=20)
    assert rk4.method == "rk4"
    assert np.max(np.abs(rk4.trajectory.r[:, 0] - res.trajectory.r[:, 0])) < 1e-9

    summary = json.loads(res.to_json())
    for key in ("scenario", "params", "model", "method", "steps", "metrics", "diagnostics", "warnings", "timing"):
        assert key in summary
    assert "jacobi_rel_drift" in summary["diagnostics"]

    df = res.to_dataframe()
    assert len(df) == 21 * 2
    assert {"time_s", "particle", "x_m", "vz_m_s"} <= set(df.columns)
    np.testing.assert_array_equal(df["x_m"].to_numpy().reshape(21, 2), res.trajectory.r[:, :, 0])

    npz = res.export(tmp_path / "run.npz")
    with np.load(npz) as data:
        assert any(np.array_equal(data[k], res.trajectory.r) for k in data.files if data[k].shape == (21, 2, 3))

    path = res.record(tmp_path / "run.rrd")
    assert path.is_file() and path.stat().st_size > 0
    assert not list(tmp_path.glob("*.partial.rrd"))
    import rerun as rr

    paths = {str(chunk.entity_path) for chunk in rr.chunk.RrdReader(str(path)).stream()}
    assert any(p.endswith("world/particle_0") for p in paths), paths
    assert any(p.endswith("world/particle_1") for p in paths), paths
    assert any("diagnostics/jacobi" in p for p in paths), paths
