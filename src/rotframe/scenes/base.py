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


def until_event(traj, name, particle=0):
    """(times, r, v) of one particle up to and including its first ``name`` event.

    Samples after the event are dropped and the exact event state appended, so
    that metrics and recordings end where the motion ended.
    """
    times = traj.event_times.get(name, [np.array([])])[particle]
    if len(times) == 0:
        return traj.times, traj.r[:, particle], traj.v[:, particle]
    t_ev = float(times[0])
    state = traj.event_states[name][particle][0]
    keep = traj.times < t_ev
    return (np.append(traj.times[keep], t_ev), np.vstack([traj.r[keep, particle], state[:3]]),
            np.vstack([traj.v[keep, particle], state[3:]]))


def resolve_terms(terms, drag=0.0):
    """The model terms a scene runs with, after two rules shared by the Earth scenes.

    The ``drag`` parameter decides whether ``quadratic-drag`` is on (a term with a
    zero coefficient is work for nothing); a gravity variant (``altitude-gravity``,
    ``central-gravity``) replaces uniform ``gravity`` rather than adding to it.
    """
    terms = [t for t in terms if t != "quadratic-drag"] + (["quadratic-drag"] if drag > 0 else [])
    if any(t in ("altitude-gravity", "central-gravity") for t in terms):
        terms = [t for t in terms if t != "gravity"]
    return tuple(terms)


def earth_model_constants(latitude_deg, g_model="wgs84"):
    """(Omega, omega_enu, g) for a site: rotation vector in ENU and effective gravity (m/s^2).

    ``g_model`` "wgs84": Somigliana normal gravity at the latitude (effective
    gravity, centrifugal included); "standard": astropy's g0 = 9.80665 m/s^2.
    """
    from rotframe import earth

    lat = np.radians(latitude_deg)
    g = float(earth.normal_gravity(lat)) if g_model == "wgs84" else earth.G0
    return earth.OMEGA_EARTH, earth.omega_enu(lat), g


def energy_in_rotating_frame(r, v, g, omega=None, centrifugal=False):
    """Jacobi energy per unit mass 1/2 |v|^2 + g z [- 1/2 |omega x r|^2]: conserved without drag."""
    e = 0.5 * np.sum(v * v, axis=1) + g * r[:, 2]
    if centrifugal and omega is not None:
        e -= 0.5 * np.sum(np.cross(omega, r) ** 2, axis=1)
    return e
