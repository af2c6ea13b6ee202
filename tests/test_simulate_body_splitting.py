"""Lie-Poisson splittings of a user's body with a torque of (t, q) alone (gravity gradient).

Oracle: scipy's DOP853 at rtol 1e-12 on Euler's equations, the quaternion kinematics and the
gravity-gradient torque, all written out here. The splittings must converge at their orders
(2, 4 and 6: errors at h and h/2 in the ratio 4, 16 and 64) and keep |L| of a free body to round-off.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import rotframe
from rotframe.errors import ScenarioError

I = np.array([1.0, 2.0, 3.0])
N2 = 0.3  # orbital rate squared
L0 = np.array([0.3, 1.0, 0.2])
Q0 = Rotation.from_euler("xyz", [0.3, 0.2, 0.1]).as_quat()
T = 10.0


def gravity_gradient(t, L, q, n2, i1, i2, i3):
    """3 n^2 c x (I c), c the space z axis (towards the Earth) in body axes."""
    x, y, z, w = q[0], q[1], q[2], q[3]
    cx = 2 * (x * z - w * y)
    cy = 2 * (y * z + w * x)
    cz = 1 - 2 * (x * x + y * y)
    return (3 * n2 * (cy * i3 * cz - cz * i2 * cy), 3 * n2 * (cz * i1 * cx - cx * i3 * cz),
            3 * n2 * (cx * i2 * cy - cy * i1 * cx))


def _scipy_reference():
    def f(t, s):
        L, q = s[:3], s[3:]
        R = Rotation.from_quat(q).as_matrix()  # body -> space
        c = R.T @ np.array([0.0, 0.0, 1.0])
        tau = 3 * N2 * np.cross(c, I * c)
        w = L / I
        qv, qs = q[:3], q[3]
        return np.concatenate([np.cross(L, w) + tau, 0.5 * (qs * w + np.cross(qv, w)), [-0.5 * qv @ w]])

    sol = solve_ivp(f, (0, T), np.concatenate([L0, Q0]), method="DOP853", rtol=1e-12, atol=1e-14)
    return sol.y[:3, -1]


@pytest.mark.parametrize("method, order, h", [("lie-poisson", 2, 0.02), ("lie-poisson4", 4, 0.02),
                                             ("lie-poisson6", 6, 0.2)])
def test_splittings_converge_at_their_order_against_scipy(method, order, h):
    ref = _scipy_reference()
    torque = rotframe.Torque(gravity_gradient, attitude_only=True)
    errors = []
    for h in (h, h / 2):
        res = rotframe.simulate_body(inertia=I, L0=L0, q0=Q0, duration=T, torque=torque, params=(N2, *I),
                                     method=method, step=h, samples=10)
        errors.append(np.linalg.norm(res.trajectory.L[-1] - ref))
    observed = np.log2(errors[0] / errors[1])
    assert abs(observed - order) < 0.2, (errors, observed)


def test_free_splitting_keeps_the_momentum_to_round_off():
    res = rotframe.simulate_body(inertia=I, L0=L0, q0=Q0, duration=200.0, method="lie-poisson", step=0.05,
                                 samples=50)
    assert res.diagnostics["momentum_rel_drift"] < 1e-13


def test_a_torque_not_marked_attitude_only_is_refused_by_the_splittings():
    with pytest.raises(ScenarioError, match="attitude_only"):
        rotframe.simulate_body(inertia=I, L0=L0, q0=Q0, duration=1.0, torque=gravity_gradient, params=(N2, *I),
                               method="lie-poisson")
    with pytest.raises(ScenarioError, match="principal"):
        rotframe.simulate_body(inertia=np.diag(I) + 0.1 * (np.ones((3, 3)) - np.eye(3)), L0=L0, q0=Q0, duration=1.0,
                               method="lie-poisson4")


@pytest.mark.parametrize("method", ["lie-poisson", "lie-poisson4"])
def test_free_splitting_keeps_the_space_frame_momentum(method):
    """A free body's angular momentum is fixed in space: R(q) L, with R from scipy's Rotation of
    the attitude, must stay L(0) in space to round-off. |L| alone would pass on an attitude that
    turns the wrong way or at the wrong rate (the body-frame L does not see q)."""
    res = rotframe.simulate_body(inertia=I, L0=L0, q0=Q0, duration=200.0, method=method, step=0.05, samples=50)
    traj = res.trajectory
    space = Rotation.from_quat(traj.q).apply(traj.L)  # body -> space
    drift = np.max(np.linalg.norm(space - space[0], axis=1)) / np.linalg.norm(L0)
    assert drift < 1e-12, drift
