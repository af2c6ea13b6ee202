"""The hat map of so(3): the skew matrix of a 3-vector (numpy only, no numba: cheap to import).

``skew(w) @ v == np.cross(w, v)``. Re-exported by `rotframe.numerics.rotation` beside the
compiled rotation primitives.
"""

from __future__ import annotations

import numpy as np

__all__ = ["skew"]

def skew(w) -> np.ndarray:
    """The skew (hat) matrix ``W`` of a 3-vector: ``W @ v = w x v``.

    Parameters
    ----------
    w : array_like, shape (3,)

    Returns
    -------
    ndarray, shape (3, 3)
    """
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
