"""A fixed-step run's numbers do not depend on how it is cut into calls of the compiled drivers.

`rotframe.particles.chunked.run_chunked` cuts a run into calls of at most ``CALL_EVALS`` step-evaluations (so that
signals, progress and failures are seen between them), and a sample interval longer than that into pieces. How many
samples a call takes depends on the ensemble's size, so a particle's numbers must not depend on where the calls end:
a sweep integrates a point beside whichever other points share its chunk. Each step starts on the grid of its sample
interval, ``T[s] + j h`` (the engine's rule, `rotframe.problem.fixed_step`), whatever the call it falls in; the event
times (``t + tau``, from the step's start) and, under a rate that varies, the states (its plan reads the step's time)
are then the same to the bit however the run is cut. The uncut run is the oracle: a planted ``t0 + k h`` from the
call's own start fails these tests.
"""

import numpy as np
import pytest

from rotframe.particles import chunked
from rotframe.particles.integrators import Event, integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel

GROUND = Event("ground", "r", 2, 0.0, -1, True)
#: step-evaluations of a call: the whole run in one; a few samples a call; a piece of a step or so (a sample
#: interval in pieces, `rotframe.particles.chunked.KernelSetup.one_sample_in_pieces`)
CUTS = [1.6e7, 3000.0, 50.0]


def _start(n, seed):
    rng = np.random.default_rng(seed)
    r0 = np.zeros((n, 3))
    r0[:, 2] = rng.uniform(5.0, 120.0, n)
    v0 = rng.normal(scale=2.0, size=(n, 3))
    return r0, v0


def _runs(monkeypatch, model, method, **kw):
    r0, v0 = _start(12, seed=11)
    runs = []
    for cut in CUTS:
        monkeypatch.setattr(chunked, "CALL_EVALS", cut)
        runs.append(integrate_particles(model, r0, v0, 6.0, method=method, step=0.013, samples=30, **kw))
    return runs


@pytest.mark.parametrize("method", ["rk4", "rotation-splitting", "rotation-splitting4"])
@pytest.mark.parametrize("steady", [True, False])
def test_event_times_and_states_are_the_same_however_the_run_is_cut(monkeypatch, method, steady):
    axis = np.array([0.0, 0.63, 0.78])
    omega = OmegaSchedule.constant(7e-5 * axis) if steady else OmegaSchedule.ramp(axis, 7e-5, 0.02, 6.0)
    model = ParticleModel(("gravity", "coriolis", "centrifugal"), omega=omega, g=np.array([0.0, 0.0, -9.81]))
    whole, *cut = _runs(monkeypatch, model, method, events=[GROUND])
    assert sum(len(t) for t in whole.event_times["ground"]) == 12  # every particle lands within the run
    for other in cut:
        assert np.array_equal(whole.r, other.r) and np.array_equal(whole.v, other.v)
        for a, b in zip(whole.event_times["ground"], other.event_times["ground"]):
            assert np.array_equal(a, b)
        for a, b in zip(whole.event_states["ground"], other.event_states["ground"]):
            assert np.array_equal(a, b)


@pytest.mark.parametrize("method", ["rk4", "rotation-splitting"])
def test_a_varying_rate_gives_the_same_samples_however_the_run_is_cut(monkeypatch, method):
    model = ParticleModel(("gravity", "coriolis", "centrifugal", "euler"),
                          omega=OmegaSchedule.ramp([0.0, 0.0, 1.0], 0.1, 0.3, 6.0), g=np.array([0.0, 0.0, -9.81]))
    whole, *cut = _runs(monkeypatch, model, method)
    for other in cut:
        assert np.array_equal(whole.r, other.r) and np.array_equal(whole.v, other.v)


@pytest.mark.parametrize("method", ["rk4", "rotation-splitting"])
def test_the_tower_drops_ensemble_lands_where_the_engines_loop_does(method):
    # the sweeps' vectorised ensemble (`rotframe.particles.ensemble`, the scenes' drivers) and the engine's own loop
    # (inline=False) on the tower drop's problem, on the same sample grid (a sweep's, `ENSEMBLE_SAMPLES`): the same
    # landing times and states, to the bit
    import math

    from rotframe import earth, forces
    from rotframe.events import crossing
    from rotframe.particles.ensemble import integrate_ensemble
    from rotframe.problem.particles import simulate_particles

    lat = math.radians(50.88)
    g, w = float(earth.normal_gravity(lat)), earth.omega_enu(lat)
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=np.array([0.0, 0.0, -g]))
    r0 = np.zeros((9, 3))
    r0[:, 2] = np.linspace(3.0, 110.0, 9)
    ens = integrate_ensemble(model, r0, np.zeros_like(r0), 8.0, GROUND, method=method,
                             run={"step": 1e-3, "samples": 16})
    engine = simulate_particles(omega=w, r0=r0, v0=np.zeros_like(r0), duration=8.0, method=method, step=1e-3,
                                samples=16, forces=[forces.gravity([0.0, 0.0, -g])], frame_terms=("coriolis",),
                                events=[crossing(2, 0.0, direction=-1, terminal=True, name="ground")], inline=False)
    t = np.array([times[0] for times in engine.trajectory.event_times["ground"]])
    states = np.array([s[0] for s in engine.trajectory.event_states["ground"]])
    assert np.array_equal(ens.t_event, t) and np.array_equal(ens.state, states)
