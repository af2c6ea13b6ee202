"""Events of the compiled particle drivers: event functions, crossings and their location.

An event row is ``(kind, component, value, direction, terminal)``
(`rotframe.particles.packed.N_EVENT_FIELDS`; kind 0 position, 1 velocity,
2 altitude above the curved ground). A crossing found over a step is located by
bisection on the length of a re-step from the step's start with the method's own
one-step map, so the event time is exact for the method's discrete trajectory
(docs/physics/events.md). The fixed-step drivers re-step with their method
(`locate_event`), the DOP853 driver with DOP853
(`rotframe.particles.dop853_particles.locate_event_dop853`),
so that neither compiles the other's steps; both are rotframe's one locator
(`rotframe.numerics.bisection.locator`) with their own trial, and record by `record_event`.
"""

from __future__ import annotations

import math

from numba import njit

from rotframe.numerics.bisection import crossed, locator
from rotframe.particles.forces import state_acceleration
from rotframe.particles.kernels import make_plan, method_steps
from rotframe.particles.packed import jit_internal

_inline = njit(inline="always", error_model="numpy", nogil=True)

__all__ = ["event_value", "event_row", "row_value", "watch_steps", "start_value", "crossed", "fixed_trial",
           "fixed_event_value", "locate_fixed", "locate_event", "record_event"]


@jit_internal
def event_value(events, e, state, radius):
    """Event function of row ``e`` of the event table at ``state``."""
    kind = events[e, 0]
    c = int(events[e, 1])
    if kind == 0.0:
        return state[c] - events[e, 2]
    if kind == 1.0:
        return state[3 + c] - events[e, 2]
    x, y, z = state[0], state[1], state[2]
    dz = z + radius
    return math.sqrt(x * x + y * y + dz * dz) - radius - events[e, 2]


@jit_internal
def event_row(events, e):
    """Row ``e`` of the event table as scalars ``(kind, component, value, direction)``, read once per call."""
    return events[e, 0], int(events[e, 1]), events[e, 2], events[e, 3]


@_inline
def row_value(row, state, radius):
    """`event_value` of an `event_row` (the same operations; inlined into the watch loop).

    The component is picked by comparisons, not by indexing the state tuple with a
    run-time index (which numba lowers through memory, at every step).
    """
    kind, c, value, _ = row
    x, y, z, vx, vy, vz = state
    if kind == 0.0:
        return (x if c == 0 else y if c == 1 else z) - value
    if kind == 1.0:
        return (vx if c == 0 else vy if c == 1 else vz) - value
    dz = z + radius
    return math.sqrt(x * x + y * y + dz * dz) - radius - value


@_inline
def watch_steps(step, method, state, n, h, m, plan, row, g_old):
    """Up to ``n`` steps with one plan, watching one event (`event_row`); stops after its first crossing.

    The fixed-step drivers' loop for one event at a steady rate, inlined into the
    driver's sample loop with ``step``, the inlined one-step map of its family
    (`rotframe.particles.kernels.free_step`, ``sphere_step`` or ``rk4_step_of``),
    so that the step's scalars stay in registers and each family's loop holds its
    body alone (one loop holding RK4's and the splitting's ran RK4 at half speed).
    Each step is followed by the event function and `crossed`. Returns
    ``(k, start, state, g_start, g_new, hit)``: the steps taken, the state before
    and after the last of them, the event function before and after it, and
    whether it crossed (then the crossing is in the last step).
    """
    direction = row[3]
    for k in range(n):
        start = state
        state = step(state, method, h, m, plan)
        g_new = row_value(row, state, m.radius)
        if _crossed(direction, g_old, g_new):
            return k + 1, start, state, g_old, g_new, True
        g_old = g_new
    return n, state, state, g_old, g_old, False


@jit_internal
def start_value(events, e, state, m, w, wd):
    """Event function of row ``e`` at the start of a run or chunk, for crossing detection.

    The rule for a function that is exactly zero at the start (a shell fired
    from the ground, z = 0): it takes the sign it has just after the start,
    the sign of its first non-zero time derivative (first or second); the
    start itself is never an event. A shell fired upward from z = 0 thus
    lands at its first return to z = 0, however soon (even inside the first
    step), and a ``direction = -1`` ground event is not triggered by the
    launch. Only the sign of the returned value is meaningful when ``g = 0``
    (see docs/physics/events.md).
    """
    g = event_value(events, e, state, m.radius)
    if g != 0.0:
        return g
    kind = events[e, 0]
    c = int(events[e, 1])
    x, y, z, vx, vy, vz = state
    a = state_acceleration(state, m, w, wd)
    if kind == 0.0:
        d1 = state[3 + c]
        d2 = a[c]
    elif kind == 1.0:
        d1 = a[c]
        d2 = 0.0
    else:
        dx, dy, dz = x, y, z + m.radius
        n = math.sqrt(dx * dx + dy * dy + dz * dz)
        dv = dx * vx + dy * vy + dz * vz
        da = dx * a[0] + dy * a[1] + dz * a[2]
        d1 = dv / n
        d2 = (vx * vx + vy * vy + vz * vz + da) / n - dv * dv / (n * n * n)
    if d1 != 0.0:
        return 1e-300 if d1 > 0.0 else -1e-300
    if d2 != 0.0:
        return 1e-300 if d2 > 0.0 else -1e-300
    return 0.0


_crossed = _inline(crossed.py_func)  # the same rule, inlined into the watch loop

@jit_internal
def fixed_trial(method, start, t, tau, m, wt, wv, wint, rk4, sphere):
    """The state one step of length ``tau`` after ``start`` (at time t) of fixed-step ``method`` (0, 1, 2).

    ``rk4``, ``sphere``: as in `rotframe.particles.kernels.method_steps`.
    """
    return method_steps(method, start, int(1), tau, m, make_plan(method, t, tau, m, wt, wv, wint), rk4,
                        sphere)  # int64 1


@_inline
def fixed_event_value(ctx, tau):
    """The event function after `fixed_trial` of length ``tau``: the trial of `locate_event`'s locator.

    ``ctx = (method, events, e, start, t, m, wt, wv, wint, rk4, sphere)``.
    """
    method, events, e, start, t, m, wt, wv, wint, rk4, sphere = ctx
    return event_value(events, e, fixed_trial(method, start, t, tau, m, wt, wv, wint, rk4, sphere), m.radius)


#: rotframe's one event locator (`rotframe.numerics.bisection.locator`) on the fixed-step map
locate_fixed = locator("fixed_step", fixed_event_value)


@jit_internal
def locate_event(method, events, e, start, g_start, t, h, m, wt, wv, wint, rk4, sphere):
    """Sub-step tau in (0, h] at which event ``e`` of the fixed-step map from ``start`` vanishes.

    rotframe's one locator (`locate_fixed`): bisection on tau of g(`fixed_trial` (start, tau)) until
    the bracket cannot shrink. ``g_start`` is the event function at ``start`` as used for the
    crossing test (its sign just after the start when it is zero there, `start_value`).
    Returns tau and the state at the event (a 6-tuple).
    """
    tau = locate_fixed((method, events, e, start, t, m, wt, wv, wint, rk4, sphere), h, g_start)
    return tau, fixed_trial(method, start, t, tau, m, wt, wv, wint, rk4, sphere)


@jit_internal
def record_event(ev_t, ev_r, ev_v, ev_count, ev_which, max_events, p, e, t_event, state):
    """Append event ``e`` of particle p at ``t_event`` with ``state`` (6-tuple) to the records.

    Beyond ``max_events`` records the event is counted (``ev_count``) but not stored.
    """
    k = ev_count[p]
    if k < max_events:
        ev_t[p, k] = t_event
        for i in range(3):
            ev_r[p, k, i] = state[i]
            ev_v[p, k, i] = state[3 + i]
        ev_which[p, k] = e
    ev_count[p] = k + 1
