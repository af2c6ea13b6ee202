"""Particle core: every method against the inertial-line oracle, orders, conservation, events."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rotframe.app import cli
from rotframe.particles.integrators import Event, integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.scenes.turntable import inertial_line

Z = np.array([0.0, 0.0, 1.0])
R0 = np.array([2.0, 0.0, 0.0])
V0 = np.array([-1.0, 0.3, 0.0])


def _turntable(alpha, method, step, duration=4.0):
    omega = OmegaSchedule.ramp(Z, 1.0, alpha, duration)
    terms = ("coriolis", "centrifugal") + (("euler",) if alpha else ())
    model = ParticleModel(terms, omega=omega)
    traj = integrate_particles(model, R0, V0, duration, method=method, step=step, rtol=1e-12, samples=40)
    oracle = inertial_line(omega, R0, V0, traj.times)
    return np.max(np.linalg.norm(traj.r[:, 0] - oracle, axis=1))


# (method, step, tolerance on the max position error in metres, order)
# Over 4 s the puck travels about 4 m and the table turns ~0.9 times; a second-order
# method at |omega| h = 1e-4 errs by ~(omega h)^2 x distance x turns ~ 1e-7 m.
CASES = [
    ("splitting", 1e-4, 1e-6, 2),
    ("splitting4", 1e-3, 1e-9, 4),
    ("rk4", 1e-3, 1e-10, 4),
    ("dop853", None, 1e-10, None),
]


@pytest.mark.parametrize("alpha", [0.0, 0.2])
@pytest.mark.parametrize("method,step,tol,order", CASES)
def test_every_method_reproduces_the_inertial_line(method, step, tol, order, alpha):
    assert _turntable(alpha, method, step) < tol


@pytest.mark.parametrize("alpha", [0.0, 0.2])
@pytest.mark.parametrize("method,step,tol,order", [c for c in CASES if c[3]])
def test_observed_order_of_convergence(method, step, tol, order, alpha):
    h = step * 20
    e1 = _turntable(alpha, method, h)
    e2 = _turntable(alpha, method, h / 2)
    observed = np.log2(e1 / e2)
    assert abs(observed - order) < 0.3, observed


def test_exact_propagator_matches_inertial_line_for_constant_spin():
    omega = OmegaSchedule.constant([0.0, 0.0, 1.0])
    model = ParticleModel(("coriolis", "centrifugal"), omega=omega)
    assert model.is_linear
    traj = integrate_particles(model, R0, V0, 10.0, method="exact", samples=500)
    oracle = inertial_line(omega, R0, V0, traj.times)
    assert np.max(np.linalg.norm(traj.r[:, 0] - oracle, axis=1)) < 1e-12


def test_splitting_keeps_speed_under_pure_coriolis_and_rk4_does_not():
    omega = OmegaSchedule.constant([0.3, -0.2, 1.0])
    model = ParticleModel(("coriolis",), omega=omega)
    v0 = np.array([1.0, 2.0, -0.5])
    n_steps = 10**6
    h = 0.05  # |2 omega| h ~ 0.1 rad per step
    speeds = {}
    for method in ("splitting", "rk4"):
        traj = integrate_particles(model, [0, 0, 0], v0, n_steps * h, method=method, step=h, samples=100)
        speeds[method] = np.abs(np.linalg.norm(traj.v[:, 0], axis=1) / np.linalg.norm(v0) - 1).max()
    # round-off only: at most one ulp per step (N eps = 2.2e-10), against RK4's truncation loss
    assert speeds["splitting"] < n_steps * np.finfo(float).eps
    assert speeds["rk4"] > 1e-6  # RK4 damps the rotation: |v| decays like (1 - (wh)^6/72) per step


def test_ground_event_is_located_to_round_off():
    lat = np.radians(50.9)
    om = 7.292115e-5 * np.array([0.0, np.cos(lat), np.sin(lat)])
    model = ParticleModel(("gravity", "coriolis", "quadratic-drag"), omega=OmegaSchedule.constant(om),
                          g=np.array([0, 0, -9.81]), k_quadratic=1e-3)
    ev = Event("ground", "r", 2, 0.0, -1, True)
    for method in ("splitting", "rk4", "dop853"):
        traj = integrate_particles(model, [0, 0, 100.0], [0, 0, 0], 20.0, method=method, step=1e-3,
                                   samples=50, events=[ev])
        (t_hit,), state = traj.event_times["ground"][0], traj.event_states["ground"][0]
        assert abs(state[0, 2]) < 1e-12
        assert 4.0 < t_hit < 6.0
        # the particle stops at the impact
        assert np.allclose(traj.r[-1, 0], state[0, :3])


def test_drag_fall_agrees_with_solve_ivp_reference():
    k2 = 2e-3
    g = np.array([0.0, 0.0, -9.81])
    om = np.array([0.0, 5e-5, 5e-5])

    def rhs(t, y):
        v = y[3:]
        a = g - 2 * np.cross(om, v) - k2 * np.linalg.norm(v) * v
        return np.concatenate([v, a])

    ref = solve_ivp(rhs, (0, 3.0), [0, 0, 100, 3, 1, 10], method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    model = ParticleModel(("gravity", "coriolis", "quadratic-drag"), omega=OmegaSchedule.constant(om), g=g,
                          k_quadratic=k2)
    for method, step, tol in [("splitting4", 1e-3, 1e-9), ("dop853", None, 1e-9), ("splitting", 1e-4, 1e-6)]:
        traj = integrate_particles(model, [0, 0, 100], [3, 1, 10], 3.0, method=method, step=step, rtol=1e-12,
                                   samples=10)
        state = np.concatenate([traj.r[-1, 0], traj.v[-1, 0]])
        assert np.max(np.abs(state - ref)) < tol, method


def test_pendulum_splitting_keeps_the_string_length():
    L = 10.0
    model = ParticleModel(("gravity", "coriolis", "pendulum"),
                          omega=OmegaSchedule.constant([0, 4e-5, 6e-5]), g=np.array([0, 0, -9.81]),
                          pendulum_length=L, pivot=np.array([0.0, 0.0, L]))
    r0 = np.array([L * np.sin(0.3), 0.0, L - L * np.cos(0.3)])
    traj = integrate_particles(model, r0, [0, 0, 0], 200.0, method="splitting", step=1e-2, samples=200)
    length = np.linalg.norm(traj.r[:, 0] - model.pivot, axis=1)
    assert np.max(np.abs(length - L)) < 1e-12
    radial_v = np.einsum("ij,ij->i", traj.r[:, 0] - model.pivot, traj.v[:, 0]) / L
    assert np.max(np.abs(radial_v)) < 1e-12


def test_ensemble_equals_separate_runs():
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant([0, 1e-4, 1e-4]),
                          g=np.array([0, 0, -9.81]))
    r0 = np.array([[0, 0, 10.0], [1, 2, 30.0], [0, 0, 5.0]])
    v0 = np.array([[1, 0, 0], [0, 3, 1.0], [0, 0, 0]])
    ens = integrate_particles(model, r0, v0, 2.0, method="splitting", step=1e-3, samples=20)
    for p in range(3):
        one = integrate_particles(model, r0[p], v0[p], 2.0, method="splitting", step=1e-3, samples=20)
        assert np.array_equal(ens.r[:, p], one.r[:, 0])


def test_dop853_tableau_is_consistent():
    from rotframe.numerics.dop853 import coefficients

    A, B, C, E3, E5 = coefficients()
    assert np.allclose(A.sum(axis=1), C, atol=1e-14)
    assert abs(B.sum() - 1) < 1e-14


def test_exact_method_refuses_nonlinear_models():
    from rotframe.errors import ScenarioError

    model = ParticleModel(("gravity", "quadratic-drag"), g=np.array([0, 0, -9.81]), k_quadratic=1e-3)
    with pytest.raises(ScenarioError, match="linear"):
        integrate_particles(model, [0, 0, 1], [0, 0, 0], 1.0, method="exact")


def test_omega_as_table_or_callable_matches_the_ramp():
    duration = 4.0
    ramp = OmegaSchedule.ramp(Z, 1.0, 0.2, duration)
    table = OmegaSchedule.table(Z, [0.0, 1.0, 4.0], [1.0, 1.2, 1.8])
    func = OmegaSchedule.from_callable(Z, lambda t: 1.0 + 0.2 * t, duration)
    for omega in (table, func):
        model = ParticleModel(("coriolis", "centrifugal", "euler"), omega=omega)
        traj = integrate_particles(model, R0, V0, duration, method="splitting4", step=1e-3, samples=40)
        oracle = inertial_line(ramp, R0, V0, traj.times)
        assert np.max(np.linalg.norm(traj.r[:, 0] - oracle, axis=1)) < 1e-9


def test_method_aliases_run_the_canonical_method_and_report_its_name():
    # the particle splittings are named rotation-splitting(4) (the heavy top has other 'splitting's);
    # the old names stay accepted through integrators.ALIASES and give bitwise the same run
    from rotframe.errors import ScenarioError
    from rotframe.particles.integrators import ALIASES, METHODS, canonical_method

    assert set(ALIASES.values()) <= set(METHODS)
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant([0.0, 0.0, 1e-3]),
                          g=np.array([0.0, 0.0, -9.81]))
    for alias, name in ALIASES.items():
        assert canonical_method(alias) == name and canonical_method(name) == name
        a = integrate_particles(model, R0, V0, 1.0, method=alias, step=1e-2, samples=5)
        b = integrate_particles(model, R0, V0, 1.0, method=name, step=1e-2, samples=5)
        assert a.method == b.method == name
        assert np.array_equal(a.r, b.r) and np.array_equal(a.v, b.v)
    with pytest.raises(ScenarioError, match="method"):
        canonical_method("lie-poisson")


def test_compile_s_counts_only_loading_done_by_this_call():
    # compile_s is the time of the driver's warm-up call when that call loaded or compiled it (the
    # dispatcher gained a signature), else 0.0: a run after one that loaded the same driver reports 0.0
    model = ParticleModel(("gravity",), g=np.array([0.0, 0.0, -9.81]))
    for method in ("rk4", "dop853"):
        integrate_particles(model, R0, V0, 1.0, method=method, samples=3)
        again = integrate_particles(model, R0, V0, 1.0, method=method, samples=3)
        assert again.extras["compile_s"] == 0.0


def test_linear_propagate_over_long_brackets_scales_and_squares():
    """A bracket far longer than the Taylor sub-steps allow (a drop from 1e30 m once took 1e11 of them: a hang)
    is scaled and squared: against scipy's expm where both are meaningful, and a drop from 1e30 m ends."""
    from scipy.linalg import expm

    from rotframe.particles.linear import MAX_SUBSTEPS, propagate

    rng = np.random.default_rng(3)
    M = np.zeros((7, 7))
    M[0:3, 3:6] = np.eye(3)
    M[3:6, 3:6] = -0.05 * np.eye(3) + np.array([[0, 0.3, 0], [-0.3, 0, 0], [0, 0, 0]])  # drag and a turn
    M[3:6, 6] = [0.0, 0.0, -9.81]
    tau = np.array([0.5 * MAX_SUBSTEPS, 3.0 * MAX_SUBSTEPS, 40.0 * MAX_SUBSTEPS])
    s = np.vstack([rng.normal(size=(6, tau.size)), np.ones((1, tau.size))])
    got = propagate(M, s, tau)
    for j, t in enumerate(tau):
        want = expm(M * t) @ s[:, j]
        assert np.allclose(got[:, j], want, rtol=1e-10, atol=1e-10 * np.abs(want).max()), t
    assert np.all(got[6] == 1.0)  # the constant stays exactly 1
    code = cli.main(["run", "tower-drop", "--set", "height=1e30", "--no-record", "--json"])
    assert code in (0, 3)


def test_linear_propagate_agrees_with_scipy_expm():
    """The batched Taylor propagator of event location (particles.linear.propagate) against scipy's
    scaling-and-squaring expm (the samples' exponential), column by column, over brackets from a
    millisecond to a pendulum period (event brackets are one sample interval) with a stiff spring:
    two independent algorithms agree to 1e-12 of the state's size. (Over 1e4 s, |M| t ~ 1e4, they
    part by up to 1e-10, and scipy is the one that errs: its last component, exactly 1 by the
    matrix's zero last row, moves by 8e-10 after its squarings; the Taylor propagator keeps it.)"""
    from scipy.linalg import expm

    from rotframe.particles.linear import propagate

    rng = np.random.default_rng(5)
    M = np.zeros((7, 7))
    M[0:3, 3:6] = np.eye(3)
    w = np.array([0.0, 4.8e-5, 5.5e-5])
    M[3:6, 3:6] = -2.0 * np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    M[3:6, 0:3] = -np.diag([0.146, 0.146, 0.0])  # small-angle pendulum spring g/L
    M[3:6, 6] = [0.0, 0.0, -9.81]
    tau = np.array([1e-3, 0.1, 0.7, 4.0, 16.4])
    s = np.vstack([rng.normal(size=(6, tau.size)), np.ones((1, tau.size))])
    got = propagate(M, s, tau)
    for j, t in enumerate(tau):
        want = expm(M * t) @ s[:, j]
        assert np.allclose(got[:, j], want, rtol=0, atol=1e-12 * max(1.0, np.abs(want).max())), t
