"""One event under the fixed-step methods: each crossing in its direction, at the closed form's time.

The fixed-step loop tests a step for a crossing of a single event without the step's start
(`rotframe.problem.fixed_step.quiet_step`) and hands the watcher only the steps that cross; these
cases hold it to the watcher's rules. The oracle is the closed form of a vertical throw under
uniform gravity, z(t) = z0 + v0 t - g t^2 / 2, which RK4 and the splittings integrate exactly (a
quadratic), so the events are at its times to round-off.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rotframe
from rotframe import forces
from rotframe.events import crossing

G = 9.81
LEVEL = 3.0
V0 = 10.0
METHODS = ["rk4", "rotation-splitting", "rotation-splitting4"]


def _crossings(z0):
    """The times a throw from z0 at V0 rises through LEVEL and falls through it (the closed form)."""
    d = math.sqrt(V0 * V0 - 2.0 * G * (LEVEL - z0))
    return (V0 - d) / G, (V0 + d) / G


def _run(method, z0, **event):
    r0 = [[0.0, 0.0, z] for z in z0]
    v0 = [[0.0, 0.0, V0]] * len(z0)
    return rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=r0, v0=v0, duration=2.5, forces=[forces.gravity([0.0, 0.0, -G])],
                             events=[crossing(2, LEVEL, name="level", **event)], method=method, step=0.01, samples=10)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("direction", [-1, 0, 1])
def test_each_crossing_in_its_direction_at_the_closed_forms_time(method, direction):
    z0 = [1.0, 2.0, 0.5]
    res = _run(method, z0, direction=direction)
    for p, z in enumerate(z0):
        up, down = _crossings(z)
        want = {0: [up, down], 1: [up], -1: [down]}[direction]
        np.testing.assert_allclose(res.trajectory.event_times["level"][p], want, rtol=0.0, atol=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_a_start_on_the_level_is_no_event_and_the_fall_through_it_is(method):
    res = _run(method, [LEVEL], direction=0)
    np.testing.assert_allclose(res.trajectory.event_times["level"][0], [2.0 * V0 / G], rtol=0.0, atol=1e-9)
    assert len(_run(method, [LEVEL], direction=1).trajectory.event_times["level"][0]) == 0


@pytest.mark.parametrize("method", METHODS)
def test_a_terminal_rise_stops_the_particle_on_the_level(method):
    res = _run(method, [1.0, 2.0], direction=1, terminal=True)
    for p, z in enumerate([1.0, 2.0]):
        up, _ = _crossings(z)
        np.testing.assert_allclose(res.trajectory.event_times["level"][p], [up], rtol=0.0, atol=1e-9)
        assert res.trajectory.r[-1, p, 2] == pytest.approx(LEVEL, abs=1e-9)  # the samples after it keep the event's state


@pytest.mark.parametrize("method", METHODS)
def test_a_hop_from_the_level_inside_the_first_step_returns_through_it(method):
    """The start rule (the sign just after the start): a hop of 2 ms from the level, inside the first step of 10 ms,
    falls through it then; a run that took the start's zero for the sign would miss it."""
    v_hop = 0.01
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=[0.0, 0.0, LEVEL], v0=[0.0, 0.0, v_hop], duration=0.05,
                            forces=[forces.gravity([0.0, 0.0, -G])], events=[crossing(2, LEVEL, name="level")],
                            method=method, step=0.01, samples=5)
    np.testing.assert_allclose(res.trajectory.event_times["level"][0], [2.0 * v_hop / G], rtol=0.0, atol=1e-12)


@pytest.mark.parametrize("method", METHODS + ["dop853"])
def test_two_terminal_events_in_one_step_keep_the_earliest(method):
    """Every event terminal: a particle keeps one record an event (`rotframe.problem.particle_setup.event_slots`),
    and the step that crosses both levels keeps the earlier crossing, the second event's, though the first event
    is recorded first. One step of 0.5 s takes the throw from 0.5 m through 3 m and 4 m (closed form, both rising)."""
    low, high = crossing(2, LEVEL, direction=1, terminal=True, name="low"), crossing(2, LEVEL + 1.0, direction=1,
                                                                                     terminal=True, name="high")
    res = rotframe.simulate(omega=[0.0, 0.0, 0.0], r0=[0.0, 0.0, 0.5], v0=[0.0, 0.0, V0], duration=2.0,
                            forces=[forces.gravity([0.0, 0.0, -G])], events=[high, low], method=method, step=0.5,
                            samples=4)
    d = math.sqrt(V0 * V0 - 2.0 * G * (LEVEL - 0.5))
    np.testing.assert_allclose(res.trajectory.event_times["low"][0], [(V0 - d) / G], rtol=0.0, atol=1e-9)
    assert len(res.trajectory.event_times["high"][0]) == 0
    assert res.trajectory.r[-1, 0, 2] == pytest.approx(LEVEL, abs=1e-9)


def test_an_ensemble_to_a_terminal_event_keeps_one_record_a_particle():
    """A terminal event's records are counted against the memory limit one a particle: 100,000 particles under a
    limit of 0.1 GB, which 256 records each (``max_events``' default, 64 bytes each) would exceed 16 times over."""
    from rotframe.limits import DEFAULT, applied

    n = 100_000
    r0 = np.zeros((n, 3))
    r0[:, 2] = np.linspace(1.0, 2.0, n)
    with applied(DEFAULT.with_overrides(max_memory=1e8)):
        res = rotframe.simulate(omega=[0.0, 0.0, 7.29e-5], r0=r0, v0=np.zeros((n, 3)), duration=0.7,
                                forces=[forces.gravity([0.0, 0.0, -G])], frame_terms=("coriolis",),
                                events=[crossing(2, 0.0, direction=-1, terminal=True, name="ground")],
                                method="rk4", step=0.01, samples=1)
    fall = np.array([t[0] for t in res.trajectory.event_times["ground"]])
    # omega along z: the Coriolis term acts on horizontal velocity alone, none here, so the fall is the vertical
    # closed form, which RK4 integrates exactly (a quadratic) and the locator finds to round-off
    np.testing.assert_allclose(fall, np.sqrt(2.0 * r0[:, 2] / G), rtol=1e-12)
