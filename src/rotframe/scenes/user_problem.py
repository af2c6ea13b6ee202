"""Recording of a user's own problem (``rotframe.simulate``, ``rotframe.simulate_body``).

Not a scenario: ``rotframe.simulate`` has no parameters file. This module gives the problem's
``Result`` the scene protocol's ``record`` so that ``Result.record(path)`` writes the same
layout as a scene's recording (DESIGN, "Recording layout"): particles as points with trails
in the frame's axes (``world/particle_<i>``, at most `MAX_SHOWN` of them), event
locations, the energy or Jacobi drift under ``diagnostics/``; a body as a transform with its
axes, L in space and the polhode.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ParticleProblemScene", "BodyProblemScene", "MAX_SHOWN"]

#: particles drawn one by one in a recording (an ensemble beyond that shows its first ones)
MAX_SHOWN = 50

_COLORS = np.array([[230, 90, 40], [60, 140, 230], [80, 190, 90], [200, 80, 200], [240, 200, 60]])


class ParticleProblemScene:
    """The scene protocol's ``record`` for a user's particle problem."""

    METHODS = ("dop853", "rk4")

    def __init__(self, extras_record=None):
        self.extras_record = extras_record

    @staticmethod
    def simulate(*args, **kwargs):  # pragma: no cover - the protocol's name; rotframe.simulate runs it
        raise NotImplementedError("a user's problem is run by rotframe.simulate")

    @staticmethod
    def analyse(values, result):
        return {"metrics": {}, "theory": {}, "diagnostics": dict(result.extras.get("diagnostics", {}))}

    def record(self, rec, values, result):
        from rotframe.numerics.sampling import decimate

        traj = result.trajectory
        idx = decimate(len(traj.times), 20000)
        t = traj.times[idx]
        N = traj.r.shape[1]
        scale = max(float(np.max(np.abs(traj.r))), 1e-300)
        factor = 1e-3 if scale > 5e4 else 1.0  # km beyond 50 km: rerun keeps float32
        for i in range(min(N, MAX_SHOWN)):
            rec.points(f"world/particle_{i}", t, traj.r[idx, i] * factor, radius=0.01 * scale * factor,
                       color=_COLORS[i % len(_COLORS)].tolist())
        for name, per_particle in traj.event_states.items():
            pts = [s[:, :3] for s in per_particle[:MAX_SHOWN] if len(s)]
            if pts:
                rec.static(f"world/events/{name}", "Points3D", positions=np.concatenate(pts) * factor,
                           radii=[0.02 * scale * factor], colors=[[250, 250, 250]])
        energy = traj.extras.get("energy")
        if energy is not None:
            e0 = energy[0]
            rel = (energy - e0) / np.where(e0 != 0, np.abs(e0), 1.0)
            name = "jacobi" if "jacobi_rel_drift" in result.extras.get("diagnostics", {}) else "energy"
            rec.scalars(f"diagnostics/{name}_rel_error", traj.times, rel[:, 0])
        if self.extras_record is not None:
            self.extras_record(rec, values, result)


class BodyProblemScene:
    """The scene protocol's ``record`` for a user's rigid body."""

    METHODS = ("dop853", "rk4", "exact")

    @staticmethod
    def simulate(*args, **kwargs):  # pragma: no cover - the protocol's name; rotframe.simulate_body runs it
        raise NotImplementedError("a user's body is run by rotframe.simulate_body")

    @staticmethod
    def analyse(values, result):
        return {"metrics": {}, "theory": {}, "diagnostics": dict(result.extras.get("diagnostics", {}))}

    @staticmethod
    def record(rec, values, result):
        from rotframe.scenes.rigid_base import record_body

        traj = result.trajectory
        record_body(rec, traj, np.diag(result.extras["inertia"]) if np.ndim(result.extras["inertia"]) == 2
                    else result.extras["inertia"], L_label="L in space")
