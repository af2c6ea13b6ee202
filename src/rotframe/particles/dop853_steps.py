"""The stages of Dormand-Prince 8(5,3) for a particle: a step, and its dense output's three more.

The tableau is `rotframe.numerics.dop853_dense.extended_tableau` (``A`` (16, 16) with the
order-8 weights as row 12 and the dense output's stages as rows 13..15, ``C`` (16,)), so that
one stage loop forms the step and, where a step holds a sample, the interpolant's stages.
"""

from __future__ import annotations

from numba import njit

from rotframe.particles.forces import state_acceleration
from rotframe.particles.packed import as_state, jit_internal
from rotframe.particles.schedule import rates

#: the force, inlined into the step (twelve evaluations a step: twelve calls passing the packed model)
_acceleration = njit(inline="always", error_model="numpy", nogil=True)(state_acceleration.py_func)
_inline = njit(inline="always", error_model="numpy", nogil=True)

__all__ = ["dop853_step", "dense_stages"]


@_inline
def _stages(first, last, t, y, h, m, wt, wv, A, C, K, z):
    """Stages ``first .. last - 1``: ``z = y + h sum_q A[s, q] K[q]``, ``K[s] = f(t + C[s] h, z)``."""
    for s in range(first, last):
        for j in range(6):
            acc = 0.0
            for q in range(s):
                acc += A[s, q] * K[q, j]
            z[j] = y[j] + h * acc
        w, wd = rates(t + C[s] * h, m.steady, m.w, wt, wv)
        K[s, 3], K[s, 4], K[s, 5] = _acceleration(as_state(z), m, w, wd)
        K[s, 0], K[s, 1], K[s, 2] = z[3], z[4], z[5]


@jit_internal
def dop853_step(t, y, f0, h, m, wt, wv, A, C, K, y_new, tmp):
    """One DOP853 step from (t, y) with f0 = f(t, y) (a 6-tuple).

    ``K`` (13 or more, 6) receives the stages and ``K[12] = f(t + h, y_new)``; tmp (6,) is scratch.
    """
    K[0, 0], K[0, 1], K[0, 2], K[0, 3], K[0, 4], K[0, 5] = f0
    _stages(1, 12, t, y, h, m, wt, wv, A, C, K, tmp)
    _stages(12, 13, t, y, h, m, wt, wv, A, C, K, y_new)  # row 12: the order-8 weights, at C[12] = 1


@jit_internal
def dense_stages(t, y, h, m, wt, wv, A, C, K, tmp):
    """The dense output's stages ``K[13..15]`` of an accepted step (``K`` (16, 6) holds its 13)."""
    _stages(13, 16, t, y, h, m, wt, wv, A, C, K, tmp)
