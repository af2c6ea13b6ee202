"""A straight line fitted to samples at any time scale.

``np.polyfit(t, y, 1)`` solves the least-squares problem in the units of ``t``:
for a run of 1e-169 s the design matrix holds numbers near 1e-169, whose squares
underflow, and LAPACK's SVD fails to converge. Fitting against ``u = (t - t0) / span``
on [0, 1] is well conditioned at every scale; the slope in the units of ``t`` is the
slope in ``u`` over the span (exact up to one rounding).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["line_fit"]


def line_fit(t, y):
    """Least-squares line through ``(t, y)``: ``(slope, residuals, slope_error)``.

    ``slope`` is in units of y per unit of t; ``residuals`` is ``y`` minus the
    fitted line at each ``t``; ``slope_error`` is the slope's standard error from
    their scatter (``inf`` with fewer than three samples). A slope the span cannot
    carry (the span is 0, or the slope overflows float64) is ``nan``, with the
    residuals about the mean.

    >>> slope, resid, err = line_fit(np.array([0.0, 1e-200, 2e-200]), np.array([1.0, 3.0, 5.0]))
    >>> float(slope), bool(np.allclose(resid, 0.0)), float(err)
    (2e+200, True, 0.0)
    """
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    span = float(t[-1] - t[0]) if t.size else 0.0
    if not span > 0.0 or not math.isfinite(span):
        return math.nan, y - np.mean(y), math.nan
    u = (t - t[0]) / span
    du = u - np.mean(u)
    spread = float(np.sum(du * du))
    slope_u = float(np.sum(du * (y - np.mean(y)))) / spread
    resid = y - (np.mean(y) + slope_u * du)
    error_u = math.sqrt(float(np.sum(resid * resid)) / (t.size - 2) / spread) if t.size > 2 else math.inf
    with np.errstate(over="ignore"):
        slope = slope_u / span
        error = error_u / span
    return (slope if math.isfinite(slope) else math.nan), resid, error
