"""The engine's DOP853 loop: rotframe's one DOP853 trajectory, per particle, from stop to stop.

The DOP853 variant of the engine's loop (`rotframe.problem.engine.variant_loop`): the one DOP853
loop of rotframe (`rotframe.numerics.dop853_loop`, which the scenes' particles and rigid bodies run
too) compiled for the model's right-hand side (`dop853_parts`), the events watched after each
accepted step (`rotframe.problem.event_watch`), and around it the loop over the particles and the
stops (`dop853_advance`, a template whose upper-case globals `rotframe.numerics.compiled.bound`
rebinds). `rotframe.problem.dop853_split` compiles the same code in parts that call one another at
their addresses.
"""

from __future__ import annotations

import math

from rotframe.numerics.compiled import bound, jit_inline
from rotframe.numerics.dop853_loop import (ABORTED, COLLAPSED, DIVERGED, NONFINITE, PAUSED, REACHED, STOPPED,
                                           WATCH_FAILED, dop853_start, dop853_trajectory)
from rotframe.numerics.step_control import own_tolerances
from rotframe.problem.by_address import problem_data, stages_at, system_at, with_reference
from rotframe.problem.calls import RAISED
from rotframe.problem.event_watch import watcher
from rotframe.problem.loop_state import load_particle, save_particle, watcher_context
from rotframe.problem.models import DOP853
from rotframe.problem.steps import body_system, particle_system, stepper

__all__ = ["dop853_loop", "dop853_parts", "dop853_advance", "store_rows", "raised"]

# the names a variant binds (`dop853_loop`): None, 0 or False in the template itself, which is never compiled
SYSTEM = TRAJECTORY = None
DIM = 0
EVENTS = False


@jit_inline
def store_rows(out, k, p, y):
    """Sample ``k`` of particle ``p``: ``out[k, p] = y``."""
    for j in range(y.shape[0]):
        out[k, p, j] = y[j]


@jit_inline
def raised(ctx):
    """Whether a user function raised since the flag was cleared (`rotframe.problem.calls`)."""
    return ctx[2][RAISED] != 0.0


@jit_inline
def run_stops(ctx):
    """The run's stops ``S`` (`rotframe.numerics.stops`), the fourth of the trajectory's ``ctx = (prob, fns, W, S,
    ...)``: no step crosses one."""
    return ctx[3]


def dop853_parts(body, events, D, entry=False):
    """The DOP853 variant's trajectory loop: `rotframe.numerics.dop853_loop`'s trajectory compiled for the model's
    right-hand side (`particle_system`, `body_system`, ``ctx = (prob, fns, W)``), from stop to stop of the run
    (its ``ctx = (prob, fns, W, S)``: every stop of ``S`` in one call, `run_stops`), the events watched by
    `rotframe.problem.event_watch.watch_events`, a user function that raised ending the trajectory at the step
    (`raised`).
    ``entry``: the trajectory of the loop compiled in parts (`rotframe.problem.dop853_split`), callable from Python
    and at its address, which calls the stages and the right-hand side at their addresses
    (`rotframe.problem.by_address`), cached apart."""
    system = particle_system if body is None else body_system
    kind = f"engine_{'particle' if body is None else 'body'}{D}"
    if entry:
        kind += "_by_address"
        stages, system = stages_at, system_at
    else:
        stages = stepper(body, DOP853, D)
    watch = watcher(kind, stages, body, DOP853, system) if events else None
    name = kind + ("_events" if events else "") + ("_entry" if entry else "")
    return dop853_trajectory(name, stages, store_rows, D, watch, entry=entry, aborted=raised,
                             enter=with_reference if entry else problem_data, stops=run_stops)


def dop853_loop(name, body, events, D):
    """The DOP853 variant's loop: `rotframe.numerics.dop853_loop`'s trajectory, per particle, from stop to stop.

    The system and the trajectory are `dop853_parts`'. A call takes at most ``budget`` accepted steps per particle
    and ends after an accepted step, so the steps do not depend on where the budget cut the calls. The template
    `dop853_advance` reads the system's functions as globals (`rotframe.numerics.compiled.bound`).
    """
    system = particle_system if body is None else body_system
    trajectory = dop853_parts(body, events, D)
    return bound(dop853_advance, name, SYSTEM=system, TRAJECTORY=trajectory, DIM=int(D), EVENTS=bool(events))


def dop853_advance(lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, rtol,
                    atol, hfix, EDIR, ETERM, S, prob, fns, K, Kb, V, F, W):
    """The template of the DOP853 variant's loop (`dop853_loop`)."""
    n = T.shape[0]
    t_last = T[n - 1]
    y, yt, yn, tmp = V[0], V[1], V[2], V[3]
    ctx = (prob, fns, W)
    stepped = (prob, fns, W, S)  # the trajectory's: the run's stops too
    wctx = watcher_context(GPREV, EVT, EVY, EVK, EVN, EDIR, ETERM, T, Kb, V) if EVENTS else 0
    for i in range(lo, hi):
        if ST[i] != 0:
            continue
        atol_i = atol[i]
        t, h, idx = load_particle(i, Y, TC, H, IDX, y)
        if atol_i[0] != atol_i[0]:  # NaN: the particle's own tolerances, from the state it starts from
            own_tolerances(y, t_last - T[0], rtol, atol_i)
        W[RAISED] = 0.0
        SYSTEM(ctx, t, y, K, 0)
        NFEV[i] += 1
        if h <= 0.0:
            h = dop853_start(SYSTEM, ctx, t, y, K, yt, rtol, atol_i, t_last - T[0])
            NFEV[i] += 1
        end = REACHED
        left = budget
        while idx < n and left > 0:
            # to the run's end, each step cut to end on a stop (a knot of a table or a body frame) it would cross;
            # once more where the last step summed to within ulps of the end, to store the samples there
            t, h, idx, end, nf, steps = TRAJECTORY(stepped, t, y, h, t_last, math.inf, T, idx, OUT, i, rtol,
                                                   atol_i, K, yn, tmp, yt, F, wctx, left)
            NFEV[i] += nf
            NSTEP[i] += steps
            left -= steps
            if end != REACHED:
                break
        status = 0
        if end == REACHED or end == PAUSED:
            status = 1 if idx >= n else 0
        elif end == STOPPED:
            status = 2
            while idx < n:  # samples after a terminal event keep the state at the event
                for j in range(DIM):
                    OUT[idx, i, j] = y[j]
                idx += 1
        elif end == NONFINITE or end == DIVERGED:
            status = 3
        elif end == COLLAPSED:
            status = 4
        elif end == WATCH_FAILED:
            status = 5
        elif end == ABORTED:
            status = 6
        save_particle(i, Y, TC, H, IDX, SUB, ST, y, t, h, idx, 0, status)
