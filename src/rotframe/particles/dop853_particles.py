"""A particle ensemble on the one DOP853 loop: the particle's right-hand side, its samples and its events.

`rotframe.numerics.dop853_loop.dop853_trajectory` integrates one trajectory;
`rotframe.particles.dop853_ensemble.run_particles` runs it for each particle of an ensemble. The scene
drivers are this loop with a right-hand side each: `rotframe.particles.drivers.run_dop853` and
`run_dop853_events` with `particle_rhs` (every term and rotation schedule; the second watches
the events); `rotframe.particles.dop853_steady.run_dop853_steady` is the same loop with the engine's
steady problems' force (`rotframe.problem.steady`). Events are watched after each accepted step
(`watch_events`) and located by bisection on the length of one DOP853 step from the step's start (`locate_event_dop853`: rotframe's one locator,
`rotframe.numerics.bisection.locator`, with that trial).
"""

from __future__ import annotations

from numba import njit

from rotframe.numerics.bisection import locator
from rotframe.numerics.compiled import bound, jit_inline, jit_llvm_inline, jit_uncounted
from rotframe.numerics.dop853_loop import dop853_stages, dop853_step, dop853_trajectory
from rotframe.particles.dop853_ensemble import store_sample
from rotframe.particles.events import crossed, event_value, record_event, start_value
from rotframe.particles.forces import state_acceleration
from rotframe.particles.packed import as_state
from rotframe.particles.schedule import rates

__all__ = ["particle_rhs", "particle_stages", "particle_trajectory", "particle_trajectory_events",
           "dop853_event_value", "locate_dop853", "locate_event_dop853", "watch_events", "dop853_watcher",
           "start_events"]

#: the force, inlined into the right-hand side (numba IR: twelve evaluations a step)
_acceleration = njit(inline="always", error_model="numpy", nogil=True)(state_acceleration.py_func)


@jit_llvm_inline
def particle_rhs(ctx, t, z, K, s):
    """``K[s] = f(t, z)`` for a particle: velocity, then the model's acceleration; ``ctx = (m, wt, wv)``."""
    m, wt, wv = ctx
    w, wd = rates(t, m.steady, m.w, wt, wv)
    K[s, 3], K[s, 4], K[s, 5] = _acceleration(as_state(z), m, w, wd)
    K[s, 0], K[s, 1], K[s, 2] = z[3], z[4], z[5]


#: the particle's stages (`rotframe.numerics.dop853_loop.dop853_stages`)
particle_stages = dop853_stages("particle", particle_rhs, 6)


# the names a system's watcher binds (`dop853_watcher`): its stages, its locator and its located event; None in the
# templates themselves, which are never compiled
STAGES = LOCATE = LOCATE_EVENT = None


def _event_value_after(lctx, tau):
    """The template of a system's trial (`dop853_watcher`): the event function after one DOP853 step of length
    ``tau`` by the system's ``STAGES``.

    ``lctx = (ctx, events, e, radius, t, y, Kt, tmp, y_out)`` (`_locate_event`).
    """
    ctx, events, e, radius, t, y, Kt, tmp, y_out = lctx
    dop853_step(STAGES, ctx, t, y, tau, Kt, y_out, tmp)
    return event_value(events, e, as_state(y_out), radius)


def _locate_event(ctx, events, e, radius, g_start, t, h, K, Kt, y, tmp, y_out):
    """The template of a system's located event (`dop853_watcher`): `rotframe.particles.events.locate_event` for a
    DOP853 step, the trial state one DOP853 step of length tau.

    The step starts from ``y`` (6,) at t with ``K[0] = f(t, y)`` of the system's right-hand side (its ``STAGES``,
    with ``ctx``); ``Kt`` (13, 6) and ``tmp`` (6,) are scratch, and ``y_out`` (6,) receives the state. Returns tau
    and the state at the event (a 6-tuple).
    """
    for j in range(6):
        Kt[0, j] = K[0, j]
    tau = LOCATE((ctx, events, e, radius, t, y, Kt, tmp, y_out), h, g_start)
    dop853_step(STAGES, ctx, t, y, tau, Kt, y_out, tmp)
    return tau, as_state(y_out)


def _watch_events(wctx, ctx, p, t, h, t_new, y, y_new, K):
    """The template of a system's watcher (`dop853_watcher`): the event rows' crossings over the accepted step
    ``(t, y) -> (t_new, y_new)``, each located (``LOCATE_EVENT``) and recorded.

    ``wctx = (events, g_old, radius, Kt, tmp, yt, ev_t, ev_r, ev_v, ev_count, ev_which,
    max_events)``: ``g_old`` each event's value at ``t`` (updated), ``Kt`` (13, 6) the locator's
    stages, ``tmp`` and ``yt`` (6,) its scratch (free while the loop watches). Returns
    ``(stop, tau)``: whether a terminal event ends the particle in the step, and the earliest such
    time's offset from ``t`` (the loop's state there is the step of that length, as the record's).
    """
    events, g_old, radius, Kt, tmp, yt, ev_t, ev_r, ev_v, ev_count, ev_which, max_events = wctx
    stop = False
    tau = h
    for e in range(events.shape[0]):
        g_new = event_value(events, e, as_state(y_new), radius)
        if crossed(events[e, 3], g_old[e], g_new):
            hi, hit = LOCATE_EVENT(ctx, events, e, radius, g_old[e], t, h, K, Kt, y, tmp, yt)
            record_event(ev_t, ev_r, ev_v, ev_count, ev_which, max_events, p, e, t + hi, hit)
            if events[e, 4] != 0.0 and hi <= tau:
                stop = True
                tau = hi
        g_old[e] = g_new
    return stop, tau


def dop853_watcher(name, stages):
    """``(trial, locate, locate_event, watch)``: the event rows' watcher of the system whose stages are ``stages``
    (`rotframe.numerics.dop853_loop.dop853_stages`), for `rotframe.numerics.dop853_loop.dop853_trajectory`.

    Events are located by rotframe's one locator (`rotframe.numerics.bisection.locator`) on one DOP853 step of the
    system from the step's start (the trial, `_event_value_after`), recorded by
    `rotframe.particles.events.record_event` (`_watch_events`). Each is a copy named after ``name``
    (`rotframe.numerics.compiled.bound`), so each system's is cached apart. The watcher is inlined into the loop: a
    call each step, passing wctx's twelve items, cost 8 % (bench ensemble).
    """
    trial = jit_inline(bound(_event_value_after, f"dop853_event_value_{name}", STAGES=stages))
    locate = locator(f"dop853_{name}", trial)
    located = jit_uncounted(bound(_locate_event, f"locate_event_dop853_{name}", STAGES=stages, LOCATE=locate))
    watch = jit_llvm_inline(bound(_watch_events, f"watch_events_{name}", LOCATE_EVENT=located))
    return trial, locate, located, watch


#: the particle's watcher (`dop853_watcher`): its trial, its locator (rotframe's one, `rotframe.numerics.bisection.
#: locator`), the located event and the watcher of its trajectory loop
dop853_event_value, locate_dop853, locate_event_dop853, watch_events = dop853_watcher("particle", particle_stages)


#: the particle's trajectory loop without events and with them (`watch_events`)
particle_trajectory = dop853_trajectory("particle", particle_stages, store_sample, 6)
particle_trajectory_events = dop853_trajectory("particle_events", particle_stages, store_sample, 6,
                                               watch_events)


@jit_uncounted
def start_events(wctx, ctx, t, y):
    """Each event's value at the particle's start ``(t, y)`` into ``g_old = wctx[1]``; ``ctx = (m, wt, wv)``."""
    m, wt, wv = ctx
    w, wd = rates(t, m.steady, m.w, wt, wv)
    g_old = wctx[1]
    for e in range(g_old.shape[0]):
        g_old[e] = start_value(wctx[0], e, as_state(y), m, w, wd)
