"""The tumbling-ball scene: a free ball in the axes of a body doing the intermediate-axis flip.

Independent oracle: the body integrated here with scipy's DOP853 (Euler's equations and the
quaternion kinematics written out, rtol 1e-12), its attitude turning the inertial straight
line into body axes (scipy's Rotation). The scene's own metric compares with the line turned
by rotframe's exact free-body attitude; both must agree with the ball rotframe integrated in
the body's frame (omega from the rigid solution, Euler force from Euler's equations).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import rotframe


def _body_attitude(I, w0, times):
    def f(t, y):
        L, q = y[:3], y[3:]
        w = L / I
        dL = np.cross(L, w)
        qv, qs = q[:3], q[3]
        dqv = 0.5 * (qs * w + np.cross(qv, w))
        dqs = -0.5 * np.dot(qv, w)
        return np.concatenate([dL, dqv, [dqs]])

    sol = solve_ivp(f, (0, times[-1]), np.concatenate([I * w0, [0, 0, 0, 1.0]]), method="DOP853", rtol=1e-12,
                    atol=1e-14, t_eval=times)
    return sol.y[3:].T


def test_ball_follows_the_inertial_line_in_body_axes():
    res = rotframe.run("tumbling-ball")
    p = res.params
    I = np.array([p["i1"], p["i2"], p["i3"]])
    w0, r0, v0 = (np.array(p[k], dtype=float) for k in ("omega", "position", "velocity"))
    t = res.trajectory.times
    q = _body_attitude(I, w0, t)
    rot = Rotation.from_quat(q)  # body -> space
    line = r0 + t[:, None] * (v0 + np.cross(w0, r0))  # space axes = body axes at t = 0
    exact = rot.inv().apply(line)
    err = np.max(np.linalg.norm(res.trajectory.r[:, 0] - exact, axis=1))
    assert err < 1e-9 * np.max(np.linalg.norm(line, axis=1))  # measured 3e-12 of the scale
    assert res.metrics["position_error_m"] < 1e-9
    assert res.metrics["flips"] >= 2
    assert not res.warnings


def test_the_frame_knots_bound_the_steps_and_both_tolerances_hold():
    # every step ends on the body's samples (the frame's knots, 200 a second), so even a loose rtol
    # integrates each smooth piece far below its tolerance; before the stops the error followed rtol
    loose = rotframe.run("tumbling-ball", rtol=1e-7, duration=20, samples=10)
    tight = rotframe.run("tumbling-ball", rtol=1e-11, duration=20, samples=10)
    knots = 200 * 20
    assert loose._summary["steps"] >= knots and tight._summary["steps"] >= knots
    for res, rtol in ((loose, 1e-7), (tight, 1e-11)):
        assert res.metrics["position_error_m"] < 10 * rtol * max(res.metrics["curl_m"], 1.0)
        assert not res.warnings
    assert tight.metrics["position_error_m"] <= 2 * loose.metrics["position_error_m"]


@pytest.mark.parametrize("duration, samples", [(1.0, 1000), (3.7, 333), (0.05, 7)])
def test_any_duration_and_sample_count_runs(duration, samples):
    """The ball's samples are always among the body's (the oracle reads the attitude there): a whole number of
    body samples between two of the ball's, whatever the duration and the sample count (a duration of 1 s with
    1000 samples was an internal error)."""
    res = rotframe.run("tumbling-ball", duration=duration, samples=samples)
    assert res.trajectory.times.size == samples + 1
    p = res.params
    I = np.array([p["i1"], p["i2"], p["i3"]])
    w0, r0, v0 = (np.array(p[k], dtype=float) for k in ("omega", "position", "velocity"))
    t = res.trajectory.times
    line = r0 + t[:, None] * (v0 + np.cross(w0, r0))
    exact = Rotation.from_quat(_body_attitude(I, w0, t)).inv().apply(line)
    assert np.max(np.linalg.norm(res.trajectory.r[:, 0] - exact, axis=1)) < 1e-9 * np.max(np.linalg.norm(line, axis=1))
