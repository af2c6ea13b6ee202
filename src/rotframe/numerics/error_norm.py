"""Hairer's DOP853 error norm, shared by the particle and rigid-body adaptive kernels (compiled).

The 5th- and 3rd-order error estimates of one step combined as in Hairer's
``dop853.f`` (Hairer, Norsett & Wanner, Solving ODEs I, II.10; docs/physics/dop853.md):
``err = |h| e5 / sqrt((e5 + 0.01 e3) n)`` with ``e5``, ``e3`` the sums of squares of
the scaled estimates ``sc_j = atol_j + rtol max(|y_j|, |y_new_j|)``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["dop853_error_norm"]

_jit = njit(cache=True, error_model="numpy", nogil=True)


@_jit
def dop853_error_norm(K, h, y, y_new, rtol, atol, E3, E5):
    """Hairer's DOP853 error norm of one step: the 5th- and 3rd-order estimates combined.

    ``atol`` holds one absolute tolerance per component of ``y`` (the particle and
    rigid-body kernels share this function).
    """
    n = y.shape[0]
    e5 = 0.0
    e3 = 0.0
    for j in range(n):
        sc = atol[j] + rtol * max(abs(y[j]), abs(y_new[j]))
        s5 = 0.0
        s3 = 0.0
        for q in range(13):
            s5 += E5[q] * K[q, j]
            s3 += E3[q] * K[q, j]
        e5 += (s5 / sc) ** 2
        e3 += (s3 / sc) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / np.sqrt((e5 + 0.01 * e3) * n)
