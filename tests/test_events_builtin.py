"""The built-in events (``rotframe.events``), and the tower-drop scene that runs on the engine with one.

Oracles:
- a user's event doing the same arithmetic as a built-in crossing: the same trajectory and event
  records to the bit under every method that runs functions (one route into one engine);
- closed forms: gravity and the Coriolis term alone have a closed-form motion for any rotation
  (`rotframe.analytic.coriolis_uniform_gravity`, sines and cosines, no matrix exponential), so
  the landing time is the root of its height, found here by bisection on that closed form; the
  exact flow locates its crossing on ``exp(M t)`` (the scenes' Newton iteration);
- the tower-drop scene on the engine against the scenes' own kernels (`integrate_particles` with
  the scenes' event row), another integrator of the same model: within each method's error.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rotframe
from rotframe import analytic, events, forces
from rotframe.errors import ScenarioError
from rotframe.problem.particles import simulate_particles

W = np.array([0.0, 4.6e-5, 5.7e-5])
G = np.array([0.0, 0.0, -9.81])
H = 100.0


def _ground_by_hand(t, r, v):
    return r[2] - 0.0


_ground_by_hand.terminal = True
_ground_by_hand.direction = -1


def _landing_by_the_closed_form():
    """The landing time: the root of z(t) of the closed form, by bisection to round-off."""
    def z(t):
        return analytic.coriolis_uniform_gravity(W, G, [0.0, 0.0, H], [0.0, 0.0, 0.0], t)[0][2]

    lo, hi = 0.0, 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if z(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def _drop(method, event, **kw):
    settings = {"step": 1e-3} if method in ("rk4", "rotation-splitting", "rotation-splitting4") else {}
    return simulate_particles(omega=W, r0=[0.0, 0.0, H], v0=[0.0, 0.0, 0.0], duration=6.0, samples=12,
                              forces=[forces.gravity(G)], events=[event], method=method, frame_terms=("coriolis",),
                              **settings, **kw).trajectory  # g the effective gravity: no centrifugal term


@pytest.mark.parametrize("method", ["dop853", "rk4", "rotation-splitting", "rotation-splitting4"])
def test_a_built_in_crossing_is_a_users_event_to_the_bit(method):
    ground = events.crossing(2, 0.0, direction=-1, terminal=True, name="ground")
    ours, theirs = _drop(method, ground), _drop(method, _ground_by_hand)
    np.testing.assert_array_equal(ours.r, theirs.r)
    np.testing.assert_array_equal(ours.v, theirs.v)
    np.testing.assert_array_equal(ours.event_times["ground"][0], theirs.event_times["_ground_by_hand"][0])
    np.testing.assert_array_equal(ours.event_states["ground"][0], theirs.event_states["_ground_by_hand"][0])


@pytest.mark.parametrize("method", ["exact", "dop853"])
def test_the_landing_is_the_closed_forms(method):
    """The exact flow locates the built-in crossing on the flow itself, to round-off; DOP853 to its tolerance."""
    ground = events.crossing(2, 0.0, direction=-1, terminal=True, name="ground")
    traj = _drop(method, ground, **({"rtol": 1e-12} if method == "dop853" else {}))
    t_hit = _landing_by_the_closed_form()
    (t,), = traj.event_times["ground"]
    r_hit, v_hit = analytic.coriolis_uniform_gravity(W, G, [0.0, 0.0, H], [0.0, 0.0, 0.0], t_hit)
    tol = 1e-13 if method == "exact" else 1e-9
    assert abs(t - t_hit) < tol * t_hit
    state = traj.event_states["ground"][0][0]
    assert np.max(np.abs(state[:2] - r_hit[:2])) < tol * H  # east and north at the landing
    assert abs(state[2]) < tol * H
    np.testing.assert_allclose(state[3:], v_hit, rtol=0, atol=tol * np.linalg.norm(v_hit))
    assert np.all(traj.r[traj.times > t, 0] == state[:3])  # a terminal event: the samples after it keep its state


def test_a_crossing_of_the_velocity_and_a_rising_one():
    """``of="v"`` crosses a velocity's coordinate (the apex of a throw, v_z = 0); ``direction=1`` only rising."""
    apex = events.crossing(2, 0.0, of="v", direction=-1, name="apex")
    up = events.crossing(2, 10.0, direction=1, name="up")
    traj = simulate_particles(omega=[0.0, 0.0, 0.0], r0=[0, 0, 0.0], v0=[0, 0, 20.0], duration=4.0, samples=8,
                              forces=[forces.gravity(G)], events=[apex, up], method="exact").trajectory
    (t_apex,), = traj.event_times["apex"]
    (t_up,), = traj.event_times["up"]  # passed on the way up only, not on the way down
    assert math.isclose(t_apex, 20.0 / 9.81, rel_tol=1e-14)
    assert math.isclose(t_up, (20.0 - math.sqrt(400.0 - 2 * 9.81 * 10.0)) / 9.81, rel_tol=1e-13)


@pytest.mark.parametrize("of,component,value,direction", [("r", 2, 10.0, 1), ("r", 0, -3.0, 0), ("v", 2, 5.0, -1),
                                                          ("v", 0, -8.0, 0)])
def test_a_crossings_function_and_the_row_the_exact_flow_reads_are_one_event(of, component, value, direction):
    """The function every other method calls and the triple the exact flow locates say the same: DOP853 at rtol
    1e-12 finds the exact flow's crossings to its tolerance (a function that disagreed with its ``crossing`` would
    put them elsewhere, or find none)."""
    ev = events.crossing(component, value, of=of, direction=direction, name="c")
    kw = dict(omega=[0.0, 0.1, 0.3], r0=[0.0, 1.0, 0.0], v0=[-10.0, 0.0, 20.0], duration=4.0, samples=8,
              forces=[forces.gravity(G)], events=[ev])
    exact = simulate_particles(method="exact", **kw).trajectory.event_times["c"][0]
    dop = simulate_particles(method="dop853", rtol=1e-12, **kw).trajectory.event_times["c"][0]
    assert len(exact) >= 1 and len(exact) == len(dop)
    np.testing.assert_allclose(dop, exact, rtol=0, atol=1e-9)


def test_the_exact_flow_refuses_an_event_of_your_own_by_name():
    with pytest.raises(ScenarioError, match=r"events\[1\].*rotframe.events.crossing"):
        simulate_particles(omega=W, r0=[0, 0, H], v0=[0, 0, 0], duration=6.0, forces=[forces.gravity(G)],
                           events=[events.crossing(2), _ground_by_hand], method="exact")


@pytest.mark.parametrize("kw,match", [
    (dict(component=3), "component=3"), (dict(component=True), "component=True"), (dict(of="x"), "of='x'"),
    (dict(value=float("nan")), "value=nan"), (dict(direction=2), "direction=2"), (dict(terminal=1), "terminal=1"),
    (dict(name="the ground"), "name='the ground'"),
])
def test_bad_arguments_are_one_line_errors(kw, match):
    kw = {"component": 2, **kw}
    with pytest.raises(ScenarioError, match=match):
        events.crossing(**kw)


# the tower-drop scene on the engine, against the scenes' own kernels running the same model

@pytest.mark.parametrize("method,extra,tol", [
    (None, {}, 1e-12),                                      # exact, the default
    ("dop853", {}, 1e-8),
    ("rk4", {"step": 1e-3}, 1e-10),
    ("rotation-splitting", {"step": 1e-3}, 1e-6),
    ("rotation-splitting4", {"step": 1e-3}, 1e-10),
    ("rotation-splitting", {"drag": 1e-3, "step": 1e-3}, 1e-6),  # quadratic drag: its exact flow in the splitting
    ("dop853", {"drag": 1e-3}, 1e-8),
])
def test_the_tower_drop_on_the_engine_lands_where_the_scenes_kernels_do(method, extra, tol):
    from rotframe.particles.integrators import integrate_particles
    from rotframe.scenes import tower_drop
    from rotframe.scenes.base import landing

    step = extra.pop("step", None)
    res = rotframe.run("tower-drop", method=method, **({"step": step} if step else {}), **extra)
    params = tower_drop.PARAMETERS(**{k: res.params[k] for k in ("height", "latitude", "drag", "g_model", "magnify")})
    model, r0, v0, duration, _ = tower_drop.build(params, ["gravity", "coriolis"])  # the scenario's model
    ref = integrate_particles(model, r0, v0, duration, method=res.method, step=step, samples=10,
                              events=[tower_drop.GROUND])
    t_ref, r_ref, _, landed = landing(ref)
    assert landed and res.metrics["fall_time_s"] > 0
    assert abs(res.metrics["fall_time_s"] - t_ref[-1]) < tol * t_ref[-1]
    east = abs(r_ref[-1, 0])
    assert abs(res.metrics["east_deflection_m"] - r_ref[-1, 0]) < tol * params.height + 1e-12 * east
    assert abs(res.metrics["north_deflection_m"] - r_ref[-1, 1]) < tol * params.height + 1e-12 * east


R_BALL = 6.371e6


def _altitude_by_hand(t, r, v):
    dz = r[2] + R_BALL
    return math.sqrt(r[0] * r[0] + r[1] * r[1] + dz * dz) - R_BALL - 0.0


_altitude_by_hand.terminal = True
_altitude_by_hand.direction = -1


def _above_a_kilometre(t, r, v):
    dz = r[2] + R_BALL
    return math.sqrt(r[0] * r[0] + r[1] * r[1] + dz * dz) - R_BALL - 1000.0


def test_an_altitude_of_its_own_value_is_crossed_going_up_and_down():
    """``value`` is the height crossed: a shell passing 1 km on the way up and on the way down, as a user's function
    of that height says, to the bit."""
    up_and_down = events.altitude(R_BALL, 1000.0, name="km")
    kw = dict(omega=W, r0=[0.0, 0.0, 0.0], v0=[300.0, 0.0, 300.0], duration=60.0, samples=12,
              forces=[forces.gravity(G)], method="dop853")
    ours = simulate_particles(events=[up_and_down], **kw).trajectory
    theirs = simulate_particles(events=[_above_a_kilometre], **kw).trajectory
    np.testing.assert_array_equal(ours.event_times["km"][0], theirs.event_times["_above_a_kilometre"][0])
    assert len(ours.event_times["km"][0]) == 2  # up through 1 km and down again (apex 4.6 km)


@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_a_built_in_altitude_is_a_users_event_to_the_bit(method):
    ground = events.altitude(R_BALL, direction=-1, terminal=True, name="ground")
    settings = {"step": 0.05} if method == "rk4" else {}
    kw = dict(omega=W, r0=[0.0, 0.0, 0.0], v0=[800.0, 0.0, 800.0], duration=200.0, samples=20,
              forces=[forces.gravity(G)], method=method, **settings)
    ours = simulate_particles(events=[ground], **kw).trajectory
    theirs = simulate_particles(events=[_altitude_by_hand], **kw).trajectory
    np.testing.assert_array_equal(ours.r, theirs.r)
    np.testing.assert_array_equal(ours.event_times["ground"][0], theirs.event_times["_altitude_by_hand"][0])
    # beyond the flat ground's landing (z = 0 at 2 v_z / g): the round Earth falls away under the shell
    (t_hit,), = ours.event_times["ground"]
    assert t_hit > 2 * 800.0 / 9.81


@pytest.mark.parametrize("method,sets,terms,tol", [
    (None, {}, (), 1e-9),                                                    # exact, the default
    (None, {"drag": 1e-5}, (), 1e-7),                                        # dop853 with drag in thin air
    (None, {}, ("curvature", "central-gravity"), 1e-7),                      # dop853, the curved ground's altitude
    ("rk4", {"step": 0.05}, ("curvature",), 1e-7),
])
def test_the_projectile_on_the_engine_lands_where_the_scenes_kernels_do(method, sets, terms, tol, tmp_path):
    """Range, lateral deflection and flight time of the scene on the engine against the scenes' kernels running
    the same model and ground (`integrate_particles`), each within its method's error of the other."""
    from rotframe.particles.integrators import integrate_particles
    from rotframe.scenes import projectile
    from rotframe.scenes.base import landing

    scn = tmp_path / "p.toml"
    scn.write_text('scene = "projectile"\nname = "p"\nmodel = ' + str(["gravity", "coriolis", *terms]).replace("'", '"')
                   + "\n")
    step = sets.pop("step", None)
    res = rotframe.run(str(scn), method=method, **({"step": step} if step else {}), **sets)
    params = projectile.PARAMETERS(**{k: v for k, v in res.params.items()
                                      if k in projectile.PARAMETERS.__dataclass_fields__})
    model, r0, v0, ground, duration, _ = projectile.build(params, ["gravity", "coriolis", *terms])
    ref = integrate_particles(model, r0, v0, duration, method=res.method, step=step, samples=50, events=[ground])
    t_ref, r_ref, _, landed = landing(ref)
    rng, lateral = projectile.ground_track(params, r_ref, model)
    assert landed and abs(res.metrics["flight_time_s"] - t_ref[-1]) < tol * t_ref[-1]
    assert abs(res.metrics["range_m"] - rng[-1]) < tol * abs(rng[-1])
    assert abs(res.metrics["lateral_deflection_m"] - lateral[-1]) < tol * abs(rng[-1])


# a scene's model as the engine's terms (scenes.base.engine_terms): every named term mapped to its built-in factory

_W_SITE = np.array([0.0, 4.6e-5, 5.7e-5])


@pytest.mark.parametrize("terms,kw,r0,v0,T", [
    (("altitude-gravity", "coriolis", "centrifugal"), dict(g0=9.81, radius=6.371e6), [0, 0, 2.0e4], [300.0, 0, 50.0],
     60.0),
    (("central-gravity", "coriolis"), dict(gm=3.986e14, radius=6.371e6), [0, 0, 1.0e5], [1500.0, 200.0, 500.0], 100.0),
    (("gravity", "linear-drag", "quadratic-drag", "coriolis"), dict(g=np.array([0, 0, -9.81]), k_linear=0.02,
                                                                    k_quadratic=3e-4, scale_height=8000.0),
     [0, 0, 100.0], [80.0, 10.0, 60.0], 20.0),
    (("spring", "coriolis"), dict(spring=0.15), [3.0, 0, 0], [0, 0.1, 0], 60.0),
    (("gravity", "pendulum", "coriolis", "euler"), dict(g=np.array([0, 0, -9.81]), pendulum_length=10.0,
                                                        pivot=np.array([0, 0, 10.0])),
     [1.0, 0, 10.0 - math.sqrt(99.0)], [0, 0, 0], 30.0),
])
def test_a_scenes_model_on_the_engine_is_the_same_motion(terms, kw, r0, v0, T):
    """The model run by the scenes' kernels and its `engine_terms` run by the engine, both DOP853 at rtol 1e-12: the
    same motion to the tolerance (a term mapped to the wrong factory or constant would part them far more)."""
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel
    from rotframe.scenes.base import engine_terms

    model = ParticleModel(terms, omega=OmegaSchedule.constant(_W_SITE), **kw)
    omega, fs, frame_terms = engine_terms(model)
    assert frame_terms == tuple(t for t in terms if t in ("coriolis", "centrifugal", "euler"))
    ref = integrate_particles(model, np.array(r0, float), np.array(v0, float), T, method="dop853", rtol=1e-12,
                              samples=10)
    ours = simulate_particles(omega=omega, r0=r0, v0=v0, duration=T, forces=fs, frame_terms=frame_terms,
                              method="dop853", rtol=1e-12, samples=10).trajectory
    scale = np.max(np.abs(ref.r))
    assert np.max(np.abs(ours.r - ref.r)) < 1e-9 * scale
    assert np.max(np.abs(ours.v - ref.v)) < 1e-9 * np.max(np.abs(ref.v))


def test_a_term_the_engine_lacks_and_a_varying_rate_are_refused_by_name():
    from rotframe.particles.model import OmegaSchedule, ParticleModel
    from rotframe.scenes.base import engine_terms

    ramp = ParticleModel(("coriolis",), omega=OmegaSchedule.ramp([0, 0, 1.0], 1.0, 0.2, 4.0))
    with pytest.raises(ScenarioError, match="varies"):
        engine_terms(ramp)
    curved = ParticleModel(("gravity", "coriolis", "curvature"), omega=OmegaSchedule.constant(_W_SITE),
                           g=np.array([0, 0, -9.81]), radius=6.371e6)
    assert [f.name for f in engine_terms(curved)[1]] == ["gravity"]  # the curved ground is the scene's event
