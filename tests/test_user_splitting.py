"""Your force under the rotation splittings (issue 32): ``rotframe.simulate(method="rotation-splitting4")``.

Oracles:
- the exact flow of a linear problem (a 3-D spring, uniform gravity, a steadily rotating frame),
  written here as scipy's matrix exponential of the first-order system: independent of rotframe;
  halving the step shows the order the registry states (2 and 4);
- the scenes' own compiled splitting kernels (`rotframe.particles.kernels`) on the same terms: the
  same method written once more for the scenes' packed models, so the two agree to round-off;
- DOP853 at rtol 1e-13 for an event's time, and for the pendulum's string under the splittings
  (the splitting on the sphere), whose order is measured against it.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from rotframe import forces
from rotframe import method_registry as registry
from rotframe.errors import ScenarioError
from rotframe.problem.particles import simulate_particles

W = np.array([0.0, 0.3, 0.4])
K = 2.0
G = np.array([0.0, 0.0, -1.0])
R0, V0, T = np.array([1.0, 0.5, 0.0]), np.array([0.0, 0.3, 0.2]), 4.0


def spring(t, r, v):
    """The user's own term: a 3-D spring of K (1/s^2) about the origin; it never reads v."""
    return -K * r[0], -K * r[1], -K * r[2]


def _exact(t):
    """r(t) of r'' = -K r + g - 2 w x v - w x (w x r): exp(A t) on (r, v, 1)."""
    Wx = np.array([[0.0, -W[2], W[1]], [W[2], 0.0, -W[0]], [-W[1], W[0], 0.0]])
    A = np.zeros((7, 7))
    A[0:3, 3:6] = np.eye(3)
    A[3:6, 0:3] = -K * np.eye(3) - Wx @ Wx
    A[3:6, 3:6] = -2.0 * Wx
    A[3:6, 6] = G
    return (expm(A * t) @ np.r_[R0, V0, 1.0])[:3]


@pytest.mark.parametrize("method", ["rotation-splitting", "rotation-splitting4"])
def test_a_user_force_under_a_splitting_has_the_methods_order(method):
    ref = _exact(T)
    errors = []
    for h in (0.02, 0.01, 0.005):
        run = simulate_particles(omega=W, r0=R0, v0=V0, duration=T, forces=[spring, forces.gravity(G)],
                                 method=method, step=h, samples=1)
        errors.append(np.max(np.abs(run.trajectory.r[-1, 0] - ref)))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - registry.get(method).order) < 0.1), (orders, errors)
    assert run.trajectory.method == method


@pytest.mark.parametrize("method", ["rotation-splitting", "rotation-splitting4"])
def test_a_user_force_under_a_splitting_matches_the_scenes_kernel(method):
    """Gravity, the horizontal spring, Coriolis and centrifugal: the user's driver and the scenes' kernel."""
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    model = ParticleModel(("gravity", "spring", "coriolis", "centrifugal"), omega=OmegaSchedule.constant(W), g=G,
                          spring=K)
    scene = integrate_particles(model, R0, V0, T, method=method, step=0.01, samples=8)

    def horizontal(t, r, v):
        return -K * r[0], -K * r[1], 0.0

    ours = simulate_particles(omega=W, r0=R0, v0=V0, duration=T, forces=[horizontal, forces.gravity(G)],
                              method=method, step=0.01, samples=8).trajectory
    assert np.max(np.abs(ours.r - scene.r)) < 1e-13 * np.max(np.abs(scene.r))
    assert np.max(np.abs(ours.v - scene.v)) < 1e-13 * np.max(np.abs(scene.v))


def test_a_splitting_keeps_the_jacobi_integral_bounded_where_rk4_drifts():
    """A spring in a rotating frame over 200 periods at a coarse step: the splitting's Jacobi error stays at
    its first size (a symplectic map's modified integral), RK4's grows with time."""
    drift = {}
    for method in ("rotation-splitting", "rk4"):
        run = simulate_particles(omega=[0.0, 0.0, 0.5], r0=[1.0, 0.0, 0.3], v0=[0.0, 0.4, 0.0], duration=900.0,
                                 forces=[forces.spring(K)], method=method, step=0.2, samples=300)
        energy = run.trajectory.extras["energy"][:, 0]
        error = np.abs(energy - energy[0])
        drift[method] = (np.max(error[:30]), np.max(error[-30:]))
    early, late = drift["rotation-splitting"]
    assert late < 2.0 * early
    early, late = drift["rk4"]
    assert late > 5.0 * early


def test_an_event_under_a_splitting_is_located_on_its_own_trajectory():
    def ground(t, r, v):
        return r[2]

    ground.terminal = True
    ground.direction = -1.0
    common = dict(omega=W * 1e-3, r0=[0.0, 0.0, 10.0], v0=[3.0, 0.0, 5.0], duration=5.0,
                  forces=[forces.gravity([0.0, 0.0, -9.81])], events=[ground])
    split = simulate_particles(method="rotation-splitting4", step=1e-3, samples=10, **common).trajectory
    ref = simulate_particles(method="dop853", rtol=1e-13, samples=10, **common).trajectory
    t_split, t_ref = split.event_times["ground"][0][0], ref.event_times["ground"][0][0]
    assert abs(t_split - t_ref) < 1e-9
    assert abs(split.event_states["ground"][0][0][2]) < 1e-12  # on the ground, to round-off


def _reads_v(t, r, v):
    return 0.0, 0.0, -0.1 * v[2]


@pytest.mark.parametrize("terms, says", [
    ([_reads_v], "_reads_v): it reads v"),
    ([forces.drag(linear=0.1), forces.drag(quadratic=0.1)], "one drag term a run"),
    ([forces.Force(spring, axes="inertial")], "is given in inertial axes"),
])
def test_a_splitting_refuses_by_name_what_it_cannot_kick(terms, says):
    with pytest.raises(ScenarioError, match="method='rotation-splitting4' cannot take") as info:
        simulate_particles(omega=W, r0=[0.0, 0.0, 0.0], v0=[0.0, 0.0, 0.0], duration=1.0, forces=terms,
                           method="rotation-splitting4", step=0.01)
    assert says in str(info.value) and "use dop853 or rk4" in str(info.value)


def test_a_splitting_in_a_spinning_up_frame_with_an_accelerating_origin_converges_at_order_four():
    """omega(t) = (0, 0.1 t, 0.3 + 0.2 t) (its direction turns: Euler's term and a moving axis) and a constant
    origin acceleration: the splitting's kick carries the Euler and origin terms, its turn the Coriolis one.
    The reference is the same problem under DOP853 at rtol 1e-13, whose right-hand side writes those terms
    apart; the error ratio on halving the step shows order 4, and a sign flipped in either term fails."""
    omega = lambda t: (0.0, 0.1 * t, 0.3 + 0.2 * t)  # noqa: E731
    omega_dot = lambda t: (0.0, 0.1, 0.2)  # noqa: E731
    common = dict(omega=omega, omega_dot=omega_dot, r0=R0, v0=V0, duration=T, forces=[spring],
                  origin_acceleration=[0.3, -0.2, 0.1], samples=1)
    ref = simulate_particles(method="dop853", rtol=1e-13, **common).trajectory.r[-1, 0]
    errors = [np.max(np.abs(simulate_particles(method="rotation-splitting4", step=h, **common).trajectory.r[-1, 0]
                            - ref)) for h in (0.02, 0.01)]
    assert errors[1] < 1e-7 * np.max(np.abs(ref))
    assert abs(np.log2(errors[0] / errors[1]) - 4.0) < 0.3, errors


@pytest.mark.parametrize("method", ["rotation-splitting", "rotation-splitting4"])
@pytest.mark.parametrize("drag", [dict(quadratic=4e-3, scale_height=200.0), dict(linear=0.05, quadratic=1e-3)])
def test_the_built_in_drag_runs_as_its_exact_flow_under_a_splitting(method, drag):
    """rotframe.forces.drag under a splitting is the drag's exact flow, h/2 on each side of the Coriolis turn,
    as the scenes' kernels run their drag terms: the two agree to round-off. A drag force of the user's own
    (it reads v) is refused under the splittings by name."""
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    terms = ("gravity", "coriolis", "centrifugal") + (("linear-drag",) if "linear" in drag else ()) \
        + ("quadratic-drag",)
    model = ParticleModel(terms, omega=OmegaSchedule.constant(W), g=G, k_linear=drag.get("linear", 0.0),
                          k_quadratic=drag["quadratic"], scale_height=drag.get("scale_height", 0.0))
    r0, v0 = [0.0, 0.0, 100.0], [30.0, -10.0, 40.0]
    scene = integrate_particles(model, r0, v0, 6.0, method=method, step=0.01, samples=6)
    ours = simulate_particles(omega=W, r0=r0, v0=v0, duration=6.0, forces=[forces.gravity(G), forces.drag(**drag)],
                              method=method, step=0.01, samples=6).trajectory
    assert np.max(np.abs(ours.r - scene.r)) < 1e-12 * np.max(np.abs(scene.r))
    assert np.max(np.abs(ours.v - scene.v)) < 1e-12 * np.max(np.abs(scene.v))
    vacuum = simulate_particles(omega=W, r0=r0, v0=v0, duration=6.0, forces=[forces.gravity(G)], method=method,
                                step=0.01, samples=6).trajectory
    assert np.max(np.abs(vacuum.r - ours.r)) > 1.0  # the drag acted: metres from the path in vacuum


PIVOT = np.array([0.0, 0.0, 67.0])
LENGTH = 67.0
W_FAST = np.array([0.0, 4.8e-5, 5.5e-5]) * 200.0  # Foucault's Earth rate, 200 times: Coriolis matters in a minute


def _pendulum(method, **run):
    """A 67 m pendulum swinging 3 m out, with a sideways push, in a fast-turning frame, for 60 s."""
    r0 = np.array([3.0, 0.0, 67.0 - np.sqrt(67.0**2 - 9.0)])
    return simulate_particles(omega=W_FAST, r0=r0, v0=[0.0, 0.4, 0.0], duration=60.0, method=method, samples=6,
                              forces=[forces.gravity([0.0, 0.0, -9.81]), forces.pendulum(LENGTH, PIVOT)],
                              **run).trajectory


@pytest.mark.parametrize("method, order", [("rotation-splitting", 2), ("rotation-splitting4", 4)])
def test_the_pendulums_string_under_a_splitting_converges_at_its_order_and_stays_on_the_sphere(method, order):
    """The reference is DOP853 at rtol 1e-13 on the constrained equations (the string's tension written
    in the right-hand side), far more accurate than the splitting at these steps."""
    ref = _pendulum("dop853", rtol=1e-13).r[-1, 0]
    errors = []
    for h in (0.1, 0.05):
        traj = _pendulum(method, step=h)
        errors.append(np.max(np.abs(traj.r[-1, 0] - ref)))
        on_sphere = np.abs(np.linalg.norm(traj.r[:, 0] - PIVOT, axis=1) - LENGTH)
        assert np.max(on_sphere) < 1e-12 * LENGTH  # the flows keep it there: no drift, no projection
    assert abs(np.log2(errors[0] / errors[1]) - order) < 0.1, errors


@pytest.mark.parametrize("method", ["rotation-splitting", "rotation-splitting4"])
def test_the_pendulums_splitting_is_the_scenes(method):
    """The scenes' pendulum splitting (`rotframe.particles.kernels`) on the same terms: the same method,
    so the two agree to round-off."""
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    model = ParticleModel(("gravity", "coriolis", "centrifugal", "pendulum"), omega=OmegaSchedule.constant(W_FAST),
                          g=np.array([0.0, 0.0, -9.81]), pendulum_length=LENGTH, pivot=PIVOT)
    r0 = np.array([3.0, 0.0, 67.0 - np.sqrt(67.0**2 - 9.0)])
    scene = integrate_particles(model, r0[None], np.array([[0.0, 0.4, 0.0]]), 60.0, method=method, step=0.05,
                                samples=6)
    ours = _pendulum(method, step=0.05)
    np.testing.assert_allclose(ours.r, scene.r, rtol=0, atol=1e-11)
    np.testing.assert_allclose(ours.v, scene.v, rtol=0, atol=1e-12)
