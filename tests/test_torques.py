"""The built-in torques (`rotframe.torques`): the same path as a torque of yours, and the right physics.

* A built-in torque and a torque of yours doing the same arithmetic move the body alike to the bit,
  under every method that takes them (DOP853, RK4, both Lie-Poisson splittings), alone and summed
  in a list beside one another.
* The physics against references that share no code with the torques:
  - gravity on a heavy symmetric top conserves the energy ``L . omega / 2 + m g l e3_z`` (the
    attitude from scipy's `Rotation`), the vertical angular momentum and the spin ``L3``;
  - a torque fixed in space makes the angular momentum in space grow as ``L(0) + tau t`` (under a
    Lie-Poisson splitting exactly: its kick adds ``h tau`` in space and its free flow keeps it);
  - a torque fixed in the body on a sphere gives ``L_body = L(0) + tau t`` (``L x omega = 0``).
* Bad arguments are refused in one line, naming the torque.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import rotframe
from rotframe import torques
from rotframe.errors import ScenarioError
from rotframe.rigid.kernels import body_torque

#: a heavy symmetric top: I1 = I2, tilted 20 degrees, spinning fast about its axis
TOP = dict(inertia=[0.02, 0.02, 0.01], L0=[0.0, 0.0, 0.01 * 40.0],
           q0=Rotation.from_euler("x", 20.0, degrees=True).as_quat().tolist())
MASS, LENGTH, G = 0.5, 0.04, 9.81
MGL = MASS * G * LENGTH  # as rotframe.rigid.checks.heavy_top_mgl multiplies


def _mine_gravity(t, L, q):  # your own torque, the built-in's arithmetic (the scenes' body_torque)
    return body_torque(q[0], q[1], q[2], q[3], MASS * G * LENGTH, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def _mine_both(t, L, q):  # gravity and a torque fixed in space, summed as the glue sums a list
    a = body_torque(q[0], q[1], q[2], q[3], MASS * G * LENGTH, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    b = body_torque(q[0], q[1], q[2], q[3], 0.0, 0.0, 0.0, 0.0, 0.01, -0.02, 0.003)
    return a[0] + b[0], a[1] + b[1], a[2] + b[2]


METHODS = [("dop853", dict(rtol=1e-10)), ("rk4", dict(step=1e-3)), ("lie-poisson", dict(step=1e-3)),
           ("lie-poisson4", dict(step=2e-3))]


def _run(torque, method, settings, duration=0.5, **kw):
    args = {**TOP, **kw}
    return rotframe.simulate_body(**args, duration=duration, torque=torque, method=method, samples=20,
                                  **settings).trajectory


@pytest.mark.parametrize("method, settings", METHODS)
def test_a_builtin_torque_and_yours_of_the_same_arithmetic_give_the_same_motion_to_the_bit(method, settings):
    built_in = _run(torques.gravity(MASS, LENGTH, G), method, settings)
    mine = _run(rotframe.Torque(_mine_gravity, attitude_only=True), method, settings)
    np.testing.assert_array_equal(built_in.L, mine.L)
    np.testing.assert_array_equal(built_in.q, mine.q)
    assert not np.allclose(built_in.L[-1], built_in.L[0])  # the torque acted


@pytest.mark.parametrize("method, settings", METHODS)
def test_a_list_of_torques_is_their_sum_in_order(method, settings):
    listed = _run([torques.gravity(MASS, LENGTH, G), torques.space_fixed([0.01, -0.02, 0.003])], method, settings)
    mine = _run(rotframe.Torque(_mine_both, attitude_only=True), method, settings)
    np.testing.assert_array_equal(listed.L, mine.L)
    np.testing.assert_array_equal(listed.q, mine.q)


def test_a_builtin_torque_sits_beside_yours_that_takes_params():
    def spin_up(t, L, q, k):
        return 0.0, 0.0, k

    res = rotframe.simulate_body(**TOP, duration=0.5, torque=[torques.gravity(MASS, LENGTH, G), spin_up],
                                 params=(0.02,), rtol=1e-12, samples=10)
    # L3 grows by k t: gravity's torque has no part along the symmetry axis, the Euler term none on a symmetric top
    np.testing.assert_allclose(res.trajectory.L[:, 2], TOP["L0"][2] + 0.02 * res.trajectory.times, rtol=0,
                               atol=1e-12)
    model = res.to_dict()["model"]
    assert model[:2] == ["euler equations", "torque gravity"] and model[2].endswith("spin_up")


def _energy_and_momenta(traj, inertia, mgl):
    """(energy, vertical angular momentum in space, L3) per sample, the attitude by scipy's Rotation."""
    R = Rotation.from_quat(traj.q).as_matrix()  # body -> space, scalar-last as rotframe's
    omega = traj.L / np.asarray(inertia)
    energy = 0.5 * np.sum(traj.L * omega, axis=1) + mgl * R[:, 2, 2]  # centre of mass at l e3: height l (R e3)_z
    L_space = np.einsum("nij,nj->ni", R, traj.L)
    return energy, L_space[:, 2], traj.L[:, 2]


@pytest.mark.parametrize("method, settings", [("dop853", dict(rtol=1e-12)), ("lie-poisson4", dict(step=2e-4))])
def test_gravity_on_a_heavy_top_conserves_its_energy_its_vertical_momentum_and_its_spin(method, settings):
    traj = _run(torques.gravity(MASS, LENGTH, G), method, settings, duration=2.0)
    energy, Lz, L3 = _energy_and_momenta(traj, TOP["inertia"], MGL)
    R = Rotation.from_quat(traj.q).as_matrix()
    drift = np.max(np.abs(energy - energy[0]))
    # the axis nutates: gravity's energy swings by far more than the drift allowed (the term is tested, not a constant)
    assert MGL * np.ptp(R[:, 2, 2]) > 1e4 * drift + 1e-6 * abs(energy[0])
    assert drift < 1e-8 * abs(energy[0])
    assert np.max(np.abs(Lz - Lz[0])) < 1e-9 * np.linalg.norm(TOP["L0"])
    assert np.max(np.abs(L3 - L3[0])) < 1e-9 * np.linalg.norm(TOP["L0"])


def test_gravity_on_the_engine_is_the_heavy_top_scenes_motion():
    from rotframe.rigid.adaptive import rigid_dop853

    traj = _run(torques.gravity(MASS, LENGTH, G), "dop853", dict(rtol=1e-12), duration=1.0)
    scene = rigid_dop853(np.array(TOP["inertia"]), np.array(TOP["L0"]), np.array(TOP["q0"]), traj.times,
                         rtol=1e-12, mgl=MGL)
    np.testing.assert_allclose(traj.L, scene.L, rtol=0, atol=1e-8 * np.linalg.norm(TOP["L0"]))
    angle = (Rotation.from_quat(traj.q) * Rotation.from_quat(scene.q).inv()).magnitude()
    assert np.max(angle) < 1e-8


@pytest.mark.parametrize("method, settings, tol", [("dop853", dict(rtol=1e-12), 1e-9), ("rk4", dict(step=1e-3), 1e-9),
                                                    ("lie-poisson", dict(step=1e-2), 1e-12)])
def test_a_torque_fixed_in_space_grows_the_angular_momentum_in_space_linearly(method, settings, tol):
    tau = np.array([0.01, -0.02, 0.003])
    inertia = [0.03, 0.02, 0.01]  # asymmetric: the body tumbles while L in space grows
    traj = _run(torques.space_fixed(tau), method, settings, duration=2.0, inertia=inertia,
                L0=[0.05, 0.3, 0.02], q0=[0.1, 0.2, 0.3, 0.9273618495495704])
    L_space = np.einsum("nij,nj->ni", Rotation.from_quat(traj.q).as_matrix(), traj.L)
    expected = L_space[0] + np.outer(traj.times, tau)
    np.testing.assert_allclose(L_space, expected, rtol=0, atol=tol * np.max(np.abs(expected)))
    assert np.ptp(traj.L[:, 0]) > 1e-3  # in the body it is not linear: the test is about the frames


@pytest.mark.parametrize("method, settings", [("dop853", dict(rtol=1e-12)), ("rk4", dict(step=1e-2))])
def test_a_torque_fixed_in_the_body_of_a_sphere_grows_its_body_momentum_linearly(method, settings):
    tau = np.array([0.02, 0.0, -0.01])
    traj = _run(torques.body_fixed(tau), method, settings, duration=2.0, inertia=[0.01, 0.01, 0.01],
                L0=[0.0, 0.02, 0.05])
    np.testing.assert_allclose(traj.L, traj.L[0] + np.outer(traj.times, tau), rtol=0, atol=1e-13)


def test_the_run_names_the_builtin_torques():
    res = rotframe.simulate_body(**TOP, duration=0.1, samples=4,
                                 torque=[torques.gravity(MASS, LENGTH, G), torques.body_fixed([0, 0, 1e-3])])
    assert res.to_dict()["model"] == ["euler equations", "torque gravity", "torque torque fixed in the body"]


@pytest.mark.parametrize("call, needle", [
    (lambda: torques.gravity(-1.0, LENGTH, G), "gravity: mass=-1.0 must be > 0"),
    (lambda: torques.gravity(MASS, LENGTH, -9.81), "gravity: g=-9.81 must be >= 0"),
    (lambda: torques.gravity(MASS, "long", G), "gravity: length='long' is not a number"),
    (lambda: torques.gravity(MASS, float("nan"), G), "gravity: length=nan is not finite"),
    (lambda: torques.space_fixed([1.0, 2.0]), "tau"),
    (lambda: torques.body_fixed("abc"), "tau"),
])
def test_bad_arguments_of_a_builtin_torque_are_refused_in_one_line(call, needle):
    with pytest.raises(ScenarioError) as err:
        call()
    assert needle in str(err.value) and "\n" not in str(err.value)


def test_a_torque_list_is_refused_by_name_where_a_method_cannot_take_an_entry():
    def drag(t, L, q):
        return -0.1 * L[0], -0.1 * L[1], -0.1 * L[2]

    with pytest.raises(ScenarioError, match=r"lie-poisson.*cannot take torque\[1\]=.*drag"):
        rotframe.simulate_body(**TOP, duration=0.1, step=1e-2, method="lie-poisson",
                               torque=[torques.gravity(MASS, LENGTH, G), drag])
    with pytest.raises(ScenarioError, match=r"exact.*cannot take torque\[0\]=gravity"):
        rotframe.simulate_body(**TOP, duration=0.1, method="exact", torque=[torques.gravity(MASS, LENGTH, G)])
    with pytest.raises(ScenarioError, match=r"torque\[1\]: 3 is not callable"):
        rotframe.simulate_body(**TOP, duration=0.1, torque=[torques.gravity(MASS, LENGTH, G), 3])


#: what a torque of your own below reads at each run (a module global: its value is part of its compiled glue)
SPIN_UP = 1e-3


def _spin_up(t, L, q):
    return 0.0, 0.0, SPIN_UP


def test_a_torque_of_yours_is_read_afresh_at_every_run_however_it_is_marked():
    """A run's set-up is kept only for the built-in torques (their constants are their own): a torque of yours,
    even marked as taking no params, is fingerprinted at every run, so a value it reads that changed is seen."""
    global SPIN_UP
    from rotframe.problem.body import simulate_rigid_body

    torque = rotframe.Torque(_spin_up, attitude_only=True, takes_params=False)

    def run():  # compiled (the plain tier would read the global as Python does, whatever the set-up kept)
        return simulate_rigid_body(**TOP, duration=1.0, torque=torque, method="lie-poisson", step=1e-3, samples=4,
                                   plain_tier=False)

    first = run()
    SPIN_UP = 2e-3
    try:
        second = run()
    finally:
        SPIN_UP = 1e-3
    # L3 grows by tau3 t (the gravity-free body's torque is along its symmetry axis)
    assert second.L[-1, 2] - TOP["L0"][2] == pytest.approx(2 * (first.L[-1, 2] - TOP["L0"][2]), rel=1e-9)
