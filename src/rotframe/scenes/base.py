"""What scenes share: typed parameters, the result type and the particle run."""

from __future__ import annotations

import dataclasses
import functools
import math
import sys
import typing
from dataclasses import dataclass, field

import numpy as np

from rotframe.errors import IntegrationError, ScenarioError
from rotframe.method_registry import MethodNames, names
from rotframe.scenes.run_settings import RUN_DEFAULTS, run_setting
from rotframe.particles.integrators import RunInterrupted


__all__ = ["UNDERFLOW", "RUN_DEFAULTS", "run_setting", "SceneResult", "scene_parameters", "with_parameters", "MethodNames", "particle_methods", "rel_drift", "until_event",
           "landing",
           "resolve_terms", "earth_model_constants", "energy_in_rotating_frame", "CONSERVATIVE_TERMS",
           "potential_energy", "jacobi_energy", "SAMPLES_PER_PERIOD", "MAX_SAMPLES", "samples_for",
           "unresolved_note", "method_rel_error", "reject_subnormal"]


# ---------------------------------------------------------------------------
# parameters: a frozen dataclass per scene, built once from the validated values
# ---------------------------------------------------------------------------

_KINDS = {float: "a number", int: "a whole number", bool: "true or false", str: "a string"}


def _convert(cls, name, kind, value):
    """``value`` as the field's type (float, int, bool, str or tuple of floats); ScenarioError otherwise."""
    origin = typing.get_origin(kind)
    if origin is tuple:
        try:
            return tuple(float(x) for x in value)
        except (TypeError, ValueError):
            raise ScenarioError(f"{name} = {value!r}: expected numbers (a vector) for {cls.__name__}") from None
    if kind is bool:
        if isinstance(value, bool):
            return value
    elif kind is str:
        if isinstance(value, str):
            return value
    elif kind is int:
        if isinstance(value, (int, float)) and not isinstance(value, bool) and value == int(value):
            return int(value)
    elif kind is float:
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return float(value)
    else:
        raise TypeError(f"{cls.__name__}.{name}: field type {kind!r} is not float, int, bool, str or tuple")
    raise ScenarioError(f"{name} = {value!r}: expected {_KINDS[kind]}")


@functools.cache
def _fields(cls):
    hints = typing.get_type_hints(cls)
    return {f.name: (hints[f.name], f) for f in dataclasses.fields(cls)}


def scene_parameters(cls, values):
    """An instance of the scene's frozen parameter dataclass ``cls`` from the validated ``values``.

    ``values`` maps parameter names to values in their documented units (what
    `rotframe.app.scenario.Scenario.with_values` resolves; a ``"run"`` key,
    the run settings, is not a parameter and is skipped). Each field is
    converted to its declared type (``float``, ``int``, ``bool``, ``str`` or
    ``tuple[float, ...]``); a field missing from ``values`` takes its default.
    An instance of ``cls`` is returned as it is.

    Raises
    ------
    ScenarioError
        For a key that is not a field of ``cls`` (a misspelt or foreign parameter
        in a scenario file: one line naming it and the allowed names), a field
        without a value and without a default, or a value of the wrong kind.
    """
    if isinstance(values, cls):
        return values
    fields = _fields(cls)
    unknown = [k for k in values if k not in fields and k != "run"]
    if unknown:
        key = unknown[0]
        raise ScenarioError(f"parameter {key} = {values[key]!r}: not a parameter of this scene "
                            f"({cls.__name__}); allowed: {', '.join(fields)}")
    kwargs = {}
    for name, (kind, f) in fields.items():
        if name in values:
            kwargs[name] = _convert(cls, name, kind, values[name])
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            raise ScenarioError(f"parameter {name}: missing; {cls.__name__} needs {', '.join(fields)}")
    return cls(**kwargs)


def with_parameters(cls, position=0):
    """Decorate a scene function whose argument ``position`` is a ``cls``: it then takes the values mapping too.

    The scene protocol passes ``values`` (a mapping; ``record(rec, values,
    result)`` has it at position 1); the decorated function receives
    ``scene_parameters(cls, values)`` in its place, so that scene code reads
    ``p.latitude`` (a misspelt name is an AttributeError, not a silent default)
    and callers that pass a dict, as the scene protocol does, keep working.
    """
    def decorate(func):
        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            args = list(args)
            args[position] = scene_parameters(cls, args[position])
            return func(*args, **kwargs)

        wrapper.parameters = cls
        return wrapper

    return decorate


# ---------------------------------------------------------------------------
# method names: canonical names in order, and the old names still accepted
# ---------------------------------------------------------------------------


def particle_methods() -> MethodNames:
    """The names of the methods that run the scenes' particle models, with their old names (`rotframe.method_registry`)."""
    return names("particle scenes")


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


def engine_terms(model):
    """A scene's model (`rotframe.particles.model.ParticleModel`, its terms by name) as the engine takes it:
    ``(omega, forces, frame_terms)``.

    Each named term becomes the built-in term of `rotframe.forces` that the scene's term is (the same arithmetic,
    `rotframe.particles.accelerations`), the frame's terms the engine's ``frame_terms``, and a steady rotation its
    vector. ``curvature`` is no force: it makes the ground a sphere, which is the scene's event
    (`rotframe.events.altitude`). A rotation that varies is a ScenarioError: a scene gives the engine its frame.
    """
    from rotframe import forces as rf
    from rotframe.problem.terms import FRAME_TERMS

    if not model.omega.is_constant:
        raise ScenarioError("model: a rotation rate that varies is not passed to the engine as a scene's model; "
                            "give the engine its frame")
    terms = []
    for t in model.terms:
        if t == "gravity":
            terms.append(rf.gravity(model.g))
        elif t == "altitude-gravity":
            terms.append(rf.altitude_gravity(model.g0, model.radius))
        elif t == "central-gravity":
            terms.append(rf.central_gravity(model.gm, (0.0, 0.0, -model.radius)))
        elif t == "spring":
            terms.append(rf.spring(model.spring, horizontal=True))
        elif t == "pendulum":
            terms.append(rf.pendulum(model.pendulum_length, model.pivot))
        elif t in ("linear-drag", "quadratic-drag"):
            if not any(getattr(f, "flow", None) for f in terms):  # both laws in one term, as the scenes sum them
                terms.append(rf.drag(linear=model.k_linear if model.has("linear-drag") else 0.0,
                                     quadratic=model.k_quadratic if model.has("quadratic-drag") else 0.0,
                                     scale_height=model.scale_height))
        elif t not in FRAME_TERMS and t != "curvature":  # the curved ground is the scene's event
            raise ScenarioError(f"model: the term {t!r} is not on the engine yet")
    return model.omega.vector(0.0), terms, tuple(t for t in model.terms if t in FRAME_TERMS)


def engine_remarks(res) -> dict:
    """``{"notes", "warnings"}`` of an engine's run (a `ProblemRun`; a partial trajectory has none) that a scene
    passes on: what the engine says of the run (its method, its tier, its caches), not of the diagnostics the scene
    does not report (a note that begins with the name of one of the engine's own, ``energy_rel_drift: ...``)."""
    own = tuple(f"{key}:" for key in getattr(res, "diagnostics", {}))
    return {"notes": [n for n in getattr(res, "notes", []) if not n.startswith(own)],
            "warnings": list(getattr(res, "warnings", []))}


def run_on_engine(model, r0, v0, duration, method, run, progress, finish, events=(), atol=None, energy=True,
                  device=None):
    """Integrate a particle scene's model on the engine (`rotframe.problem.particles.simulate_particles`) with the
    run settings (``step``, ``rtol``, ``samples``): every particle scene's run.

    ``finish(result)`` builds the scene's result from the engine's run (a `ProblemRun`, or the trajectory up to an
    early stop: `guarded`); its ``notes`` and ``warnings`` are the engine's. ``atol`` (DOP853's absolute tolerance,
    as ``rotframe.simulate`` takes it) where the scene has its own scale; None for each particle's own. ``energy``
    False skips the engine's energy diagnostic (an ensemble that reads its events alone); ``device`` is
    ``rotframe.simulate``'s (None: the CPU).
    """
    from rotframe.problem.particles import simulate_particles  # the engine's front door: imported by a run

    omega, forces, frame_terms = engine_terms(model)
    return guarded(finish, simulate_particles, omega=omega, r0=r0, v0=v0, duration=duration, method=method,
                   forces=forces, frame_terms=frame_terms, events=list(events), rtol=run_setting(run, "rtol"),
                   atol=atol, step=run.get("step"), samples=int(run_setting(run, "samples")), progress=progress,
                   energy=energy, device=device)


def guarded(finish, func, *args, **kwargs):
    """Run ``func`` and build the scene's result with ``finish(trajectory)``, even when the run stops early.

    The one home of a scene's early stop: an `IntegrationError` or `RunInterrupted` (a signal, a
    limit reached as the run goes) re-raises with ``exc.partial`` made by ``finish`` from the
    trajectory up to the stop (None when nothing was computed), so that the partial is analysed
    and recorded like a complete result, whichever integrator ran (a scene's own kernels, or
    `rotframe.problem` for the scenes built on the API).
    """
    try:
        traj = func(*args, **kwargs)
    except (IntegrationError, RunInterrupted) as exc:
        partial = getattr(exc, "partial", None)
        if hasattr(partial, "trajectory"):  # already a result
            partial = partial.trajectory
        exc.partial = finish(partial) if partial is not None and len(partial.times) else None
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


def landing(traj, name="ground", particle=0):
    """``(times, r, v, landed)``: `until_event` of the ``name`` event, and whether it happened."""
    times, r, v = until_event(traj, name, particle)
    return times, r, v, len(traj.event_times[name][particle]) > 0


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

    Uniform gravity only; `jacobi_energy` builds the energy from any model's terms.
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
    Euler force (a spin rate that changes) have no potential: see `jacobi_energy`.

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

    It is conserved when every term of the model is in `CONSERVATIVE_TERMS`
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
    scenes): 1e-8, its local tolerance grown over many steps. Fixed-step methods: 10 (h / T)^p with p their
    order in the particle registry (``rotframe.particles.integrators.METHODS``: 2 for the rotation
    splitting, 4 for its fourth-order composition and for ``rk4``; their global error over a
    motion of time scale T), a factor 10 of margin over the leading term.
    """
    from rotframe.particles.integrators import METHODS

    h = traj.extras.get("step") or 0.0
    info = METHODS.get(particle_methods().canonical(traj.method))
    order = info.order if info is not None and info.step == "fixed" else None
    if info is not None and info.step == "adaptive":
        return 1e-8
    if order is None or not h or not time_scale > 0:
        return 1e-9
    return 1e-9 + 10.0 * (h / time_scale) ** order


#: Magnitudes below this (m or s) have lost float64's relative precision (normal range ends at 2.2e-308):
#: a scene's metric derived from them is null with a note.
UNDERFLOW = 1e-290


def reject_subnormal(values):
    """ScenarioError for a nonzero parameter below the smallest normal float64 (2.2e-308).

    Such a value has fewer than 53 significant bits (1e-320 keeps about 10), and
    every length or time derived from it loses the rest: no result can be right
    to its stated accuracy, so the input is refused (exit 2) rather than run.
    """
    tiny = sys.float_info.min
    if dataclasses.is_dataclass(values):
        values = dataclasses.asdict(values)
    for key, value in values.items():
        items = value if isinstance(value, (list, tuple, np.ndarray)) else [value]
        for x in items:
            if isinstance(x, (float, int)) and not isinstance(x, bool) and x != 0 and abs(x) < tiny:
                raise ScenarioError(f"{key} = {x!r}: below the smallest normal float64 ({tiny:.4g}), a value that "
                                    "keeps too few significant digits to compute with; allowed: 0 or "
                                    f"|{key}| >= {tiny:.4g}")
