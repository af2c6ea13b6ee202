"""Argument checks shared by the frames modules: their error class, where a bad entry sits, broadcast shapes."""

from __future__ import annotations

import numpy as np

from rotframe.errors import RotframeError

__all__ = ["FrameInputError", "where_text", "common_shape"]


class FrameInputError(RotframeError, ValueError):
    """Bad argument (sequence, frame, axis or array shape) to a frames function."""


def where_text(mask):
    """' at index (..) (n of N entries)' for a boolean array of bad entries, '' for a scalar."""
    mask = np.asarray(mask)
    if mask.ndim == 0:
        return ""
    first = tuple(int(n) for n in np.argwhere(mask)[0])
    return f" at index {first} ({int(mask.sum())} of {mask.size} entries)"


def common_shape(caller, **arrays):
    """Broadcast shape of the named arrays, or an error naming their shapes."""
    try:
        return np.broadcast_shapes(*(a.shape for a in arrays.values()))
    except ValueError:
        shapes = ", ".join(f"{name} {a.shape}" for name, a in arrays.items())
        raise FrameInputError(
            f"{caller}: shapes do not broadcast: {shapes}; leading axes must match or be 1"
        ) from None
