"""``rotframe.simulate(method="exact")``: the exact flow of a linear problem, against oracles written here.

The oracles are closed forms (the inertial circle, the cyclotron orbit and its E x B drift, the
damped oscillator, the parabola of an accelerating origin, the inertial straight line seen from
the turning frame, with scipy's ``Rotation``), scipy's ``solve_ivp`` on a right-hand side written
here, and the scenes' exact flow of the same model (which the engine chooses: the same numbers to
the bit). Each class of term or frame the exact flow cannot take is refused by name.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import rotframe
from inertial_circle import inertial_circle
from rotframe import forces
from rotframe.errors import ScenarioError


def test_coriolis_alone_is_the_inertial_circle_and_the_scenes_exact_flow():
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    w = np.array([0.0, 0.0, 0.7e-4])
    f = 2.0 * w[2]
    period = 2.0 * math.pi / f
    v0 = np.array([3.0, 1.0, 0.0])
    res = rotframe.simulate(omega=w, r0=[0.0, 0.0, 0.0], v0=v0, duration=3 * period, method="exact", samples=90,
                            frame_terms=("coriolis",))
    r, v = inertial_circle(f, v0, res.trajectory.times)
    speed = np.linalg.norm(v0)
    assert np.max(np.abs(res.trajectory.v[:, 0] - v)) < 1e-12 * speed
    assert np.max(np.abs(res.trajectory.r[:, 0] - r)) < 1e-12 * speed / f
    assert res.method == "exact"
    scene = integrate_particles(ParticleModel(("coriolis",), omega=OmegaSchedule.constant(w)), [0.0, 0.0, 0.0], v0,
                                3 * period, method="exact", samples=90)
    # the same flow matrices to the bit; each particle's products summed in a fixed order (independent of N),
    # the scene's by BLAS: the same numbers to round-off
    assert np.max(np.abs(res.trajectory.r[:, 0] - scene.r[:, 0])) < 1e-14 * speed / f
    assert np.max(np.abs(res.trajectory.v[:, 0] - scene.v[:, 0])) < 1e-14 * speed


@pytest.mark.parametrize("B, E", [([0.0, 0.0, 0.5], [0.3, -0.2, 0.0]), ([0.3, -0.4, 0.5], [0.2, 0.1, -0.3])])
def test_the_cyclotron_orbit_and_the_e_cross_b_drift(B, E):
    """v' = (q/m)(E + v x B): with u = E x B / B^2 and w = v0 - u, v = u + w_par + (q/m) E_par t + R(-w_c t) w_perp,
    the part across B turned about B at w_c = (q/m) |B| (scipy's Rotation), E along B accelerating along it."""
    qm = 2.0
    B, E = np.array(B), np.array(E)
    v0 = np.array([1.0, 0.5, 0.25])
    b = B / np.linalg.norm(B)
    wc = qm * np.linalg.norm(B)
    u = np.cross(E, B) / (B @ B)
    w = v0 - u
    w_par, E_par = (w @ b) * b, (E @ b) * b
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=[0.0, 0.0, 0.0], v0=v0, duration=20.0, method="exact",
                            samples=40, forces=[forces.lorentz(qm, B, E)])
    t = res.trajectory.times
    turned = Rotation.from_rotvec(-wc * t[:, None] * b).apply(w - w_par)
    v = u + w_par + qm * t[:, None] * E_par + turned
    assert np.max(np.abs(res.trajectory.v[:, 0] - v)) < 1e-12 * np.max(np.abs(v))


def test_a_damped_spring_about_its_anchor():
    """x'' = -k (x - a) - c x' per axis: x = a + exp(-c t / 2)(A cos(wd t) + B sin(wd t))."""
    k, c = 4.0, 0.3
    anchor = np.array([1.0, -2.0, 0.5])
    r0, v0 = np.array([0.0, 0.0, 0.0]), np.array([0.5, 0.0, -1.0])
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=r0, v0=v0, duration=10.0, method="exact", samples=50,
                            forces=[forces.spring(k, anchor), forces.drag(linear=c)])
    t = res.trajectory.times[:, None]
    wd = math.sqrt(k - c * c / 4)
    A = r0 - anchor
    B = (v0 + c / 2 * A) / wd
    x = anchor + np.exp(-c * t / 2) * (A * np.cos(wd * t) + B * np.sin(wd * t))
    assert np.max(np.abs(res.trajectory.r[:, 0] - x)) < 1e-12 * 3.0


def test_a_horizontal_spring_under_gravity():
    """The scenes' small-angle pendulum: x and y pulled back to the anchor at rate sqrt(k), z falling freely."""
    k, g = 0.25, np.array([0.0, 0.0, -9.81])
    anchor = np.array([1.0, 2.0, 30.0])  # its height pulls nothing
    r0, v0 = np.array([0.0, 0.5, 10.0]), np.array([0.3, 0.0, 4.0])
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=r0, v0=v0, duration=6.0, method="exact", samples=12,
                            forces=[forces.spring(k, anchor, horizontal=True), forces.gravity(g)])
    t = res.trajectory.times[:, None]
    w = math.sqrt(k)
    xy = anchor[:2] + (r0[:2] - anchor[:2]) * np.cos(w * t) + v0[:2] / w * np.sin(w * t)
    z = r0[2] + v0[2] * t[:, 0] + 0.5 * g[2] * t[:, 0] ** 2
    assert np.max(np.abs(res.trajectory.r[:, 0, :2] - xy)) < 1e-12 * 3.0
    assert np.max(np.abs(res.trajectory.r[:, 0, 2] - z)) < 1e-12 * 100.0


def test_gravity_in_an_accelerating_frame_is_a_parabola():
    g, a0 = np.array([0.0, 0.0, -9.81]), np.array([0.5, 0.0, 2.0])
    r0, v0 = np.array([1.0, 2.0, 3.0]), np.array([4.0, 0.0, 10.0])
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=r0, v0=v0, duration=3.0, method="exact", samples=6,
                            forces=[forces.gravity(g)], origin_acceleration=a0)
    t = res.trajectory.times[:, None]
    assert np.max(np.abs(res.trajectory.r[:, 0] - (r0 + v0 * t + 0.5 * (g - a0) * t * t))) < 1e-12 * 50.0


def test_a_free_particle_is_the_inertial_line_seen_from_the_turning_frame():
    w = np.array([0.1, -0.2, 0.3])
    r0, v0 = np.array([1.0, 0.0, 2.0]), np.array([0.0, 0.5, -0.1])
    res = rotframe.simulate(omega=w, r0=r0, v0=v0, duration=50.0, method="exact", samples=25)
    t = res.trajectory.times
    line = r0 + t[:, None] * (v0 + np.cross(w, r0))
    seen = Rotation.from_rotvec(-t[:, None] * w).apply(line)
    assert np.max(np.abs(res.trajectory.r[:, 0] - seen)) < 1e-12 * np.max(np.abs(line))


@pytest.mark.parametrize("terms", [None, ("coriolis",), ("centrifugal",)])
def test_gravity_spring_and_the_frame_against_scipy(terms):
    """Every term of a linear problem at once, in a tilted steady frame, against scipy's DOP853 at rtol 1e-13."""
    w = np.array([0.05, 0.1, 0.2])
    g, k, c = np.array([0.0, -0.3, -1.0]), 0.5, 0.05
    r0, v0 = np.array([1.0, -1.0, 0.5]), np.array([0.2, 0.1, 0.0])
    chosen = ("coriolis", "centrifugal", "euler") if terms is None else terms

    def rhs(t, y):
        r, v = y[:3], y[3:]
        a = g - k * r - c * v
        if "coriolis" in chosen:
            a = a - 2.0 * np.cross(w, v)
        if "centrifugal" in chosen:
            a = a - np.cross(w, np.cross(w, r))
        return np.concatenate([v, a])

    res = rotframe.simulate(omega=w, r0=r0, v0=v0, duration=20.0, method="exact", samples=10, frame_terms=terms,
                            forces=[forces.gravity(g), forces.spring(k), forces.drag(linear=c)])
    t = res.trajectory.times
    sol = solve_ivp(rhs, (0.0, t[-1]), np.concatenate([r0, v0]), method="DOP853", t_eval=t, rtol=1e-13, atol=1e-15)
    assert np.max(np.abs(res.trajectory.r[:, 0] - sol.y[:3].T)) < 1e-10
    assert np.max(np.abs(res.trajectory.v[:, 0] - sol.y[3:].T)) < 1e-10


def test_an_ensemble_is_each_particle_alone():
    w = np.array([0.0, 0.3, 0.4])
    r0 = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 1.0], [3.0, -1.0, 0.5]])
    v0 = np.array([[0.0, 0.1, 0.0], [0.5, 0.0, -0.2], [0.0, 0.0, 1.0]])
    kw = dict(omega=w, duration=7.0, method="exact", samples=7, forces=[forces.gravity([0.0, 0.0, -1.0])])
    many = rotframe.simulate(r0=r0, v0=v0, **kw)
    for i in range(3):
        one = rotframe.simulate(r0=r0[i], v0=v0[i], **kw)
        assert np.array_equal(many.trajectory.r[:, i], one.trajectory.r[:, 0])


@pytest.mark.parametrize("terms, name", [(None, "jacobi"), (("coriolis",), "energy")])
def test_the_energy_diagnostic(terms, name):
    res = rotframe.simulate(omega=[0.0, 0.0, 0.1], r0=[1.0, 0.0, 0.0], v0=[0.0, 0.3, 0.2], duration=60.0,
                            method="exact", samples=50, frame_terms=terms,
                            forces=[forces.spring(0.04, [0.3, -0.2, 0.1]), forces.gravity([0.1, -0.2, -1.0])])
    assert res.diagnostics[f"{name}_rel_drift"] < 1e-10  # each potential exercised: a wrong one drifts
    assert len(res.diagnostics) == 1


def _wind(t, r, v):
    return 0.1, 0.0, 0.0


@pytest.mark.parametrize("kwargs, words", [
    ({"forces": [_wind]}, ["forces[0]", "a force of your own", "no linear form"]),
    ({"forces": [forces.gravity([0, 0, -1.0]), forces.drag(quadratic=0.01)]}, ["forces[1]", "quadratic-drag"]),
    ({"forces": [forces.drag(linear=0.1, scale_height=8000.0)]}, ["forces[0]", "linear-drag", "no linear form"]),
    ({"forces": [forces.altitude_gravity(9.8, 6.4e6)]}, ["forces[0]", "altitude-gravity"]),
    ({"forces": [forces.central_gravity(4e14, [0, 0, -6.4e6])]}, ["forces[0]", "central-gravity"]),
    ({"forces": [forces.pendulum(1.0, [0.0, 0.0, 1.0])], "r0": [0.0, 0.0, 0.0]}, ["forces[0]", "pendulum",
                                                                                   "not linear"]),
    ({"omega": lambda t: (0.0, 0.0, 0.1 * t)}, ["omega", "function", "constant"]),
    ({"omega": ([0.0, 1.0, 2.0], [[0, 0, 0.1], [0, 0, 0.2], [0, 0, 0.3]])}, ["omega", "table"]),
    ({"origin_acceleration": lambda t: (0.0, 0.0, t)}, ["origin_acceleration", "function"]),
    ({"events": [lambda t, r, v: r[2]]}, ["events[0]", "no other event function", "rotframe.events.crossing"]),
    ({"device": "gpu"}, ["gpu"]),  # no GPU here: refused for that; where one is, the registry refuses exact
])
def test_what_the_exact_flow_cannot_take_is_refused_by_name(kwargs, words):
    args = dict(omega=[0.0, 0.0, 0.1], r0=[0.0, 0.0, 1.0], v0=[0.0, 0.0, 0.0], duration=2.0, method="exact")
    args.update(kwargs)
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(**args)
    text = str(info.value)
    assert "\n" not in text
    for word in words:
        assert word in text


def test_methods_lists_exact_for_your_own_particles():
    exact = next(m for m in rotframe.methods() if m["name"] == "exact")
    assert "particles" in exact["runs"] and not exact["gpu"]


@pytest.mark.parametrize("method, given, flagged", [
    ("exact", {"step": 1.0, "atol": 1e-9}, ["step", "atol"]),
    ("exact", {"rtol": 1e-8}, ["rtol"]),
    ("dop853", {"step": 1.0, "rtol": 1e-9}, ["step"]),
    ("rk4", {"rtol": 1e-6, "atol": 1e-9, "step": 1.0}, ["rtol", "atol"]),
    ("rotation-splitting", {"step": 1.0}, []),
])
def test_a_setting_the_method_does_not_read_is_flagged_and_changes_nothing(method, given, flagged):
    """The scenes' rule (`rotframe.method_registry.unread_settings`) in ``rotframe.simulate``: each unread setting
    the caller gave is named in a warning, and two values of it give the same numbers to the bit."""
    kw = dict(omega=[0.0, 0.0, 1e-2], r0=[1.0, 0.0, 0.0], v0=[1.0, 0.0, 0.0], duration=10.0, method=method, samples=5)
    res = rotframe.simulate(**kw, **given)
    warned = [w.split(" = ")[0] for w in res.warnings if "is not used" in w]
    assert warned == flagged
    for key in flagged:
        other = rotframe.simulate(**kw, **dict(given, **{key: given[key] * 0.5}))
        assert np.array_equal(res.trajectory.r, other.trajectory.r)
