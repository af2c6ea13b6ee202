"""What scenes share: the result type and the particle run."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rotframe.errors import IntegrationError
from rotframe.integrators import RunInterrupted, integrate_particles


@dataclass
class SceneResult:
    """A finished (or interrupted) run of a scene.

    ``trajectory`` has ``times`` and the state arrays; ``extras`` holds what the
    scene computed on the way (oracle curves, frames) for analysis and recording.
    """

    trajectory: object
    terms: list
    method: str
    steps: int
    nfev: int = 0
    extras: dict = field(default_factory=dict)

    @property
    def complete(self) -> bool:
        return bool(getattr(self.trajectory, "complete", True))


def run_particles(model, r0, v0, duration, method, run, progress, finish, events=(), step=None):
    """Integrate a particle scene with the run settings (``step``, ``rtol``, ``samples``).

    ``finish(trajectory) -> SceneResult`` builds the scene's result; it is
    applied to a partial trajectory too, so that an interrupted or failed run
    re-raises with a SceneResult in ``exc.partial`` that can be analysed and
    recorded like a complete one.
    """
    try:
        traj = integrate_particles(model, r0, v0, duration, method=method, step=step or run.get("step"),
                                   rtol=run.get("rtol") or 1e-10, samples=int(run.get("samples") or 2000),
                                   events=events, progress=progress)
    except (IntegrationError, RunInterrupted) as exc:
        if exc.partial is not None and len(exc.partial.times):
            exc.partial = finish(exc.partial)
        else:
            exc.partial = None
        raise
    return finish(traj)


def rel_drift(series) -> float:
    """max |X(t) - X(0)| / |X(0)| (absolute when X(0) = 0)."""
    x = np.asarray(series, dtype=float)
    scale = abs(x[0]) if x[0] != 0 else 1.0
    return float(np.max(np.abs(x - x[0])) / scale)
