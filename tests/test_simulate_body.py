"""``rotframe.simulate_body`` and a body's axes as a frame, against oracles written here.

The oracles are scipy's ``solve_ivp`` on Euler's equations and the rotation-matrix kinematics
written out in this file, scipy's ``Rotation``, and rotframe's closed-form free flow
(``method="exact"``: Jacobi elliptic functions, no integrator shared with DOP853). The
torques are module-level functions so that the generated drivers are compiled once and shared.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import rotframe
from rotframe.errors import ScenarioError

INERTIA = np.array([1.0, 2.0, 3.0])


def body_torque(t, L, q, tau):
    """A constant torque in body axes (N m), from the params."""
    return tau[0], tau[1], tau[2]


def _hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def euler_oracle(I, L0, R0, tau, times):
    """L' = L x w + tau, R' = R [w]x with w = I^-1 L (body axes), scipy DOP853 at rtol 1e-12."""
    Iinv = np.linalg.inv(I)

    def rhs(t, y):
        L = y[:3]
        R = y[3:].reshape(3, 3)
        w = Iinv @ L
        return np.concatenate([np.cross(L, w) + tau, (R @ _hat(w)).ravel()])

    sol = solve_ivp(rhs, (times[0], times[-1]), np.concatenate([L0, R0.ravel()]), method="DOP853", rtol=1e-12,
                    atol=1e-14, t_eval=times)
    assert sol.success
    return sol.y[:3].T, sol.y[3:].T.reshape(-1, 3, 3)


Q0 = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_quat()  # scalar last, body -> space
L0 = np.array([0.4, 2.0, 0.3])


def test_constant_body_torque_against_solve_ivp():
    """DOP853 at rtol 1e-12 against scipy at 1e-12: both errors ~1e-11 of |L|; allowed 1e-9."""
    tau = np.array([0.05, -0.02, 0.1])
    res = rotframe.simulate_body(inertia=INERTIA, L0=L0, q0=Q0, duration=10.0, torque=body_torque, params=(tau,),
                                 rtol=1e-12, samples=100)
    t = res.trajectory.times
    L_ref, R_ref = euler_oracle(np.diag(INERTIA), L0, Rotation.from_quat(Q0).as_matrix(), tau, t)
    assert np.max(np.abs(res.trajectory.L - L_ref)) < 1e-9 * np.max(np.abs(L_ref))
    R = Rotation.from_quat(res.trajectory.q).as_matrix()
    assert np.max(np.abs(R - R_ref)) < 1e-9
    # the torque really acted: the torque-free body's L is far from this one
    L_free, _ = euler_oracle(np.diag(INERTIA), L0, Rotation.from_quat(Q0).as_matrix(), np.zeros(3), t)
    assert np.max(np.abs(L_free - L_ref)) > 0.1 * np.linalg.norm(L0)
    assert any("torque" in n for n in res.notes)


def test_constant_body_torque_rk4():
    tau = np.array([0.05, -0.02, 0.1])
    res = rotframe.simulate_body(inertia=INERTIA, L0=L0, q0=Q0, duration=10.0, torque=body_torque, params=(tau,),
                                 method="RK4", step=2e-3, samples=100)
    assert res.method == "rk4"
    L_ref, R_ref = euler_oracle(np.diag(INERTIA), L0, Rotation.from_quat(Q0).as_matrix(), tau,
                                res.trajectory.times)
    # RK4 at h = 2 ms: measured 3.5e-13 in L and 2.3e-12 in R; allowed 1e-10 (a third-order step, ~1e-8, fails)
    assert np.max(np.abs(res.trajectory.L - L_ref)) < 1e-10
    assert np.max(np.abs(Rotation.from_quat(res.trajectory.q).as_matrix() - R_ref)) < 1e-10


def test_torque_free_dop853_against_exact_flow():
    """The intermediate-axis flip: DOP853 at rtol 1e-12 against the closed-form flow, to ~1e-9."""
    L = np.array([0.02, 2.0, 0.01])
    dop = rotframe.simulate_body(inertia=INERTIA, L0=L, q0=Q0, duration=30.0, rtol=1e-12, samples=300)
    exact = rotframe.simulate_body(inertia=INERTIA, L0=L, q0=Q0, duration=30.0, method="exact", samples=300)
    assert exact.method == "exact"
    np.testing.assert_array_equal(dop.trajectory.times, exact.trajectory.times)
    assert np.max(np.abs(dop.trajectory.L - exact.trajectory.L)) < 1e-9 * np.linalg.norm(L)
    dq = np.abs(np.einsum("ij,ij->i", dop.trajectory.q, exact.trajectory.q))  # q and -q are the same attitude
    assert np.max(1.0 - dq) < 1e-15 + 1e-9
    ang = (Rotation.from_quat(dop.trajectory.q).inv() * Rotation.from_quat(exact.trajectory.q)).magnitude()
    assert np.max(ang) < 1e-8
    # the flip happened (L2 changed sign), else the comparison is of nothing
    assert np.min(exact.trajectory.L[:, 1]) < -1.0
    for key in ("energy_rel_drift", "momentum_rel_drift"):
        assert dop.diagnostics[key] < 1e-10


def test_splitting_methods_refuse_a_torque_by_name():
    tau = np.array([0.0, 0.0, 0.1])
    for method in ("lie-poisson", "Lie-Poisson", "rotation-splitting", "exact"):
        with pytest.raises(ScenarioError) as info:
            rotframe.simulate_body(inertia=INERTIA, L0=L0, q0=Q0, duration=1.0, torque=body_torque, params=(tau,),
                                   method=method)
        msg = str(info.value)
        assert "\n" not in msg
        assert method in msg and "body_torque" in msg


def test_full_inertia_tensor_equals_principal_run():
    """A non-diagonal tensor Q diag(I) Q^T with L0 = Q L0_p and attitude R_u = R_p Q^T gives L_u = Q L_p and
    R_u(t) = R_p(t) Q^T of the principal-axes run (both DOP853 at rtol 1e-12, different roundings)."""
    Q = Rotation.from_rotvec([0.4, 0.9, -0.3]).as_matrix()
    I_full = Q @ np.diag(INERTIA) @ Q.T
    I_full = 0.5 * (I_full + I_full.T)
    Lp = np.array([0.02, 2.0, 0.01])
    Rp0 = Rotation.from_quat(Q0).as_matrix()
    Ru0 = Rp0 @ Q.T
    principal = rotframe.simulate_body(inertia=INERTIA, L0=Lp, q0=Q0, duration=20.0, rtol=1e-12, samples=200)
    full = rotframe.simulate_body(inertia=I_full, L0=Q @ Lp, q0=Rotation.from_matrix(Ru0).as_quat(),
                                  duration=20.0, rtol=1e-12, samples=200)
    L_back = full.trajectory.L @ Q  # Q^T L_u, row-wise
    assert np.max(np.abs(L_back - principal.trajectory.L)) < 1e-9 * np.linalg.norm(Lp)
    Ru = Rotation.from_quat(full.trajectory.q).as_matrix()
    Rp = Rotation.from_quat(principal.trajectory.q).as_matrix()
    assert np.max(np.abs(Ru @ Q - Rp)) < 1e-8
    assert np.min(principal.trajectory.L[:, 1]) < -1.0  # it flipped: the comparison covers the hard part
    with pytest.raises(ScenarioError, match="exact"):
        rotframe.simulate_body(inertia=I_full, L0=Q @ Lp, q0=Q0, duration=1.0, method="exact")


def test_body_bad_input():
    with pytest.raises(ScenarioError, match="inertia"):
        rotframe.simulate_body(inertia=[1.0, 1.0, 5.0], L0=L0, q0=Q0, duration=1.0)
    with pytest.raises(ScenarioError, match="q0"):
        rotframe.simulate_body(inertia=INERTIA, L0=L0, q0=[0.0, 0.0, 0.0, 2.0], duration=1.0)
    with pytest.raises(ScenarioError, match="method"):
        rotframe.simulate_body(inertia=INERTIA, L0=L0, q0=Q0, duration=1.0, method="verlet")

    def wrong(t, L, q):
        return 1.0, 2.0

    with pytest.raises(ScenarioError) as info:
        rotframe.simulate_body(inertia=INERTIA, L0=L0, q0=Q0, duration=1.0, torque=wrong)
    assert "wrong" in str(info.value) and "torque" in str(info.value)


# ---------------------------------------------------------------------------------------------
# 11. a body's axes as the frame of a particle problem
# ---------------------------------------------------------------------------------------------

def test_free_particle_in_a_tumbling_body():
    """A free particle seen from the axes of a body doing the intermediate-axis flip, against the inertial line
    turned into body axes by the body's own attitude q(t) (scipy Rotation).

    The frame's omega between the body's samples is a quintic Hermite interpolant of omega, omega', omega''
    (from Euler's equations at the samples): its error is ~ (h |w|)^6 / 6! ~ 1e-13 at h = 10 ms, so the
    particle's error is set by the body's own (rtol 1e-12) and the particle's DOP853: allowed 1e-8 of the scale.
    """
    L = np.array([0.02, 2.0, 0.01])
    body = rotframe.simulate_body(inertia=INERTIA, L0=L, q0=Q0, duration=20.0, rtol=1e-12, samples=2000)
    r0 = np.array([0.5, -0.2, 0.1])
    v0 = np.array([0.05, 0.1, -0.02])
    res = rotframe.simulate(omega=body, r0=r0, v0=v0, duration=20.0, rtol=1e-12, samples=2000)
    np.testing.assert_array_equal(res.trajectory.times, body.trajectory.times)
    w0 = L / INERTIA
    q0 = Rotation.from_quat(body.trajectory.q[0])
    r_in0 = q0.apply(r0)
    v_in0 = q0.apply(v0 + np.cross(w0, r0))
    t = body.trajectory.times
    line = r_in0 + t[:, None] * v_in0
    expected = Rotation.from_quat(body.trajectory.q).inv().apply(line)
    scale = np.max(np.linalg.norm(line, axis=1))
    err = np.max(np.abs(res.trajectory.r[:, 0] - expected))
    assert err < 1e-8 * scale, err / scale
    # the path really curls in the body frame (it is no straight line there)
    assert np.max(np.abs(res.trajectory.r[:, 0] - (r0 + t[:, None] * v0))) > 0.1 * scale


def test_body_frame_from_exact_flow():
    """The same with the exact free flow as the frame (the Result of method='exact')."""
    L = np.array([0.02, 2.0, 0.01])
    body = rotframe.simulate_body(inertia=INERTIA, L0=L, q0=Q0, duration=20.0, method="exact", samples=2000)
    r0 = np.array([0.5, -0.2, 0.1])
    v0 = np.array([0.05, 0.1, -0.02])
    res = rotframe.simulate(omega=body, r0=r0, v0=v0, duration=20.0, rtol=1e-12, samples=2000)
    w0 = L / INERTIA
    q0 = Rotation.from_quat(body.trajectory.q[0])
    t = body.trajectory.times
    line = q0.apply(r0) + t[:, None] * q0.apply(v0 + np.cross(w0, r0))
    expected = Rotation.from_quat(body.trajectory.q).inv().apply(line)
    scale = np.max(np.linalg.norm(line, axis=1))
    assert np.max(np.abs(res.trajectory.r[:, 0] - expected)) < 1e-8 * scale


def test_body_result_surface(tmp_path):
    tau = np.array([0.05, -0.02, 0.1])
    res = rotframe.simulate_body(inertia=INERTIA, L0=L0, q0=Q0, duration=2.0, torque=body_torque, params=(tau,),
                                 method="DOP853", samples=20)
    assert isinstance(res, rotframe.Result) and res.method == "dop853"
    assert res.trajectory.L.shape == (21, 3) and res.trajectory.q.shape == (21, 4)
    df = res.to_dataframe()
    assert len(df) == 21 and {"time_s", "L1_kg_m2_s", "qw"} <= set(df.columns)
    assert '"method": "dop853"' in res.to_json()
    npz = res.export(tmp_path / "body.npz")
    assert npz.is_file()
    path = res.record(tmp_path / "body.rrd")
    assert path.is_file() and path.stat().st_size > 0


def torque_raises_later(t, L, q, tau):
    if t > 1.0:
        raise ValueError("torque too late")
    return tau[0], tau[1], tau[2]


def torque_nan_later(t, L, q, tau):
    if t > 1.0:
        return np.nan, 0.0, 0.0
    return tau[0], tau[1], tau[2]


def torque_sqrt_later(t, L, q, tau):
    s = math.sqrt(1.0 - t)  # compiled (error_model numpy): NaN after t = 1; as plain Python: ValueError
    return tau[0] * s, tau[1] * s, tau[2] * s


def test_torque_that_gives_nan_compiled_and_raises_in_python_is_named_in_one_line():
    """The blame probe runs the torque as plain Python, where math.sqrt(-x) raises instead of giving
    NaN: the failure must still be one IntegrationError line naming the torque, not a traceback."""
    from rotframe.errors import IntegrationError

    with pytest.raises(IntegrationError) as info:
        rotframe.simulate_body(inertia=INERTIA, L0=L0, q0=Q0, duration=3.0, torque=torque_sqrt_later,
                               params=(np.array([0.0, 0.0, 0.1]),), samples=30)
    msg = str(info.value)
    assert "\n" not in msg and "torque_sqrt_later" in msg and "ValueError" in msg


def test_torque_that_fails_later_is_named():
    from rotframe.errors import IntegrationError

    tau = np.array([0.0, 0.0, 0.1])
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate_body(inertia=INERTIA, L0=L0, q0=Q0, duration=3.0, torque=torque_raises_later,
                               params=(tau,), samples=30)
    msg = str(info.value)
    assert "\n" not in msg and "torque_raises_later" in msg and "torque too late" in msg
    assert "L = [" in msg and "q = [" in msg
    assert float(re.search(r" at t = ([-+0-9.e]+) s", msg).group(1)) > 1.0  # where the torque raised: after 1 s
    with pytest.raises(IntegrationError) as info:
        rotframe.simulate_body(inertia=INERTIA, L0=L0, q0=Q0, duration=3.0, torque=torque_nan_later, params=(tau,),
                               samples=30)
    msg = str(info.value)
    assert "\n" not in msg and "torque_nan_later" in msg and "non-finite" in msg
    part = info.value.partial
    assert part is not None and 0.9 <= part.times[-1] <= 1.0 and np.all(np.isfinite(part.L))
