"""Compiled adaptive DOP853 for rigid bodies (rotframe.rigid.adaptive) against independent references.

References: the exact free-body flow in elliptic functions (rigid.free_body_exact,
itself checked against mpmath in test_rigid), scipy's own DOP853 at rtol 1e-13 for
the heavy top, and the closed form L_space(t) = L_space(0) + N t under a constant
space-fixed torque.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from rotframe.rigid import dynamics as rigid
from rotframe.errors import ScenarioError
from rotframe.rigid.adaptive import rigid_dop853

I = np.array([1.0, 2.0, 3.0])
L0 = I * np.array([0.01, 1.0, 0.01])  # near the unstable middle axis: the Dzhanibekov flip
Q0 = np.array([0.0, 0.0, 0.0, 1.0])


def _angle(q, q_ref):
    # rotation angle between unit quaternions, |q - q_ref| = 2 sin(angle / 4) with the sign that makes
    # them closest; arccos of the dot product would lose half the digits (floor ~1e-8)
    s = np.where(np.sum(q * q_ref, axis=-1) < 0, -1.0, 1.0)[..., None]
    return 4 * np.arcsin(np.minimum(1.0, 0.5 * np.linalg.norm(q - s * q_ref, axis=-1)))


def _errors(run, times):
    Lx, qx = rigid.free_body_exact(I, L0, Q0, times)
    return np.max(np.linalg.norm(run.L - Lx, axis=1)) / np.linalg.norm(L0), np.max(_angle(run.q, qx))


def test_free_body_matches_the_exact_flow_at_every_sample():
    # 2.6 flips; rtol 1e-12 gives a global error of about 1e-12 (measured); dense output (order 7) a
    # little more; 1e-9 leaves room for the long-time growth of the error near the separatrix
    times = np.linspace(0.0, 100.0, 201)
    run = rigid_dop853(I, L0, Q0, times, rtol=1e-12)
    eL, eq = _errors(run, times)
    assert eL < 1e-9 and eq < 1e-9
    assert np.allclose(np.linalg.norm(run.q, axis=1), 1.0, atol=1e-15)  # outputs are normalised


def test_error_control_matches_scipy_dop853():
    # the same method and the same error control (scaled by atol_j + rtol |y_j|) in scipy's independent
    # implementation: at each rtol our global error is within a factor 10 of scipy's (step sequences
    # differ a little), and it falls with rtol. Near the separatrix the global error is some 100 times
    # the local tolerance for both.
    times = np.array([0.0, 100.0])
    Lx, qx = rigid.free_body_exact(I, L0, Q0, times)
    M = np.linalg.norm(L0)
    errs = []
    for rtol in (1e-6, 1e-9, 1e-12):
        eL, eq = _errors(rigid_dop853(I, L0, Q0, times, rtol=rtol), times)
        atol = np.array([rtol * M] * 3 + [rtol] * 4)
        ref = solve_ivp(lambda t, y: rigid.rigid_rhs(t, y, I), (0, 100.0), np.concatenate([L0, Q0]),
                        method="DOP853", rtol=rtol, atol=atol).y[:, -1]
        e_scipy = max(np.linalg.norm(ref[:3] - Lx[-1]) / M, _angle(ref[3:] / np.linalg.norm(ref[3:]), qx[-1]))
        errs.append(max(eL, eq))
        assert errs[-1] < 10 * max(e_scipy, 1e-13), (rtol, errs[-1], e_scipy)
    assert errs[0] > errs[1] > errs[2]


def test_observed_order_is_eight():
    # forced fixed steps (rtol so loose that every step is accepted, h_max = the step): halving the
    # step divides the error by 2^8 = 256 for an 8th-order method
    times = np.array([0.0, 4.0])
    errs = []
    for n in (4, 8):  # steps of 1 s and 0.5 s: errors 4e-10 and 2e-12, far above round-off (1e-15)
        run = rigid_dop853(I, L0, Q0, times, rtol=1e6, h_max=4.0 / n)
        eL, eq = _errors(run, times)
        errs.append(max(eL, eq))
    order = math.log2(errs[0] / errs[1])
    assert 7.3 < order < 8.7, order


def test_heavy_top_matches_scipy_dop853():
    # a fast top (spin 300 rad/s) for 0.5 s: scipy DOP853 at rtol 1e-13 is good to ~1e-11, the
    # compiled run at rtol 1e-11 to ~1e-10; 1e-8 bounds both with a margin for the dense output
    inertia = np.array([1.9e-4, 1.9e-4, 2.5e-5])
    mgl = 0.1 * 9.81 * 0.04
    q0 = Rotation.from_euler("x", 20, degrees=True).as_quat()
    Lb = inertia * np.array([0.0, 0.0, 300.0])
    times = np.linspace(0.0, 0.5, 11)
    run = rigid_dop853(inertia, Lb, q0, times, rtol=1e-11, mgl=mgl)
    ref = solve_ivp(lambda t, y: rigid.rigid_rhs(t, y, inertia, mgl=mgl), (0, 0.5), np.concatenate([Lb, q0]),
                    method="DOP853", rtol=1e-13, atol=1e-16, t_eval=times).y.T
    M = np.linalg.norm(Lb)
    assert np.max(np.linalg.norm(run.L - ref[:, :3], axis=1)) / M < 1e-8
    qref = ref[:, 3:] / np.linalg.norm(ref[:, 3:], axis=1)[:, None]
    assert np.max(_angle(run.q, qref)) < 1e-8


def test_space_torque_gives_linear_growth_of_space_momentum():
    # dL_space/dt = N for a torque constant in space axes, whatever the body does
    N = np.array([0.3, -0.2, 0.5])
    times = np.linspace(0.0, 5.0, 6)
    run = rigid_dop853(I, L0, Q0, times, rtol=1e-12, torque=N, torque_frame="space")
    L_space = Rotation.from_quat(run.q).apply(run.L)
    expected = Rotation.from_quat(Q0).apply(L0) + times[:, None] * N
    assert np.max(np.abs(L_space - expected)) < 1e-9 * np.linalg.norm(expected, axis=1).max()


@pytest.mark.parametrize("times", [[1.0, 0.5], [], [[0.0, 1.0]]])
def test_bad_times_are_refused(times):
    with pytest.raises(ScenarioError, match="times"):
        rigid_dop853(I, L0, Q0, np.asarray(times, dtype=float))


def test_bad_torque_frame_is_refused():
    with pytest.raises(ScenarioError, match="torque_frame"):
        rigid_dop853(I, L0, Q0, [0.0, 1.0], torque=[0, 0, 1.0], torque_frame="world")


def test_dense_output_tables_are_those_scipy_ships():
    # the dense-output stages and weights are typed out in rotframe.numerics.dop853_dense (so that a run
    # does not import scipy.integrate); scipy's solve_ivp ships the same published dop853.f constants,
    # an independent transcription: equal to the last bit
    from scipy.integrate._ivp import dop853_coefficients as d

    from rotframe.numerics.dop853_dense import dense_tables

    A_extra, D = dense_tables()
    assert np.array_equal(A_extra, d.A[13:16]) and np.array_equal(D, d.D)

