"""The engine's loop of a fixed-step method (RK4, the models' splittings): a step that divides each sample interval.

A variant of the engine (`rotframe.problem.engine.variant_loop`) for a fixed-step method runs this
loop, one particle (or body) at a time, a bounded number of steps per call, on the CPU and on the
GPU (`rotframe.problem.gpu` compiles the same template). A step ends on the next sample or the next
stop, whichever is first (the steps of a sample interval are counted, so the step divides it);
RK4's grid goes on from a stop; the events are watched after each step
(`rotframe.problem.engine`'s watcher).

A particle carries its six numbers in registers from step to step (``CARRIED``): a splitting's
step takes and returns them (`rotframe.problem.models.particle_split`), RK4's too with the
acceleration at the step's start beside them (`rotframe.problem.steps.carried_rk4`); they are
written to the arrays only where they are read: at a sample, for the events' watcher, where the
call ends. The arrays' round trips on the state's path were half of a splitting's step. The
numbers are those of the array steps to the bit (the method's step of `rotframe.problem.steps.take_step`,
which the events' re-steps take, calls the same functions).

What a step costs beyond its arithmetic is decided as seldom as it can be: the sample grid once a
run of steps (on the grid, with no stop before the sample, the rest of the interval is steps of
``hfix``), the state's finiteness by one test of its sum, and a single event by `quiet_step`, which
asks the watcher (and writes the step's start for its re-steps) only where the step may cross. On
the tower drop's ensemble with the ground event (20,000 particles, 2 s at 1 ms, one thread; `python
tools/ensembles_on_engine.py 20000 1`, 2026-11-30) the inlined loop went from 2.3 to 1.54 times the
scenes' kernels' time under the splitting (the watcher a function of its own,
`rotframe.problem.event_watch.watcher`) and from 1.33 to 1.13 under RK4; without an event, 1.33 and
1.12 times the scenes' event-free driver.
"""

from __future__ import annotations

import math

from rotframe.numerics.bisection import crossed
from rotframe.numerics.compiled import bound, jit_inline
from rotframe.numerics.step_control import grid_time, start_short_of
from rotframe.problem.calls import RAISED, call_event
from rotframe.problem.loop_state import (all_finite, load_particle, save_particle, store_state, store_tuple,
                                         tuple_finite, watcher_context)
from rotframe.problem.models import EVALUATIONS_PER_STEP, RK4, particle_split, rhs
from rotframe.problem.steps import carried_rk4, particle_acceleration, take_step
from rotframe.numerics.stops import next_stop

__all__ = ["fixed_step_loop"]

# the names a loop binds (`fixed_step_loop`): None, 0 or False in the template itself, which is never compiled
STEPPER = BODY_FLAG = WATCH = ENTER = None
METHOD = DIM = 0
EVENTS = CARRIED = False


@jit_inline
def same_context(ctx):
    """The loop's context as it is: ``(prob, fns, W)`` (`fixed_step_loop`'s ``enter``)."""
    return ctx


def fixed_step_loop(name, body, method, D, step, watch, take=None, enter=None):
    """The loop of a fixed-step variant, as Python: the template `_fixed_step_advance` with the variant's constants
    as its globals (`rotframe.numerics.compiled.bound`): ``body`` (None: a particle), the ``method``'s code, the
    length of the state ``D``, the method's ``step`` (`rotframe.problem.steps.stepper`) and the events' ``watch``
    (None: no events, none of the watching compiled). A particle of six numbers carries its state (``CARRIED``).
    ``take`` takes a step (default the method's, `rotframe.problem.steps.take_step`) and ``enter`` makes the context
    it takes, once a call, from ``(prob, fns, W)`` (default `same_context`): a body's splitting at its address takes
    the problem's data by reference too (`rotframe.problem.body_split_step`)."""
    return bound(_fixed_step_advance, name, STEPPER=step, TAKE=take or take_step(method), ENTER=enter or same_context,
                 BODY_FLAG=body, METHOD=method, EVENTS=watch is not None, WATCH=watch, DIM=int(D),
                 CARRIED=body is None and D == 6)


@jit_inline
def quiet_step(wctx, ctx, p, t, t_new, y_new):
    """Whether the step of particle ``p`` ending at ``(t_new, y_new)`` leaves its one event function finite and
    uncrossed (its value then recorded as the watcher would): the watcher's own test (`rotframe.problem.engine`),
    made first without the step's start, which only a crossing reads. False for two events or more, a crossing, a
    value that is not finite and the run's first step (its start rule): the watcher then decides, as before."""
    GPREV, EDIR, t0 = wctx[0], wctx[5], wctx[7]
    if EDIR.shape[0] != 1:
        return False
    prob, fns, W = ctx
    g_new = call_event(fns[1], 0, t_new, y_new, prob[2])
    g_old = GPREV[p, 0]
    if not math.isfinite(g_new) or (g_old == 0.0 and t == t0) or crossed(EDIR[0], g_old, g_new):
        return False
    GPREV[p, 0] = g_new
    return True


def _fixed_step_advance(lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, rtol,
                        atol, hfix, EDIR, ETERM, S, prob, fns, K, Kb, V, F, W):
    """The template of a fixed-step variant's loop (`fixed_step_loop`)."""
    # K (16, D), Kb (13, D) stages, V (7, D) state vectors, W the models' scratch: the caller's (`scratch`), one
    # set for the block
    n = T.shape[0]
    D = DIM
    y, yt, yn, yev = V[0], V[1], V[2], V[3]
    ctx = ENTER((prob, fns, W))
    stage = (prob, fns, W, yt, K[1])  # a carried RK4 step's (`rotframe.problem.steps.carried_rk4`)
    wctx = watcher_context(GPREV, EVT, EVY, EVK, EVN, EDIR, ETERM, T, Kb, V) if EVENTS else 0
    for i in range(lo, hi):
        if ST[i] != 0:
            continue
        t, h, idx = load_particle(i, Y, TC, H, IDX, y)
        s = (y[0], y[1], y[2], y[3], y[4], y[5])  # a particle's splitting carries its state in registers (CARRIED)
        sub = SUB[i]
        W[RAISED] = 0.0
        # the particle's counts kept here and added to NSTEP and NFEV once, where the call leaves it: on a GPU, two
        # reads and writes of global memory per step were more traffic than the step's own
        steps = 0
        nfev = 0
        a1 = (0.0, 0.0, 0.0)  # RK4's first stage carried: the acceleration at the step's start
        if METHOD == RK4:  # its first stage, f at the step's start (a splitting evaluates what it needs itself)
            if CARRIED:
                a1 = particle_acceleration(stage, t, s)
            else:
                rhs(BODY_FLAG, t, y, K[0], prob, fns, W)
            nfev += 1
        status = 0
        per = -1.0  # the steps of the current sample interval, counted once an interval (`run_grid`'s hfix divides it)
        while idx < n and steps < budget:
            if t >= T[idx]:
                if CARRIED:
                    store_tuple(OUT, idx, i, s)
                else:
                    for j in range(D):
                        OUT[idx, i, j] = y[j]
                idx += 1
                sub = 0
                per = -1.0
                continue
            # a step ends on the next sample or the next stop, whichever is first
            stop = next_stop(S, t)
            at_knot = stop < T[idx]
            if per < 0.0:
                per = math.floor((T[idx] - T[idx - 1]) / hfix + 0.5)
            t_end = T[idx]
            on_grid = t == grid_time(T, idx - 1, sub, hfix)
            # on the grid with no stop before the sample, the rest of the interval is a run of steps of hfix, each
            # ending on the grid (the last on the sample): decided here once, not at every step
            regular = on_grid and not at_knot
            hh = hfix
            t_new = t_end
            if not regular:
                # the substeps counted (hfix divides the interval: `run_grid`), not lengths compared: the interval's
                # own rounding (2e-12 of 5e-4 s at t = 4 s) took a step short of each sample and a sliver to it
                last = sub + 1 >= per
                grid_next = t_end if last else grid_time(T, idx - 1, sub + 1, hfix)
                if at_knot and stop < grid_next:
                    hh = stop - t  # to the knot; the grid goes on from there
                    t_new = stop
                else:
                    hh = hfix if on_grid else grid_next - t
                    sub += 1
                    t_new = t_end if last else grid_time(T, idx - 1, sub, hfix)
            while True:
                if regular:
                    sub += 1
                    t_new = t_end if sub >= per else grid_time(T, idx - 1, sub, hfix)
                t_stages = t
                if METHOD == RK4 and stop <= t_new:  # the step ends on a knot: its last stage just before it
                    t_stages = start_short_of(t, hh, t_new)
                if CARRIED:  # the step of `take_step`, on the state in registers (yt: its kicks' scratch)
                    if METHOD == RK4:
                        sn = carried_rk4(stage, t_stages, s, hh, a1)
                    else:
                        sn = particle_split(METHOD, t, s, hh, yt, prob, fns, W)
                else:
                    TAKE(STEPPER, BODY_FLAG, t_stages, y, hh, K, yt, yn, ctx)
                steps += 1
                nfev += EVALUATIONS_PER_STEP[METHOD]
                if W[RAISED] != 0.0:  # a user function raised in this step: stop here, Python names it
                    status = 6
                    break
                if CARRIED:
                    if not tuple_finite(sn):
                        status = 3
                        break
                elif not all_finite(yn, D):
                    status = 3
                    break
                if EVENTS:  # a constant of the variant: without events, none of this is compiled
                    if CARRIED:  # the event functions read the step's end from the array
                        store_state(yn, sn)
                    stop_now = False
                    tau = 0.0
                    if not quiet_step(wctx, ctx, i, t, t_new, yn):  # a crossing (or a NaN, or the run's start)
                        if CARRIED:  # the watcher re-steps from the step's start
                            store_state(y, s)
                        # the locator's bracket is the step's own length hh (its re-step of hh is this step), not
                        # t_new - t, which the grid's rounding may leave an ulp or two apart from it
                        stop_now, tau = WATCH(wctx, ctx, i, t, hh, t_new, y, yn, K)
                    if stop_now:
                        if not tau > 0.0:  # an event function gave NaN or raised: stop here, Python names it
                            status = 5
                            break
                        # the state at the terminal event: the step of that length from the step's start (the
                        # locator's last trial; Kb[0] is f(t, y)); the samples after it keep it
                        TAKE(STEPPER, BODY_FLAG, t, y, tau, Kb, V[4], yev, ctx)
                        t = t + tau
                        for j in range(D):
                            y[j] = yev[j]
                        s = (y[0], y[1], y[2], y[3], y[4], y[5])
                        while idx < n:
                            for j in range(D):
                                OUT[idx, i, j] = y[j]
                            idx += 1
                        status = 2
                        break
                t = t_new
                if CARRIED:
                    s = sn
                else:
                    for j in range(D):
                        y[j] = yn[j]
                if METHOD == RK4:
                    if CARRIED:
                        a1 = particle_acceleration(stage, t, s)
                    else:
                        rhs(BODY_FLAG, t, y, K[0], prob, fns, W)
                    nfev += 1
                if not regular or sub >= per or t >= t_end or steps >= budget:
                    break
            if status != 0:
                break
        if status == 0 and idx >= n:
            status = 1
        NSTEP[i] += steps
        NFEV[i] += nfev
        if CARRIED:
            store_state(y, s)
        save_particle(i, Y, TC, H, IDX, SUB, ST, y, t, h, idx, sub, status)
