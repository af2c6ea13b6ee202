"""Events that start on the zero or happen inside the first step; unstable steps end in IntegrationError.

References: closed forms of a flat vacuum trajectory (no rotation: t = 2 v sin(e) / g
exactly; with Coriolis the flight time changes at first order in Omega by
4 Omega cos(lat) sin(az) v^2 sin(e) cos(e) / g^2 ... so the check with rotation uses
scipy's solve_ivp with its own event location at rtol 1e-13, an independent integrator).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rotframe.errors import IntegrationError
from rotframe.particles.integrators import Event, integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel

METHODS = ("exact", "splitting", "splitting4", "rk4", "dop853")
G = 9.81
GROUND = Event("ground", "r", 2, 0.0, -1, True)


def _vacuum(omega=(0.0, 0.0, 0.0)):
    terms = ("gravity", "coriolis") if any(omega) else ("gravity",)
    return ParticleModel(terms, omega=OmegaSchedule.constant(list(omega)), g=np.array([0.0, 0.0, -G]))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("elevation_deg", [0.001, 0.01, 30.0])
def test_shot_from_the_ground_lands_at_the_closed_form_time(method, elevation_deg):
    """No rotation: flight time 2 v sin(e) / g exactly; the flight may be far shorter than a step.

    Tolerance: the event is located to round-off on each method's own trajectory, and every
    method here is exact for a constant acceleration (a quadratic in t) up to round-off, so
    1e-9 relative (a few hundred ulps of the bisection in time) is ample.
    """
    e = math.radians(elevation_deg)
    v = 100.0
    v0 = np.array([v * math.cos(e), 0.0, v * math.sin(e)])
    flight = 2 * v * math.sin(e) / G
    duration = max(10.0, 2 * flight)  # 1000 samples of >= 10 ms: the grazing shots land inside the first step
    traj = integrate_particles(_vacuum(), np.zeros(3), v0, duration, method=method, samples=1000, events=[GROUND])
    t_hit = traj.event_times["ground"][0]
    assert len(t_hit) == 1, "the shell must land"
    assert t_hit[0] == pytest.approx(flight, rel=1e-9)
    assert traj.event_states["ground"][0][0][0] == pytest.approx(v * math.cos(e) * flight, rel=1e-9)


def _ref_landing(model_omega, v0):
    w = np.array(model_omega)

    def rhs(t, y):
        return np.concatenate([y[3:], np.array([0.0, 0.0, -G]) - 2 * np.cross(w, y[3:])])

    def ground(t, y):
        return y[2]
    ground.terminal, ground.direction = True, -1
    # start just after t = 0 from the exact Taylor step, so that scipy does not stop at z(0) = 0
    t0 = 1e-12
    y0 = np.concatenate([v0 * t0, v0]) + 0.0
    sol = solve_ivp(rhs, (t0, 100.0), y0, method="DOP853", rtol=1e-13, atol=1e-15, events=ground)
    return sol.t_events[0][0], sol.y_events[0][0]


@pytest.mark.parametrize("method", METHODS)
def test_rotating_frame_grazing_shot_matches_solve_ivp(method):
    """With Coriolis (a large Omega to make it visible), against solve_ivp's own event location.

    scipy's error at rtol 1e-13 on a 3.6 ms flight is ~1e-13 relative; the 1e-12 start offset
    changes the time by 1e-12 s (3e-10 relative); so 1e-8 relative.
    """
    omega = (0.0, 0.3, 0.5)
    e = math.radians(0.01)
    v0 = np.array([100 * math.cos(e), 0.0, 100 * math.sin(e)])
    t_ref, y_ref = _ref_landing(omega, v0)
    traj = integrate_particles(_vacuum(omega), np.zeros(3), v0, 10.0, method=method, samples=1000,
                               events=[GROUND])
    assert traj.event_times["ground"][0][0] == pytest.approx(t_ref, rel=1e-8)
    np.testing.assert_allclose(traj.event_states["ground"][0][0][:3], y_ref[:3], rtol=1e-7, atol=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_ensemble_with_a_particle_starting_on_the_ground(method):
    """An ensemble: shots from z = 0 and one from 1 m; each lands once at its closed-form time."""
    v = np.array([[10.0, 0, 1e-3], [10.0, 0, 5.0], [3.0, 0, 2.0]])
    r = np.array([[0.0, 0, 0], [0.0, 0, 0], [0.0, 0, 1.0]])
    traj = integrate_particles(_vacuum(), r, v, 5.0, method=method, samples=50, events=[GROUND])
    for p in range(3):
        vz, z0 = v[p, 2], r[p, 2]
        expected = (vz + math.sqrt(vz * vz + 2 * G * z0)) / G
        assert traj.event_times["ground"][p] == pytest.approx([expected], rel=1e-9)


@pytest.mark.parametrize("method", ("splitting", "dop853"))
def test_curved_ground_event_from_the_ground(method):
    """Altitude event (curved ground) from the surface: a short hop lands at ~2 v_z / g."""
    R = 6.371e6
    model = ParticleModel(("central-gravity",), gm=G * R * R, radius=R)
    ev = Event("ground", "altitude", 2, 0.0, -1, True)
    v0 = np.array([1.0, 0.0, 1.0])
    traj = integrate_particles(model, np.zeros(3), v0, 1.0, method=method, samples=2, events=[ev])
    # flat-ground value 2 v_z / g; the curvature and the turning of g change it by ~v_x^2/(g R) = 2e-8
    # relative; the altitude |r - c| - R carries round-off R eps = 1.4e-9 m on a 5 cm hop (3e-8): 1e-6
    assert traj.event_times["ground"][0] == pytest.approx([2.0 / G], rel=1e-6)


def test_turntable_instability_ends_in_integration_error_with_partial_samples():
    """A free puck on a fast-spinning table with a fixed step that cannot follow it.

    Reference: its inertial motion is a straight line at constant speed, so the inertial speed
    may not grow; the run must stop (IntegrationError) and keep the samples before the failure.
    """
    model = ParticleModel(("coriolis", "centrifugal", "euler"),
                          omega=OmegaSchedule(np.array([0.0, 0.0, 1.0]), np.array([0.0, 2000.0]),
                                              np.array([1.0, 401.0])))
    with pytest.raises(IntegrationError) as exc:
        integrate_particles(model, np.array([2.0, 0, 0]), np.array([-1.0, 0, 0]), 2000.0, method="splitting",
                            step=2e-3, samples=200)
    partial = exc.value.partial
    assert partial is not None and 1 < len(partial.times) < 201
    assert np.all(np.isfinite(partial.r))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("height", [1e-300, 1e-30, 1e-3])
def test_drop_from_a_tiny_height_lands_at_sqrt_2h_over_g(method, height):
    """A crossing far below the step: bisection/Newton must go down to round-off of tau itself.

    Closed form t = sqrt(2 h / g) (no rotation); every method is exact for constant gravity
    up to round-off, so 1e-9 relative. (A fixed 60 halvings of the step stopped at 1e-21 s.)
    """
    traj = integrate_particles(_vacuum(), np.array([0.0, 0.0, height]), np.zeros(3), 1.0, method=method,
                               samples=10, events=[GROUND])
    assert traj.event_times["ground"][0] == pytest.approx([math.sqrt(2 * height / G)], rel=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_overflow_ends_in_integration_error_with_finite_partial_samples(method):
    """An anti-spring a = +1e4 r grows like e^(100 t) and overflows after ~7 s: every method must
    raise IntegrationError and keep only finite samples (never write inf into a recording)."""
    model = ParticleModel(("spring",), spring=-1e4)
    with pytest.raises(IntegrationError) as exc:
        integrate_particles(model, [1.0, 0, 0], [0.0, 0, 0], 100.0, method=method, samples=100)
    partial = exc.value.partial
    assert partial is not None and 1 <= len(partial.times) < 101
    assert np.all(np.isfinite(partial.r)) and np.all(np.isfinite(partial.v))
