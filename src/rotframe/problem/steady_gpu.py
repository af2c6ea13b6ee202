"""The engine's steady specialisation on the GPU: a fixed-step run that keeps its end alone, on the scenes' GPU kernel.

`rotframe.problem.steady` chooses it from the terms (its module docstring says which problems qualify);
`rotframe.problem.particles.simulate_particles` runs it here and wraps its trajectory.
"""

from __future__ import annotations

import numpy as np

from rotframe.particles.trajectory import Trajectory, per_particle
from rotframe.problem.tiers import SteadyLoopFailed

__all__ = ["steady_gpu_trajectory"]


def steady_gpu_trajectory(s, progress):
    """``(trajectory, note)`` of a fixed-step method on a steady problem on the GPU, its end
    kept alone (``samples=1``, its event terminal: `rotframe.problem.steady`), for the set-up ``s``: the scenes' GPU
    kernel (`rotframe.particles.gpu.GpuLaunch`), one thread a particle, on the steps of the CPU's run of the same
    problem (`rotframe.problem.particles._steady_fixed_run`), which its thread takes from the same source
    (round-off: a GPU may fuse a multiply and an add). A particle's end sample is its state at its terminal event,
    else at the end, as the engine's loop keeps it; the counts are the CPU's steady run's. A state that is not
    finite raises `SteadyLoopFailed`: the engine's own loop on the GPU runs the problem again and names the cause."""
    from rotframe.particles.gpu import GpuLaunch
    from rotframe.particles.kernels import EVALS_PER_STEP
    from rotframe.numerics.step_control import steps_to_event

    model, rows = s.steady.model, s.steady.rows
    N = s.r.shape[0]
    launch = GpuLaunch(model, s.duration, rows[0] if rows else None, method=s.method,
                       run={"step": s.hfix, "samples": 1})
    t_stop, end = launch.from_host(s.r, s.v)
    if not np.all(np.isfinite(end)):
        raise SteadyLoopFailed
    traj = Trajectory(s.times.copy(), np.stack([s.r, end[:, :3]]), np.stack([s.v, end[:, 3:]]), s.method,
                      t_reached=float(s.times[-1]), extras={"step": launch.h})
    stopped = np.isfinite(t_stop)
    counts = stopped.astype(np.int64)  # one record (its terminal event) where a particle stopped
    for row in rows:
        traj.event_times[row.name] = per_particle(t_stop[stopped], counts)
        traj.event_states[row.name] = per_particle(end[stopped], counts)
    traj.extras["status"] = np.where(stopped, 2, 1).astype(np.int64)
    steps = np.full(N, launch.steps, dtype=np.int64)
    steps[stopped] = steps_to_event(t_stop[stopped], s.times, launch.steps, launch.h)
    traj.steps = int(steps.max()) if N else 0
    traj.nfev = traj.steps * EVALS_PER_STEP[s.method]
    if progress is not None:
        progress(1.0)
    return traj, (f"method {s.method}: the scenes' GPU kernel (a constant rotation rate, uniform or altitude gravity, "
                  "air drag, a string, the frame's terms, one terminal built-in crossing, the end kept alone: "
                  "rotframe.problem.steady), the engine's steps to round-off")
