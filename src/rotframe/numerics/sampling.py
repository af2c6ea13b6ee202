"""Choosing which samples of a long series to keep (for recordings, plots and tracks)."""

from __future__ import annotations

import numpy as np

__all__ = ["decimate"]


def decimate(n: int, max_samples: int) -> np.ndarray:
    """Indices of at most ``max_samples`` evenly spread samples of ``n``, first and last kept.

    Parameters
    ----------
    n : int
        Number of samples in the series.
    max_samples : int
        Most indices to return (at least 2 when ``n >= 2``).

    Returns
    -------
    numpy.ndarray of int64
        Sorted, unique indices into the series; ``arange(n)`` when ``n <= max_samples``.

    Examples
    --------
    >>> decimate(10, 4).tolist()
    [0, 3, 6, 9]
    """
    if n <= max_samples:
        return np.arange(n)
    return np.unique(np.linspace(0, n - 1, max_samples).round().astype(np.int64))
