"""One DOP853 trajectory loop for the scenes' systems: a particle in any model, a steady model, a rigid body.

Hairer's DOP853 (Hairer, Norsett & Wanner, *Solving Ordinary Differential Equations I*, 2nd ed.,
II.10; docs/physics/dop853.md) from ``(t, y)`` to ``t_end``, written once here and compiled for
each system's right-hand side:

* the stages of the extended tableau (`rotframe.numerics.dop853_dense.extended_tableau`: row 12
  the order-8 weights, rows 13..15 the dense output's stages), ``z = y + h sum_q A[s, q] K[q]`` in
  this order, then ``K[s] = f(t + C[s] h, z)``;
* the error norm (`rotframe.numerics.dop853.dop853_error_norm`), Hairer's step control
  (`rotframe.numerics.step_control.next_step`), a step cut to land on ``t_end`` exactly;
* the samples inside an accepted step from Hairer's dense output of order 7 (three more stages,
  only in a step that holds one), the new state at a sample on the step's end;
* an optional watcher of events after each accepted step (the particle scenes' event rows:
  `rotframe.particles.dop853_particles`; a problem's event functions: `rotframe.problem.engine`),
  which may stop the trajectory at a time inside the step; the state there is one DOP853 step of
  that length from the step's start;
* a budget of accepted steps per call (a caller that must see signals, or pace its calls), and an
  optional check after each try that the system's functions did not fail (a user function that
  raised: `rotframe.problem.calls`).

A system is ``rhs(ctx, t, z, K, s)``, a compiled function that writes ``f(t, z)`` into row ``s`` of
``K``, with its data ``ctx``. `dop853_stages` and `dop853_trajectory` compile the loop for a
system: the system's functions are global names of a copy of the loop's code
(`rotframe.numerics.compiled.bound`), so numba calls them directly (a right-hand side compiled
with `rotframe.numerics.compiled.jit_llvm_inline` is inlined into the one stage loop), prunes the
event code of a system without events, and caches each system's loop on disk under its own name.
Functions passed as arguments instead would have to be inlined into every caller to be cached
(numba compiles a function value passed on as an address, which it cannot cache), which made a
first run compile twice as long; held in a closure's cells, they made numba's cache key change
with every process (`bound`).
"""

from __future__ import annotations

import math

from numba import njit, types

from rotframe.numerics.compiled import ENTRY_OPTIONS, bound, inlined, jit_inline, jit_uncounted
from rotframe.numerics.dop853 import coefficients, dop853_error_norm
from rotframe.numerics.dop853_dense import dense_coefficients, dense_value, extended_tableau
from rotframe.numerics.step_control import first_step, first_step_trial, next_step, step_collapsed
from rotframe.numerics.stops import next_stop

__all__ = ["dop853_stages", "dop853_trajectory", "dop853_step", "dop853_start", "REACHED", "STOPPED", "COLLAPSED",
           "NONFINITE", "PAUSED", "WATCH_FAILED", "ABORTED", "DIVERGED", "UNLIMITED", "TRAJECTORY_RETURNS"]

#: how `dop853_trajectory` ended: ``t_end`` reached; a terminal event; the step size collapsed (finite errors); an
#: accepted step's state not finite; the budget of steps spent (``t < t_end``); the watcher could not tell (NaN); the
#: system's ``aborted`` check; the step size collapsed where the last rejected try's state was not finite (the
#: solution diverges, or f is not finite past a time)
REACHED, STOPPED, COLLAPSED, NONFINITE, PAUSED, WATCH_FAILED, ABORTED, DIVERGED = 0, 1, 2, 3, 4, 5, 6, 7
#: the step budget of a call that runs to its end (a caller that bounds its calls by their samples)
UNLIMITED = 1 << 62

#: what `dop853_trajectory`'s loop returns, ``(t, h, k_out, status, nfev, steps)``: the return type of its signature
#: where it is an entry point called at its address (`rotframe.numerics.at_address`)
TRAJECTORY_RETURNS = types.Tuple((types.float64, types.float64, types.int64, types.int64, types.int64, types.int64))

#: a loop called from Python: an entry point without reference counts (its caller owns every array)
_uncounted_entry = njit(**ENTRY_OPTIONS)

A, C, DW = extended_tableau()
E3, E5 = coefficients()[3:]
_error_norm = inlined(dop853_error_norm)
_dense_coefficients = inlined(dense_coefficients)


@jit_inline
def _stage_state(z, y, h, K, s, D):
    """``z = y + h sum_{q < s} A[s, q] K[q]``, each component summed in order from q = 0."""
    for j in range(D):
        acc = 0.0
        for q in range(s):
            acc += A[s, q] * K[q, j]
        z[j] = y[j] + h * acc


def dop853_stages(name, rhs, D):
    """The stage function of the system ``rhs``, compiled for it (cached on disk as ``dop853_stages_<name>``).

    ``D`` is the length of the state. ``stages(ctx, first, last, t, y, h, K, z, z12, t12)`` forms stages
    ``first .. last - 1`` of the step ``(t, y, h)``: each state ``y + h sum_{q < s} A[s, q] K[q]`` (into
    ``z12`` for stage 12, the step's end with the order-8 weights, else into ``z``), then
    ``K[s] = f(t + C[s] h, state)``, the one call site of the right-hand side. Stage 12 is f at ``t12``,
    the time the step ends on: ``t + h``, or the target a cut step lands on, which ``t + h`` may miss by
    an ulp (on the wrong side of a table's knot, where f jumps; ``K[12]`` starts the next step).
    ``stages(ctx, 1, 13, ...)`` is a step (`dop853_step`), ``stages(ctx, 13, 16, ...)`` the dense
    output's three more.
    """

    return jit_uncounted(bound(_stages, f"dop853_stages_{name}", RHS=rhs, DIM=int(D)))


# the names a system binds (`rotframe.numerics.compiled.bound`): its right-hand side, the length of its state, its
# stage function, sample writer, watcher and check; None or 0 in the templates themselves, which are never compiled
RHS = STAGES = STORE = WATCH = CHECK = ENTER = STOPS = None
DIM = 0
WATCHED = CHECKED = STOPPING = False


def _stages(ctx, first, last, t, y, h, K, z, z12, t12):
    """The template of `dop853_stages`."""
    for s in range(first, last):
        zs = z12 if s == 12 else z
        _stage_state(zs, y, h, K, s, DIM)  # DIM a constant of the code: loops the compiler unrolls
        RHS(ctx, t12 if s == 12 else t + C[s] * h, zs, K, s)


@jit_inline
def dop853_step(stages, ctx, t, y, h, K, y_new, tmp):
    """One DOP853 step from ``(t, y)`` with ``K[0] = f(t, y)``: ``y_new``, and ``K[12] = f(t + h, y_new)``.

    ``stages`` a system's (`dop853_stages`), a global of the caller.
    """
    stages(ctx, int(1), int(13), t, y, h, K, tmp, y_new, t + h)  # int64 values, not literals: one compiled `stages`


@jit_inline
def dop853_start(rhs, ctx, t, y, K, yt, rtol, atol, h_max):
    """Hairer's starting step (`rotframe.numerics.step_control`) from ``K[0] = f(t, y)``; ``K[1]`` f at its trial step."""
    h0 = first_step_trial(y, K[0], rtol, atol, h_max)
    for j in range(y.shape[0]):
        yt[j] = y[j] + h0 * K[0, j]
    rhs(ctx, t + h0, yt, K, 1)
    return first_step(y, K[0], K[1], h0, rtol, atol, h_max)


@jit_inline
def _same(ctx):
    """The system's data as the trajectory loop was given it (`dop853_trajectory`'s default ``enter``)."""
    return ctx


def dop853_trajectory(name, stages, store, D, watch=None, entry=False, aborted=None, enter=_same, stops=None):
    """The trajectory loop of one system, compiled for it (cached on disk as ``dop853_trajectory_<name>``).

    ``stages`` the system's (`dop853_stages`), ``D`` the length of its state; ``store(out, k, p, y)`` writes sample ``k`` of
    trajectory ``p``; ``watch(wctx, ctx, p, t, h, t_new, y, y_new, K) -> (stop, tau)`` is called
    after each accepted step ``(t, y) -> (t_new, y_new)`` of length ``h`` (it may not change ``K``):
    a stop with ``tau`` in ``(0, h]`` ends the trajectory at ``t + tau``, a stop with a NaN ``tau``
    ends it at the step's start (`WATCH_FAILED`: the watcher could not tell); None compiles no event
    code. ``aborted(ctx) -> bool``, checked after each try's stages and the dense output's, ends the
    trajectory at the step's start (`ABORTED`: a function of the system failed); None compiles no
    check. With ``entry`` the loop is also callable from Python (a kernel of its own, not only a callee).
    ``enter(ctx)`` is the system's data that the loop hands on, made once a call from the ``ctx`` it was given
    (the default hands on ``ctx`` itself). ``stops(ctx)``, of the ``ctx`` given, is a sorted array of times that
    no step crosses (a table's knots: `rotframe.numerics.stops`): each step that would is cut to end on the stop,
    and the trajectory goes on from there as a new call would (Hairer's step control starts afresh; samples at
    the stop are stored), so a trajectory with its stops given takes the steps of one call from stop to stop,
    to the bit. None compiles no stops.

    The loop, ``trajectory(ctx, t, y, h, t_end, h_max, times, k_out, out, p, rtol, atol, K, y_new,
    tmp, yt, F, wctx, budget)``, integrates one trajectory from ``(t, y)``, ``K[0] = f(t, y)``, to ``t_end``:

    * ``y`` is the state at the end on return (at the stop, the collapse or the non-finite state);
      ``K[0]`` is f there, where the trajectory goes on (`REACHED`, `PAUSED`);
    * ``h`` the first step to try (> 0: Hairer's starting step, `dop853_start`, or the last call's);
    * ``t_end``, ``h_max``: the end (the last step is cut to land on it exactly), the largest step
      taken after an accepted one (``inf`` for none);
    * ``times``, ``k_out``: increasing sample times, and the first not yet stored (samples at or
      before ``t`` are stored first, then each as the run passes it), into ``out`` for trajectory ``p``;
    * ``rtol``, ``atol`` (D,): the tolerances; ``K`` (16, D) the stages, ``y_new``, ``tmp``, ``yt``
      (D,) states and ``F`` (7, D) the interpolant: work arrays; ``wctx`` the watcher's data;
    * ``budget``: the accepted steps this call may take (`PAUSED` after that many, short of ``t_end``).
      A call ends after an accepted step, never after a rejected try, so a trajectory cut into calls
      takes the same steps as one call, to the bit.

    It returns ``(t, h, k_out, status, nfev, steps)``: the time reached, the next step to try, the
    next sample, how it ended (`REACHED`, `STOPPED`, `COLLAPSED`, `NONFINITE`, `PAUSED`,
    `WATCH_FAILED`, `ABORTED`, `DIVERGED`), the right-hand sides evaluated and the accepted steps.
    """
    compile = _uncounted_entry if entry else jit_uncounted
    return compile(bound(_trajectory, f"dop853_trajectory_{name}", STAGES=stages, STORE=store, WATCH=watch,
                         CHECK=aborted, ENTER=enter, STOPS=stops, DIM=int(D), WATCHED=watch is not None,
                         CHECKED=aborted is not None, STOPPING=stops is not None))


@jit_inline
def _leg_end(S, t, t_end):
    """The end of the leg from ``t``: the first stop of ``S`` after ``t`` (`rotframe.numerics.stops.next_stop`), or
    ``t_end`` where that is the nearer."""
    stop = next_stop(S, t)
    return stop if stop < t_end else t_end


def _trajectory(ctx, t, y, h, t_end, h_max, times, k_out, out, p, rtol, atol, K, y_new, tmp, yt, F, wctx, budget):
    """The template of `dop853_trajectory`."""
    final = t_end
    if STOPPING:  # the first leg's end: the first stop after t, or the end (`_leg_end`)
        S = STOPS(ctx)
        t_end = _leg_end(S, t, final)
    ctx = ENTER(ctx)
    # the stage ranges as int64 values, not literals: one compiled `stages` for every range
    _FIRST, _END, _DENSE, _DENSE_END = int(1), int(13), int(13), int(16)
    n_out = times.shape[0]
    nf = 0
    steps = 0
    status = REACHED
    rejected = False
    finite_rejection = True  # whether the last rejected try's state was finite (else a collapse is divergence)
    while k_out < n_out and times[k_out] <= t:
        STORE(out, k_out, p, y)
        k_out += 1
    while t < t_end or (STOPPING and t < final):
        if STOPPING and t >= t_end:
            # a stop reached: the next leg, begun as a call from the stop would begin it
            t_end = _leg_end(S, t, final)
            finite_rejection = True  # (``rejected`` is False: a step ends on a stop on its first try, or accepted)
            while k_out < n_out and times[k_out] <= t:
                STORE(out, k_out, p, y)
                k_out += 1
        if steps >= budget:
            status = PAUSED
            break
        # one accepted step
        accepted = False
        at_end = False
        truncated = False
        h_used = h
        while not accepted:
            h_ctrl = h
            truncated = t + h > t_end
            if truncated:
                h = t_end - t
            if step_collapsed(h, t):
                if step_collapsed(t_end - t, t):
                    # the steps summed to within a few ulp of the end: it is reached (the state is off by
                    # |f| * 10 ulp(t), far below any tolerance); not a collapsed step
                    at_end = True
                    h = h_ctrl  # the next call starts from the controller's step, not from the ulps
                else:
                    status = COLLAPSED if finite_rejection else DIVERGED
                break
            STAGES(ctx, _FIRST, _END, t, y, h, K, tmp, y_new, t_end if truncated else t + h)
            nf += 12
            if CHECKED and CHECK(ctx):
                status = ABORTED
                break
            err = _error_norm(K, h, y, y_new, rtol, atol, E3, E5)
            accepted, h_next = next_step(h, h_ctrl, err, rejected)  # Hairer's control (numerics.step_control)
            rejected = not accepted
            if rejected:
                finite_rejection = math.isfinite(err)
            h_used = h
            h = h_next
        if status != REACHED:
            break
        if at_end:
            t = t_end
            if STOPPING:
                continue  # the next leg, or the end
            break
        if h > h_max:
            h = h_max
        # a step cut to land on t_end ends there exactly (t + (t_end - t) may round below it)
        t_new = t_end if truncated else t + h_used
        steps += 1
        stop = False
        tau = h_used
        if WATCHED:
            stop, tau = WATCH(wctx, ctx, p, t, h_used, t_new, y, y_new, K)
            if stop and not tau > 0.0:  # NaN: the watcher could not tell
                status = WATCH_FAILED
                break
        t_stop = t + tau if stop else t_new
        # samples inside (t, t_stop]: the dense output inside the step, the new state at its end
        dense = False
        while k_out < n_out and times[k_out] <= t_stop:
            ts = times[k_out]
            if ts == t_new:
                STORE(out, k_out, p, y_new)
            else:
                if not dense:
                    STAGES(ctx, _DENSE, _DENSE_END, t, y, h_used, K, tmp, tmp, t_new)
                    nf += 3
                    if CHECKED and CHECK(ctx):
                        status = ABORTED
                        break
                    _dense_coefficients(y, y_new, K, h_used, DW, F)
                    dense = True
                x = (ts - t) / h_used
                for j in range(DIM):
                    yt[j] = dense_value(F, y, x, j)
                STORE(out, k_out, p, yt)
            k_out += 1
        if status != REACHED:
            break
        if stop:
            # the state at the stop: one step of length tau from the step's start (K[0] is still f(t, y))
            STAGES(ctx, _FIRST, _END, t, y, tau, K, tmp, yt, t_stop)
            for j in range(DIM):
                y[j] = yt[j]
            t = t_stop
            status = STOPPED
            break
        finite = True
        for j in range(DIM):
            y[j] = y_new[j]
            K[0, j] = K[12, j]
            if not math.isfinite(y[j]):
                finite = False
        t = t_new
        if not finite:
            status = NONFINITE
            break
    return t, h, k_out, status, nf, steps

