"""Stops: the times inside a run where a problem's right-hand side is not smooth, and how a step meets them.

A table's knots and a body frame's samples (`rotframe.problem.frame.stop_times`, the sorted ``S``
of the engine's loops) are where an interpolant's higher derivatives jump, or, for a
piecewise-linear table, omega' itself. No step of the engine crosses one
(`rotframe.problem.engine`): DOP853's and RK4's steps are cut to end on it, as
DifferentialEquations.jl's ``tstops``, so each integrates a smooth function and keeps its order;
an RK4 step that ends on one reads f on its own side of it
(`rotframe.numerics.step_control.start_short_of`).
"""

from __future__ import annotations

import math

from rotframe.numerics.compiled import jit_inline

__all__ = ["next_stop"]


@jit_inline
def next_stop(S, t):
    """The first stop time in the sorted S after t (inf if none): a knot where the right-hand side is not smooth."""
    n = S.shape[0]
    if n == 0 or S[n - 1] <= t:
        return math.inf
    lo = 0
    hi = n - 1
    while lo < hi:  # the first S[k] > t
        mid = (lo + hi) // 2
        if S[mid] > t:
            hi = mid
        else:
            lo = mid + 1
    return S[lo]


