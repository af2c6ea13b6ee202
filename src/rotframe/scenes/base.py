"""What scenes share: the result type and the particle run."""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field

import numpy as np

from rotframe.errors import IntegrationError, ScenarioError
from rotframe.particles.integrators import RunInterrupted, integrate_particles


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
    """Jacobi energy per unit mass 1/2 |v|^2 + g z [- 1/2 |omega x r|^2]: conserved without drag.

    Uniform gravity only; :func:`jacobi_energy` builds the energy from any model's terms.
    """
    e = 0.5 * np.sum(v * v, axis=1) + g * r[:, 2]
    if centrifugal and omega is not None:
        e -= 0.5 * np.sum(np.cross(omega, r) ** 2, axis=1)
    return e


#: Terms whose force does no work or derives from a potential (the Jacobi energy is then conserved).
CONSERVATIVE_TERMS = ("gravity", "altitude-gravity", "central-gravity", "coriolis", "centrifugal", "pendulum",
                      "spring", "curvature")


def potential_energy(model, r):
    """Potential per unit mass (J/kg) of the model's own position forces, zero at the frame origin.

    One function for every particle scene, built from the terms the model has
    (docs: the force is -grad V):

    - ``gravity``: V = -g . r (uniform ``model.g``);
    - ``altitude-gravity`` (a_z = -g0 (R / (R + z))^2): V = g0 R z / (R + z);
    - ``central-gravity`` (a = -GM (r - c) / |r - c|^3, c = (0, 0, -R)): V = GM (1/R - 1/|r - c|);
    - ``centrifugal`` (a = -w x (w x r)): V = -1/2 |w x r|^2;
    - ``spring`` (a = -w0^2 (x, y, 0)): V = 1/2 w0^2 (x^2 + y^2).

    Coriolis, the pendulum string and the curved ground do no work. Drag and the
    Euler force (a spin rate that changes) have no potential: see :func:`jacobi_energy`.

    Parameters
    ----------
    model : ParticleModel
    r : (n, 3) array
        Positions, m.
    """
    r = np.atleast_2d(np.asarray(r, dtype=float))
    V = np.zeros(len(r))
    if model.has("gravity"):
        V -= r @ np.asarray(model.g, dtype=float)
    if model.has("altitude-gravity"):
        R = model.radius
        V += model.g0 * R * r[:, 2] / (R + r[:, 2])
    if model.has("central-gravity"):
        d = r - np.array([0.0, 0.0, -model.radius])
        V += model.gm * (1.0 / model.radius - 1.0 / np.linalg.norm(d, axis=1))
    if model.has("centrifugal"):
        w = model.omega.vector(0.0)
        V -= 0.5 * np.sum(np.cross(w, r) ** 2, axis=1)
    if model.has("spring"):
        V += 0.5 * model.spring * (r[:, 0] ** 2 + r[:, 1] ** 2)
    return V


def jacobi_energy(model, r, v):
    """Jacobi energy per unit mass 1/2 |v|^2 + V(r) in the rotating frame, or None if not conserved.

    It is conserved when every term of the model is in :data:`CONSERVATIVE_TERMS`
    and the frame turns at a constant rate; otherwise (drag, a spin-up) there is
    no invariant to check and None is returned.
    """
    if any(t not in CONSERVATIVE_TERMS for t in model.terms) or not model.omega.is_constant:
        return None
    if (model.k_linear and model.has("linear-drag")) or (model.k_quadratic and model.has("quadratic-drag")):
        return None
    v = np.atleast_2d(np.asarray(v, dtype=float))
    return 0.5 * np.sum(v * v, axis=1) + potential_energy(model, r)


# ---------------------------------------------------------------------------
# resolution: metrics only from samples that resolve them
# ---------------------------------------------------------------------------

#: At least this many samples per shortest period of a measured motion.
SAMPLES_PER_PERIOD = 32
#: At most this many samples in a run chosen for resolution (memory and time stay bounded).
MAX_SAMPLES = 400_000


def samples_for(duration, shortest_period, requested, per_period=SAMPLES_PER_PERIOD, bound=MAX_SAMPLES):
    """Samples that resolve ``shortest_period`` over ``duration``, and whether the bound allowed it.

    Returns ``(samples, resolved)``: ``samples = max(requested, per_period *
    duration / shortest_period)`` when that is at most ``bound``; otherwise
    ``(requested, False)``: the samples cannot resolve the motion, and its
    metrics must be reported as null with a note.
    A non-positive or infinite period needs no resolution.
    """
    requested = max(1, int(requested))
    if not (shortest_period > 0 and math.isfinite(shortest_period)):
        return requested, True
    ratio = per_period * duration / shortest_period
    if not math.isfinite(ratio):  # more periods than a float counts: no bound of samples resolves them
        return requested, False
    need = math.ceil(ratio)
    if need <= requested:
        return requested, True
    if need > max(requested, int(bound)):
        return requested, False  # the metrics will be null: no point in paying for samples that cannot help
    return need, True


def unresolved_note(metric, what, period, duration, per_period=SAMPLES_PER_PERIOD, bound=MAX_SAMPLES):
    """The note for a metric left null because ``bound`` samples cannot resolve ``period``."""
    return (f"{metric} not measured: the run covers {duration / period:.4g} {what} periods of {period:.4g} s; "
            f"resolving them needs {per_period} samples per period, more than the {bound} allowed; "
            f"set duration <= {bound * period / per_period:.4g} s")


def method_rel_error(traj, time_scale):
    """A bound on the relative error of a run's metrics from its method, for a motion of ``time_scale`` s.

    ``exact``: 1e-9 (round-off). The adaptive ``dop853`` (rtol <= 1e-10 in the
    scenes): 1e-8, its local tolerance grown over many steps. Fixed-step methods: 10 (h / T)^p with p = 2 for
    ``splitting`` and 4 for ``splitting4`` and ``rk4`` (their global error over a
    motion of time scale T), a factor 10 of margin over the leading term.
    """
    h = traj.extras.get("step") or 0.0
    order = {"rotation-splitting": 2, "rotation-splitting4": 4, "rk4": 4}.get(traj.method)
    if traj.method == "dop853":
        return 1e-8
    if order is None or not h or not time_scale > 0:
        return 1e-9
    return 1e-9 + 10.0 * (h / time_scale) ** order


def reject_subnormal(values):
    """ScenarioError for a nonzero parameter below the smallest normal float64 (2.2e-308).

    Such a value has fewer than 53 significant bits (1e-320 keeps about 10), and
    every length or time derived from it loses the rest: no result can be right
    to its stated accuracy, so the input is refused (exit 2) rather than run.
    """
    tiny = sys.float_info.min
    for key, value in values.items():
        items = value if isinstance(value, (list, tuple, np.ndarray)) else [value]
        for x in items:
            if isinstance(x, (float, int)) and not isinstance(x, bool) and x != 0 and abs(x) < tiny:
                raise ScenarioError(f"{key} = {x!r}: below the smallest normal float64 ({tiny:.4g}), a value that "
                                    "keeps too few significant digits to compute with; allowed: 0 or "
                                    f"|{key}| >= {tiny:.4g}")
