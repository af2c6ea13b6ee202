"""A particle problem set up once and run many times (`rotframe.problem.prepared.PreparedProblem`).

The oracle is `simulate_particles` itself with the same arguments, whose physics the other suites check
against closed forms, scipy and mpmath: what is checked here is that a prepared run is the same computation
(the same set-up, loop and steps, so the same numbers to the bit), that each run starts from its own states,
and that it refuses and fails as ``simulate`` does.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotframe import forces
from rotframe.errors import IntegrationError, ScenarioError
from rotframe.problem.particles import Force, simulate_particles
from rotframe.problem.prepared import PreparedProblem
from raising_force import raise_after_one_second


@pytest.fixture(autouse=True)
def _compiled_from_the_start(monkeypatch):
    """simulate's runs here begin compiled, whatever the caches hold: these tests compare its counts of right-hand
    sides with a prepared run's, and each call begins with one, where the plain tier's calls are shorter
    (`rotframe.problem.tiers`; its numbers are the compiled loop's to the bit: tests/test_tiers.py)."""
    from rotframe.problem import tiers

    monkeypatch.setattr(tiers, "PLAIN_PARTICLES", 0)


def pull(t, r, v, k):
    return -k * r[0] + 0.1 * math.sin(t), -k * r[1], -k * r[2] - 0.05 * v[2]


def inertial_push(t, r, v):
    return 0.2, 0.0, 0.0  # in inertial axes: the frame's attitude is integrated with the particle


def height(t, r, v, k):
    return r[2]


height.terminal = True
height.direction = -1


def omega_of(t):
    return np.array([0.1 * math.sin(0.3 * t), 0.05, 0.4 + 0.02 * t])


R0 = np.array([[1.0, 0.5, 2.0], [0.3, -0.2, 1.0]])
V0 = np.array([[0.0, 0.4, 0.1], [0.2, 0.0, 0.0]])
PROBLEMS = {
    "dop853, a user force and a terminal event": dict(omega=[0.0, 0.1, 0.7], forces=[pull], params=(1.5,),
                                                      events=[height], method="dop853", rtol=1e-9),
    "rk4 in a frame given as a function": dict(omega=omega_of, forces=[pull], params=(0.8,), method="rk4", step=0.01),
    "rotation-splitting4, a built-in spring": dict(omega=[0.0, 0.0, 0.9], forces=[forces.spring(2.0, [0, 0, 0])],
                                                   method="rotation-splitting4", step=0.02),
    "dop853, a force in inertial axes": dict(omega=[0.0, 0.0, 0.5], forces=[Force(inertial_push, axes="inertial")],
                                             method="dop853", rtol=1e-8),
    "dop853, atol given": dict(omega=[0.0, 0.1, 0.7], forces=[pull], params=(1.5,), method="dop853", rtol=1e-9,
                               atol=[1e-9, 1e-9, 1e-9, 1e-8, 1e-8, 1e-8]),
}


def same_trajectory(a, b):
    assert np.array_equal(a.times, b.times)
    assert np.array_equal(a.r, b.r) and np.array_equal(a.v, b.v)
    assert a.steps == b.steps
    # each of simulate's calls (its pacer cuts the run into a few) evaluates f once at its start: a prepared run makes
    # one call, so it may count fewer evaluations, never more
    assert a.nfev <= b.nfev <= a.nfev + 16
    assert np.array_equal(a.extras["status"], b.extras["status"])
    assert sorted(a.event_times) == sorted(b.event_times)
    for name in a.event_times:
        for ta, tb in zip(a.event_times[name], b.event_times[name]):
            assert np.array_equal(ta, tb)
    if "frame_q" in b.extras:
        assert np.array_equal(a.extras["frame_q"], b.extras["frame_q"])


@pytest.mark.parametrize("inline", [False, True])
@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_a_prepared_run_is_simulate_to_the_bit(name, inline):
    """Each run from new start states gives ``simulate``'s trajectory for those states, every array to the bit."""
    kw = dict(PROBLEMS[name], duration=3.0, samples=30)
    prepared = PreparedProblem(r0=R0, v0=V0, inline=inline, **kw)
    for r0, v0 in ((R0, V0), (R0[::-1] * 1.1, V0[::-1]), (R0[0], V0[1])):
        want = simulate_particles(r0=r0, v0=v0, inline=inline, **kw).trajectory
        same_trajectory(prepared.run(r0, v0), want)
        r, v = prepared.states(r0, v0)  # the samples as arrays
        np.testing.assert_array_equal(r, want.r)
        np.testing.assert_array_equal(v, want.v)


def test_a_prepared_run_starts_from_its_own_states():
    """Two runs of different states differ, and a run after them of the first states gives the first numbers."""
    prepared = PreparedProblem(r0=R0, v0=V0, inline=False, **PROBLEMS["rk4 in a frame given as a function"],
                               duration=2.0, samples=10)
    first = prepared.run(R0, V0)
    other = prepared.run(R0 * 0.5, V0)
    assert not np.allclose(first.r[-1], other.r[-1])
    assert np.array_equal(prepared.run(R0, V0).r, first.r)


def test_a_failed_prepared_run_raises_as_simulate_does():
    """A force that blows up ends the run with simulate's error: the particle, the time, the samples kept."""

    def blow_up(t, r, v):
        return 0.0, 0.0, 100.0 * r[2] * r[2] * r[2]  # z'' = 100 z^3 from z = 1: infinite within a second

    kw = dict(omega=[0.0, 0.0, 0.1], forces=[blow_up], method="rk4", step=0.01, duration=3.0, samples=30)
    prepared = PreparedProblem(r0=[1.0, 0.0, 1.0], v0=[0.0, 0.0, 0.0], inline=False, **kw)
    with pytest.raises(IntegrationError) as ours:
        prepared.run([1.0, 0.0, 1.0], [0.0, 0.0, 0.0])
    with pytest.raises(IntegrationError) as theirs:
        simulate_particles(r0=[1.0, 0.0, 1.0], v0=[0.0, 0.0, 0.0], inline=False, **kw)
    assert str(ours.value) == str(theirs.value)
    assert ours.value.t_reached == theirs.value.t_reached < 1.0
    assert np.array_equal(ours.value.partial.r, theirs.value.partial.r, equal_nan=True)


def test_each_run_is_checked_on_the_strings_sphere():
    """A pendulum's states are checked at every run, as simulate checks them: off the sphere is one line."""
    L, pivot = 2.0, np.array([0.0, 0.0, 2.0])
    kw = dict(omega=[0.0, 0.0, 0.2], forces=[forces.gravity([0, 0, -9.81]), forces.pendulum(L, pivot)],
              method="dop853", duration=1.0, samples=5)
    prepared = PreparedProblem(r0=[0.5, 0.0, 2.0 - math.sqrt(L * L - 0.25)], v0=[0, 0, 0], inline=False, **kw)
    with pytest.raises(ScenarioError, match="from the pivot of forces\\[1\\]"):
        prepared.run([0.5, 0.0, 0.0], [0.0, 0.0, 0.0])
    with pytest.raises(ScenarioError, match="r0, v0: not finite"):
        prepared.run([np.nan, 0.0, 0.0], [0.0, 0.0, 0.0])


@pytest.mark.parametrize("frame", ["steady, gravity and a spring", "spinning up, force-free"])
def test_a_prepared_exact_flow_is_simulates_to_round_off(frame):
    """method="exact" prepared keeps the flow's matrices for the sample grid: each run gives simulate's samples to
    round-off (the same flow, its products grouped otherwise), for many particles at once, and a non-linear term is
    refused by name as simulate refuses it."""
    if frame.startswith("steady"):
        kw = dict(omega=[0.0, 0.3, 0.9], forces=[forces.gravity([0, 0, -9.81]), forces.spring(2.0, [0, 0, 1.0])])
    else:
        kw = dict(omega=(np.array([0.0, 5.0]), np.array([[0, 0, 1.0], [0, 0, 2.0]]), "linear"))
    kw.update(duration=5.0, samples=50, method="exact")
    r0 = np.array([[1.0, 0.0, 0.5], [0.0, -2.0, 0.1]])
    v0 = np.array([[0.0, 0.4, 0.0], [1.0, 0.0, -0.3]])
    prepared = PreparedProblem(r0=r0[0], v0=v0[0], **kw)
    for r, v in ((r0[0], v0[0]), (r0, v0)):
        got, want = prepared.run(r, v), simulate_particles(r0=r, v0=v, **kw).trajectory
        scale = np.max(np.abs(want.r))
        np.testing.assert_allclose(got.r, want.r, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(got.v, want.v, rtol=0, atol=1e-12 * np.max(np.abs(want.v)))
        np.testing.assert_array_equal(got.times, want.times)
        assert got.method == "exact" and got.complete
        rs, vs = prepared.states(r, v)  # the same samples as arrays, without the Trajectory
        np.testing.assert_array_equal(rs, got.r)
        np.testing.assert_array_equal(vs, got.v)
    with pytest.raises(ScenarioError, match="forces\\[0\\]"):
        PreparedProblem(r0=r0[0], v0=v0[0], **dict(kw, forces=[forces.drag(quadratic=0.1)]))


def test_what_a_prepared_problem_refuses():
    """Bad arguments are simulate's one-line errors; a non-boolean inline is refused by name."""
    base = dict(r0=[1.0, 0.0, 0.0], v0=[0.0, 0.0, 0.0], omega=[0.0, 0.0, 1.0], duration=1.0,
                forces=[forces.spring(1.0, [0, 0, 0])])
    with pytest.raises(ScenarioError, match="inline='yes'"):
        PreparedProblem(inline="yes", **base)
    with pytest.raises(ScenarioError, match="duration=-1.0"):
        PreparedProblem(**{**base, "duration": -1.0})


@pytest.mark.parametrize("inline", [False, True])
def test_a_force_that_raises_is_named_as_simulate_names_it(inline):
    """A force raising inside the compiled run: simulate's one-line error (the function, the step, the state) and
    samples, whether the loop flagged it (by address) or the exception ended the call (inlined)."""
    from rotframe.problem.callables import UserFunctionError

    kw = dict(omega=[0.0, 0.0, 1.0], forces=[raise_after_one_second], duration=3.0, samples=30)
    prepared = PreparedProblem(r0=R0, v0=V0, inline=inline, **kw)
    with pytest.raises(UserFunctionError) as ours:
        prepared.run(R0, V0)
    with pytest.raises(UserFunctionError) as theirs:
        simulate_particles(r0=R0, v0=V0, inline=inline, **kw)
    assert str(ours.value) == str(theirs.value)
    assert "raise_after_one_second" in str(ours.value) and "too late" in str(ours.value)
    assert np.array_equal(ours.value.partial.r, theirs.value.partial.r, equal_nan=True)


def test_more_particles_than_the_first_run_are_held_to_the_limits():
    """A run of more particles than the set-up's is checked against the work limits, as simulate checks it."""
    import dataclasses

    from rotframe.limits import LimitError, applied, current

    kw = dict(omega=[0.0, 0.0, 1.0], forces=[forces.spring(1.0, [0, 0, 0])], method="rk4", step=0.01, duration=1.0,
              samples=10)
    prepared = PreparedProblem(r0=[1.0, 0.0, 0.0], v0=[0.0, 0.0, 0.0], inline=False, **kw)
    many = np.tile([1.0, 0.0, 0.0], (50, 1))
    with applied(dataclasses.replace(current(), max_steps=1000)):  # 100 steps a particle: 10 fit, 50 do not
        prepared.run(many[:10], np.zeros((10, 3)))
        with pytest.raises(LimitError, match="integration steps"):
            prepared.run(many, np.zeros((50, 3)))
        with pytest.raises(LimitError, match="integration steps"):
            simulate_particles(r0=many, v0=np.zeros((50, 3)), inline=False, **kw)


@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_runs_of_one_particle_after_another_each_start_afresh(name):
    """A prepared problem keeps one particle's arrays from run to run (reset at each): every run is still simulate's
    to the bit, whatever the run before left in them (a terminal event, a sample grid filled or not, events kept),
    and a trajectory handed out is not changed by the runs after it."""
    kw = dict(PROBLEMS[name], duration=3.0, samples=30)
    prepared = PreparedProblem(r0=R0[0], v0=V0[0], inline=False, **kw)
    starts = [(R0[0], V0[0]), (R0[1], V0[1]), (R0[0] * 3.0, -V0[1]), (R0[1], V0[0] * 0.0), (R0[0], V0[0])]
    given = [(prepared.run(r0, v0), simulate_particles(r0=r0, v0=v0, inline=False, **kw).trajectory)
             for r0, v0 in starts]
    for ours, theirs in given:  # checked after every run is made: the later runs left the earlier ones alone
        same_trajectory(ours, theirs)


def test_runs_on_threads_at_once_are_each_their_own():
    """Runs of one prepared problem called from several threads at once (one holds the kept arrays, the others make
    their own) give each the numbers of that run made alone."""
    from concurrent.futures import ThreadPoolExecutor

    kw = dict(PROBLEMS["dop853, a user force and a terminal event"], duration=3.0, samples=30)
    prepared = PreparedProblem(r0=R0[0], v0=V0[0], inline=False, **kw)
    starts = [(R0[k % 2] * (1.0 + 0.1 * k), V0[(k + 1) % 2]) for k in range(24)]
    alone = [prepared.run(r0, v0) for r0, v0 in starts]
    with ThreadPoolExecutor(4) as pool:
        together = list(pool.map(lambda start: prepared.run(*start), starts))
    for a, b in zip(alone, together):
        same_trajectory(a, b)


def test_a_prepared_exact_flow_refuses_events_and_holds_more_particles_to_the_limits():
    """The kept matrices give samples alone: a crossing is refused by name (simulate's exact run locates it), never
    dropped in silence; more particles than the set-up's are held to the sample limit before any work."""
    from rotframe import events
    from rotframe.limits import LimitError

    kw = dict(omega=[0.0, 0.0, 1.0], duration=1.0, method="exact", forces=[forces.gravity([0, 0, -9.81])])
    with pytest.raises(ScenarioError, match="events: a prepared exact flow"):
        PreparedProblem(r0=[0.0, 0.0, 1.0], v0=[0.0, 0.0, 0.0], events=[events.crossing(2)], **kw)
    prepared = PreparedProblem(r0=[0.0, 0.0, 1.0], v0=[0.0, 0.0, 0.0], samples=1000, **kw)
    with pytest.raises(LimitError, match="output samples"):
        prepared.states(np.zeros((10**5, 3)), np.zeros((10**5, 3)))
