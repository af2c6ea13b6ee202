"""Integrators for particles in a rotating frame, chosen by name.

Every method honours one contract (as REBOUND's integrators do): it takes a
[`ParticleModel`][rotframe.particles.model.ParticleModel], initial positions and velocities of an
ensemble ``(N, 3)`` in the rotating frame, a duration and a number of output
samples, and returns a [`Trajectory`][rotframe.particles.trajectory.Trajectory]. The work is done by compiled
kernels (`rotframe.particles.kernels`) called in chunks, so that progress can be
shown, Ctrl-C and SIGTERM interrupt cleanly, and a numerical failure returns
everything computed before it.

Methods
-------
``rotation-splitting`` (alias ``splitting``)
    Exact-rotation splitting (drift, kick, exact Coriolis rotation, kick,
    drift). Order 2, explicit, time-reversible, volume-preserving; keeps |v|
    exactly under pure Coriolis motion; for a pendulum keeps the string length
    to round-off. One force evaluation per step. The default for particles.
``rotation-splitting4`` (alias ``splitting4``)
    Yoshida's symmetric composition of three ``rotation-splitting`` steps. Order 4,
    same conservation properties, three force evaluations per step.
``rk4``
    Classical Runge-Kutta. Order 4, four evaluations per step, conserves
    nothing exactly (energy and |v| drift secularly). For comparison.
``dop853``
    Adaptive Dormand-Prince 8(5,3) with Hairer's error control, output and
    events by re-stepping from the step start (an interpolant of order 8).
    Use when the forces are not smooth in time or the step must adapt
    (drag, close approach), or as a tight reference.
``exact``
    The exact flow, to round-off (docs/physics/earth.md, the exact linear flow and the exact
    flow of a force-free particle): the matrix exponential of the augmented linear system
    (r, v, 1) when the model is linear with constant coefficients
    (`ParticleModel.is_linear`; then the default), or the inertial straight line
    seen from the turning frame when the model is force-free under a varying rate
    (`ParticleModel.is_force_free`; events are not located on that one).
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING

import numpy as np

from rotframe import method_registry as registry
from rotframe.errors import IntegrationError, ScenarioError
from rotframe.particles.chunked import KernelSetup, run_chunked, sample_times
from rotframe.particles.trajectory import Event, RunInterrupted, Trajectory, per_particle

if TYPE_CHECKING:  # names used only in annotations
    from collections.abc import Callable, Sequence

    from numpy.typing import ArrayLike

    from rotframe.particles.model import ParticleModel

__all__ = ["METHODS", "ALIASES", "METHOD_NAMES", "canonical_method", "Event", "Trajectory", "RunInterrupted", "integrate_particles", "default_method", "check_work"]


#: The methods of the scenes' particle models, read from the one registry
#: (`rotframe.method_registry`): name -> `rotframe.method_registry.Method`.
METHODS = {m.name: m for m in registry.methods("particle scenes")}

#: Former names of particle methods, still accepted everywhere a particle method is named:
#: alias -> the `METHODS` key. (The heavy top's ``splitting``/``splitting4`` are other methods.)
ALIASES = registry.names("particle scenes").aliases

#: Every name a particle method may be given by: the `METHODS` keys, then the `ALIASES`.
METHOD_NAMES = tuple(METHODS) + tuple(ALIASES)


def canonical_method(name: str) -> str:
    """The `METHODS` key of a particle method given by its name or an alias (`ALIASES`), in any case.

    Raises
    ------
    ScenarioError
        A name that is neither.

    Examples
    --------
    >>> canonical_method("splitting4"), canonical_method("DOP853")
    ('rotation-splitting4', 'dop853')
    """
    return registry.check(name, "particle scenes")


def default_method(model: ParticleModel, events: Sequence[Event] = (), otherwise: str = "rotation-splitting") -> str:
    """``exact`` where the model has an exact flow, else ``otherwise`` (``rotation-splitting``).

    The exact flow: a linear constant-coefficient model, or a force-free one without
    events (events are located on the linear flow only). A scene whose other models need
    an adaptive method passes ``otherwise="dop853"``.
    """
    if model.is_linear or (model.is_force_free and not events):
        return "exact"
    return otherwise


def integrate_particles(model: ParticleModel, r0: ArrayLike, v0: ArrayLike, duration: float, *,
                        method: str | None = None, step: float | None = None, rtol: float = 1e-10,
                        atol: float | None = None, samples: int = 1000, events: Sequence[Event] = (),
                        progress: Callable[[float], object] | None = None, max_events: int = 64,
                        records: bool = False) -> Trajectory:
    """Integrate an ensemble of particles in a rotating frame, on every core.

    More than `rotframe.particles.threads.BLOCK` particles run in blocks on
    the threads in force (``--threads``, ``rotframe.run(..., threads=N)``, else every
    core); the result is bitwise the same for any number of threads. For many calls of
    one set-up, [`rotframe.particles.prepared.PreparedRun`][rotframe.particles.prepared.PreparedRun] makes it once.

    Parameters
    ----------
    model : ParticleModel
    r0, v0 : (3,) or (N, 3) array_like
        Initial positions (m) and velocities (m/s) in the rotating frame.
    duration : float
        Simulated time (s), > 0.
    method : str, optional
        A key of `METHODS` or an alias (`ALIASES`); default [`default_method`][rotframe.particles.integrators.default_method].
        The trajectory's ``method`` is the canonical name (the `METHODS` key).
    step : float, optional
        Step size (s) for fixed-step methods (the step used divides the output
        interval exactly and is never larger). Default: 1/20 of the output interval.
    rtol, atol : float
        Tolerances for ``dop853`` (atol defaults to rtol times the initial state scale).
    samples : int
        Number of output samples after t = 0 (uniform in time).
    events : sequence of Event
    progress : callable(fraction) or None
    max_events : int
        Event records kept per particle (more are counted, not kept).
    records : bool
        Leave the events of a complete run of a compiled method in their record arrays,
        ``traj.extras["event_records"]`` ([`rotframe.particles.trajectory.EventBuffers`][rotframe.particles.trajectory.EventBuffers]),
        instead of per-particle lists in ``event_times`` and ``event_states`` (for large
        ensembles, [`rotframe.particles.ensemble`][rotframe.particles.ensemble]). ``exact`` always gives the lists.

    Returns
    -------
    Trajectory
        ``samples + 1`` samples including t = 0.

    Raises
    ------
    ScenarioError
        Unknown method, or ``exact`` on a nonlinear model.
    IntegrationError
        Non-finite state or step-size collapse; ``partial`` holds the samples before it.
    RunInterrupted
        KeyboardInterrupt during the run; ``partial`` holds the samples before it.
    """
    method = canonical_method(method or default_method(model, events))
    info = METHODS[method]
    r0 = np.array(r0, dtype=np.float64, ndmin=2)  # our own copies (the drivers advance them in place)
    v0 = np.array(v0, dtype=np.float64, ndmin=2)
    if r0.shape != v0.shape or r0.shape[-1] != 3 or r0.ndim != 2:
        raise ScenarioError(f"initial state: r0 and v0 must be (N, 3), got {r0.shape} and {v0.shape}")
    duration = float(duration)
    if not (math.isfinite(duration) and duration > 0):
        raise ScenarioError(f"duration: {duration:g} s; must be finite and > 0 (a parameter too large or too small?)")
    if not _finite(r0, v0):
        raise ScenarioError("initial state: the parameters give a non-finite position or velocity "
                            "(a parameter too large?)")
    samples = max(1, int(samples))
    if info.step != "exact":
        setup = _setup(model, info, duration, samples, step, rtol, atol, events, r0.shape[0])
        return run_chunked(setup, model, r0, v0, progress, max_events, records, owned=True)
    check_work(info, duration, step, samples, r0.shape[0], model)
    check_exact(model)
    return integrate_exact(model, r0, v0, duration, samples, events, progress)


def check_exact(model: ParticleModel) -> None:
    """A one-line ScenarioError where ``method="exact"`` cannot run the scene's ``model`` (no exact flow), naming why."""
    if not model.has_exact_flow:
        why = "; ".join(model.nonlinear_reasons())
        raise ScenarioError(f"method: 'exact' needs a linear model with constant coefficients ({why}) "
                            "or a force-free one (only coriolis, centrifugal and euler); "
                            "use rotation-splitting, rotation-splitting4, rk4 or dop853")


# ---------------------------------------------------------------------------

#: the set-ups of recent runs: (model and run settings) -> [KernelSetup, limits checked, particles checked]
_SETUPS: dict = {}
_SETUPS_KEPT = 16


def _setup(model, info, duration, samples, step, rtol, atol, events, n):
    """The `KernelSetup` of a run, made once for the same model and settings (its work checked).

    A repeated call (the same model values, method, duration, samples, step, tolerances and
    events) reuses the set-up and its work check, so that a short run costs little beyond its
    steps. The key holds the model's packed values and schedule, so a model changed in place
    is a new key.
    """
    from rotframe import limits

    P = model.pack()
    w = model.omega
    try:
        key = (model.terms, P.tobytes(), w.axis.tobytes(), w.times.tobytes(), w.values.tobytes(), info.name,
               duration, samples, step, rtol, atol, tuple(events))
        hash(key)
    except TypeError:  # an unhashable setting: no reuse
        key = None
    entry = _SETUPS.get(key) if key is not None else None
    lim = limits.current()
    if entry is None:
        check_work(info, duration, step, samples, n, model)
        entry = [KernelSetup(model, info, duration, samples, step=step, rtol=rtol, atol=atol, events=events), lim, n]
        if key is not None:
            if len(_SETUPS) >= _SETUPS_KEPT:
                _SETUPS.pop(next(iter(_SETUPS)))
            _SETUPS[key] = entry
    elif entry[1] is not lim or entry[2] != n:
        check_work(info, duration, step, samples, n, model)
        entry[1], entry[2] = lim, n
    return entry[0]



def _finite(r0, v0):
    """Whether every value of ``r0`` and ``v0`` is finite (a few particles: in Python, faster than numpy's calls)."""
    if r0.size <= 24:
        return all(map(math.isfinite, r0.ravel().tolist() + v0.ravel().tolist()))
    return bool(np.isfinite(r0).all() and np.isfinite(v0).all())


def check_work(info, duration, step, samples, n, model):
    """Refuse, before allocating anything, a run over the work limits (`rotframe.limits`)."""
    from rotframe import limits

    steps, remedy = 0.0, "shorten duration or enlarge step"
    if info.step == "fixed":
        # in floats: a step far below the sample interval gives a count beyond any integer a float holds
        per = (duration / samples) / float(step) if step else 20.0
        steps = float(samples) * math.ceil(per) if per < 1e300 else math.inf
    elif info.step == "adaptive":
        # the least an adaptive method can take, from the model's own rates (a closed form, before any
        # compiling or probing): no step spans more than MAX_RAD_PER_STEP of its fastest oscillation
        steps = duration * fastest_rate(model) / MAX_RAD_PER_STEP
        remedy = "shorten duration (no tolerance takes fewer steps than the motion's own rate allows)"
    limits.check_run(steps=steps, samples=samples + 1, particles=n, what=f"method {info.name}", remedy=remedy)


#: The most radians of its fastest oscillation one adaptive step can span: DOP853's stability interval on
#: the imaginary axis is shorter (about 4.5); an accurate step spans far less (0.2 at rtol 1e-10).
MAX_RAD_PER_STEP = 6.0


def fastest_rate(model) -> float:
    """The fastest angular rate (rad/s) of ``model``'s motion, from its parameters: the pendulum's
    sqrt(g / length), the spring's sqrt(k) and twice the frame's largest rate (the inertial
    oscillation of a Coriolis term). 0 when it has none (a steady fall)."""
    rates = [0.0]
    if model.has("pendulum") and model.pendulum_length > 0:
        g = float(np.linalg.norm(model.g)) or float(model.g0)
        rates.append(math.sqrt(g / model.pendulum_length))
    if model.has("spring") and model.spring > 0:
        rates.append(math.sqrt(model.spring))
    if any(model.has(t) for t in ("coriolis", "centrifugal", "euler")):
        values = np.asarray(model.omega.values, dtype=float)
        if values.size:
            rates.append(2.0 * float(np.max(np.abs(values))))
    rate = max(rates)
    return rate if math.isfinite(rate) else math.inf


def integrate_exact(model, r0, v0, duration, samples, events, progress, ordered=False):
    """The exact flow (`rotframe.particles.linear.ExactFlow`): s(t_k) = Phi_k s(0), s = (r, v, 1).

    ``model``: what `ExactFlow` reads (a linear or force-free `ParticleModel`, or a problem of your
    own's `rotframe.problem.exact.LinearProblem`); ``r0``, ``v0`` (N, 3) float arrays; ``ordered``:
    each particle's numbers independent of N (`rotframe.particles.linear.ordered_product`).

    Events are located on the exact flow of a linear model for all particles at
    once (`rotframe.particles.linear.locate_crossings`).
    """
    from rotframe.particles.linear import ExactFlow, locate_crossings

    if events and not model.is_linear:
        raise ScenarioError(f"event {events[0].name!r}: method 'exact' locates events on a linear model only "
                            "(this one is force-free with a varying rate); use dop853")
    n = r0.shape[0]
    s0 = np.concatenate([r0, v0, np.ones((n, 1))], axis=1).T  # (7, N)
    times = sample_times(duration, samples)
    out = np.empty((samples + 1, 7, n))
    flow = None
    done = 0

    def count(fraction):
        nonlocal done
        done = round(fraction * (samples + 1))
        if progress is not None:
            progress(fraction)

    try:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            # an overflow (an unstable linear model run far) is caught below as a non-finite state
            warnings.simplefilter("ignore", RuntimeWarning)
            flow = ExactFlow(model, times)
            flow.states(s0, out, count, ordered)
    except KeyboardInterrupt:
        partial = Trajectory(times, np.transpose(out[:, 0:3, :], (0, 2, 1)), np.transpose(out[:, 3:6, :], (0, 2, 1)),
                             "exact", 1, 0).truncated(max(done, 1)) if done else None
        if partial is not None:  # events not located in a partial run: none, for every particle
            for ev in events:
                partial.event_times.setdefault(ev.name, [np.empty(0) for _ in range(n)])
                partial.event_states.setdefault(ev.name, [np.empty((0, 6)) for _ in range(n)])
        raise RunInterrupted(partial) from None
    traj = Trajectory(times, np.transpose(out[:, 0:3, :], (0, 2, 1)).copy(),
                      np.transpose(out[:, 3:6, :], (0, 2, 1)).copy(), "exact", 1, 0, True, duration)
    finite = np.all(np.isfinite(out), axis=(1, 2))
    if not finite.all():
        k = int(np.argmin(finite))  # the first sample with a non-finite state; keep those before it
        partial = traj.truncated(max(k, 1))
        raise IntegrationError(f"exact propagator produced a non-finite state at t = {times[k]:.6g} s",
                               t_reached=float(times[max(k - 1, 0)]), partial=partial)
    M = flow.M if events else None
    dt = duration / samples
    for ev in events:
        if ev.kind not in ("r", "v"):
            raise ScenarioError(f"event {ev.name!r}: kind {ev.kind!r} needs a nonlinear model, not 'exact'")
        col = ev.component + (0 if ev.kind == "r" else 3)
        g = out[:, col, :] - ev.value  # (samples + 1, N)
        # a function that starts at exactly zero takes the sign it has just after the start
        # (first non-zero derivative), as in the kernels (docs/physics/events.md)
        g = g.copy()
        zero = g[0] == 0.0
        if zero.any():
            d1 = M[col] @ out[0]
            d2 = M[col] @ (M @ out[0])
            g[0] = np.where(zero, np.where(d1 != 0.0, np.sign(d1), np.sign(d2)) * 1e-300, g[0])
        rising = (g[:-1] < 0.0) & (g[1:] >= 0.0)
        falling = (g[:-1] > 0.0) & (g[1:] <= 0.0)
        crossed = rising if ev.direction > 0 else falling if ev.direction < 0 else rising | falling
        if ev.terminal:  # only each particle's first crossing counts
            has = crossed.any(axis=0)
            first = np.argmax(crossed, axis=0)
            crossed = np.zeros_like(crossed)
            crossed[first[has], np.nonzero(has)[0]] = True
        k, p = np.nonzero(crossed)
        tau, state = locate_crossings(M, out[k, :, p].T, np.full(len(k), dt), g[k, p], g[k + 1, p], col,
                                      ev.value, times[k])
        order = np.argsort(p, kind="stable")  # group the crossings by particle, in time order
        counts = np.bincount(p, minlength=n)
        traj.event_times[ev.name] = per_particle((times[k] + tau)[order], counts)
        traj.event_states[ev.name] = per_particle(state[:6].T[order], counts)
        if ev.terminal:  # a stopped particle keeps its event state in the later samples
            after = np.arange(samples + 1)[:, None] > k[None, :]  # (samples + 1, crossings)
            traj.r[:, p] = np.where(after[:, :, None], state[0:3].T[None], traj.r[:, p])
            traj.v[:, p] = np.where(after[:, :, None], state[3:6].T[None], traj.v[:, p])
    return traj
