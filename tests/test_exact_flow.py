"""Method ``exact`` on its two kinds of model, and its prepared run.

- Force-free particles (only the frame's own terms) under a varying rotation rate:
  checked against scipy's DOP853 at rtol 1e-12 on the rotating-frame equations of
  motion written out here (a different integrator, a different code path), and
  against a conserved quantity (the inertial speed).
- The turned angle against a quadrature of the rate.
- ``PreparedRun(method="exact")`` against ``integrate_particles(method="exact")``,
  for linear and force-free models (the same matrices, grouped differently:
  round-off), and its errors.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rotframe.errors import IntegrationError, ScenarioError
from rotframe.particles.integrators import Event, integrate_particles
from rotframe.particles.linear import turned_angle
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.particles.prepared import PreparedRun

AXIS = np.array([0.3, -0.2, 1.0]) / np.linalg.norm([0.3, -0.2, 1.0])
#: A spin-up and spin-down about a tilted axis; the nodes start before t = 0 (the angle counts from 0).
SCHEDULE = OmegaSchedule.table(AXIS, [-1.0, 2.0, 5.0], [0.5, 1.5, -0.7])


def _free(schedule=SCHEDULE):
    return ParticleModel(("coriolis", "centrifugal", "euler"), omega=schedule)


def _reference(schedule, r0, v0, times):
    """scipy DOP853 at rtol 1e-12 on a = -2 w x v - w x (w x r) - w' x r (written out here), node to node."""
    def rate(t):
        return float(np.interp(t, schedule.times, schedule.values))

    def slope(t):
        k = np.searchsorted(schedule.times, t, side="right") - 1
        if k < 0 or k >= len(schedule.times) - 1:
            return 0.0
        return (schedule.values[k + 1] - schedule.values[k]) / (schedule.times[k + 1] - schedule.times[k])

    def rhs(t, y):
        w, wd = rate(t) * AXIS, slope(t) * AXIS
        r, v = y[:3], y[3:]
        a = -2 * np.cross(w, v) - np.cross(w, np.cross(w, r)) - np.cross(wd, r)
        return np.concatenate([v, a])

    # integrate between the kinks of the rate so that each piece is smooth
    cuts = sorted({0.0, float(times[-1]), *[t for t in schedule.times if 0 < t < times[-1]]})
    y, out, k = np.concatenate([r0, v0]), [], 0
    for a, b in zip(cuts[:-1], cuts[1:]):
        inside = [t for t in times if a <= t <= b]
        sol = solve_ivp(rhs, (a, b), y, method="DOP853", rtol=1e-12, atol=1e-12, t_eval=inside, dense_output=False)
        for j, t in enumerate(sol.t):
            if k < len(times) and t == times[k]:
                out.append(sol.y[:, j])
                k += 1
        y = sol.y[:, -1] if sol.t[-1] == b else solve_ivp(rhs, (a, b), y, method="DOP853", rtol=1e-12,
                                                           atol=1e-12).y[:, -1]
    return np.array(out)


def test_force_free_exact_flow_matches_an_independent_integrator():
    """Spin-up then spin-down about a tilted axis over 8 s (about 6 rad turned): the exact flow
    and scipy's DOP853 (rtol 1e-12; its own error after ~300 steps ~1e-11 of the state) agree
    to 1e-9 of the motion's size. A sign error in the rotation or in w(0) x r0 is off by O(1)."""
    r0, v0 = np.array([2.0, 0.3, -0.1]), np.array([-1.0, 0.4, 0.2])
    traj = integrate_particles(_free(), r0, v0, 8.0, method="exact", samples=16)
    ref = _reference(SCHEDULE, r0, v0, traj.times)
    scale = np.max(np.abs(ref))
    assert np.max(np.abs(traj.r[:, 0] - ref[:, :3])) < 1e-9 * scale
    assert np.max(np.abs(traj.v[:, 0] - ref[:, 3:])) < 1e-9 * scale


def test_force_free_exact_flow_keeps_the_inertial_speed():
    """|v + w x r| is the inertial speed, constant for a free particle: to round-off (1e-13 relative)."""
    r0, v0 = np.array([[2.0, 0.0, 0.0], [0.1, -0.5, 0.3]]), np.array([[-1.0, 0.0, 0.0], [0.2, 0.2, -0.1]])
    traj = integrate_particles(_free(), r0, v0, 20.0, method="exact", samples=400)
    w = np.interp(traj.times, SCHEDULE.times, SCHEDULE.values)[:, None, None] * AXIS
    speed = np.linalg.norm(traj.v + np.cross(w, traj.r), axis=2)
    assert np.max(np.abs(speed / speed[0] - 1)) < 1e-13


def test_turned_angle_is_the_integral_of_the_rate():
    """Against the trapezoid rule through the nodes, exact for a piecewise-linear rate (to 1e-13)."""
    times = np.linspace(-2.0, 8.0, 23)
    expected = []
    for t in times:
        lo, hi = min(0.0, t), max(0.0, t)
        grid = np.unique(np.concatenate([[lo, hi], SCHEDULE.times[(SCHEDULE.times > lo) & (SCHEDULE.times < hi)]]))
        w = np.interp(grid, SCHEDULE.times, SCHEDULE.values)
        expected.append(math.copysign(1.0, t) * float(np.sum(0.5 * np.diff(grid) * (w[1:] + w[:-1]))))
    assert turned_angle(SCHEDULE, times) == pytest.approx(expected, rel=1e-13, abs=1e-13)


def test_steady_force_free_model_is_linear_and_euler_may_be_named():
    steady = OmegaSchedule.constant([0.0, 0.0, 2.0])
    assert ParticleModel(("coriolis", "centrifugal"), omega=steady).is_linear
    assert ParticleModel(("coriolis", "centrifugal", "euler"), omega=steady).has_exact_flow
    assert _free().is_force_free and not _free().is_linear
    # a missing frame term, or any force, leaves no exact flow under a varying rate
    assert not ParticleModel(("coriolis", "centrifugal"), omega=SCHEDULE).has_exact_flow
    assert not ParticleModel(("gravity", "coriolis", "centrifugal", "euler"), omega=SCHEDULE,
                             g=np.array([0.0, 0.0, -9.81])).has_exact_flow


def test_exact_is_refused_where_there_is_no_exact_flow():
    model = ParticleModel(("coriolis", "centrifugal"), omega=SCHEDULE)  # Euler's term missing
    with pytest.raises(ScenarioError, match="method: 'exact'.*omega varies"):
        integrate_particles(model, np.ones(3), np.zeros(3), 1.0, method="exact")


def test_events_on_the_force_free_flow_are_refused_with_the_event_named():
    with pytest.raises(ScenarioError, match="event 'wall'.*dop853"):
        integrate_particles(_free(), np.ones(3), np.zeros(3), 1.0, method="exact",
                            events=[Event("wall", "r", 0, 5.0)])


def _linear():
    return ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant([0.0, 4.6e-5, 5.7e-5]),
                         g=np.array([0.0, 0.0, -9.81]))


@pytest.mark.parametrize("model", [_linear(), _free()], ids=["linear", "force-free"])
@pytest.mark.parametrize("samples", [1, 7, 200])
@pytest.mark.parametrize("n", [1, 3])
def test_prepared_exact_equals_integrate_particles_to_round_off(model, samples, n):
    """The same matrices, multiplied in another grouping: a few ulps of the state's scale."""
    rng = np.random.default_rng(7)
    r0, v0 = rng.normal(size=(n, 3)) * 100, rng.normal(size=(n, 3))
    run = PreparedRun(model, "exact", 5.0, samples=samples, n=n)
    for _ in range(2):  # the kept matrices give the same answer every call
        r, v = run(r0, v0)
        traj = integrate_particles(model, r0, v0, 5.0, method="exact", samples=samples)
        assert np.array_equal(run.times, traj.times)
        scale = max(np.max(np.abs(traj.r)), np.max(np.abs(traj.v)))
        assert np.max(np.abs(r - traj.r)) <= 1e-14 * scale
        assert np.max(np.abs(v - traj.v)) <= 1e-14 * scale


def test_prepared_exact_overflow_raises_integration_error():
    """An anti-spring a = +1e4 r overflows after ~7 s: a non-finite state is an error, never returned."""
    run = PreparedRun(ParticleModel(("spring",), spring=-1e4), "exact", 100.0, samples=100)
    with pytest.raises(IntegrationError, match="non-finite"):
        run(np.array([1.0, 0.0, 0.0]), np.zeros(3))


@pytest.mark.parametrize("rate", [7.3e-5, 0.3, 2.0])  # 2 |w| t = 7e-4 (the series), 3, 20 over 5 s
def test_coriolis_closed_form_matches_scipy_and_the_exact_linear_flow(rate):
    """analytic.coriolis_uniform_gravity (sines, no matrix exponential) against scipy DOP853 at rtol
    1e-13 (its error over 5 s ~1e-12 of the state) and against rotframe's exact linear flow (expm):
    three independent routes agree to 1e-11 of the state's scale."""
    from rotframe.analytic import coriolis_uniform_gravity

    rng = np.random.default_rng(11)
    w = rng.normal(size=3)
    w *= rate / np.linalg.norm(w)
    g, r0, v0 = rng.normal(size=3) * 5, rng.normal(size=3), rng.normal(size=3)
    T = 5.0
    r, v = coriolis_uniform_gravity(w, g, r0, v0, T)
    sol = solve_ivp(lambda t, y: np.concatenate([y[3:], g - 2 * np.cross(w, y[3:])]), (0, T),
                    np.concatenate([r0, v0]), method="DOP853", rtol=1e-13, atol=1e-13)
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=g)
    traj = integrate_particles(model, r0, v0, T, method="exact", samples=1)
    scale = max(np.max(np.abs(r)), np.max(np.abs(v)))
    for other_r, other_v in ((sol.y[:3, -1], sol.y[3:, -1]), (traj.r[-1, 0], traj.v[-1, 0])):
        assert np.max(np.abs(r - other_r)) < 1e-11 * scale
        assert np.max(np.abs(v - other_v)) < 1e-11 * scale


def test_coriolis_closed_form_gives_the_classic_eastward_deflection():
    """A drop from rest at small |w| t: east = (1/3) w g t^3 cos(latitude), to relative order (w t)^2."""
    from rotframe.analytic import coriolis_uniform_gravity

    lat, rate, g, t = math.radians(50.9), 7.292115e-5, 9.81, 5.0
    w = rate * np.array([0.0, math.cos(lat), math.sin(lat)])
    r, _ = coriolis_uniform_gravity(w, [0.0, 0.0, -g], np.zeros(3), np.zeros(3), t)
    assert r[0] == pytest.approx(rate * g * t**3 * math.cos(lat) / 3, rel=1e-6)


def test_prepared_exact_refuses_a_state_of_the_wrong_shape():
    run = PreparedRun(_linear(), "exact", 1.0, n=2)
    with pytest.raises(ScenarioError, match=r"r0 and v0 must be \(3,\) or \(2, 3\)"):
        run(np.zeros((3, 3)), np.zeros((3, 3)))
