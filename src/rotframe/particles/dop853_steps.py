"""One step of Dormand-Prince 8(5,3) for a particle (the tableau: `rotframe.numerics.dop853`)."""

from __future__ import annotations

from numba import njit

from rotframe.particles.forces import state_acceleration
from rotframe.particles.packed import as_state, jit_internal
from rotframe.particles.schedule import rates

#: the force, inlined into the step (twelve evaluations a step: twelve calls passing the packed model)
_acceleration = njit(inline="always", error_model="numpy", nogil=True)(state_acceleration.py_func)

__all__ = ["dop853_step"]


@jit_internal
def dop853_step(t, y, f0, h, m, wt, wv, A, B, C, K, y_new, tmp):
    """One DOP853 step from (t, y) with f0 = f(t, y) (a 6-tuple); K (13, 6) receives the stages, tmp (6,) is scratch."""
    K[0, 0], K[0, 1], K[0, 2], K[0, 3], K[0, 4], K[0, 5] = f0
    for s in range(1, 12):
        for j in range(6):
            acc = 0.0
            for q in range(s):
                acc += A[s, q] * K[q, j]
            tmp[j] = y[j] + h * acc
        w, wd = rates(t + C[s] * h, m.steady, m.w, wt, wv)
        K[s, 3], K[s, 4], K[s, 5] = _acceleration(as_state(tmp), m, w, wd)
        K[s, 0], K[s, 1], K[s, 2] = tmp[3], tmp[4], tmp[5]
    for j in range(6):
        acc = 0.0
        for q in range(12):
            acc += B[q] * K[q, j]
        y_new[j] = y[j] + h * acc
    w, wd = rates(t + h, m.steady, m.w, wt, wv)
    K[12, 3], K[12, 4], K[12, 5] = _acceleration(as_state(y_new), m, w, wd)
    K[12, 0], K[12, 1], K[12, 2] = y_new[3], y_new[4], y_new[5]
