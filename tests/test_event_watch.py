"""The fixed-step drivers' watch loop for one event is the general event loop, bitwise.

A run with one event takes the watch loop (rotframe.particles.events.watch_steps); the same
run with a second event that never fires takes the general loop over the event table. Both
must give the same samples, event times and event states, bit for bit, for every fixed-step
method, event kind, direction and terminal flag.
"""

import numpy as np
import pytest

from rotframe.particles.integrators import Event, integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel

NEVER = Event("never", "r", 0, 1e9, 0, False)


def _model(kind):
    w = np.array([0.0, 4.6e-5, 5.7e-5]) * (1.0 if kind != "spin" else 2e3)
    if kind == "pendulum":
        return ParticleModel(("gravity", "coriolis", "pendulum"), omega=OmegaSchedule.constant(w),
                             g=np.array([0.0, 0.0, -9.81]), pendulum_length=2.0, pivot=np.array([0.0, 0.0, 2.0]))
    terms = ("gravity", "coriolis", "centrifugal", "quadratic-drag") if kind == "drag" else ("gravity", "coriolis")
    kw = {"k_quadratic": 1e-3} if kind == "drag" else {}
    return ParticleModel(terms, omega=OmegaSchedule.constant(w), g=np.array([0.0, 0.0, -9.81]), **kw)


def _compare(model, r0, v0, duration, method, event, samples=7):
    a = integrate_particles(model, r0, v0, duration, method=method, step=duration / samples / 13, samples=samples,
                            events=[event])
    b = integrate_particles(model, r0, v0, duration, method=method, step=duration / samples / 13, samples=samples,
                            events=[event, NEVER])
    assert np.array_equal(a.r, b.r) and np.array_equal(a.v, b.v)
    hits = 0
    for ta, tb, sa, sb in zip(a.event_times[event.name], b.event_times[event.name], a.event_states[event.name],
                              b.event_states[event.name]):
        assert np.array_equal(ta, tb) and np.array_equal(sa, sb)
        hits += len(ta)
    return hits


@pytest.mark.parametrize("method", ["rotation-splitting", "rotation-splitting4", "rk4"])
@pytest.mark.parametrize("event", [Event("ground", "r", 2, 0.0, -1, True), Event("z", "r", 2, 5.0, 0, False),
                                   Event("apex", "v", 2, 0.0, -1, False), Event("alt", "altitude", 0, 2.0, 0, True),
                                   Event("x", "r", 0, 0.3, 1, False)])
def test_one_event_is_the_general_loop(method, event):
    rng = np.random.default_rng(3)
    r0 = rng.normal(size=(5, 3)) + [0, 0, 8.0]
    v0 = rng.normal(size=(5, 3)) * 3 + [0, 0, 6.0]
    model = _model("drag" if method == "rk4" else "plain")
    assert _compare(model, r0, v0, 4.0, method, event) > 0  # the events fire


def test_one_event_on_the_sphere_is_the_general_loop():
    model = _model("pendulum")
    r0 = np.array([[0.5, 0.0, 2.0 - np.sqrt(4.0 - 0.25)], [0.0, 0.4, 2.0 - np.sqrt(4.0 - 0.16)]])
    v0 = np.zeros((2, 3))
    assert _compare(model, r0, v0, 6.0, "rotation-splitting", Event("x0", "r", 0, 0.0, 0, False)) > 0
