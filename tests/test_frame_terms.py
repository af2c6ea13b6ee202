"""``rotframe.simulate(frame_terms=...)``: which of the frame's terms act, against oracles written here.

The oracles are independent of rotframe's frame and stepping code: closed forms (the inertial
circle of the Coriolis term alone, the cosh/sinh of the centrifugal term alone, the straight line
of none), and scipy's ``solve_ivp`` on a right-hand side written in numpy below, for every subset
of the three terms in a frame whose omega turns and grows (so that the Euler term acts), under
each method of the engine. The Foucault pendulum on the engine (the local gravity, the string,
the Coriolis term alone: the scene's own model) is checked against the scene's kernels, a second
integrator of the same equations.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rotframe
from inertial_circle import inertial_circle
from rotframe import forces
from rotframe.errors import ScenarioError
from rotframe.problem.terms import FRAME_TERMS, check_frame_terms
from rotframe.problem.particles import simulate_particles


def omega_fn(t):
    """A frame whose axis turns and whose rate grows (rad/s, frame axes): every term acts."""
    return np.array([0.3 * np.sin(0.6 * t), 0.2 * np.cos(0.4 * t), 0.8 + 0.1 * t])


def omega_dot_fn(t):
    return np.array([0.18 * np.cos(0.6 * t), -0.08 * np.sin(0.4 * t), 0.1])


def pull(t, r, v):
    """A force of (t, r) alone (the splittings kick with it): a spring towards the origin, forced in x."""
    return -0.5 * r[0] + 0.2 * math.cos(t), -0.5 * r[1], -0.5 * r[2]


def oracle(terms, r0, v0, times):
    """scipy's DOP853 at rtol 1e-13 on r'' = pull - (the chosen frame terms), written here in numpy."""
    def rhs(t, y):
        r, v = y[:3], y[3:]
        w, wd = omega_fn(t), omega_dot_fn(t)
        a = np.array([-0.5 * r[0] + 0.2 * math.cos(t), -0.5 * r[1], -0.5 * r[2]])
        if "coriolis" in terms:
            a -= 2.0 * np.cross(w, v)
        if "centrifugal" in terms:
            a -= np.cross(w, np.cross(w, r))
        if "euler" in terms:
            a -= np.cross(wd, r)
        return np.concatenate([v, a])

    sol = solve_ivp(rhs, (0.0, times[-1]), np.concatenate([r0, v0]), method="DOP853", t_eval=times, rtol=1e-13,
                    atol=1e-15)
    return sol.y[:3].T, sol.y[3:].T


SUBSETS = [tuple(c) for n in range(4) for c in itertools.combinations(FRAME_TERMS, n)]
R0 = np.array([1.0, -0.5, 0.3])
V0 = np.array([0.2, 0.4, -0.1])
DURATION = 3.0


@pytest.mark.parametrize("method, settings, tol", [
    ("dop853", {"rtol": 1e-12}, 1e-9),
    ("rk4", {"step": 1e-3}, 1e-9),  # global error ~ h^4
    ("rotation-splitting4", {"step": 1e-3}, 1e-9),
])
def test_every_subset_of_the_frame_terms_against_scipy(method, settings, tol):
    for terms in SUBSETS:
        res = rotframe.simulate(omega=omega_fn, omega_dot=omega_dot_fn, r0=R0, v0=V0, duration=DURATION,
                                forces=[pull], method=method, samples=6, frame_terms=terms, **settings)
        t = res.trajectory.times
        r, v = oracle(terms, R0, V0, t)
        err = max(np.max(np.abs(res.trajectory.r[:, 0] - r)), np.max(np.abs(res.trajectory.v[:, 0] - v)))
        assert err < tol, (terms, method, err)


def test_the_terms_change_the_motion():
    """The oracle test would pass if frame_terms were ignored only were the terms negligible: they are not."""
    t = np.linspace(0.0, DURATION, 7)
    paths = [oracle(terms, R0, V0, t)[0][-1] for terms in SUBSETS]
    gaps = [np.linalg.norm(a - b) for a, b in itertools.combinations(paths, 2)]
    assert min(gaps) > 1e-3


W_F = np.array([0.0, 0.0, 0.7e-4])  # an f-plane: omega vertical (rad/s)


@pytest.mark.parametrize("method", ["dop853", "rk4", "rotation-splitting", "rotation-splitting4"])
def test_coriolis_alone_turns_the_velocity_clockwise_at_2_omega(method):
    """The inertial oscillation: v turns at -f, f = 2 w_z, and the puck circles with radius |v| / f.

    The splittings turn v exactly (the Coriolis flow); the order-2 one drifts r with an error of
    order (f h)^2 of the radius, the others stay within 1e-8 of it."""
    f = 2.0 * W_F[2]
    period = 2.0 * math.pi / f
    h = period / 4000
    v0 = np.array([3.0, 1.0, 0.0])
    res = rotframe.simulate(omega=W_F, r0=[0.0, 0.0, 0.0], v0=v0, duration=period, method=method, samples=40,
                            frame_terms=("coriolis",), step=None if method == "dop853" else h)
    r, v = inertial_circle(f, v0, res.trajectory.times)
    speed = np.linalg.norm(v0)
    assert np.max(np.abs(res.trajectory.v[:, 0] - v)) < 1e-8 * speed
    tol = (f * h) ** 2 if method == "rotation-splitting" else 1e-8
    assert np.max(np.abs(res.trajectory.r[:, 0] - r)) < tol * speed / f


def test_centrifugal_alone_flings_outwards_as_cosh():
    """r'' = w^2 r in the plane normal to omega: x = x0 cosh(w t) + (vx0 / w) sinh(w t); z untouched."""
    w = 0.5
    res = rotframe.simulate(omega=[0.0, 0.0, w], r0=[1.0, 0.0, 2.0], v0=[0.3, 0.0, 0.1], duration=4.0,
                            rtol=1e-12, samples=8, frame_terms=["centrifugal"])
    t = res.trajectory.times
    x = np.cosh(w * t) + 0.3 / w * np.sinh(w * t)
    z = 2.0 + 0.1 * t
    assert np.max(np.abs(res.trajectory.r[:, 0, 0] - x)) < 1e-9 * np.max(x)
    assert np.max(np.abs(res.trajectory.r[:, 0, 1])) == 0.0
    assert np.max(np.abs(res.trajectory.r[:, 0, 2] - z)) < 1e-9 * np.max(z)


def test_no_frame_terms_is_a_straight_line_in_the_rotating_axes():
    r0, v0 = np.array([1.0, 2.0, 3.0]), np.array([3.0, 1.0, -2.0])
    res = rotframe.simulate(omega=omega_fn, r0=r0, v0=v0, duration=10.0, samples=5, frame_terms=())
    t = res.trajectory.times[:, None]
    assert np.max(np.abs(res.trajectory.r[:, 0] - (r0 + t * v0))) < 1e-12 * 30.0
    assert np.all(res.trajectory.v[:, 0] == v0)


def test_the_default_is_every_term_to_the_bit():
    kwargs = dict(omega=omega_fn, omega_dot=omega_dot_fn, r0=R0, v0=V0, duration=1.0, forces=[pull], samples=4)
    default = rotframe.simulate(**kwargs)
    explicit = rotframe.simulate(**kwargs, frame_terms=("Euler", "coriolis", "CENTRIFUGAL"))
    assert np.array_equal(default.trajectory.r, explicit.trajectory.r)
    assert np.array_equal(default.trajectory.v, explicit.trajectory.v)
    assert default.to_dict()["model"][-3:] == ["coriolis", "centrifugal", "euler"]


def test_the_summary_model_lists_the_terms_that_acted():
    res = rotframe.simulate(omega=W_F, r0=[0.0, 0.0, 0.0], v0=[1.0, 0.0, 0.0], duration=1.0, samples=2,
                            forces=[forces.gravity([0.0, 0.0, -9.8])], frame_terms="coriolis")
    assert res.to_dict()["model"] == ["gravity", "coriolis"]


@pytest.mark.parametrize("terms, name", [(("coriolis",), "energy"), (("coriolis", "centrifugal"), "jacobi"),
                                         (("centrifugal",), "jacobi")])
def test_the_conserved_quantity_follows_the_centrifugal_term(terms, name):
    """Coriolis does no work: v^2/2 + U is kept without the centrifugal term, the Jacobi integral with it.

    The oracle of the quantity: it is computed here from the samples (numpy), and must be constant
    to the integrator's tolerance; the other one must not be (the test would pass on a wrong name
    only if both were constant).
    """
    k = 0.04
    spring = forces.spring(k)
    w = np.array([0.0, 0.0, 0.1])
    res = rotframe.simulate(omega=w, r0=[1.0, 0.0, 0.0], v0=[0.0, 0.3, 0.2], duration=60.0, rtol=1e-12, samples=50,
                            forces=[spring], frame_terms=terms)
    r, v = res.trajectory.r[:, 0], res.trajectory.v[:, 0]
    energy = 0.5 * np.sum(v * v, axis=1) + 0.5 * k * np.sum(r * r, axis=1)
    jacobi = energy - 0.5 * np.sum(np.cross(w, r) ** 2, axis=1)
    kept, other = (energy, jacobi) if name == "energy" else (jacobi, energy)
    assert np.ptp(kept) < 1e-10 * abs(kept[0])
    assert np.ptp(other) > 1e-4 * abs(other[0])
    assert res.diagnostics[f"{name}_rel_drift"] < 1e-10
    assert not any(key.endswith("_rel_drift") and not key.startswith(name) for key in res.diagnostics)


def foucault_model():
    """The Foucault scene's model in Paris: omega (rad/s), the local g, the string's length and pivot, a bob 3 m out."""
    lat = math.radians(48.85)
    w = 7.292115e-5 * np.array([0.0, math.cos(lat), math.sin(lat)])
    L = 67.0
    return w, np.array([0.0, 0.0, -9.81]), L, np.array([0.0, 0.0, L]), np.array([3.0, 0.0, L - math.sqrt(L * L - 9.0)])


@pytest.mark.parametrize("terms", [("coriolis",), ("coriolis", "centrifugal"), ()])
@pytest.mark.parametrize("method, step", [("dop853", None), ("rotation-splitting4", 0.01)])
def test_foucault_on_the_engine_matches_the_scenes_kernels(method, step, terms):
    """The Foucault scene's model (local gravity, the string, Coriolis alone: the first case) run by the engine and
    by the scene's own kernels (`rotframe.particles.integrators`), a second integrator of the same equations: they
    agree to their tolerance, and each choice of the frame's terms moves the bob apart from the others.

    The engine's splitting runs on the string's sphere, with the Coriolis turn about the string
    (order 4: (w0 h)^4 ~ 2e-10 at this step, w0 = sqrt(g / L))."""
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    w, g, L, pivot, r0 = foucault_model()
    v0 = np.zeros(3)

    def engine(chosen):
        return rotframe.simulate(omega=w, r0=r0, v0=v0, duration=120.0, rtol=1e-12, samples=12, method=method,
                                 step=step, forces=[forces.gravity(g), forces.pendulum(L, pivot)],
                                 frame_terms=chosen).trajectory.r[:, 0]

    def scene(chosen):
        model = ParticleModel(("gravity", *chosen, "pendulum"), omega=OmegaSchedule.constant(w), g=g,
                              pendulum_length=L, pivot=pivot)
        return integrate_particles(model, r0, v0, 120.0, method="dop853", rtol=1e-12, samples=12).r[:, 0]

    r = engine(terms)
    assert np.max(np.abs(r - scene(terms))) < 1e-8 * 3.0
    assert np.max(np.abs(np.linalg.norm(r - pivot, axis=1) - L)) < 1e-9 * L  # on the string's sphere
    for other in [("coriolis",), ("coriolis", "centrifugal"), ()]:
        if other != terms:
            assert np.max(np.abs(r - scene(other))) > 1e-6, other


@pytest.mark.parametrize("value, words", [
    (("corioli",), ["'corioli'", "coriolis, centrifugal, euler"]),
    (("coriolis", 3), ["3", "allowed"]),
    (5, ["frame_terms=5", "sequence of names"]),
])
def test_a_bad_frame_term_is_named_in_one_line(value, words):
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=W_F, r0=[0.0, 0.0, 0.0], v0=[1.0, 0.0, 0.0], duration=1.0, frame_terms=value)
    text = str(info.value)
    assert "\n" not in text and "frame_terms" in text
    for word in words:
        assert word in text


def test_check_frame_terms_keeps_the_canonical_order():
    assert check_frame_terms(None) == FRAME_TERMS
    assert check_frame_terms(["euler", "Coriolis", "euler"]) == ("coriolis", "euler")
    assert check_frame_terms("centrifugal") == ("centrifugal",)
    assert check_frame_terms([]) == ()


@pytest.mark.parametrize("inline", [False, True])
def test_foucault_under_dop853_at_the_scenes_tolerance_is_the_scenes_run_to_the_bit(inline):
    """One DOP853 loop: the Foucault model on the engine, given the scene's absolute tolerance (rtol times the largest
    start value), takes the scene's very steps and gives its numbers to the bit, in the engine's loop and in the
    inlined one (docs/architecture.md)."""
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    w, g, L, pivot, r0 = foucault_model()
    rtol = 1e-10
    atol = rtol * max(1.0, float(np.max(np.abs(r0))))  # the scene's rule (`rotframe.particles.chunked`, abs_tol)
    engine = simulate_particles(omega=w, r0=r0, v0=np.zeros(3), duration=120.0, rtol=rtol, atol=atol, samples=12,
                                forces=[forces.gravity(g), forces.pendulum(L, pivot)], frame_terms=("coriolis",),
                                inline=inline).trajectory
    model = ParticleModel(("gravity", "coriolis", "pendulum"), omega=OmegaSchedule.constant(w), g=g,
                          pendulum_length=L, pivot=pivot)
    scene = integrate_particles(model, r0, np.zeros(3), 120.0, method="dop853", rtol=rtol, samples=12)
    assert engine.steps == scene.steps > 10
    assert np.array_equal(engine.r, scene.r) and np.array_equal(engine.v, scene.v)
