"""Euclidean norms of 3-vectors that neither overflow nor underflow in their squares.

``np.linalg.norm`` squares the components: at 1.3e154 m the square overflows to inf and
a finite position reads as infinitely far (a turntable puck at 1e170 m/s was reported
as diverged, exit 3). `norm3` chains ``hypot``, which scales internally: finite for
every finite vector, exact to a rounding or two.
"""

from __future__ import annotations

import numpy as np

__all__ = ["norm3"]


def norm3(x):
    """|x| over the last axis of ``x`` (..., 3), by ``hypot(hypot(x0, x1), x2)``.

    >>> round(float(norm3(np.array([3e200, 4e200, 0.0]))) / 5e200, 12)  # np.linalg.norm: inf
    1.0
    """
    x = np.asarray(x, dtype=np.float64)
    return np.hypot(np.hypot(x[..., 0], x[..., 1]), x[..., 2])
