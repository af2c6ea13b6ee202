"""The turntable scene, built on the engine of your own problems, against inertial space's straight line.

The scene chooses its frame (a constant spin, or the rate's two knots joined linearly, which is
the spin-up ``w0 + alpha t`` exactly) and its terms (the frame's) and hands them to
`rotframe.problem.particles.simulate_particles`. The oracle is independent of the engine: the
puck is force-free, so it moves on a straight line in inertial space, turned into the table's
frame by the rate's exact integral (`rotframe.analytic.turntable_inertial_line`, a closed form).
Under every method the scene's samples, positions and velocities, are within the method's error
of it: round-off for ``exact``, DOP853's tolerance, and ``C (w h)^p`` for a fixed step ``h`` of
order ``p``; halving the step divides the error by ``2^p`` (the order is the method's, in the
positions and in the last sample's velocity).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rotframe
from rotframe import method_registry

W0, ALPHA, T = 1.0, 0.2, 4.0
R0, SPEED = 2.0, 1.0


def _oracle(times):
    """(r, v) of the exact motion in the table's frame at ``times``: the inertial line turned by -theta(t)."""
    theta = W0 * times + 0.5 * ALPHA * times**2
    w = W0 + ALPHA * times
    # inertial: x = R0 - SPEED t, y = W0 R0 t (the table's speed at the start), z = 0
    x, y = R0 - SPEED * times, W0 * R0 * times
    c, s = np.cos(theta), np.sin(theta)
    r = np.stack([c * x + s * y, -s * x + c * y, 0 * times], axis=1)
    vx, vy = -SPEED + 0 * times, W0 * R0 + 0 * times
    v_in = np.stack([c * vx + s * vy, -s * vx + c * vy, 0 * times], axis=1)
    v = v_in - np.cross(np.stack([0 * w, 0 * w, w], axis=1), r)  # v_rot = v_in - w x r, in the table's axes
    return r, v


def _run(method, **settings):
    res = rotframe.run("turntable", method=method, omega0=W0, alpha=ALPHA, duration=T, speed=SPEED,
                       start_radius=R0, samples=40, **settings)
    traj = res.trajectory
    r, v = _oracle(traj.times)
    return res, np.max(np.abs(traj.r[:, 0] - r)), np.max(np.abs(traj.v[:, 0] - v))


def test_the_default_is_the_exact_flow_to_round_off():
    res, dr, dv = _run(None)
    assert res.method == "exact"
    assert dr < 1e-13 and dv < 1e-13
    assert res.metrics["position_error_m"] < 1e-13


@pytest.mark.parametrize("method", ["rotation-splitting", "rotation-splitting4", "rk4"])
def test_a_fixed_step_method_converges_at_its_order(method):
    order = method_registry.get(method).order
    w_max = W0 + ALPHA * T
    errors = []
    for h in (0.02, 0.01):
        res, dr, dv = _run(method, step=h)
        assert res.method == method
        bound = 10.0 * (w_max * h) ** order * (R0 + 3 * SPEED * T)
        assert dr < bound and dv < bound * w_max, (h, dr, dv, bound)
        errors.append((dr, dv))
    for k in (0, 1):  # halving the step divides the error by 2^p (within a factor 1.5 of it)
        ratio = errors[0][k] / errors[1][k]
        assert 2 ** order / 1.5 < ratio < 2 ** order * 1.5, (k, ratio)


def test_dop853_is_within_its_tolerance():
    res, dr, dv = _run("dop853", rtol=1e-10)
    assert res.method == "dop853"
    assert dr < 1e-8 and dv < 1e-8


def test_a_steady_table_and_a_term_left_out(tmp_path):
    """A steady spin is a constant omega (every subset of the frame's terms is linear: the exact flow); without
    Coriolis on a spinning-up table there is no exact flow, and the fourth-order splitting runs."""
    res = rotframe.run("turntable", alpha=0.0, samples=10)
    assert res.method == "exact" and res.metrics["position_error_m"] < 1e-13
    assert math.isclose(res.metrics["turns"], W0 * 4.0 / (2 * math.pi), rel_tol=1e-12)
    scn = tmp_path / "tt.toml"
    scn.write_text('scene = "turntable"\nname = "tt"\nmodel = ["centrifugal", "euler"]\n[run]\nstep = 1e-3\n')
    res = rotframe.run(str(scn), samples=10)
    assert res.method == "rotation-splitting4"
    assert res.metrics["position_error_m"] > 1e-3  # the puck without Coriolis leaves the inertial line: no failure,
    assert "position_error_m" not in res.theory and not res.warnings  # and no theory to miss
    assert any("leaves out the frame's coriolis," in note for note in res.notes), res.notes

