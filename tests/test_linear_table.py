"""A frame whose rate is given as a piecewise-linear table: ``omega=(times, vectors, "linear")``.

The oracle is inertial space: a free particle moves on a straight line there, and the frame's angle
about its fixed axis is the integral of a piecewise-linear rate, a sum of trapezoids, exact. The
particle seen from the frame is that line turned back by the angle. A cubic spline through the same
knots (the default form of a table) rounds the ramp's corner off and misses the line by far more
than the tolerance: the test tells the two forms apart.
"""

from __future__ import annotations

import numpy as np
import pytest

import rotframe
from rotframe.errors import ScenarioError
from rotframe.problem.frame import frame_spec
from rotframe.problem.particles import simulate_particles

KNOTS = np.array([0.0, 2.0, 5.0, 6.0, 9.0])
RATES = np.array([0.0, 1.2, 1.2, -0.4, 0.3])  # rad/s about z: a ramp up, a plateau, a reversal, a ramp


def angle(t):
    """The frame's angle at t: the integral of the piecewise-linear rate, interval by interval (trapezoids)."""
    total = 0.0
    for k in range(KNOTS.size - 1):
        a, b = KNOTS[k], KNOTS[k + 1]
        if t <= a:
            break
        end = min(t, b)
        w_end = RATES[k] + (RATES[k + 1] - RATES[k]) * (end - a) / (b - a)
        total += 0.5 * (RATES[k] + w_end) * (end - a)
    return total


def seen_from_the_frame(r0, v0, times):
    """The free particle from (r0, v0) (frame axes, t = 0, where the frame's angle is 0) seen from the frame."""
    w0 = np.array([0.0, 0.0, RATES[0]])
    v_inertial = v0 + np.cross(w0, r0)
    out = []
    for t in times:
        x = r0 + v_inertial * t
        c, s = np.cos(angle(t)), np.sin(angle(t))
        out.append([c * x[0] + s * x[1], -s * x[0] + c * x[1], x[2]])
    return np.array(out)


def table(how=None):
    vectors = np.column_stack([np.zeros_like(RATES), np.zeros_like(RATES), RATES])
    return (KNOTS, vectors) if how is None else (KNOTS, vectors, how)


def test_the_table_is_its_straight_lines_and_their_slopes():
    spec = frame_spec(table("linear"))
    t = np.linspace(0.0, 9.0, 181)
    w, wd = spec.vector_at(t)
    np.testing.assert_allclose(w[:, 2], np.interp(t, KNOTS, RATES), rtol=0, atol=1e-15)
    inside = np.searchsorted(KNOTS, t, side="right") - 1
    inside = np.clip(inside, 0, KNOTS.size - 2)
    slopes = np.diff(RATES) / np.diff(KNOTS)
    np.testing.assert_allclose(wd[:, 2], slopes[inside], rtol=0, atol=1e-15)
    assert np.all(w[:, :2] == 0.0) and np.all(wd[:, :2] == 0.0)


@pytest.mark.parametrize("method, settings, tol", [("dop853", {"rtol": 1e-12}, 1e-9),
                                                   ("rk4", {"step": 1e-3}, 1e-8)])
def test_a_free_particle_is_the_inertial_line_turned_back(method, settings, tol):
    """Coriolis, centrifugal and the Euler force of a rate that ramps, plateaus and reverses: the exact line."""
    r0, v0 = np.array([1.0, -0.5, 0.2]), np.array([0.3, 0.8, -0.1])
    run = simulate_particles(omega=table("linear"), r0=r0, v0=v0, duration=9.0, samples=90, method=method,
                             **settings).trajectory
    expected = seen_from_the_frame(r0, v0, run.times)
    scale = np.max(np.abs(expected))
    assert np.max(np.abs(run.r[:, 0] - expected)) < tol * scale
    spline = simulate_particles(omega=table(), r0=r0, v0=v0, duration=9.0, samples=90, method=method,
                                **settings).trajectory
    assert np.max(np.abs(spline.r[:, 0] - expected)) > 1e-3 * scale  # the spline's rate is another rate


def test_the_public_door_converts_a_linear_table_and_refuses_another_form():
    import astropy.units as u

    res = rotframe.simulate(omega=(KNOTS / 60.0 * u.min, table()[1] * u.rad / u.s, "linear"), r0=[1.0, 0.0, 0.0],
                            v0=[0.0, 0.0, 0.0], duration=9.0 * u.s, samples=9)
    plain = simulate_particles(omega=table("linear"), r0=[1.0, 0.0, 0.0], v0=[0.0, 0.0, 0.0], duration=9.0,
                               samples=9).trajectory
    np.testing.assert_allclose(res.trajectory.r[:, 0], plain.r[:, 0], rtol=1e-12, atol=1e-12)
    with pytest.raises(ScenarioError, match="interpolation 'spline'; allowed: 'cubic', 'linear'"):
        rotframe.simulate(omega=table("spline"), r0=[1.0, 0.0, 0.0], v0=[0.0, 0.0, 0.0], duration=9.0)


def test_the_exact_flow_in_a_turning_frame_is_the_inertial_line():
    """``method="exact"``: a particle under the frame's terms alone in a frame turning about one axis at a
    piecewise-linear rate (here a tilted axis, not a coordinate one) is the inertial line turned back, to round-off."""
    axis = np.array([0.3, -0.4, 0.866])
    axis = axis / np.linalg.norm(axis)
    r0, v0 = np.array([1.0, -0.5, 0.2]), np.array([0.3, 0.8, -0.1])
    run = simulate_particles(omega=(KNOTS, RATES[:, None] * axis, "linear"), r0=r0, v0=v0, duration=9.0, samples=90,
                             method="exact").trajectory
    # the oracle about z, turned: the same motion in axes where the rotation axis is z
    e3 = axis
    e1 = np.cross([0.0, 1.0, 0.0], e3)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(e3, e1)
    R = np.array([e1, e2, e3])  # rows: the axes of the z frame in the given frame's components
    expected = seen_from_the_frame(R @ r0, R @ v0, run.times) @ R
    assert np.max(np.abs(run.r[:, 0] - expected)) < 1e-13 * np.max(np.abs(expected))


@pytest.mark.parametrize("change, names", [
    (dict(forces=[rotframe.forces.gravity([0.0, 0.0, -9.8])]), "forces[0]"),
    (dict(frame_terms=("coriolis", "centrifugal")), "frame_terms="),
    (dict(omega=(KNOTS, np.column_stack([RATES, 0.0 * RATES, 0.0 * RATES + 0.1]), "linear")), "off the axis"),
    (dict(omega=table()), "(times, vectors, 'linear')"),
])
def test_what_the_exact_flow_of_a_turning_frame_refuses(change, names):
    kw = dict(omega=table("linear"), r0=[1.0, -0.5, 0.2], v0=[0.3, 0.8, -0.1], duration=9.0, method="exact")
    kw.update(change)
    with pytest.raises(ScenarioError) as refused:
        rotframe.simulate(**kw)
    assert names in str(refused.value) and "use dop853" in str(refused.value) and "\n" not in str(refused.value)
