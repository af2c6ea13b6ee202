"""A particle's place in the engine's loops: its slot in the run's arrays, its state's checks, the watcher's data.

What both loops of the engine's variants read and write of a particle (or a body) between steps
(`rotframe.problem.engine`'s DOP853 loop, `rotframe.problem.fixed_step`): its state, time, step and
next sample loaded from and saved to the run's arrays, whether its state is finite, and the
events' watcher's data. A particle's six numbers carried in registers (`tuple_finite`,
`store_state`, `store_tuple`) are written to the arrays only where they are read.
"""

from __future__ import annotations

import math

from rotframe.numerics.compiled import jit_inline

__all__ = ["load_particle", "save_particle", "all_finite", "tuple_finite", "store_state", "store_tuple",
           "watcher_context"]


@jit_inline
def load_particle(i, Y, TC, H, IDX, y):
    """Particle ``i``'s state into ``y``; returns its time, step and next sample ``(t, h, idx)``."""
    for j in range(y.shape[0]):
        y[j] = Y[i, j]
    return TC[i], H[i], IDX[i]


@jit_inline
def save_particle(i, Y, TC, H, IDX, SUB, ST, y, t, h, idx, sub, status):
    """Particle ``i``'s state, time, step, next sample, fixed-step count and status, where the next call goes on."""
    for j in range(y.shape[0]):
        Y[i, j] = y[j]
    TC[i] = t
    H[i] = h
    IDX[i] = idx
    SUB[i] = sub
    ST[i] = status


@jit_inline
def all_finite(y, n):
    """Whether the first ``n`` numbers of ``y`` are finite; ``n`` a constant of the caller's code (`DIM`), so that the
    compiler unrolls the loop: over ``y.shape[0]``, known only at run time, it was a sixth of a splitting's step."""
    for j in range(n):
        if not math.isfinite(y[j]):
            return False
    return True


@jit_inline
def tuple_finite(s):
    """Whether a particle's six numbers ``s`` are all finite: their sum is, where they are (one test at every step;
    each number's own, six tests and branches, were a fifth of a splitting's step), else each is asked (a sum of
    finite numbers can overflow)."""
    if math.isfinite(s[0] + s[1] + s[2] + s[3] + s[4] + s[5]):
        return True
    return (math.isfinite(s[0]) and math.isfinite(s[1]) and math.isfinite(s[2]) and math.isfinite(s[3])
            and math.isfinite(s[4]) and math.isfinite(s[5]))


@jit_inline
def store_state(y, s):
    """A particle's six numbers ``s`` into ``y``."""
    y[0], y[1], y[2], y[3], y[4], y[5] = s


@jit_inline
def store_tuple(OUT, k, i, s):
    """A particle's six numbers ``s`` into sample ``k`` of particle ``i``."""
    OUT[k, i, 0], OUT[k, i, 1], OUT[k, i, 2], OUT[k, i, 3], OUT[k, i, 4], OUT[k, i, 5] = s


@jit_inline
def watcher_context(GPREV, EVT, EVY, EVK, EVN, EDIR, ETERM, T, Kb, V):
    """The data of a variant's watcher, ``wctx`` (`rotframe.problem.event_watch.watch_events`): the events' arrays, the
    run's start, the locator's stages ``Kb`` and states ``V[4:7]`` (the loops keep ``V[0:4]`` for their own). A
    variant without events passes 0 instead (``EVENTS``, a constant of its code): no tuple of twelve to build, type
    and pass on."""
    return GPREV, EVT, EVY, EVK, EVN, EDIR, ETERM, T[0], Kb, V[4], V[5], V[6]
