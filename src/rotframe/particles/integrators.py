"""Integrators for particles in a rotating frame, chosen by name.

Every method honours one contract (as REBOUND's integrators do): it takes a
:class:`~rotframe.particles.model.ParticleModel`, initial positions and velocities of an
ensemble ``(N, 3)`` in the rotating frame, a duration and a number of output
samples, and returns a :class:`Trajectory`. The work is done by compiled
kernels (:mod:`rotframe.particles.kernels`) called in chunks, so that progress can be
shown, Ctrl-C and SIGTERM interrupt cleanly, and a numerical failure returns
everything computed before it.

Methods
-------
``splitting``
    Exact-rotation splitting (drift, kick, exact Coriolis rotation, kick,
    drift). Order 2, explicit, time-reversible, volume-preserving; keeps |v|
    exactly under pure Coriolis motion; for a pendulum keeps the string length
    to round-off. One force evaluation per step. The default for particles.
``splitting4``
    Yoshida's symmetric composition of three ``splitting`` steps. Order 4,
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
    Matrix exponential of the augmented linear system (r, v, 1)
    (docs/physics/earth.md, the exact linear flow). Exact to round-off; applies only when the model is
    linear with constant coefficients (:attr:`ParticleModel.is_linear`), and is
    then the default.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from rotframe.errors import IntegrationError, ScenarioError

if TYPE_CHECKING:  # names used only in annotations
    from collections.abc import Callable, Sequence

    from numpy.typing import ArrayLike

    from rotframe.particles.model import ParticleModel

__all__ = ["METHODS", "Event", "Trajectory", "RunInterrupted", "integrate_particles", "default_method"]


@dataclass(frozen=True)
class MethodInfo:
    name: str
    order: int
    kind: str  # "fixed", "adaptive" or "exact"
    conserves: str
    code: int = -1


METHODS = {
    "splitting": MethodInfo("splitting", 2, "fixed", "|v| under Coriolis, pendulum constraint; time-reversible", 0),
    "splitting4": MethodInfo("splitting4", 4, "fixed", "as splitting", 1),
    "rk4": MethodInfo("rk4", 4, "fixed", "nothing exactly", 2),
    "dop853": MethodInfo("dop853", 8, "adaptive", "nothing exactly; error per step below rtol"),
    "exact": MethodInfo("exact", 0, "exact", "everything (exact solution of the linear model)"),
}


@dataclass(frozen=True)
class Event:
    """A zero crossing located to round-off on the method's own trajectory.

    ``kind`` "r" or "v": the event function is ``r[component] - value`` or
    ``v[component] - value``; "altitude": height above the sphere of the
    model's ``radius`` centred at (0, 0, -radius), minus ``value`` (curved ground); ``direction`` +1 rising, -1 falling, 0 both;
    a ``terminal`` event stops that particle (ground impact).
    """

    name: str
    kind: str
    component: int
    value: float = 0.0
    direction: int = 0
    terminal: bool = False

    def row(self):
        kind = {"r": 0.0, "v": 1.0, "altitude": 2.0}[self.kind]
        return [kind, float(self.component), float(self.value),
                float(self.direction), float(self.terminal)]


@dataclass
class Trajectory:
    """Samples of an ensemble trajectory (rotating frame, SI).

    Attributes
    ----------
    times : (n,) array, s
    r, v : (n, N, 3) arrays, m and m/s
    event_times : dict name -> list (per particle) of arrays of event times
    event_states : dict name -> list (per particle) of (k, 6) arrays (r, v)
    method, steps, nfev : what was run and what it cost (one trajectory)
    complete : False when the run stopped early; ``t_reached`` says where.
    """

    times: np.ndarray
    r: np.ndarray
    v: np.ndarray
    method: str
    steps: int = 0
    nfev: int = 0
    complete: bool = True
    t_reached: float = math.nan
    event_times: dict = field(default_factory=dict)
    event_states: dict = field(default_factory=dict)
    extras: dict = field(default_factory=dict)

    def truncated(self, n: int) -> Trajectory:
        return Trajectory(self.times[:n], self.r[:n], self.v[:n], self.method, self.steps, self.nfev,
                          False, float(self.times[n - 1]) if n else math.nan,
                          self.event_times, self.event_states, self.extras)


_LOADED = set()  # kernels already loaded in this process


class RunInterrupted(Exception):
    """Ctrl-C or SIGTERM during a run; ``partial`` holds what was computed."""

    def __init__(self, partial, reason="interrupted"):
        super().__init__(reason)
        self.partial = partial
        self.reason = reason


def default_method(model: ParticleModel) -> str:
    """``exact`` for linear constant-coefficient models, else ``splitting``."""
    return "exact" if model.is_linear else "splitting"


def integrate_particles(model: ParticleModel, r0: ArrayLike, v0: ArrayLike, duration: float, *,
                        method: str | None = None, step: float | None = None, rtol: float = 1e-10,
                        atol: float | None = None, samples: int = 1000, events: Sequence[Event] = (),
                        progress: Callable[[float], object] | None = None, max_events: int = 64) -> Trajectory:
    """Integrate an ensemble of particles in a rotating frame.

    Parameters
    ----------
    model : ParticleModel
    r0, v0 : (3,) or (N, 3) array_like
        Initial positions (m) and velocities (m/s) in the rotating frame.
    duration : float
        Simulated time (s), > 0.
    method : str, optional
        A key of :data:`METHODS`; default :func:`default_method`.
    step : float, optional
        Step size (s) for fixed-step methods (the step used divides the output
        interval exactly and is never larger). Default: 1/20 of the output interval.
    rtol, atol : float
        Tolerances for ``dop853`` (atol defaults to rtol times the initial state scale).
    samples : int
        Number of output samples after t = 0 (uniform in time).
    events : sequence of Event
    progress : callable(fraction) or None

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
    method = method or default_method(model)
    if method not in METHODS:
        raise ScenarioError(f"method: unknown {method!r}; allowed: {', '.join(METHODS)}")
    info = METHODS[method]
    r0 = np.atleast_2d(np.asarray(r0, dtype=np.float64)).copy()
    v0 = np.atleast_2d(np.asarray(v0, dtype=np.float64)).copy()
    if r0.shape != v0.shape or r0.shape[-1] != 3:
        raise ScenarioError(f"initial state: r0 and v0 must be (N, 3), got {r0.shape} and {v0.shape}")
    duration = float(duration)
    if not (math.isfinite(duration) and duration > 0):
        raise ScenarioError(f"duration: {duration:g} s; must be finite and > 0 (a parameter too large or too small?)")
    if not (np.isfinite(r0).all() and np.isfinite(v0).all()):
        raise ScenarioError("initial state: the parameters give a non-finite position or velocity "
                            "(a parameter too large?)")
    samples = max(1, int(samples))
    _check_work(info, duration, step, samples, r0.shape[0])
    if info.kind == "exact":
        if not model.is_linear:
            why = "; ".join(model.nonlinear_reasons())
            raise ScenarioError(f"method: 'exact' needs a linear model with constant coefficients ({why}); "
                                "use splitting, splitting4, rk4 or dop853")
        return _integrate_exact(model, r0, v0, duration, samples, events, progress)
    return _integrate_kernel(model, info, r0, v0, duration, step, rtol, atol, samples, events, progress,
                             max_events)


# ---------------------------------------------------------------------------


def _check_work(info, duration, step, samples, n):
    """Refuse, before allocating anything, a run over the work limits (:mod:`rotframe.limits`)."""
    from rotframe import limits

    steps = 0.0
    if info.kind == "fixed":
        dt_sample = duration / samples
        h_req = float(step) if step else dt_sample / 20.0
        if h_req > 0:
            steps = samples * max(1.0, math.ceil(dt_sample / h_req - 1e-9))
    limits.check_run(steps=steps, samples=samples + 1, particles=n, what=f"method {info.name}")


def _adaptive_chunk(info, per_sample, samples, n):
    """Samples per call of an adaptive kernel that took ``per_sample`` steps over its first sample.

    The run's total is projected from that rate and refused (:mod:`rotframe.limits`) when it
    is over the work limit; a call is kept under about 2e5 particle-steps (a tenth of a
    second), so that Python regains control (signals, progress) that often.
    """
    from rotframe import limits

    per_sample = max(float(per_sample), 1.0)
    limits.check_run(steps=per_sample * samples, particles=n,
                     what=f"method {info.name} (projected from its first sample interval)")
    return int(max(1.0, 2e5 / (per_sample * max(n, 1))))


def _event_table(events):
    if not events:
        return np.zeros((0, 5))
    return np.array([e.row() for e in events], dtype=np.float64)


class _EventBuffers:
    """Per-particle event records filled by the kernels, in order of occurrence."""

    def __init__(self, n, max_events):
        self.t = np.full((n, max_events), np.nan)
        self.r = np.zeros((n, max_events, 3))
        self.v = np.zeros((n, max_events, 3))
        self.count = np.zeros(n, dtype=np.int64)
        self.which = np.zeros((n, max_events), dtype=np.int64)
        self.max_events = max_events

    def args(self):
        return self.t, self.r, self.v, self.count, self.which, self.max_events

    def attach(self, traj, events):
        """Split the records by event name into ``traj.event_times`` / ``event_states``."""
        for e_idx, ev in enumerate(events):
            traj.event_times[ev.name] = []
            traj.event_states[ev.name] = []
            for p in range(self.count.shape[0]):
                k = min(int(self.count[p]), self.max_events)
                mask = self.which[p, :k] == e_idx
                traj.event_times[ev.name].append(self.t[p, :k][mask])
                traj.event_states[ev.name].append(
                    np.concatenate([self.r[p, :k][mask], self.v[p, :k][mask]], axis=1))


def _integrate_kernel(model, info, r0, v0, duration, step, rtol, atol, samples, events, progress,
                      max_events):
    from rotframe.particles import drivers as kernels
    n = r0.shape[0]
    P = model.pack()
    wt, wv = model.omega.times, model.omega.values
    wint = model.omega.cumulative()
    ev_tab = _event_table(events)
    evb = _EventBuffers(n, max_events)
    alive = np.ones(n, dtype=np.bool_)
    r = r0.copy()
    v = v0.copy()
    out_r = np.empty((samples + 1, n, 3))
    out_v = np.empty((samples + 1, n, 3))
    out_r[0] = r0
    out_v[0] = v0
    dt_sample = duration / samples
    times = np.arange(samples + 1) * dt_sample
    times[-1] = duration

    if info.kind == "fixed":
        h_req = float(step) if step else dt_sample / 20.0
        if not h_req > 0:
            raise ScenarioError(f"step: {step}; must be > 0")
        sps = max(1, math.ceil(dt_sample / h_req - 1e-9))
        h = dt_sample / sps
        cost = sps * n * (3 if info.code == 1 else 4 if info.code == 2 else 1)
    else:
        sps = 0
        h = 0.0
        scale = max(1.0, float(np.max(np.abs(np.concatenate([r0, v0])))))
        atol = float(atol) if atol else float(rtol) * scale
        h_state = np.zeros(n)
        from rotframe.numerics.dop853 import coefficients

        A, B, C, E3, E5 = coefficients()
        cost = n * 200
    guard = _energy_guard(model, r0, v0)
    chunk = max(1, int(4e6 // max(cost, 1)))
    done = 0
    nfev = 0
    steps = 0
    try:
        # a call with no samples loads (or compiles) the kernel, once per process: timed apart, as compile_s
        t_load = time.perf_counter()
        if info.kind in _LOADED:
            pass
        elif info.kind == "fixed":
            kernels.run_fixed(info.code, r[:0], v[:0], alive[:0], 0.0, h, sps, 0, P, wt, wv, wint, ev_tab,
                              out_r[:0], out_v[:0], *_EventBuffers(0, 1).args())
        else:
            kernels.run_dop853(r[:0], v[:0], alive[:0], 0.0, times[1:2], P, wt, wv, float(rtol), atol, 1.0, A, B,
                               C, E3, E5, ev_tab, out_r[:0], out_v[:0], *_EventBuffers(0, 1).args(), h_state[:0])
        _LOADED.add(info.kind)
        compile_s = time.perf_counter() - t_load
        if info.kind != "fixed":
            # an adaptive method's cost is known only once it ran: a probe of the first sample
            # interval, on copies (the run itself is untouched), projects the work and sizes the calls
            probe = kernels.run_dop853(
                r.copy(), v.copy(), alive.copy(), 0.0, times[1:2], P, wt, wv, float(rtol), atol, dt_sample / 10.0,
                A, B, C, E3, E5, ev_tab, out_r[1:2].copy(), out_v[1:2].copy(),
                *_EventBuffers(n, max_events).args(), h_state.copy())
            chunk = min(chunk, _adaptive_chunk(info, probe[3], samples, n))
        while done < samples:
            m = min(chunk, samples - done)
            t0 = times[done]
            sl = slice(done + 1, done + 1 + m)
            if info.kind == "fixed" and cost > 4e6:
                # one sample interval is more than a chunk of work: advance it in pieces, so that
                # Python regains control (signals, progress) about every 0.1 s
                n_done, bad, nf = _fixed_in_pieces(kernels, info, r, v, alive, t0, h, sps, n, P, wt, wv, wint,
                                                   ev_tab, out_r[sl], out_v[sl], evb)
                steps += sps * n_done
            elif info.kind == "fixed":
                n_done, bad, nf = kernels.run_fixed(
                    info.code, r, v, alive, t0, h, sps, m, P, wt, wv, wint, ev_tab,
                    out_r[sl], out_v[sl], *evb.args())
                steps += sps * n_done
            else:
                n_done, bad, nf, st = kernels.run_dop853(
                    r, v, alive, t0, times[sl], P, wt, wv, float(rtol), atol, dt_sample / 10.0,
                    A, B, C, E3, E5, ev_tab, out_r[sl], out_v[sl], *evb.args(), h_state)
                steps += st
            nfev += nf
            if n_done < m or bad >= 0:
                good = done + 1 + n_done
                partial = Trajectory(times, out_r, out_v, info.name, steps, nfev).truncated(good)
                evb.attach(partial, events)
                raise IntegrationError(
                    f"non-finite state of particle {bad} after t = {times[good - 1]:.6g} s "
                    f"(method {info.name})", t_reached=float(times[good - 1]), partial=partial)
            bad_k = _energy_growth(model, guard, times, out_r, out_v, done + 1, done + 1 + m)
            if bad_k is not None:
                partial = Trajectory(times, out_r, out_v, info.name, steps, nfev).truncated(bad_k)
                evb.attach(partial, events)
                raise IntegrationError(
                    f"unstable step: the inertial speed of a particle under no real force grew by more than "
                    f"{_GROWTH_LIMIT:g} (relative) by t = {times[bad_k]:.6g} s (method {info.name}, step {h:.3g} s); "
                    "use a smaller step or dop853", t_reached=float(times[bad_k - 1]), partial=partial)
            done += m
            if progress is not None:
                progress(done / samples)
            if not alive.any():
                # every particle stopped at a terminal event: fill the rest and finish
                out_r[done + 1:] = r
                out_v[done + 1:] = v
                done = samples
    except KeyboardInterrupt:
        partial = Trajectory(times, out_r, out_v, info.name, steps, nfev).truncated(done + 1)
        evb.attach(partial, events)
        raise RunInterrupted(partial) from None
    traj = Trajectory(times, out_r, out_v, info.name, steps, nfev, True, duration)
    traj.extras["step"] = h
    traj.extras["compile_s"] = compile_s
    evb.attach(traj, events)
    return traj


#: Relative growth of the inertial speed beyond which a run of a force-free model is unstable.
_GROWTH_LIMIT = 1e-3


def _inertial_speed(model, t, r, v):
    """|v + w(t) x r| for positions and velocities (..., N, 3) at times t (...,)."""
    w = np.interp(t, model.omega.times, model.omega.values)
    wv = np.asarray(w)[..., None, None] * model.omega.axis
    return np.linalg.norm(v + np.cross(wv, r), axis=-1)


def _energy_guard(model, r0, v0):
    """The initial inertial speeds when the model's true motion keeps them (else None).

    A particle under the fictitious forces alone (Coriolis, centrifugal, and
    Euler when the rate varies) moves on a straight line at constant speed in
    inertial space; drag only slows it. So its inertial speed |v + w x r| never
    grows, whatever the frame does, and a growth beyond :data:`_GROWTH_LIMIT`
    is the mark of an unstable step (docs/physics/stability.md). Models with a
    real force that can add energy (gravity, springs, a pendulum) return None.
    """
    terms = set(model.terms)
    fictitious = {"coriolis", "centrifugal"} | (set() if model.omega.is_constant else {"euler"})
    if not fictitious <= terms or not terms <= fictitious | {"euler", "linear-drag", "quadratic-drag"}:
        return None
    return _inertial_speed(model, 0.0, r0, v0)


def _energy_growth(model, guard, times, out_r, out_v, lo, hi):
    """Index of the first sample in [lo, hi) where the inertial speed grew past the limit, or None."""
    if guard is None:
        return None
    with np.errstate(all="ignore"):
        speed = _inertial_speed(model, times[lo:hi], out_r[lo:hi], out_v[lo:hi])
    scale = np.maximum(guard, 1e-300)
    grown = np.any(speed > (1.0 + _GROWTH_LIMIT) * scale + 1e-12, axis=1) | ~np.all(np.isfinite(speed), axis=1)
    if not grown.any():
        return None
    return lo + int(np.argmax(grown))


def _fixed_in_pieces(kernels, info, r, v, alive, t0, h, sps, n, P, wt, wv, wint, ev_tab, out_r, out_v, evb):
    """One sample interval of ``sps`` fixed steps as several kernel calls of about 4e6 step-evaluations."""
    factor = 3 if info.code == 1 else 4 if info.code == 2 else 1
    piece = max(1, int(4e6 // (n * factor)))
    scratch_r, scratch_v = np.empty((1, n, 3)), np.empty((1, n, 3))
    j = 0
    nfev = 0
    while j < sps:
        k = min(piece, sps - j)
        last = j + k == sps
        n_done, bad, nf = kernels.run_fixed(info.code, r, v, alive, t0 + j * h, h, k, 1, P, wt, wv, wint, ev_tab,
                                            out_r[:1] if last else scratch_r, out_v[:1] if last else scratch_v,
                                            *evb.args())
        nfev += nf
        if n_done < 1 or bad >= 0:
            return 0, bad, nfev
        j += k
    return 1, -1, nfev


def _integrate_exact(model, r0, v0, duration, samples, events, progress):
    """Exact propagator: s(t) = expm(M t) s(0), s = (r, v, 1) (docs/physics/earth.md).

    expm is evaluated directly at every 64th sample and the samples between
    are reached by powers of the one-interval propagator, so round-off stays
    at a few tens of ulps however long the run. Events are located on the exact
    flow for all particles at once (:func:`rotframe.particles.linear.locate_crossings`).
    """
    from scipy.linalg import expm

    from rotframe.particles.linear import flow_matrix, locate_crossings

    M = flow_matrix(model)
    n = r0.shape[0]
    s0 = np.concatenate([r0, v0, np.ones((n, 1))], axis=1).T  # (7, N)
    dt = duration / samples
    times = np.arange(samples + 1) * dt
    times[-1] = duration
    block = 64
    out = np.empty((samples + 1, 7, n))
    done = 0
    try:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            # an overflow (an unstable linear model run far) is caught below as a non-finite state
            warnings.simplefilter("ignore", RuntimeWarning)
            powers = [np.eye(7)]
            step_matrix = expm(M * dt)
            for _ in range(block - 1):
                powers.append(step_matrix @ powers[-1])
            for start in range(0, samples + 1, block):
                anchor = expm(M * times[start]) @ s0
                for j in range(min(block, samples + 1 - start)):
                    out[start + j] = powers[j] @ anchor
                done = min(samples + 1, start + block)
                if progress is not None:
                    progress(min(1.0, (start + block) / (samples + 1)))
    except KeyboardInterrupt:
        partial = Trajectory(times, np.transpose(out[:, 0:3, :], (0, 2, 1)), np.transpose(out[:, 3:6, :], (0, 2, 1)),
                             "exact", 1, 0).truncated(max(done, 1)) if done else None
        raise RunInterrupted(partial) from None
    traj = Trajectory(times, np.transpose(out[:, 0:3, :], (0, 2, 1)).copy(),
                      np.transpose(out[:, 3:6, :], (0, 2, 1)).copy(), "exact", 1, 0, True, duration)
    finite = np.all(np.isfinite(out), axis=(1, 2))
    if not finite.all():
        k = int(np.argmin(finite))  # the first sample with a non-finite state; keep those before it
        partial = traj.truncated(max(k, 1))
        raise IntegrationError(f"exact propagator produced a non-finite state at t = {times[k]:.6g} s",
                               t_reached=float(times[max(k - 1, 0)]), partial=partial)
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
        splits = np.cumsum(np.bincount(p, minlength=n))[:-1]
        traj.event_times[ev.name] = np.split((times[k] + tau)[order], splits)
        traj.event_states[ev.name] = np.split(state[:6].T[order], splits)
        if ev.terminal:  # a stopped particle keeps its event state in the later samples
            after = np.arange(samples + 1)[:, None] > k[None, :]  # (samples + 1, crossings)
            traj.r[:, p] = np.where(after[:, :, None], state[0:3].T[None], traj.r[:, p])
            traj.v[:, p] = np.where(after[:, :, None], state[3:6].T[None], traj.v[:, p])
    return traj
