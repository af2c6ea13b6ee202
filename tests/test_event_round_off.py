"""Every event locator brackets a crossing to round-off in time, however small the crossing's offset in its step.

A crossing at tau = 1e-100 s inside a step of some 0.01 s needs some 320 halvings of the
bracket, one at 1e-300 s some 990. The scenes' locators bisect until the bracket cannot shrink
(`rotframe.numerics.bisection`); the engine of `rotframe.simulate` once stopped after 200 and
reported the first crossing at 2e-62 s. Here a free particle moving at 1 m/s from x = 0
crosses x = c at t = c exactly, and every trial state is x = tau to one rounding, so the
located time must be c to a few ulp.
"""

import math

import numpy as np
import pytest

import rotframe
from rotframe.particles.integrators import Event, integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel

OFFSETS = [1e-100, 1e-300]


def _ulps(got, want):
    return abs(got - want) / math.ulp(want)


@pytest.mark.parametrize("c", OFFSETS)
@pytest.mark.parametrize("method", ["dop853", "rk4", "rotation-splitting"])
def test_a_user_event_a_hair_after_the_start_is_located_to_round_off(method, c):
    def crossing(t, r, v):
        return r[0] - c

    crossing.direction = 1
    step = {} if method == "dop853" else {"step": 0.01}
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=[0.0, 0.0, 0.0], v0=[1.0, 0.0, 0.0], duration=1.0,
                            events=[crossing], samples=4, method=method, **step)
    times = res.trajectory.event_times["crossing"][0]
    assert len(times) == 1
    assert _ulps(times[0], c) <= 4, (times[0], c)


@pytest.mark.parametrize("c", OFFSETS)
@pytest.mark.parametrize("method", ["dop853", "rk4", "rotation-splitting"])
def test_a_scene_event_a_hair_after_the_start_is_located_to_round_off(method, c):
    # the scenes' drivers (a position event row), for the same crossing
    model = ParticleModel(("coriolis",), omega=OmegaSchedule.constant([0.0, 0.0, 0.0]), g=np.zeros(3))
    event = Event("crossing", "r", 0, c, 1, False)
    step = {} if method == "dop853" else {"step": 0.01}
    traj = integrate_particles(model, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 1.0, method=method, samples=4,
                               events=[event], **step)
    times = traj.event_times["crossing"][0]
    assert len(times) == 1
    assert _ulps(times[0], c) <= 4, (times[0], c)


# a function exactly zero at the start takes the sign it has just after it: the start is never an event, and a hop
# shorter than the first step still lands (docs/physics/events.md)

def _hop(method, vz, use_scene):
    g = 9.81
    step = {} if method == "dop853" else {"step": 0.01}
    if use_scene:
        model = ParticleModel(("gravity",), omega=OmegaSchedule.constant([0.0, 0.0, 0.0]), g=np.array([0.0, 0.0, -g]))
        traj = integrate_particles(model, [0.0, 0.0, 0.0], [1.0, 0.0, vz], 1.0, method=method, samples=4,
                                   events=[Event("ground", "r", 2, 0.0, -1, True)], **step)
        return traj.event_times["ground"][0], traj.r[-1, 0]

    def gravity(t, r, v):
        return np.array([0.0, 0.0, -g])

    def ground(t, r, v):
        return r[2]

    ground.direction = -1
    ground.terminal = True
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=[0.0, 0.0, 0.0], v0=[1.0, 0.0, vz], duration=1.0,
                            forces=[gravity], events=[ground], samples=4, method=method, **step)
    return res.trajectory.event_times["ground"][0], res.trajectory.r[-1, 0]


@pytest.mark.parametrize("use_scene", [False, True], ids=["simulate", "scene"])
@pytest.mark.parametrize("method", ["dop853", "rk4", "rotation-splitting"])
@pytest.mark.parametrize("vz", [1e-3, 1e-12])
def test_a_hop_inside_the_first_step_lands(method, use_scene, vz):
    # fired up at 1 mm/s (or 1 pm/s) from the ground: it lands at 2 v / g = 0.2 ms (0.2 ps), inside the first step of
    # every method; at 1 pm/s g is ruled by gravity's term down to trials of some 1e-13 s, and only below by v
    g = 9.81
    times, final = _hop(method, vz, use_scene)
    assert len(times) == 1
    assert abs(times[0] - 2 * vz / g) <= 1e-12 * (2 * vz / g), times
    assert abs(final[2]) <= 1e-15  # stopped on the ground, not fallen through it


@pytest.mark.parametrize("use_scene", [False, True], ids=["simulate", "scene"])
@pytest.mark.parametrize("method", ["dop853", "rk4", "rotation-splitting"])
@pytest.mark.parametrize("vz", [-1e-3, 0.0])
def test_fired_into_the_ground_is_no_event(method, use_scene, vz):
    # down, or level (g's first derivative zero, its second -g: below the ground just after the start)
    times, final = _hop(method, vz, use_scene)
    assert len(times) == 0
    assert final[2] < -1.0  # it went on down: nothing stopped it
