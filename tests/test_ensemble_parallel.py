"""Ensembles on several threads give bitwise the same result as on one (rotframe.particles.ensemble).

The particles are cut into fixed blocks whatever the number of threads, and
each particle is integrated on its own, so equality is exact (no tolerance).
The blocked run is also compared with one unblocked ``integrate_particles``
call: with one sample per run the kernel sees the same inputs, so it too is
equal bitwise; a small block size keeps the test cheap.
"""

import numpy as np
import pytest

from rotframe.particles import ensemble, threads
from rotframe.particles.integrators import Event, integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel

GROUND = Event("ground", "r", 2, 0.0, -1, True)


def _model():
    w = np.array([0.0, 4.6e-5, 5.7e-5])
    return ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=np.array([0.0, 0.0, -9.81]))


def _start(n, seed=3):
    rng = np.random.default_rng(seed)
    r0 = np.zeros((n, 3))
    r0[:, 2] = rng.uniform(10.0, 200.0, n)
    v0 = rng.normal(scale=2.0, size=(n, 3))
    return r0, v0


def _same(a, b):
    return np.array_equal(a, b, equal_nan=True)


@pytest.mark.parametrize("method,run", [("splitting", {"step": 1e-2, "samples": 1}),
                                        ("dop853", {"rtol": 1e-8, "samples": 1})])
def test_threads_do_not_change_the_result(monkeypatch, method, run):
    monkeypatch.setattr(threads, "BLOCK", 64)
    monkeypatch.setattr(ensemble, "PATH_BUDGET", 100)  # the large-ensemble branch: one sample per particle
    r0, v0 = _start(300)
    model = _model()
    runs = [ensemble.integrate_ensemble(model, r0, v0, 10.0, GROUND, method=method, run=run, keep=[0, 150],
                                        threads=t) for t in (1, 2, 3)]
    for other in runs[1:]:
        assert _same(runs[0].t_event, other.t_event)
        assert _same(runs[0].state, other.state)
        for k in (0, 150):
            assert _same(runs[0].paths[k][1], other.paths[k][1])
    assert np.isfinite(runs[0].t_event).all()  # every particle landed within 10 s


def test_blocked_equals_one_unblocked_call(monkeypatch):
    monkeypatch.setattr(threads, "BLOCK", 50)
    monkeypatch.setattr(ensemble, "PATH_BUDGET", 100)
    r0, v0 = _start(170, seed=5)
    model = _model()
    ens = ensemble.integrate_ensemble(model, r0, v0, 10.0, GROUND, method="splitting", run={"step": 1e-2},
                                      threads=2)
    traj = integrate_particles(model, r0, v0, 10.0, method="splitting", step=1e-2, samples=1, events=[GROUND])
    t_ref = np.array([t[0] for t in traj.event_times["ground"]])
    assert _same(ens.t_event, t_ref)
    assert _same(ens.state, np.array([s[0] for s in traj.event_states["ground"]]))


def test_small_ensemble_with_paths_is_thread_independent(monkeypatch):
    monkeypatch.setattr(threads, "BLOCK", 40)
    r0, v0 = _start(100, seed=7)
    model = _model()
    a = ensemble.integrate_ensemble(model, r0, v0, 10.0, GROUND, method="rk4", run={"step": 1e-2, "samples": 50},
                                    keep=[3, 99], threads=1)
    b = ensemble.integrate_ensemble(model, r0, v0, 10.0, GROUND, method="rk4", run={"step": 1e-2, "samples": 50},
                                    keep=[3, 99], threads=2)
    assert _same(a.t_event, b.t_event) and _same(a.state, b.state)
    for k in (3, 99):
        assert _same(a.paths[k][0], b.paths[k][0]) and _same(a.paths[k][1], b.paths[k][1])
        assert a.paths[k][0][-1] == a.t_event[k]  # the path ends at the landing


def test_thread_count_validation():
    from rotframe.errors import ScenarioError

    assert ensemble.resolve_threads(2) == 2
    assert ensemble.resolve_threads(None) >= 1
    for bad in (0, -1, 1.5, "two", True):
        with pytest.raises(ScenarioError, match="threads"):
            ensemble.threads_scope(bad).__enter__()
        with pytest.raises(ScenarioError, match="threads"):
            ensemble.resolve_threads(bad)


def test_threads_scope_is_per_block_and_restored():
    import os

    every = os.cpu_count() or 1
    assert ensemble.resolve_threads(None) == every
    with ensemble.threads_scope(3):
        assert ensemble.resolve_threads(None) == 3
        assert ensemble.resolve_threads(2) == 2  # an explicit count wins
        with ensemble.threads_scope(1):
            assert ensemble.resolve_threads(None) == 1
        assert ensemble.resolve_threads(None) == 3
    assert ensemble.resolve_threads(None) == every  # nothing outlives the block


def test_threads_scope_is_not_seen_by_other_threads():
    """A ContextVar: a count set in one thread (one command) does not leak into another."""
    import threading

    seen = {}
    with ensemble.threads_scope(5):
        t = threading.Thread(target=lambda: seen.update(n=ensemble.resolve_threads(None)))
        t.start()
        t.join()
    assert seen["n"] == ensemble.resolve_threads(None)


def test_large_steady_dop853_run_takes_the_steady_driver_in_blocks_bitwise(monkeypatch):
    """More particles than a block run the engine's steady loop (`rotframe.problem.steady`) block by block; the same
    bits as one block."""
    from rotframe import forces
    from rotframe.particles import blocks, dop853_steady
    from rotframe.problem.particles import simulate_particles

    r0, v0 = _start(12, seed=9)
    kw = dict(omega=[0.0, 4.6e-5, 5.7e-5], forces=[forces.gravity([0.0, 0.0, -9.81])], duration=5.0, rtol=1e-9,
              samples=3, frame_terms=("coriolis",))
    one = simulate_particles(r0=r0, v0=v0, **kw).trajectory
    monkeypatch.setattr(threads, "BLOCK", 5)
    calls = []
    real = blocks.run_blocks

    def spy(one_block, n, per_particle, outputs, **how):
        kernel = dict(zip(one_block.__code__.co_freevars, (c.cell_contents for c in one_block.__closure__)))["kernel"]
        calls.append(kernel)
        return real(one_block, n, per_particle, outputs, **how)

    monkeypatch.setattr(blocks, "run_blocks", spy)
    many = simulate_particles(r0=r0, v0=v0, **kw).trajectory
    assert calls and all(kernel is dop853_steady.run_dop853_steady for kernel in calls)  # the steady driver, in blocks
    assert np.array_equal(one.r, many.r) and np.array_equal(one.v, many.v)
    assert one.steps == many.steps and one.nfev == many.nfev  # the most any particle took, in blocks as in one


@pytest.mark.parametrize("n", [1, 4095, 4096, 4097, 10_000, 100_000, 123_457])
@pytest.mark.parametrize("workers", [1, 2, 3, 16])
def test_the_blocks_cover_every_particle_once_and_share_the_work_evenly(n, workers):
    from rotframe.particles.blocks import block_bounds

    bounds = block_bounds(n, workers)
    assert bounds[0][0] == 0 and bounds[-1][1] == n
    assert all(hi == lo2 for (_, hi), (lo2, _) in zip(bounds, bounds[1:]))  # contiguous, in order
    sizes = [hi - lo for lo, hi in bounds]
    assert max(sizes) <= threads.BLOCK
    if workers > 1 and n > threads.BLOCK:
        assert len(bounds) % workers == 0 and max(sizes) - min(sizes) <= 1
        # each thread's share (blocks dealt in turn) is within one block of the even share
        shares = [sum(sizes[k::workers]) for k in range(workers)]
        assert max(shares) - min(shares) <= len(bounds) // workers
