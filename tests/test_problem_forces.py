"""The built-in forces as user forces (rotframe.problem.forces) against the scenes' compiled kernels.

The oracle is the particle core's own model terms (``integrate_particles`` with a
``ParticleModel``): a different implementation of the same physics (flags in a packed model,
compiled kernels) than the closures of ``rotframe.problem.forces`` run by the generated
driver. Both run DOP853 at rtol 1e-12; they must agree to the tolerance, not to round-off.
"""

from __future__ import annotations

import numpy as np
import pytest

from rotframe.errors import ScenarioError
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.problem import forces
from rotframe.problem.particles import simulate_particles

W = np.array([0.0, 4.6e-5, 5.7e-5])
RTOL = 1e-12


def _both(model_kw, terms, user_forces, r0, v0, T):
    model = ParticleModel(terms, omega=OmegaSchedule.constant(W), **model_kw)
    ref = integrate_particles(model, r0, v0, T, method="dop853", rtol=RTOL, samples=20)
    ours = simulate_particles(omega=W, r0=r0, v0=v0, duration=T, forces=user_forces, rtol=RTOL, samples=20)
    return ref, ours.trajectory


def test_gravity_drag_and_spring_match_the_model_terms():
    g = np.array([0.0, 0.0, -9.81])
    ref, ours = _both(dict(g=g, k_quadratic=4e-5, scale_height=8000.0, spring=0.04),
                      ("gravity", "quadratic-drag", "spring", "coriolis", "centrifugal"),
                      [forces.uniform_gravity(g), forces.quadratic_drag(4e-5, 8000.0), forces.horizontal_spring(0.04)],
                      [10.0, -5.0, 2000.0], [50.0, 20.0, 10.0], 20.0)
    scale = np.max(np.abs(ref.r))
    assert np.max(np.abs(ours.r - ref.r)) < 1e-9 * scale
    assert np.max(np.abs(ours.v - ref.v)) < 1e-9 * np.max(np.abs(ref.v))


def test_central_gravity_and_linear_drag_match_the_model_terms():
    R, GM = 6.371e6, 3.986004418e14
    ref, ours = _both(dict(radius=R, gm=GM, k_linear=1e-3), ("central-gravity", "linear-drag", "coriolis",
                                                              "centrifugal"),
                      [forces.central_gravity(GM, [0.0, 0.0, -R]), forces.linear_drag(1e-3)],
                      [0.0, 0.0, 1.0e5], [1500.0, 0.0, 500.0], 120.0)
    assert np.max(np.abs(ours.r - ref.r)) < 1e-9 * np.max(np.abs(ref.r))


def test_altitude_gravity_matches_the_model_term():
    R, g0 = 6.371e6, 9.80665
    ref, ours = _both(dict(radius=R, g0=g0), ("altitude-gravity", "coriolis", "centrifugal"),
                      [forces.altitude_gravity(g0, R)], [0.0, 0.0, 3.0e4], [200.0, 0.0, 0.0], 60.0)
    assert np.max(np.abs(ours.r - ref.r)) < 1e-9 * np.max(np.abs(ref.r))


def test_energy_of_gravity_and_spring_is_conserved_in_an_inertial_frame():
    run = simulate_particles(omega=[0.0, 0.0, 0.0], r0=[1.0, 0.0, 5.0], v0=[0.0, 1.0, 0.0], duration=30.0,
                             forces=[forces.uniform_gravity([0, 0, -9.81]), forces.horizontal_spring(1.0)],
                             rtol=1e-12, samples=50)
    assert run.diagnostics["energy_rel_drift"] < 1e-10


def test_lorentz_force_gyrates_at_the_cyclotron_radius():
    qm, B, speed = 2.0, 0.5, 3.0
    run = simulate_particles(omega=[0.0, 0.0, 0.0], r0=[speed / (qm * B), 0.0, 0.0], v0=[0.0, -speed, 0.0],
                             duration=10.0, forces=[forces.lorentz(qm, [0.0, 0.0, B])], rtol=1e-12, samples=200)
    radius = np.linalg.norm(run.trajectory.r[:, 0, :2], axis=1)
    assert np.max(np.abs(radius - speed / (qm * B))) < 1e-9


def _charged_particle(qm, B, E, r0, v0, t):
    """Closed form of a' = qm (E + v x B), uniform fields: free fall along B at qm E_par, gyration at
    qm |B| about the E x B drift across it (written out here, independent of rotframe)."""
    B, E, r0, v0 = (np.asarray(a, dtype=float) for a in (B, E, r0, v0))
    b = B / np.linalg.norm(B)
    omega = qm * np.linalg.norm(B)
    e_par = (E @ b) * b
    drift = np.cross(E, B) / (B @ B)
    v_par = (v0 @ b) * b
    u0 = v0 - v_par - drift  # the gyrating part: du/dt = qm u x B = -omega b x u
    c, s = np.cos(omega * t), np.sin(omega * t)
    u = u0 * c - np.cross(b, u0) * s
    v = v_par + qm * e_par * t + drift + u
    r = r0 + (v_par + drift) * t + 0.5 * qm * e_par * t * t + (u0 * s + np.cross(b, u0) * (c - 1.0)) / omega
    return r, v


def test_lorentz_force_in_oblique_fields_drifts_at_e_cross_b():
    """B oblique to every axis and E with parts along and across it: the closed form catches a
    flipped sign, a swapped component or a dropped E (the B along z test alone would not)."""
    qm, B, E = 1.5, [0.3, -0.4, 0.5], [0.2, 0.1, -0.3]
    r0, v0, T = [1.0, -2.0, 0.5], [0.7, 0.4, -0.2], 12.0
    run = simulate_particles(omega=[0.0, 0.0, 0.0], r0=r0, v0=v0, duration=T, forces=[forces.lorentz(qm, B, E)],
                             rtol=1e-12, samples=40)
    r, v = _charged_particle(qm, B, E, r0, v0, T)
    assert np.linalg.norm(np.cross(E, B)) > 0.1  # a real drift
    assert np.max(np.abs(run.trajectory.r[-1, 0] - r)) < 1e-9 * max(1.0, np.max(np.abs(r)))
    assert np.max(np.abs(run.trajectory.v[-1, 0] - v)) < 1e-9 * max(1.0, np.max(np.abs(v)))


def test_bad_constants_are_refused_in_one_line():
    with pytest.raises(ScenarioError, match="altitude_gravity: radius"):
        forces.altitude_gravity(9.81, 0.0)
    with pytest.raises(ScenarioError, match="uniform_gravity"):
        forces.uniform_gravity([0.0, np.nan, 1.0])
