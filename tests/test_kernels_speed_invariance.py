"""The fast paths of the compiled kernels give the results of the plain ones.

``run_fixed`` advances a whole sample interval in one loop when there is no
event to watch, and at a steady rotation rate computes the rotation of a step
once per call instead of reading the schedule every step. These tests check
that neither shortcut changes a result, and that the array-level step
functions agree with the drivers.
"""

import numpy as np
import pytest

from rotframe.particles import kernels
from rotframe.particles.drivers import run_fixed, run_fixed_events
from rotframe.particles.forces import acceleration
from rotframe.particles.schedule import omega_angle, omega_magnitude, omega_rate
from rotframe.errors import IntegrationError
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel

G = np.array([0.0, 0.1, -9.81])
PEND = {"pendulum_length": 10.0, "pivot": np.array([0.5, -0.2, 10.0])}


def _models():
    steady = OmegaSchedule.constant([0.03, -0.02, 0.1])
    varying = OmegaSchedule.table([0.2, 0.1, 1.0], [0.0, 0.5, 1.3, 3.0], [0.5, 1.0, -0.3, 0.7])
    return {
        "steady free": ParticleModel(("gravity", "coriolis", "quadratic-drag"), omega=steady, g=G, k_quadratic=0.01),
        "steady uniform": ParticleModel(("gravity", "coriolis"), omega=steady, g=G),
        "varying free": ParticleModel(("gravity", "coriolis", "centrifugal", "euler", "linear-drag"), omega=varying,
                                      g=G, k_linear=0.05),
        "steady pendulum": ParticleModel(("gravity", "coriolis", "pendulum"), omega=steady, g=G, **PEND),
        "varying pendulum": ParticleModel(("gravity", "coriolis", "centrifugal", "euler", "pendulum"), omega=varying,
                                          g=G, **PEND),
    }


def _initial(model, n=3):
    rng = np.random.default_rng(7)
    if model.pendulum_length > 0:
        theta = rng.uniform(0.2, 0.8, n)
        normal = np.stack([np.sin(theta), np.zeros(n), -np.cos(theta)], axis=1)
        v = rng.normal(size=(n, 3))
        v -= np.sum(v * normal, axis=1)[:, None] * normal
        return model.pivot + model.pendulum_length * normal, v
    return rng.normal(size=(n, 3)) + [0.0, 0.0, 50.0], rng.normal(size=(n, 3))


def _run_fixed(model, method, events, t0=0.3, h=0.01, steps_per_sample=7, n_samples=9, steady_as_none=False,
               family_at_run_time=False):
    r, v = _initial(model)
    wt = None if steady_as_none else model.omega.times
    pendulum = model.pendulum_length > 0
    if family_at_run_time:  # booleans: every step kernel compiled, the choice made at run time
        family = (method == 2, pendulum)
    else:  # None where absent: pruned at compile time, as the drivers' callers pass them
        family = (True if method == 2 else None, True if pendulum else None)
    n = r.shape[0]
    alive = np.ones(n, dtype=np.bool_)
    out_r = np.empty((n_samples, n, 3))
    out_v = np.empty((n_samples, n, 3))
    records = (np.full((n, 4), np.nan), np.zeros((n, 4, 3)), np.zeros((n, 4, 3)), np.zeros(n, np.int64),
               np.zeros((n, 4), np.int64), 4)
    kernel = run_fixed if events is None else run_fixed_events
    times = t0 + np.arange(n_samples + 1) * (steps_per_sample * h)  # the sample times, from t0
    result = kernel(method, r, v, alive, times, 0, h, steps_per_sample, n_samples, model.pack(),
                    wt, model.omega.values, model.omega.cumulative(), events,
                    out_r, out_v, *records, *family)
    return result, out_r, out_v, r, v


@pytest.mark.parametrize("name", list(_models()))
@pytest.mark.parametrize("method", [0, 1, 2])
def test_watching_an_event_that_never_happens_changes_nothing(name, method):
    # with an event the driver steps one by one; without, a sample interval is one loop
    model = _models()[name]
    never = np.array([[0.0, 2.0, 1e9, 0.0, 1.0]])
    plain = _run_fixed(model, method, never)
    fast = _run_fixed(model, method, None)
    for a, b in zip(plain, fast):
        assert np.array_equal(np.asarray(a), np.asarray(b))
    # an empty event table takes the stepping path of a table (nothing pruned): the same numbers
    for a, b in zip(_run_fixed(model, method, np.zeros((0, 5))), fast):
        assert np.array_equal(np.asarray(a), np.asarray(b))


@pytest.mark.parametrize("name", [name for name in _models() if name.startswith("steady")])
@pytest.mark.parametrize("method", [0, 1, 2])
@pytest.mark.parametrize("events", [None, "never"])
def test_a_steady_schedule_passed_as_none_changes_nothing(name, method, events):
    # wt = None prunes the schedule readers at compile time; the steady plan is the one used either way
    model = _models()[name]
    table = None if events is None else np.array([[0.0, 2.0, 1e9, 0.0, 1.0]])
    for a, b in zip(_run_fixed(model, method, table), _run_fixed(model, method, table, steady_as_none=True)):
        assert np.array_equal(np.asarray(a), np.asarray(b))


@pytest.mark.parametrize("name", list(_models()))
@pytest.mark.parametrize("method", [0, 1, 2])
@pytest.mark.parametrize("events", [None, "never"])
def test_the_step_family_pruned_or_chosen_at_run_time_changes_nothing(name, method, events):
    # rk4 / sphere passed as None (pruned at compile time) or as booleans read at run time
    model = _models()[name]
    table = None if events is None else np.array([[0.0, 2.0, 1e9, 0.0, 1.0]])
    for a, b in zip(_run_fixed(model, method, table), _run_fixed(model, method, table, family_at_run_time=True)):
        assert np.array_equal(np.asarray(a), np.asarray(b))


@pytest.mark.parametrize("method", [0, 1, 2])
def test_steady_rate_as_one_node_or_as_a_flat_table(method):
    w = [0.03, -0.02, 0.1]
    one = ParticleModel(("gravity", "coriolis", "centrifugal"), omega=OmegaSchedule.constant(w), g=G)
    norm = float(np.linalg.norm(w))
    flat = ParticleModel(("gravity", "coriolis", "centrifugal"),
                         omega=OmegaSchedule.table(w, [0.0, 1.0, 2.5], [norm] * 3), g=G)
    for a, b in zip(_run_fixed(one, method, None), _run_fixed(flat, method, None)):
        assert np.array_equal(np.asarray(a), np.asarray(b))


def _reference_splitting(model, r, v, t0, h, steps):
    """The exact-rotation splitting written out with numpy, reading the schedule every step."""
    wt, wv, wint = model.omega.times, model.omega.values, model.omega.cumulative()
    axis = model.omega.axis
    r, v = r.copy(), v.copy()
    for k in range(steps):
        t = t0 + k * h
        r = r + 0.5 * h * v
        v = v + 0.5 * h * model.g
        angle = -2.0 * (omega_angle(t + h, wt, wv, wint) - omega_angle(t, wt, wv, wint))
        c, s = np.cos(angle), np.sin(angle)
        v = v * c + np.cross(axis, v) * s + axis * (axis @ v) * (1.0 - c)
        v = v + 0.5 * h * model.g
        r = r + 0.5 * h * v
    return r, v


def test_hoisted_rotation_matches_a_plain_reference_to_round_off():
    model = _models()["steady uniform"]
    r0, v0 = _initial(model)
    (n_done, bad, _), out_r, out_v, _, _ = _run_fixed(model, 0, None, t0=12.5, h=0.01,
                                                       steps_per_sample=500, n_samples=1)
    r_ref, v_ref = _reference_splitting(model, r0[0], v0[0], 12.5, 0.01, 500)
    assert (n_done, bad) == (1, -1)
    assert np.max(np.abs(out_r[0, 0] - r_ref)) < 1e-12 * np.max(np.abs(r_ref))
    assert np.max(np.abs(out_v[0, 0] - v_ref)) < 1e-12 * np.max(np.abs(v_ref))


@pytest.mark.parametrize("name", list(_models()))
@pytest.mark.parametrize("method", [0, 1, 2])
def test_array_step_functions_agree_with_the_driver(name, method):
    model = _models()[name]
    t0, h = 0.3, 0.01
    _, out_r, out_v, _, _ = _run_fixed(model, method, None, t0=t0, h=h, steps_per_sample=1,
                                       n_samples=3)
    r0, v0 = _initial(model)
    P, wt, wv, wint = model.pack(), model.omega.times, model.omega.values, model.omega.cumulative()
    step = (kernels.step_splitting, kernels.step_splitting4, kernels.step_rk4)[method]
    for p in range(r0.shape[0]):
        r, v = r0[p].copy(), v0[p].copy()
        r2, v2 = r0[p].copy(), v0[p].copy()
        for k in range(3):
            assert step(r, v, t0 + k * h, h, P, wt, wv, wint, np.empty(3)) == (1, 3, 4)[method]
            kernels.select_step(method, r2, v2, t0 + k * h, h, P, wt, wv, wint, np.empty(3))
            assert np.array_equal(r, out_r[k, p]) and np.array_equal(v, out_v[k, p])
            assert np.array_equal(r2, r) and np.array_equal(v2, v)


def test_step_sphere_is_the_pendulum_splitting():
    model = _models()["varying pendulum"]
    P, wt, wv, wint = model.pack(), model.omega.times, model.omega.values, model.omega.cumulative()
    r0, v0 = _initial(model, n=1)
    r, v = r0[0].copy(), v0[0].copy()
    r2, v2 = r0[0].copy(), v0[0].copy()
    kernels.step_sphere(r, v, 0.4, 0.02, P, wt, wv, wint, np.empty(3))
    kernels.step_splitting(r2, v2, 0.4, 0.02, P, wt, wv, wint, np.empty(3))
    assert np.array_equal(r, r2) and np.array_equal(v, v2)
    assert abs(np.linalg.norm(r - model.pivot) - model.pendulum_length) < 1e-12


def test_acceleration_is_the_rk4_force():
    model = _models()["varying free"]
    P, wt, wv = model.pack(), model.omega.times, model.omega.values
    r, v, t = np.array([1.0, -2.0, 30.0]), np.array([0.5, 0.2, -1.0]), 0.7
    out = np.empty(3)
    acceleration(r, v, t, P, wt, wv, out)
    w = omega_magnitude(t, wt, wv) * model.omega.axis
    wd = omega_rate(t, wt, wv) * model.omega.axis
    expected = (model.g - 2 * np.cross(w, v) - np.cross(w, np.cross(w, r)) - np.cross(wd, r)
                - model.k_linear * v)
    assert np.allclose(out, expected, rtol=1e-14, atol=1e-14)


def test_division_by_zero_is_reported_as_a_non_finite_state():
    # a particle released at the centre of central gravity: an IntegrationError, not a ZeroDivisionError
    model = ParticleModel(("central-gravity",), gm=3.986e14, radius=6.371e6)
    with pytest.raises(IntegrationError, match="non-finite"):
        integrate_particles(model, [0.0, 0.0, -6.371e6], [0.0, 0.0, 0.0], 1.0, method="splitting", step=0.1,
                            samples=2)
