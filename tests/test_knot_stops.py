"""Tables and body frames keep their accuracy at their knots (issue 33, class 4).

The right-hand side is smooth between the knots of an omega table (a C2 spline) or the samples of
a body frame (a Hermite interpolant) only. The drivers end a step on every knot; without that a
finer table gave a larger error. Oracles: scipy's DOP853 integrating knot interval by knot
interval with scipy's own spline, and for the body frame one coupled solve of Euler's equations
with the particle (no interpolation at all).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

import rotframe

R0, V0, T = np.array([1.0, 0.5, 0.2]), np.array([0.1, -0.3, 0.2]), 10.0


def rate_table(n):
    t = np.linspace(0.0, T, n)
    w = np.stack([0.3 * np.sin(0.7 * t), 0.2 * np.cos(1.3 * t), 1.0 + 0.5 * np.sin(0.9 * t)], axis=1)
    return t, w


def origin_table(n):
    t = np.linspace(0.0, T, n)
    return t, np.stack([0.05 * np.cos(t), 0.02 * t, 0.01 * np.sin(2 * t)], axis=1)


def piecewise_oracle(omega, origin=None):
    """scipy's DOP853, restarted at every knot, on scipy's splits of the same tables."""
    w = CubicSpline(*omega, axis=0, bc_type="not-a-knot")
    wd = w.derivative()
    a0 = CubicSpline(*origin, axis=0, bc_type="not-a-knot") if origin is not None else (lambda t: np.zeros(3))

    def f(t, y):
        r, v = y[:3], y[3:]
        W, Wd = w(t), wd(t)
        acc = -2 * np.cross(W, v) - np.cross(W, np.cross(W, r)) - np.cross(Wd, r) - a0(t)
        return np.concatenate([v, acc])

    knots = np.unique(np.concatenate([omega[0]] + ([origin[0]] if origin is not None else [])))
    y = np.concatenate([R0, V0])
    for a, b in zip(knots[:-1], knots[1:]):
        y = solve_ivp(f, (a, b), y, method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
    return y[:3]


@pytest.mark.parametrize("knots", [301, 1201])
def test_an_omega_table_keeps_dop853_at_its_tolerance(knots):
    omega = rate_table(knots)
    res = rotframe.simulate(omega=omega, r0=R0, v0=V0, duration=T, rtol=1e-12, samples=10)
    err = np.max(np.abs(res.trajectory.r[-1, 0] - piecewise_oracle(omega)))
    assert err < 1e-10, err  # 2.6e-8 (301 knots) and 9.1e-8 (1201) before the stops; 4e-14 and 5e-15 with them


def test_an_origin_table_with_other_knots_is_stopped_at_too():
    omega, origin = rate_table(101), origin_table(77)
    res = rotframe.simulate(omega=omega, origin_acceleration=origin, r0=R0, v0=V0, duration=T, rtol=1e-12,
                            samples=10)
    err = np.max(np.abs(res.trajectory.r[-1, 0] - piecewise_oracle(omega, origin)))
    assert err < 1e-10, err


def test_rk4_across_knots_keeps_order_four():
    omega = rate_table(41)
    ref = piecewise_oracle(omega)
    errors = []
    for step in (0.037, 0.0185):  # not a divisor of the knot spacing 0.25 s: steps are cut at the knots
        res = rotframe.simulate(omega=omega, r0=R0, v0=V0, duration=T, method="rk4", step=step, samples=10)
        errors.append(np.max(np.abs(res.trajectory.r[-1, 0] - ref)))
    assert errors[0] / errors[1] > 12.0, errors  # 2^4 = 16 for order 4


I_BODY = np.array([1.0, 2.0, 3.0])
L_BODY = np.array([0.3, 2.0, 0.4])
T_BODY = 4.0
R_B, V_B = np.array([0.5, 0.2, -0.1]), np.array([0.0, 0.3, 0.1])


def body_torque(t, L, q):
    return 0.2 * np.sin(3 * t), 0.1, -0.15 * np.cos(2 * t)


def coupled_oracle():
    """Euler's equations and the particle in the body's axes, one solve: omega and omega' exact at every t."""

    def f(t, y):
        L, r, v = y[:3], y[3:6], y[6:9]
        w = L / I_BODY
        Ld = np.cross(L, w) + np.array(body_torque(t, L, None))
        wd = Ld / I_BODY
        acc = -2 * np.cross(w, v) - np.cross(w, np.cross(w, r)) - np.cross(wd, r)
        return np.concatenate([Ld, v, acc])

    y0 = np.concatenate([L_BODY, R_B, V_B])
    return solve_ivp(f, (0, T_BODY), y0, method="DOP853", rtol=1e-13, atol=1e-15).y[3:6, -1]


@pytest.fixture(scope="module")
def body_reference():
    return coupled_oracle()


def _in_body_frame(per_second):
    body = rotframe.simulate_body(inertia=I_BODY, L0=L_BODY, q0=[0, 0, 0, 1], duration=T_BODY, torque=body_torque,
                                  samples=int(per_second * T_BODY), rtol=1e-13)
    return rotframe.simulate(omega=body, r0=R_B, v0=V_B, duration=T_BODY, rtol=1e-12, samples=8)


def test_a_torqued_body_frame_converges_with_its_samples(body_reference):
    errors = [np.max(np.abs(_in_body_frame(k).trajectory.r[-1, 0] - body_reference)) for k in (100, 200, 400)]
    # before the stops: 3.6e-9, 5.4e-10, 1.0e-9 (no convergence); with them order 4 in the sample interval
    assert errors[0] / errors[1] > 8.0 and errors[1] / errors[2] > 8.0, errors
    assert errors[2] < 1e-12 * 10, errors


def test_a_body_frame_too_coarse_for_rtol_warns_with_a_true_estimate(body_reference):
    res = _in_body_frame(50)
    err = np.max(np.abs(res.trajectory.r[-1, 0] - body_reference)) / np.max(np.abs(res.trajectory.r))
    estimate = res.diagnostics["frame_interpolation_rel_error"]
    assert err / 10 < estimate < err * 10, (err, estimate)
    assert any("body frame's samples limit the accuracy" in w for w in res.warnings)
    fine = _in_body_frame(400)
    assert not fine.warnings, fine.warnings
