"""DOP853 on the steady problems: the one DOP853 loop with a small force, for a smaller first compile.

The engine's loop (`rotframe.problem.engine`) handles every term, frame, stop and event, and a
first run compiles the problem's functions and all of that with them. Most particle problems that
run DOP853 need much less (`rotframe.problem.steady` chooses them from their terms):

- a **steady** rotation rate (omega a constant vector, so no frame table and no Euler term);
- **uniform** gravity (a constant vector, or none);
- any of **Coriolis**, **centrifugal** and a **pendulum** string;
- no drag, no spring, and at most one event, a crossing of a coordinate (`steady_events_kernel`).

For such a problem `run_dop853_steady` runs the same loop (`rotframe.particles.dop853_ensemble.run_particles`
on `rotframe.numerics.dop853_loop`) with a force of its own (`_acceleration`: the terms of
`rotframe.particles.accelerations` on a vector of 12 numbers), in the floating-point order of the
engine's right-hand side (`rotframe.problem.models`), so that its results are bitwise those of
the engine's loop (``tests/test_steady_route.py`` checks this on random problems).
`steady_parameters` packs a problem for it.
"""

from __future__ import annotations

import numpy as np

from rotframe.numerics.compiled import bound, jit_internal, jit_kernel, jit_llvm_inline
from rotframe.numerics.dop853_loop import dop853_stages, dop853_trajectory
from rotframe.particles.accelerations import centrifugal, coriolis, string_tension
from rotframe.particles.dop853_ensemble import run_particles, store_sample

__all__ = ["steady_parameters", "run_dop853_steady", "steady_events_kernel"]

# The force sums the terms of rotframe.particles.accelerations (each term's arithmetic, written once) over the
# steady vector, rather than running the engine's right-hand side: that would compile the problem's functions and
# the frame's readers (what this driver exists to avoid). tests/test_steady_route.py keeps the two bitwise the same.

# layout of the parameter vector of the steady driver
_G, _OMEGA, _PIVOT, _L, _CORIOLIS, _CENTRIFUGAL = 0, 3, 6, 9, 10, 11
_N = 12


def steady_parameters(g, omega, pivot, length, coriolis, centrifugal):
    """The parameter vector (12,) of `run_dop853_steady`: uniform gravity ``g`` (3,), m/s^2 (zeros for none), the
    frame's rate ``omega`` (3,), rad/s, the string's ``pivot`` (3,), m, and ``length``, m (0 for none), and whether
    the Coriolis and the centrifugal terms act."""
    q = np.zeros(_N)
    q[_G:_G + 3] = g
    q[_OMEGA:_OMEGA + 3] = omega
    q[_PIVOT:_PIVOT + 3] = pivot
    q[_L] = length
    q[_CORIOLIS] = float(bool(coriolis))
    q[_CENTRIFUGAL] = float(bool(centrifugal))
    return q


@jit_internal
def _acceleration(x, y, z, vx, vy, vz, q):
    """The steady problem's acceleration, in the order of the engine's right-hand side (`rotframe.problem.models`):
    gravity, Coriolis, centrifugal, then the string's tension."""
    ax = q[_G]
    ay = q[_G + 1]
    az = q[_G + 2]
    wx = q[_OMEGA]
    wy = q[_OMEGA + 1]
    wz = q[_OMEGA + 2]
    if q[_CORIOLIS] != 0.0:
        cx, cy, cz = coriolis(vx, vy, vz, wx, wy, wz)
        ax -= cx
        ay -= cy
        az -= cz
    if q[_CENTRIFUGAL] != 0.0:
        cx, cy, cz = centrifugal(x, y, z, wx, wy, wz)
        ax += cx
        ay += cy
        az += cz
    L = q[_L]
    if L > 0.0:
        ax, ay, az = string_tension(ax, ay, az, x, y, z, vx, vy, vz, q[_PIVOT], q[_PIVOT + 1], q[_PIVOT + 2], L)
    return ax, ay, az


@jit_llvm_inline
def _steady_rhs(q, t, z, K, s):
    """``K[s] = f(z)`` of the steady model ``q`` (`steady_parameters`): velocity, then `_acceleration`."""
    K[s, 3], K[s, 4], K[s, 5] = _acceleration(z[0], z[1], z[2], z[3], z[4], z[5], q)
    K[s, 0] = z[3]
    K[s, 1] = z[4]
    K[s, 2] = z[5]


_steady_stages = dop853_stages("steady", _steady_rhs, 6)
_steady_trajectory = dop853_trajectory("steady", _steady_stages, store_sample, 6)


@jit_kernel
def run_dop853_steady(r, v, t0, sample_times, q, rtol, atol, span, work, out_r, out_v, h_state):
    """Adaptive DOP853 for an ensemble under a steady model (see the module docstring).

    Parameters and results as `rotframe.particles.drivers.run_dop853`, with ``q`` from
    `steady_parameters`. There are no events, so every particle stays alive. Returns
    ``(n_done, bad, nfev, steps)``, the cost the most any particle took (as the engine's loop counts it).
    """
    return run_particles(_steady_rhs, _steady_trajectory, None, q, r, v, None, t0, sample_times, rtol, atol, span,
                         out_r, out_v, h_state, work, None, True)


_EVENTS_KERNEL = []


def steady_events_kernel():
    """`run_dop853_steady` with event rows (`rotframe.particles.trajectory.Event`: crossings of a coordinate of r or
    v), made when first asked for: ``kernel(r, v, alive, t0, sample_times, q, rtol, atol, span, events, work, out_r,
    out_v, h_state, ev_t, ev_r, ev_v, ev_count, ev_which, max_events, Kt)``.

    The events are watched after each accepted step and located on the steady loop's own DOP853 re-steps
    (`rotframe.particles.dop853_particles.dop853_watcher`: rotframe's one locator), as the engine's loop locates
    them; a terminal event clears the particle's ``alive``. Each event's value at the start is the function's own:
    the engine's rule for a function that is zero there (its sign just after, from re-steps) is not this loop's, so
    `rotframe.problem.steady` sends no such run here.
    """
    if not _EVENTS_KERNEL:  # imported here: a run without events imports none of the events' code
        from rotframe.particles.dop853_particles import dop853_watcher
        from rotframe.particles.events import event_value
        from rotframe.particles.packed import as_state

        watch = dop853_watcher("steady", _steady_stages)[3]
        trajectory = dop853_trajectory("steady_events", _steady_stages, store_sample, 6, watch)
        start = jit_internal(bound(_start_values, "steady_start_values", EVENT_VALUE=event_value, AS_STATE=as_state))
        _EVENTS_KERNEL.append(jit_kernel(bound(_run_with_events, "run_dop853_steady_events", TRAJECTORY=trajectory,
                                               START=start)))
    return _EVENTS_KERNEL[0]


# the names `steady_events_kernel` binds in its copies: the events' trajectory loop and start values, the event rows'
# function and the state's view; None in the templates, which are never compiled
TRAJECTORY = START = EVENT_VALUE = AS_STATE = None


def _start_values(wctx, q, t, y):
    """The template of the events' start values: each event row's value at ``(t, y)`` into ``g_old = wctx[1]``."""
    events, g_old = wctx[0], wctx[1]
    for e in range(g_old.shape[0]):
        g_old[e] = EVENT_VALUE(events, e, AS_STATE(y), 0.0)


def _run_with_events(r, v, alive, t0, sample_times, q, rtol, atol, span, events, work, out_r, out_v, h_state, ev_t,
                     ev_r, ev_v, ev_count, ev_which, max_events, Kt):
    """The template of `steady_events_kernel`'s kernel."""
    g_old = np.empty(events.shape[0])
    # the locator's scratch states are the loop's (free while it watches: rotframe.particles.dop853_particles)
    wctx = (events, g_old, 0.0, Kt, work[18], work[19], ev_t, ev_r, ev_v, ev_count, ev_which, max_events)
    return run_particles(_steady_rhs, TRAJECTORY, START, q, r, v, alive, t0, sample_times, rtol, atol, span,
                         out_r, out_v, h_state, work, wctx, True)
