"""The rotation-rate schedule w(t) as the compiled kernels read it.

The magnitude table is ``wt`` (node times, increasing) and ``wv`` (values,
rad/s); w(t) is piecewise linear between the nodes and held constant outside
them. ``wint`` holds the integral of w from ``wt[0]`` to each node, so the
rotation angle over any interval is exact for the piecewise-linear schedule
([`rotframe.particles.model.OmegaSchedule.cumulative`][rotframe.particles.model.OmegaSchedule.cumulative]).

A steady schedule (one value at every node) is passed to the drivers as
``wt = None``: numba prunes every branch under ``if wt is None`` at compile
time, so a run at a steady rate compiles none of the table readers.
"""

from __future__ import annotations


from rotframe.particles.packed import jit_internal, jit_kernel

__all__ = ["node_index", "omega_magnitude", "omega_rate", "omega_angle", "rates"]


@jit_kernel
def node_index(wt, t):
    """``np.searchsorted(wt, t)`` for increasing ``wt``, by bisection: the first index i with ``wt[i] >= t``.

    Written out because numba's ``np.searchsorted`` compiles a generic version (complex
    comparisons included) that costs a first run about a second of compiling.
    """
    lo = 0
    hi = wt.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if wt[mid] < t:
            lo = mid + 1
        else:
            hi = mid
    return lo


@jit_kernel
def omega_magnitude(t, wt, wv):
    """Magnitude w(t) of the piecewise-linear schedule (rad/s)."""
    n = wt.shape[0]
    if n == 1 or t <= wt[0]:
        return wv[0]
    if t >= wt[n - 1]:
        return wv[n - 1]
    k = node_index(wt, t) - 1
    s = (t - wt[k]) / (wt[k + 1] - wt[k])
    return wv[k] + s * (wv[k + 1] - wv[k])


@jit_kernel
def omega_rate(t, wt, wv):
    """Time derivative w'(t) of the schedule (rad/s^2); zero outside the table."""
    n = wt.shape[0]
    if n == 1 or t < wt[0] or t >= wt[n - 1]:
        return 0.0
    i = node_index(wt, t)
    k = i if wt[i] == t else i - 1  # searchsorted side='right', less 1: the node times increase strictly
    return (wv[k + 1] - wv[k]) / (wt[k + 1] - wt[k])


@jit_kernel
def omega_angle(t, wt, wv, wint):
    """Integral of w from ``wt[0]`` to t (rad), exact for the piecewise-linear schedule."""
    n = wt.shape[0]
    if n == 1 or t <= wt[0]:
        return wv[0] * (t - wt[0])
    if t >= wt[n - 1]:
        return wint[n - 1] + wv[n - 1] * (t - wt[n - 1])
    k = node_index(wt, t) - 1
    dt = t - wt[k]
    slope = (wv[k + 1] - wv[k]) / (wt[k + 1] - wt[k])
    return wint[k] + wv[k] * dt + 0.5 * slope * dt * dt


@jit_internal
def rates(t, steady, w, wt, wv):
    """Rotation rate w(t) and its derivative (rad/s, rad/s^2): ``(w, 0)`` when ``steady``, else from the table.

    ``wt = None`` is a steady schedule known at compile time: the table readers are not compiled.
    """
    if wt is None:
        return w, 0.0
    if steady:
        return w, 0.0
    return omega_magnitude(t, wt, wv), omega_rate(t, wt, wv)
