"""The built-in terms (``rotframe.forces``): against the scenes' kernels, closed forms, and a user's force.

Three oracles:
- the particle core's own model terms (``integrate_particles`` with a ``ParticleModel``): the
  same arithmetic for each term (`rotframe.particles.accelerations`, whose formulas
  ``tests/test_accelerations.py`` checks against independent ones), but summed another way (flags
  in a packed model, the frame's terms about a fixed axis) than the closures of
  ``rotframe.forces`` run by the engine (the frame's terms as vectors). Both run DOP853 at rtol
  1e-12; they must agree to the tolerance, not to round-off;
- closed forms: the charged particle's gyration and drift, the large-amplitude pendulum's
  period (a complete elliptic integral), a Foucault plane turning at Omega sin(lat);
- a force of the user's doing the same arithmetic: the same trajectory to the last bit,
  under every method that takes both (one route into one driver).
"""

from __future__ import annotations

import numpy as np
import pytest

from rotframe.errors import ScenarioError
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe import forces
from rotframe.problem.particles import Force, simulate_particles

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
                      [forces.gravity(g), forces.drag(quadratic=4e-5, scale_height=8000.0), forces.spring(0.04, horizontal=True)],
                      [10.0, -5.0, 2000.0], [50.0, 20.0, 10.0], 20.0)
    scale = np.max(np.abs(ref.r))
    assert np.max(np.abs(ours.r - ref.r)) < 1e-9 * scale
    assert np.max(np.abs(ours.v - ref.v)) < 1e-9 * np.max(np.abs(ref.v))


def test_central_gravity_and_linear_drag_match_the_model_terms():
    R, GM = 6.371e6, 3.986004418e14
    ref, ours = _both(dict(radius=R, gm=GM, k_linear=1e-3), ("central-gravity", "linear-drag", "coriolis",
                                                              "centrifugal"),
                      [forces.central_gravity(GM, [0.0, 0.0, -R]), forces.drag(linear=1e-3)],
                      [0.0, 0.0, 1.0e5], [1500.0, 0.0, 500.0], 120.0)
    assert np.max(np.abs(ours.r - ref.r)) < 1e-9 * np.max(np.abs(ref.r))


def test_altitude_gravity_matches_the_model_term():
    R, g0 = 6.371e6, 9.80665
    ref, ours = _both(dict(radius=R, g0=g0), ("altitude-gravity", "coriolis", "centrifugal"),
                      [forces.altitude_gravity(g0, R)], [0.0, 0.0, 3.0e4], [200.0, 0.0, 0.0], 60.0)
    assert np.max(np.abs(ours.r - ref.r)) < 1e-9 * np.max(np.abs(ref.r))


def test_energy_of_gravity_and_spring_is_conserved_in_an_inertial_frame():
    run = simulate_particles(omega=[0.0, 0.0, 0.0], r0=[1.0, 0.0, 5.0], v0=[0.0, 1.0, 0.0], duration=30.0,
                             forces=[forces.gravity([0, 0, -9.81]), forces.spring(1.0, horizontal=True)],
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
    with pytest.raises(ScenarioError, match="gravity: g = .* 3 finite numbers"):
        forces.gravity([0.0, np.nan, 1.0])
    with pytest.raises(ScenarioError, match="drag: give linear"):
        forces.drag()
    with pytest.raises(ScenarioError, match="pendulum: length"):
        forces.pendulum(-1.0)
    with pytest.raises(ScenarioError, match="spring: anchor"):
        forces.spring(1.0, anchor=[1.0, 2.0])


def test_the_frame_free_spring_pulls_in_three_dimensions():
    """a = -k (r - anchor) with k = w0^2: an isotropic oscillator about the anchor, r(t) in closed form."""
    k, anchor = 2.25, np.array([1.0, -2.0, 0.5])
    r0, v0, T = np.array([1.5, -1.0, 0.0]), np.array([0.3, 0.0, -0.6]), 7.0
    run = simulate_particles(omega=[0.0, 0.0, 0.0], r0=r0, v0=v0, duration=T, forces=[forces.spring(k, anchor)],
                             rtol=1e-12, samples=10)
    w = np.sqrt(k)
    expected = anchor + (r0 - anchor) * np.cos(w * T) + v0 / w * np.sin(w * T)
    assert np.max(np.abs(run.trajectory.r[-1, 0] - expected)) < 1e-9
    assert run.diagnostics["energy_rel_drift"] < 1e-10


# ---- one route: a built-in term and the user's own force doing the same arithmetic -------------

def _users_gravity_and_drag(t, r, v):
    """What forces.gravity([0.3, -0.2, -9.81]) + forces.drag(quadratic=4e-5, scale_height=8000) compute."""
    air = np.exp(-r[2] / 8000.0)
    c = 0.0 * air + 4e-5 * air * np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])  # k1, k2 at the local air
    return 0.3 + -c * v[0], -0.2 + -c * v[1], -9.81 + -c * v[2]


@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_a_built_in_term_and_the_same_user_force_give_the_same_trajectory_to_the_bit(method):
    common = dict(omega=[0.0, 4.6e-5, 5.7e-5], r0=[0.0, 0.0, 100.0], v0=[60.0, 10.0, 80.0], duration=12.0,
                  samples=24, method=method, rtol=1e-11, step=1e-3 if method == "rk4" else None)
    built_in = simulate_particles(forces=[forces.gravity([0.3, -0.2, -9.81]),
                                          forces.drag(quadratic=4e-5, scale_height=8000.0)], **common)
    own = simulate_particles(forces=[_users_gravity_and_drag], **common)
    # two terms summed in the driver against one function summing them: the same numbers in another
    # order can differ in the last bit of a sum, so the sum is compared to 2 ulp of the path's scale
    assert np.max(np.abs(built_in.trajectory.r - own.trajectory.r)) <= 4e-16 * np.max(np.abs(own.trajectory.r)) * 2
    single = simulate_particles(forces=[forces.gravity([0.3, -0.2, -9.81])], **common)
    users = simulate_particles(forces=[lambda t, r, v: (0.3, -0.2, -9.81)], **common)
    assert np.array_equal(single.trajectory.r, users.trajectory.r)  # the same arithmetic: the same bits
    assert np.array_equal(single.trajectory.v, users.trajectory.v)


GM_EARTH, R_EARTH = 3.986004418e14, 6.371e6


def _users_point_mass(t, r, v):
    """What forces.central_gravity(GM_EARTH, [0, 0, -R_EARTH]) computes, written from the physics: -GM d / |d|^3."""
    dx = r[0] - 0.0
    dy = r[1] - 0.0
    dz = r[2] + R_EARTH
    d2 = dx * dx + dy * dy + dz * dz
    f = -GM_EARTH / (d2 * np.sqrt(d2))
    return f * dx, f * dy, f * dz


@pytest.mark.parametrize("method", ["dop853", "rk4", "rotation-splitting", "rotation-splitting4"])
def test_a_built_in_term_of_position_and_the_same_user_force_agree_to_the_bit_under_every_method(method):
    """A force of position alone: every method takes it, the splittings as a kick; one route, the same bits."""
    common = dict(omega=[0.0, 4.6e-5, 5.7e-5], r0=[[0.0, 0.0, 2.0e5]] * 2,
                  v0=[[0.0, 0.0, 0.0], [3000.0, 500.0, 2000.0]], duration=60.0,
                  samples=12, method=method, rtol=1e-11, step=None if method == "dop853" else 1e-2)
    built_in = simulate_particles(forces=[forces.central_gravity(GM_EARTH, [0.0, 0.0, -R_EARTH])], **common)
    own = simulate_particles(forces=[_users_point_mass], **common)
    assert np.array_equal(built_in.trajectory.r, own.trajectory.r)
    assert np.array_equal(built_in.trajectory.v, own.trajectory.v)
    assert np.ptp(own.trajectory.r[:, :, 2], axis=0).min() > 1e4  # they flew: a test of the term, not of rest


def test_a_built_in_term_sits_beside_a_force_with_params():
    """The run's params go to your forces, not to a built-in term (its constants are its own): they sit side by side."""

    def users_gravity(t, r, v, gz, shear):
        return 0.0, shear[0] * r[2], gz

    def wind(t, r, v, gz, shear):
        return 0.0, shear[0] * r[2], 0.0

    common = dict(omega=[0.0, 4.6e-5, 5.7e-5], r0=[0.0, 0.0, 100.0], v0=[6.0, 1.0, 8.0], duration=3.0, samples=6,
                  method="rk4", step=1e-3, params=(-9.81, np.array([0.02, 0.0])))
    mixed = simulate_particles(forces=[forces.gravity([0.0, 0.0, -9.81]), wind], **common)
    own = simulate_particles(forces=[users_gravity], **common)
    assert np.max(np.abs(mixed.trajectory.r - own.trajectory.r)) <= 1e-12 * np.max(np.abs(own.trajectory.r))
    assert np.max(np.abs(own.trajectory.r[-1, 0, 1])) > 1.0  # the wind's params reached it
    # potentials too: a built-in spring's (no params) and one of yours (params) summed for the energy diagnostic

    def pull(t, r, v, gz, shear):
        return 0.0, 0.0, gz

    def pull_potential(t, r, gz, shear):
        return -gz * r[2]

    run = simulate_particles(forces=[forces.spring(2.0), Force(pull, potential=pull_potential)],
                             **dict(common, omega=[0.0, 0.0, 0.0], method="dop853", step=None, rtol=1e-11))
    assert run.diagnostics["energy_rel_drift"] < 1e-9


# ---- the pendulum's string ---------------------------------------------------------------------

def test_the_pendulum_swings_with_the_large_amplitude_period():
    """Non-rotating frame, 1 rad amplitude: the period is 4 K(sin^2(theta0 / 2)) sqrt(L / g) (scipy's ellipk
    takes m = k^2), 18 % longer than the small-angle one; the string's length holds to the tolerance."""
    from scipy.special import ellipk

    L, g, th0 = 2.0, 9.81, 1.0
    pivot = np.array([0.0, 0.0, L])
    r0 = pivot + L * np.array([np.sin(th0), 0.0, -np.cos(th0)])

    def crossing(t, r, v):
        return r[0]

    crossing.direction = 1.0
    period = 4.0 * ellipk(np.sin(th0 / 2.0) ** 2) * np.sqrt(L / g)
    run = simulate_particles(omega=[0.0, 0.0, 0.0], r0=r0, v0=[0.0, 0.0, 0.0], duration=2.2 * period,
                             forces=[forces.gravity([0, 0, -g]), forces.pendulum(L, pivot)], events=[crossing],
                             rtol=1e-12, samples=200)
    t_up = run.trajectory.event_times["crossing"][0]
    assert abs(np.diff(t_up)[0] - period) < 1e-9 * period
    assert abs(t_up[0] - 0.75 * period) < 1e-9 * period  # from rest at +x: through x = 0 upward at 3/4 period
    length = np.linalg.norm(run.trajectory.r[:, 0] - pivot, axis=1)
    assert np.max(np.abs(length - L)) < 1e-9 * L
    assert run.diagnostics["energy_rel_drift"] < 1e-9  # the string does no work


def test_the_pendulum_string_matches_the_scenes_term_in_a_rotating_frame():
    """Gravity and the string at 45 degrees north, against the particle core's ``pendulum`` term (DOP853 both)."""
    L, g = 10.0, 9.81
    lat = np.radians(45.0)
    w = 7.292115e-5 * np.array([0.0, np.cos(lat), np.sin(lat)]) * 50.0  # a fast turntable: the frame's terms matter
    pivot = np.array([0.0, 0.0, L])
    r0 = pivot + L * np.array([np.sin(0.2), 0.0, -np.cos(0.2)])
    model = ParticleModel(("gravity", "pendulum", "coriolis", "centrifugal"), omega=OmegaSchedule.constant(w),
                          g=np.array([0.0, 0.0, -g]), pendulum_length=L, pivot=pivot)
    ref = integrate_particles(model, r0, np.zeros(3), 60.0, method="dop853", rtol=RTOL, samples=20)
    ours = simulate_particles(omega=w, r0=r0, v0=[0.0, 0.0, 0.0], duration=60.0, rtol=RTOL, samples=20,
                              forces=[forces.gravity([0.0, 0.0, -g]), forces.pendulum(L, pivot)]).trajectory
    assert np.max(np.abs(ours.r - ref.r)) < 1e-8 * L


def test_a_pendulum_must_start_on_its_string():
    with pytest.raises(ScenarioError, match="r0: particle 0 is .* from the pivot"):
        simulate_particles(omega=[0, 0, 0], r0=[1.0, 0.0, 0.0], v0=[0, 0, 0], duration=1.0,
                           forces=[forces.gravity([0, 0, -9.81]), forces.pendulum(2.0, [0, 0, 2.0])])
    with pytest.raises(ScenarioError, match="v0: particle 0 moves along the string"):
        simulate_particles(omega=[0, 0, 0], r0=[0.0, 0.0, 0.0], v0=[0, 0, 1.0], duration=1.0,
                           forces=[forces.gravity([0, 0, -9.81]), forces.pendulum(2.0, [0, 0, 2.0])])
    with pytest.raises(ScenarioError, match="a second pendulum"):
        simulate_particles(omega=[0, 0, 0], r0=[0.0, 0.0, 0.0], v0=[0, 0, 0], duration=1.0,
                           forces=[forces.pendulum(2.0, [0, 0, 2.0]), forces.pendulum(2.0, [0, 0, 2.0])])


def test_a_force_after_the_string_is_named_by_the_users_own_number():
    """The string is no force of the driver's; a message about the force after it still says forces[1]."""
    def broken(t, r, v):
        return 0.0, 0.0

    with pytest.raises(ScenarioError, match=r"forces\[1\]"):
        simulate_particles(omega=[0, 0, 0], r0=[0.0, 0.0, 0.0], v0=[0, 0, 0], duration=1.0,
                           forces=[forces.pendulum(2.0, [0, 0, 2.0]), broken])


@pytest.mark.parametrize("frame_terms", [None, ("coriolis",)])
def test_the_built_in_terms_energy_is_numpys_and_the_compiled_ones(frame_terms):
    """Every built-in potential takes arrays (``array_potential``): the run's energy (or Jacobi) diagnostic is then
    numpy's, and the problem's glue compiles no potential; the same potentials marked as a user's (compiled, summed
    per sample by the engine) give the same energies to round-off."""
    import dataclasses

    from rotframe.problem.glue import particle_source

    fs = [forces.gravity([0.0, 0.0, -9.81]), forces.central_gravity(3.986e14, (0.0, 0.0, -6.371e6)),
          forces.spring(0.3, (1.0, 2.0, 3.0)), forces.altitude_gravity(9.8, 6.371e6)]
    assert all(f.array_potential for f in fs)
    assert "def potential" not in particle_source(fs, [], (), splitting=False, omega="", origin=False)
    kw = dict(omega=[0.0, 0.3, 0.5], r0=[[1.0, 0.0, 0.0], [0.0, 2.0, 1.0]], v0=[[0.0, 1.0, 0.0], [0.5, 0.0, 0.0]],
              duration=5.0, samples=30, method="dop853", frame_terms=frame_terms)
    numpys = simulate_particles(forces=fs, **kw)
    theirs = [dataclasses.replace(f, array_potential=False) for f in fs]
    assert "def potential" in particle_source(theirs, [], (), splitting=False, omega="", origin=False)
    compiled = simulate_particles(forces=theirs, **kw)
    E, E_ref = numpys.trajectory.extras["energy"], compiled.trajectory.extras["energy"]
    np.testing.assert_allclose(E, E_ref, rtol=1e-14, atol=0)
    name = "jacobi_rel_drift" if frame_terms is None else "energy_rel_drift"
    assert numpys.diagnostics[name] == pytest.approx(compiled.diagnostics[name], rel=1e-6, abs=1e-15)


def test_a_potential_marked_array_potential_that_takes_no_arrays_is_refused_at_the_start():
    """``array_potential=True`` says numpy may call the potential on every sample at once: a potential of yours that
    cannot (math.sqrt on an array) is named in one line before the run, not met as a raw error after it."""
    import math

    from rotframe.problem.callables import UserFunctionError

    def pull(t, r, v):
        return -r[0], -r[1], -r[2]

    def scalar_only(t, r):
        return 0.5 * math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2) ** 2

    with pytest.raises(UserFunctionError, match=r"^forces\[0\]\.potential \(array_potential=True: r as \(3, 2\)"):
        simulate_particles(omega=W, r0=[1.0, 0.0, 0.0], v0=[0.0, 0.0, 0.0], duration=1.0,
                           forces=[Force(pull, potential=scalar_only, takes_params=False, array_potential=True)])
