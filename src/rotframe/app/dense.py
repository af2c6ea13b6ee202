"""``Result.sol(t)``: the state of a finished ``dop853`` particle run at any time, as scipy's
``solve_ivp(dense_output=True).sol(t)`` gives it.

The run keeps only its samples. ``sol(t)`` restarts the same integrator (DOP853, its step control), with
the same tolerances (``rtol`` of the run, and each particle's absolute tolerances as the run took them:
``Trajectory.extras["atol"]``), from the last sample at or before ``t`` and integrates the short gap to
``t`` on the scenes' kernels (the engine's terms in their arithmetic: the same motion to round-off): the
answer is as accurate as the run's own samples (each step's local error below its tolerance), and at a
sample time it is that sample exactly. After a terminal event (the ground) the state is the state at the event,
as in the samples.

Only runs whose model does not depend on time are restarted this way (a constant rotation
rate: every built-in Earth scene); a turntable that spins up, a rigid body or another method
raise `rotframe.errors.ScenarioError` naming what is allowed.
"""

from __future__ import annotations

import numpy as np

from rotframe.errors import ScenarioError

__all__ = ["DenseSolution"]


class DenseSolution:
    """A callable ``sol(t) -> (r, v)`` over a finished ``dop853`` particle run.

    ``t`` a number: ``r``, ``v`` of shape (N, 3); ``t`` an array of shape (m,): (m, N, 3).
    Times outside ``[0, t_end]`` raise ScenarioError.
    """

    def __init__(self, scenario_name, scene_result, run_settings):
        traj = scene_result.trajectory
        model = scene_result.extras.get("model") if scene_result.extras else None
        where = f"{scenario_name}: sol(t)"
        if getattr(traj, "r", None) is None or model is None:
            raise ScenarioError(f"{where}: dense output is for particle runs; allowed: a dop853 run of a particle scene")
        if traj.method != "dop853":
            raise ScenarioError(f"{where}: the run used method {traj.method!r}; allowed: a dop853 run "
                                f"(rotframe.run(..., method='dop853'))")
        if not model.omega.is_constant:
            raise ScenarioError(f"{where}: the frame's rotation rate changes with time, so the run cannot be "
                                "restarted from a sample; allowed: a run with a constant rotation rate")
        from rotframe.scenes.run_settings import run_setting

        self._model = model
        self._times = np.asarray(traj.times, dtype=float)
        self._r = np.asarray(traj.r, dtype=float)
        self._v = np.asarray(traj.v, dtype=float)
        self._rtol = float(run_setting(run_settings, "rtol"))
        # the absolute tolerances the run took, a row (r then v) per particle (the engine's and the calls' driver's
        # record of them), else rtol times the initial states' scale (chunked.KernelSetup.abs_tol's default)
        rows = (getattr(traj, "extras", None) or {}).get("atol")
        if rows is None:
            from rotframe.numerics.step_control import ensemble_scale

            rows = np.full((self._r.shape[1], 6), self._rtol * ensemble_scale(self._r[0], self._v[0]))
        self._atol = np.asarray(rows, dtype=float)
        # the terminal event of the built-in scenes: a particle stops at the ground
        ground = (getattr(traj, "event_times", {}) or {}).get("ground", [])
        self._stops = [float(np.min(ground[p])) if p < len(ground) and np.size(ground[p]) else np.inf
                       for p in range(self._r.shape[1])]
        self._where = where
        self.t_end = float(self._times[-1])

    def __call__(self, t):
        t_arr = np.asarray(t, dtype=float)
        if t_arr.ndim > 1:
            raise ScenarioError(f"{self._where}: t must be a number or a 1-D array")
        flat = np.atleast_1d(t_arr)
        bad = flat[~((flat >= 0.0) & (flat <= self.t_end))]
        if bad.size:
            raise ScenarioError(f"{self._where}: t = {float(bad[0]):g} s; allowed: 0 <= t <= {self.t_end:g} s")
        out = [self._at(float(x)) for x in flat]
        r = np.stack([o[0] for o in out])
        v = np.stack([o[1] for o in out])
        return (r[0], v[0]) if t_arr.ndim == 0 else (r, v)

    def _at(self, t):
        from rotframe.particles.integrators import integrate_particles

        k = int(np.searchsorted(self._times, t, side="right")) - 1
        r, v = self._r[k].copy(), self._v[k].copy()
        gap = t - self._times[k]
        if gap <= 0.0:
            return r, v
        # particles that stopped (an event) keep their samples' state; the others are restarted
        moving = [p for p, stop in enumerate(self._stops) if t < stop]
        stopped = [p for p in range(r.shape[0]) if p not in moving]
        if stopped:
            r[stopped], v[stopped] = self._r[-1, stopped], self._v[-1, stopped]
        for p in moving:  # each with the run's own tolerances
            traj = integrate_particles(self._model, r[p], v[p], gap, method="dop853", rtol=self._rtol,
                                       atol=tuple(self._atol[p].tolist()), samples=1)
            r[p], v[p] = traj.r[-1, 0], traj.v[-1, 0]
        return r, v
