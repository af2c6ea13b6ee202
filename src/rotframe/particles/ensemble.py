"""Ensembles of particles to a terminal event, on every core.

A scene's ``simulate_ensemble`` integrates many particles that share one model
(for example drops from different heights) in one call of the compiled core
([`rotframe.particles.integrators.integrate_particles`][rotframe.particles.integrators.integrate_particles]), which cuts them
into blocks of at most `BLOCK` particles, the same share for each thread, and
runs the blocks on a pool of threads (`rotframe.particles.blocks`; the compiled
kernels release the GIL). Every particle is integrated on its own inside a
block, so the results are bitwise identical for any ``threads`` and any cut (tested in ``tests/test_ensemble_parallel.py``). The first
events are read from the kernels' record arrays, not from per-particle lists.

``threads=None`` means the count in force, ``device=None`` the device in force
([`rotframe.particles.threads`][rotframe.particles.threads]: the CLI's ``--threads N`` and ``--device``,
``rotframe.run(..., threads=N, device=...)``, else every core of the CPU).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# where ensembles run (threads, device) is rotframe.particles.threads; its names are kept here too
from rotframe.particles.threads import (BLOCK, DEVICES, check_device, check_threads, device_in_force,  # noqa: F401
                                        device_scope, resolve_threads, threads_in_force, threads_scope)

__all__ = ["EnsembleRun", "integrate_ensemble", "group_points", "threads_scope", "threads_in_force", "check_threads",
           "resolve_threads", "DEVICES", "check_device", "device_scope", "device_in_force",
           "BLOCK", "MAX_TRACK_SAMPLES", "PATH_BUDGET"]

#: at most this many samples per kept path
MAX_TRACK_SAMPLES = 500
#: particle-samples held at once by `integrate_ensemble` (13 floats each)
PATH_BUDGET = 2_000_000


@dataclass
class EnsembleRun:
    """What `integrate_ensemble` returns.

    Attributes
    ----------
    t_event : (N,) array
        Time (s) of each particle's first event; NaN where it had none.
    state : (N, 6) array
        (r, v) at the event, or at the end of the run where there was none.
    paths : dict
        Index -> (times (n,), positions (n, 3)) up to the event, for the indices asked for.
    method : str
    """

    t_event: np.ndarray
    state: np.ndarray
    paths: dict
    method: str


def integrate_ensemble(model, r0, v0, duration, event, *, method, run, keep=(), threads=None,
                       device=None) -> EnsembleRun:
    """Integrate an ensemble to a terminal event in vectorised calls of the compiled core, on every core.

    The integrator locates the event for every particle (the kernels inside the
    compiled loop; ``exact`` for all particles at once on the exact flow).
    Paths for ``keep`` come from the same call when the ensemble is small, else
    from a second call on those particles only.

    Parameters
    ----------
    model : ParticleModel
    r0, v0 : (N, 3) arrays
    duration : float
        Long enough for every particle to reach the event.
    event : rotframe.particles.integrators.Event
        Terminal event (kinds ``r`` and ``v`` with ``exact``).
    method : str
    run : dict
        Run settings (``step``, ``rtol``, ``samples``: at most `MAX_TRACK_SAMPLES` are kept in paths).
    keep : sequence of int
        Particles whose paths are wanted.
    threads : int, optional
        Threads for the compiled methods (None: `resolve_threads`). The
        result does not depend on it. ``exact`` runs in one vectorised call.
    device : str, optional
        ``"cpu"`` or ``"gpu"`` (None: [`device_in_force`][rotframe.particles.threads.device_in_force]). On the GPU
        ([`rotframe.particles.gpu`][rotframe.particles.gpu], the fixed-step methods) the event times and
        states agree with the CPU's to round-off (the same steps from the same source);
        the kept paths are integrated on the CPU.
    """
    r0 = np.asarray(r0, dtype=np.float64)
    v0 = np.asarray(v0, dtype=np.float64)
    n = len(r0)
    keep = list(keep)
    path_samples = max(2, min(int(run.get("samples") or MAX_TRACK_SAMPLES), MAX_TRACK_SAMPLES))
    exact = method == "exact"
    # one absolute tolerance for the whole ensemble (dop853), whatever the blocks
    atol = run.get("atol")
    if method == "dop853" and not atol and n:
        from rotframe.numerics.step_control import ensemble_scale

        atol = float(run.get("rtol") or 1e-10) * ensemble_scale(r0, v0)
    run = dict(run, atol=atol)
    if (check_device(device) or device_in_force()) == "gpu":
        return _on_gpu(model, r0, v0, duration, event, method, run, keep, path_samples)
    if n * (path_samples + 1) <= PATH_BUDGET:
        t_event, state, traj = _integrate_blocks(model, r0, v0, duration, event, method, run,
                                                 max(path_samples, 16), threads)
        sub, sub_index = traj, keep
    else:
        samples = int(np.clip(PATH_BUDGET // n, 16, path_samples)) if exact else 1
        t_event, state, traj = _integrate_blocks(model, r0, v0, duration, event, method, run, samples, threads)
        sub = _integrate(model, r0[keep], v0[keep], duration, event, method, run, path_samples) if keep else None
        sub_index = list(range(len(keep)))
    paths = {k: _path_until(sub, j, t_event[k], state[k]) for k, j in zip(keep, sub_index)}
    return EnsembleRun(t_event, state, paths, method)


def _on_gpu(model, r0, v0, duration, event, method, run, keep, path_samples):
    """[`integrate_ensemble`][rotframe.particles.ensemble.integrate_ensemble] on the GPU: the same step as the CPU's (its sample count), paths on the CPU."""
    from rotframe.particles.gpu import integrate_ensemble_gpu

    n = len(r0)
    # the samples the CPU ensemble asks for (the fixed step divides their interval)
    small = n * (path_samples + 1) <= PATH_BUDGET
    samples = max(path_samples, 16) if small else 1
    t_event, state = integrate_ensemble_gpu(model, r0, v0, duration, event, method=method,
                                            run=dict(run, samples=samples))
    paths = {}
    if keep:  # on the CPU's sample grid for them
        sub = _integrate(model, r0[keep], v0[keep], duration, event, method, run, samples if small else path_samples)
        paths = {k: _path_until(sub, j, t_event[k], state[k]) for j, k in enumerate(keep)}
    return EnsembleRun(t_event, state, paths, method)


def group_points(values_list, varying) -> list:
    """Indices of ``values_list`` grouped by every value except the keys in ``varying``.

    Points of one group share the model and differ only in initial conditions, so a scene
    can integrate each group as one ensemble.
    """
    groups = {}
    for i, values in enumerate(values_list):
        key = tuple(sorted((k, repr(v)) for k, v in values.items() if k not in varying))
        groups.setdefault(key, []).append(i)
    return list(groups.values())


# ---------------------------------------------------------------------------


def _integrate_blocks(model, r0, v0, duration, event, method, run, samples, threads):
    """(t_event, state, trajectory) of the whole ensemble: one call, in blocks on the thread pool.

    [`rotframe.particles.integrators.integrate_particles`][rotframe.particles.integrators.integrate_particles] cuts the particles into
    blocks of `BLOCK` on the threads in force (`rotframe.particles.blocks`).
    """
    with threads_scope(resolve_threads(threads)):
        traj = _integrate(model, r0, v0, duration, event, method, run, samples)
    t_event, state = _first_events(traj, event)
    return t_event, state, traj


def _integrate(model, r0, v0, duration, event, method, run, samples):
    from rotframe.particles.integrators import integrate_particles

    kw = {}
    if run.get("atol"):
        kw["atol"] = run["atol"]
    # a terminal event stops the particle: one record per particle is enough
    max_events = 1 if event.terminal else 64
    return integrate_particles(model, r0, v0, duration, method=method, step=run.get("step"),
                               rtol=run.get("rtol") or 1e-10, samples=int(samples), events=[event],
                               max_events=max_events, records=True, **kw)


def _first_events(traj, event):
    """(t, state) of each particle's first ``event`` found by the kernel; the end state where none.

    Read from the kernels' record arrays where the run left them there (vectorised, so
    that little time is spent holding the GIL), else from the per-particle sequences
    (`rotframe.particles.trajectory.Trajectory.first_events`).
    """
    evb = traj.extras.get("event_records")
    if evb is None:
        return traj.first_events(event.name)
    state = np.concatenate([traj.r[-1], traj.v[-1]], axis=1)
    t_event = np.full(traj.r.shape[1], math.nan)
    hit = evb.count > 0  # one event: every record is of it, the first in column 0
    t_event[hit] = evb.t[hit, 0]
    state[hit, :3] = evb.r[hit, 0]
    state[hit, 3:] = evb.v[hit, 0]
    return t_event, state


def _path_until(traj, j, t_event, state):
    """Samples of particle j before its event, then the event state; positions only."""
    times = traj.times
    if not np.isfinite(t_event):
        return times, traj.r[:, j]
    keep = times < t_event
    return np.append(times[keep], t_event), np.vstack([traj.r[keep, j], state[None, :3]])
