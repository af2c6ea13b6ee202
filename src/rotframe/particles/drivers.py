"""Compiled ensemble drivers: many steps, output samples and events, for many particles.

`run_fixed` runs a fixed-step method (`rotframe.particles.kernels`),
`run_dop853` the adaptive Dormand-Prince 8(5,3) (Hairer, Norsett & Wanner
II.10); `run_fixed_events` and `run_dop853_events` are the same with an event table
(`rotframe.particles.events`). All advance ``r, v`` (N, 3) in place, fill output samples
and report a non-finite state instead of raising.

A kernel per event table's presence, not one with a branch on ``events is None``: numba
prunes such a branch before it types a function only where the argument is None, so a
run with events compiled the event-free loops too (a DOP853 run's second trajectory loop,
a fixed-step run's throughput loop: seconds of a first run).

The Python side ([`rotframe.particles.integrators`][rotframe.particles.integrators]) calls
them in chunks of output samples, so that progress, Ctrl-C and a numerical failure are
handled between chunks without losing data.
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit

from rotframe.numerics.compiled import inlined
from rotframe.particles.dop853_ensemble import run_particles
from rotframe.particles.dop853_particles import particle_rhs, particle_trajectory, particle_trajectory_events, start_events
from rotframe.particles.events import crossed, event_row, event_value, watch_steps, locate_event, record_event, start_value
from rotframe.numerics.step_control import grid_time
from rotframe.particles.kernels import advance, free_step, loop_code, make_plan, method_steps, rk4_step_of, sphere_step
from rotframe.particles.packed import NFEV, is_finite, jit_internal, jit_kernel, store, store_particle, unpack
from rotframe.particles.schedule import rates

__all__ = ["fixed_step_driver", "run_fixed", "run_fixed_events", "run_dop853", "run_dop853_events"]


def fixed_step_driver(name, events):
    """The compiled fixed-step driver of the method ``name`` (``events``: whether the run watches an event table),
    called as `run_fixed` without its first argument: the integer its loops branch on stays with the modules that
    compile them (`rotframe.particles.kernels.loop_code`). ``.func`` is the dispatcher."""
    return functools.partial(run_fixed_events if events else run_fixed, loop_code(name))

# inlined into run_fixed: a call per sample interval that passes arrays (the schedule, the output)
# costs their reference counts, some 20 ns a particle and sample, as much as a few steps
_store = inlined(store)
_advance = inlined(advance)
_is_finite = inlined(is_finite)
#: a loop that takes its one-step map as an argument, inlined with it into its caller
_inline_kernel = njit(inline="always", error_model="numpy", nogil=True)


@_inline_kernel
def _failed(n_done, bad, s, p):
    """The drivers' failure record once particle p is not finite at sample s: the first such sample and particle."""
    return (s if s < n_done else n_done), (p if bad < 0 else bad)


@_inline_kernel
def _steady_loop(step, method, r, v, alive, n_samples, steps_per_sample, h, m, plan, out_r, out_v):
    """`run_fixed` at a steady rate with no event to watch, with the inlined one-step map ``step``.

    Every particle, ``steps_per_sample`` steps of ``step`` a sample. Inlined with
    its ``step`` (numba resolves the argument to the global it is passed), so each
    step family gets a loop holding its body alone. Returns ``(n_done, bad, steps)``:
    ``steps`` is particle 0's (its force evaluations are ``steps`` times the method's).
    """
    n_done = n_samples
    bad = -1
    steps0 = 0
    for p in range(r.shape[0]):
        state = (r[p, 0], r[p, 1], r[p, 2], v[p, 0], v[p, 1], v[p, 2])
        if alive[p]:
            for s in range(n_samples):
                for _ in range(steps_per_sample):
                    state = step(state, method, h, m, plan)
                if p == 0:
                    steps0 += steps_per_sample
                if not _is_finite(state):
                    n_done, bad = _failed(n_done, bad, s, p)
                    break
                _store(out_r, out_v, s, p, state)
        else:
            for s in range(n_samples):
                _store(out_r, out_v, s, p, state)
        store_particle(r, v, p, state)
    return n_done, bad, steps0


@jit_internal
def _steady_run(method, r, v, alive, n_samples, steps_per_sample, h, m, plan, rk4, sphere, out_r, out_v):
    """`_steady_loop` with the step family's map (`run_fixed` at a steady rate, no event).

    A function of its own, not inlined into `run_fixed`: its types do not depend on
    the event table or the schedule, so every variant of the driver calls the one
    compiled loop (a first run compiles it once, not once per variant). ``rk4`` and
    ``sphere`` None are pruned here, before the steps are inlined, so a free
    particle's loop compiles no RK4 and no sphere (numba inlines before it types,
    and prunes only on arguments).
    """
    if rk4 is not None:
        if rk4:
            return _steady_loop(rk4_step_of, method, r, v, alive, n_samples, steps_per_sample, h, m, plan, out_r,
                                out_v)
    if sphere is not None:
        if sphere:
            return _steady_loop(sphere_step, method, r, v, alive, n_samples, steps_per_sample, h, m, plan, out_r,
                                out_v)
    return _steady_loop(free_step, method, r, v, alive, n_samples, steps_per_sample, h, m, plan, out_r, out_v)


@jit_kernel
def run_fixed(method, r, v, alive, times, j0, h, steps_per_sample, n_samples, P, wt, wv, wint,
              events, out_r, out_v, ev_t, ev_r, ev_v, ev_count, ev_which, max_events, rk4, sphere):
    """Advance an ensemble with a fixed-step method and store samples.

    Parameters
    ----------
    method : int
        0 splitting, 1 splitting4, 2 rk4.
    r, v : (N, 3) arrays
        State at the call's start (rotating frame, m and m/s); updated in place.
    alive : (N,) bool array
        Particles still moving; a terminal event clears the flag (in place).
    times : (n_samples + 1,) array
        The run's sample times from the start of the call's first sample interval (s).
    j0 : int
        The steps of the first interval made before the call (a call that starts inside it: the pieces of
        `rotframe.particles.chunked.KernelSetup.one_sample_in_pieces`).
    h : float
        Step (s). Samples are stored every ``steps_per_sample`` steps. Step ``j`` of sample interval ``s``
        starts at ``times[s] + j h`` (`rotframe.numerics.step_control.grid_time`), however the run is cut into
        calls: the engine's rule (`rotframe.problem.fixed_step`).
    events : None
        No event table (an array raises `ValueError`): a run with one calls
        `run_fixed_events`, with the same arguments (each kernel compiles only
        its own loops).
    out_r, out_v : (n_samples, N, 3) arrays
        Filled with the state after each sample interval; a stopped particle
        keeps its state at the terminal event.
    ev_t, ev_r, ev_v, ev_count, ev_which : event records per particle (time, state, event index).
    rk4, sphere : None or bool
        Whether the method is RK4 (method 2) and the model a pendulum: None where it is
        not, pruned at compile time (a free particle's splitting compiles neither RK4
        nor the splitting on the sphere), else a boolean
        (`rotframe.particles.kernels.method_steps`).

    Returns
    -------
    n_done : int
        Samples completed (``n_samples`` unless a state became non-finite).
    bad : int
        Index of the first particle with a non-finite state, or -1.
    nfev : int
        Force evaluations of particle 0 (the cost of one trajectory).
    """
    if events is not None:
        raise ValueError("run_fixed takes no event table (events=None): a run with one calls run_fixed_events")
    m = unpack(P, wt, wv)
    plan = make_plan(method, grid_time(times, 0, j0, h), h, m, wt, wv, wint)
    nfev_step = NFEV[method]
    if wt is None or m.steady:
        # the throughput path: one loop compiled once for every variant of this driver
        n_done, bad, steps0 = _steady_run(method, r, v, alive, n_samples, steps_per_sample, h, m, plan, rk4, sphere,
                                          out_r, out_v)
        return n_done, bad, nfev_step * steps0
    nfev0 = 0
    n_done = n_samples
    bad = -1
    for p in range(r.shape[0]):
        state = (r[p, 0], r[p, 1], r[p, 2], v[p, 0], v[p, 1], v[p, 2])
        for s in range(n_samples):
            if alive[p]:
                # a varying rate: the whole sample interval in one call
                state = _advance(method, state, times, s, j0 if s == 0 else 0, steps_per_sample, h, m, wt, wv, wint,
                                 plan, rk4, sphere)
                if p == 0:
                    nfev0 += nfev_step * steps_per_sample
                if not _is_finite(state):
                    n_done, bad = _failed(n_done, bad, s, p)
                    break
            _store(out_r, out_v, s, p, state)  # inlined: a call passing two arrays costs their reference counts
        store_particle(r, v, p, state)
    return n_done, bad, nfev0


@jit_kernel
def run_fixed_events(method, r, v, alive, times, j0, h, steps_per_sample, n_samples, P, wt, wv, wint,
                     events, out_r, out_v, ev_t, ev_r, ev_v, ev_count, ev_which, max_events, rk4, sphere):
    """`run_fixed` with an event table ``events`` (E, 5) (`rotframe.particles.events.event_table`).

    The same arguments and results. Each step is followed by the events' functions; a crossing is
    located by re-stepping from the last state before it with a shorter step (bisection to
    round-off), so an event time is exact for the method's own discrete trajectory, and recorded
    in ``ev_t, ev_r, ev_v, ev_count, ev_which`` (at most ``max_events`` a particle). A terminal
    event clears the particle's ``alive`` flag; it keeps its state at the event in later samples.
    """
    m = unpack(P, wt, wv)
    t_start = grid_time(times, 0, j0, h)
    plan = make_plan(method, t_start, h, m, wt, wv, wint)
    nfev_step = NFEV[method]
    n_ev = events.shape[0]
    g_old = np.empty(n_ev)
    row = event_row(events, 0) if n_ev > 0 else (0.0, 0, 0.0, 0.0)  # the watch loop's event, read once
    nfev0 = 0
    n_done = n_samples
    bad = -1
    for p in range(r.shape[0]):
        state = (r[p, 0], r[p, 1], r[p, 2], v[p, 0], v[p, 1], v[p, 2])
        is_alive = alive[p]
        w0, wd0 = rates(t_start, m.steady, m.w, wt, wv)
        for e in range(n_ev):
            g_old[e] = start_value(events, e, state, m, w0, wd0)
        for s in range(n_samples):
            if is_alive:
                j = j0 if s == 0 else 0  # the steps of this sample interval made before (`grid_time`)
                if n_ev == 1 and (wt is None or m.steady):
                    # one event at a steady rate (an ensemble to the ground): the watch loop keeps the
                    # step and the event test in registers; the same steps, tests and location as below
                    k = 0
                    while k < steps_per_sample:
                        # the step family's map, chosen where numba prunes rk4 and sphere None before it
                        # inlines the watch loop: a free particle's loop compiles no RK4 and no sphere
                        if rk4 is not None and rk4:
                            watched = watch_steps(rk4_step_of, method, state, steps_per_sample - k, h, m, plan, row,
                                                  g_old[0])
                        elif sphere is not None and sphere:
                            watched = watch_steps(sphere_step, method, state, steps_per_sample - k, h, m, plan, row,
                                                  g_old[0])
                        else:
                            watched = watch_steps(free_step, method, state, steps_per_sample - k, h, m, plan, row,
                                                  g_old[0])
                        done, start, state, g_start, g_new, hit = watched
                        k += done
                        g_old[0] = g_new
                        if hit:
                            t = grid_time(times, s, j + k - 1, h)
                            tau, at = locate_event(method, events, 0, start, g_start, t, h, m, wt, wv, wint,
                                                   rk4, sphere)
                            record_event(ev_t, ev_r, ev_v, ev_count, ev_which, max_events, p, 0, t + tau, at)
                            if events[0, 4] != 0.0:
                                state = at
                                is_alive = False
                                break
                    if p == 0:
                        nfev0 += nfev_step * k
                else:
                    for _ in range(steps_per_sample):
                        t = grid_time(times, s, j, h)
                        start = state
                        step_plan = plan if m.steady else make_plan(method, t, h, m, wt, wv, wint)
                        state = method_steps(method, state, int(1), h, m, step_plan, rk4, sphere)  # int64 1
                        if p == 0:
                            nfev0 += nfev_step
                        j += 1
                        stop = False
                        for e in range(n_ev):
                            g_new = event_value(events, e, state, m.radius)
                            if crossed(events[e, 3], g_old[e], g_new):
                                tau, hit = locate_event(method, events, e, start, g_old[e], t, h, m, wt, wv, wint,
                                                        rk4, sphere)
                                record_event(ev_t, ev_r, ev_v, ev_count, ev_which, max_events, p, e, t + tau, hit)
                                if events[e, 4] != 0.0:
                                    stop = True
                                    state = hit
                            g_old[e] = g_new
                        if stop:
                            is_alive = False
                            break
                if not _is_finite(state):
                    n_done, bad = _failed(n_done, bad, s, p)
                    break
            _store(out_r, out_v, s, p, state)  # inlined: a call passing two arrays costs their reference counts
        store_particle(r, v, p, state)
        alive[p] = is_alive
    return n_done, bad, nfev0


@jit_kernel
def run_dop853(r, v, alive, t0, sample_times, P, wt, wv, rtol, atol, span, events, out_r, out_v, ev_t, ev_r, ev_v,
               ev_count, ev_which, max_events, h_state, work, Kt):
    """Adaptive Dormand-Prince 8(5,3) (Hairer, Norsett & Wanner, II.10) for an ensemble, any model.

    The one DOP853 loop (`rotframe.numerics.dop853_loop`) with the particle's right-hand side
    (`rotframe.particles.dop853_particles`): Hairer's error control, step control and starting
    step; the samples at ``sample_times`` inside a step are its dense output of order 7. Events are
    located on the method's own steps: bisection on the length of one extra DOP853 step from the
    step's start (`run_dop853_events`). ``h_state`` (N,) carries each particle's step between
    calls; where it is 0, the particle starts with Hairer's starting step, at most ``span`` (the
    whole run's length, the same in every call; each call still ends with a step cut to land on its
    last sample, so the steps depend on where the calls end). ``events`` is None (a run with an event table calls `run_dop853_events`);
    ``wt`` None (a steady rotation rate) prunes the schedule readers at compile time. ``work``
    (`rotframe.particles.dop853_ensemble.WORK_ROWS`, 6) and ``Kt`` (13, 6, the event locator's
    stages) are work arrays from the caller (a kernel that allocates compiles numpy's allocators
    on a first run).

    Returns (n_done, bad, nfev, steps) like `run_fixed` (cost of particle 0).
    """
    if events is not None:
        raise ValueError("run_dop853 takes no event table (events=None): a run with one calls run_dop853_events")
    m = unpack(P, wt, wv)
    return run_particles(particle_rhs, particle_trajectory, None, (m, wt, wv), r, v, alive, t0, sample_times, rtol,
                         atol, span, out_r, out_v, h_state, work, None)


@jit_kernel
def run_dop853_events(r, v, alive, t0, sample_times, P, wt, wv, rtol, atol, span, events, out_r, out_v, ev_t, ev_r,
                      ev_v, ev_count, ev_which, max_events, h_state, work, Kt):
    """`run_dop853` with an event table ``events`` (E, 5): the trajectory loop that watches them.

    The same arguments and results. Events are located on the method's own steps: bisection on
    the length of one extra DOP853 step from the step's start
    (`rotframe.particles.dop853_particles.watch_events`), recorded in ``ev_t, ev_r, ev_v,
    ev_count, ev_which``; a terminal event clears the particle's ``alive`` flag.
    """
    m = unpack(P, wt, wv)
    g_old = np.empty(events.shape[0])
    # the locator's scratch states are the loop's (free while it watches: rotframe.particles.dop853_particles)
    wctx = (events, g_old, m.radius, Kt, work[18], work[19], ev_t, ev_r, ev_v, ev_count, ev_which, max_events)
    return run_particles(particle_rhs, particle_trajectory_events, start_events, (m, wt, wv), r, v, alive, t0,
                         sample_times, rtol, atol, span, out_r, out_v, h_state, work, wctx)
