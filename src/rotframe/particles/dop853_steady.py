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

The loop without events compiles as two kernels (`SteadyDriver`): the trajectory, an entry point of
its own, and the driver over the particles, which calls the trajectory at its address
(`rotframe.numerics.at_address`). numba links a callee into its caller and optimises it again there;
apart, the trajectory compiles once, and on a first run in a second process while this one compiles
the driver (`rotframe.numerics.compile_apart`): `rotframe run foucault`'s first run takes about a
third of its time before. The call at an address costs one call a particle, not a step.
"""

from __future__ import annotations

import threading

import numpy as np
from numba import njit, types

from rotframe.numerics.at_address import address, caller
from rotframe.numerics.compiled import ENTRY_OPTIONS, bound, jit_inline, jit_internal, jit_kernel, jit_llvm_inline
from rotframe.numerics.dop853_loop import TRAJECTORY_RETURNS, dop853_stages, dop853_trajectory
from rotframe.particles.accelerations import centrifugal, coriolis, string_tension
from rotframe.particles.dop853_ensemble import run_particles, store_sample

__all__ = ["steady_parameters", "run_dop853_steady", "steady_events_kernel", "SteadyDriver",
           "TRAJECTORY_SIG", "DRIVER_SIG"]

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

# the loop's trajectory, an entry point of its own for one signature, which `run_dop853_steady`'s driver calls at its
# address (`rotframe.numerics.at_address`): the two compile apart (module docstring)
_F8, _I8 = types.float64, types.int64
_A1, _A2, _A3 = types.float64[::1], types.float64[:, ::1], types.float64[:, :, ::1]
#: the trajectory's signature (`rotframe.numerics.dop853_loop.dop853_trajectory`: ``ctx`` is ``q``, no watcher)
TRAJECTORY_SIG = TRAJECTORY_RETURNS(
    _A1, _F8, _A1, _F8, _F8, _F8, _A1, _I8, types.Tuple((_A3, _A3)), _I8, _F8, _A1, _A2, _A1, _A1, _A1, _A2,
    types.none, _I8)
#: the driver's signature: `run_dop853_steady`'s arguments, then the trajectory's address
DRIVER_SIG = types.UniTuple(_I8, 4)(_A2, _A2, _F8, _A1, _A1, _F8, _A2, _F8, _A2, _A3, _A3, _A1, _I8)
_steady_trajectory = dop853_trajectory("steady", _steady_stages, store_sample, 6, entry=True)
_call_trajectory = caller(TRAJECTORY_SIG)


@jit_inline
def _trajectory_at(ctx, t, y, h, t_end, h_max, times, k_out, out, p, rtol, atol, K, y_new, tmp, yt, F, wctx, budget):
    """The steady trajectory at its address, ``ctx = (q, address)``."""
    return _call_trajectory(ctx[1], ctx[0], t, y, h, t_end, h_max, times, k_out, out, p, rtol, atol, K, y_new, tmp,
                            yt, F, wctx, budget)


@jit_llvm_inline
def _rhs_at(ctx, t, z, K, s):
    """`_steady_rhs` with ``ctx = (q, address)``: each particle's first f and Hairer's starting step."""
    _steady_rhs(ctx[0], t, z, K, s)


@njit(**ENTRY_OPTIONS)
def _run_at(r, v, t0, sample_times, q, rtol, atol, span, work, out_r, out_v, h_state, at):
    """`run_dop853_steady`'s driver: the trajectory at the address ``at``."""
    return run_particles(_rhs_at, _trajectory_at, None, (q, at), r, v, None, t0, sample_times, rtol, atol, span,
                         out_r, out_v, h_state, work, None, True)


def compile_steady_trajectory():
    """Compile the steady trajectory into numba's cache: the second process of a first compile
    (`rotframe.numerics.compile_apart`, `SteadyDriver`)."""
    _steady_trajectory.compile(TRAJECTORY_SIG)


class SteadyDriver:
    """Adaptive DOP853 for an ensemble under a steady model (see the module docstring): `run_dop853_steady`.

    ``driver(r, v, t0, sample_times, q, rtol, atol, span, work, out_r, out_v, h_state)``, with the parameters and
    results of `rotframe.particles.drivers.run_dop853` and ``q`` from `steady_parameters`. There are no events,
    so every particle stays alive. Returns ``(n_done, bad, nfev, steps)``, the cost the most any particle took (as
    the engine's loop counts it). Every array is C-contiguous.

    Two kernels, each compiled for its one signature and cached: the trajectory loop (`TRAJECTORY_SIG`) and the
    driver over the particles (`DRIVER_SIG`), which calls the trajectory at its address. Made at the first call:
    loaded from numba's cache, else the trajectory compiles in a second process while this one compiles the driver
    (`rotframe.numerics.compile_apart`). ``overloads`` and ``signatures`` are the driver's (what a caller reads to
    tell a first load or compile, `rotframe.particles.chunked.KernelSetup.warm_up`).
    """

    def __init__(self):
        self._made = None
        self._lock = threading.Lock()

    @property
    def overloads(self):
        return _run_at.overloads

    @property
    def signatures(self):
        return _run_at.signatures

    def _make(self):
        from rotframe.numerics.compile_apart import made

        with self._lock:
            if self._made is None:  # the driver here, the trajectory in a second process where both compile
                made(((_steady_trajectory, TRAJECTORY_SIG), (_run_at, DRIVER_SIG)), __name__,
                     apart={0: ("compile_steady_trajectory", ())})
                self._made = address(_steady_trajectory, TRAJECTORY_SIG)
        return self._made

    def __call__(self, r, v, t0, sample_times, q, rtol, atol, span, work, out_r, out_v, h_state):
        at = self._made if self._made is not None else self._make()
        return _run_at(r, v, t0, sample_times, q, rtol, atol, span, work, out_r, out_v, h_state, at)


#: the steady loop without events (`SteadyDriver`)
run_dop853_steady = SteadyDriver()


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
