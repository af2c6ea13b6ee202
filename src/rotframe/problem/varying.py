"""The engine's evaluator of a varying frame or origin: a table's spline, a body frame's samples, a user's function.

`rotframe.problem.models.vector_of_time` answers the constant kinds itself and calls this one by
its address (`rotframe.problem.calls.call_varying`) for the others: ``TABLE``, a C2 cubic spline
(``T`` the knots, ``C`` (n - 1, 4, 3) its coefficients); ``BODY_FRAME``, the quintic Hermite
interpolant through a body's omega, omega', omega'' (``T`` its sample times, ``C`` (n, 3, 3));
``FUNCTION``, the user's ``omega(t)`` with omega' from the fourth-order central difference of step
``T[0]`` (`rotframe.problem.frame.derivative_step`), or ``FUNCTION_DOT``, with the user's omega'.

A problem's run calls the copy of its own kinds alone (`varying_into_for`: each kind's code
compiled only where a problem has it); the GPU's kernel and a long run's inlined loop rebuild
`varying_into`, which holds every kind. The numpy twins used for analysis are in
`rotframe.problem.frame`.
"""

from __future__ import annotations

import math

from rotframe.numerics.compiled import bound, jit_inline, jit_uncounted
from rotframe.problem.calls import call_vector
from rotframe.problem.models import BODY_FRAME, CONSTANT, FUNCTION, FUNCTION_DOT, TABLE, ZERO

__all__ = ["varying_into", "varying_into_for", "varying_vector", "needs_varying", "hermite", "interval"]


@jit_inline
def interval(knots, t):
    """The index i of the interval [knots[i], knots[i + 1]] holding t (clipped to the ends)."""
    n = knots.shape[0]
    if t <= knots[0]:
        return 0
    if t >= knots[n - 1]:
        return n - 2
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if knots[mid] <= t:
            lo = mid
        else:
            hi = mid
    return lo


def needs_varying(kinds) -> bool:
    """Whether a frame's or origin's kinds need `varying_into` (a table, a body's samples, a user's function)."""
    return any(kind not in (CONSTANT, ZERO) for kind in kinds)


# the kinds a copy of the varying evaluator holds (`varying_into_for`): every kind in the template's own copy
HAS_TABLE = HAS_BODY = HAS_FUNCTION = True
VARYING_VECTOR = None


def _varying_into(kind, T, C, fn, t, out):
    """The template of `varying_into`: `varying_vector` (``VARYING_VECTOR``, a copy's) into ``out[0:6]``."""
    out[0], out[1], out[2], out[3], out[4], out[5] = VARYING_VECTOR(kind, T, C, fn, t, out)


def _varying_vector(kind, T, C, fn, t, buf):
    """`vector_of_time` of a table, a body's samples or a user's function: the branches of the kinds a copy holds
    (``HAS_TABLE``, ``HAS_BODY``, ``HAS_FUNCTION``; a kind it does not hold gives NaN)."""
    if HAS_TABLE:
        if kind == TABLE:
            i = interval(T, t)
            s = t - T[i]
            x = ((C[i, 0, 0] * s + C[i, 1, 0]) * s + C[i, 2, 0]) * s + C[i, 3, 0]
            y = ((C[i, 0, 1] * s + C[i, 1, 1]) * s + C[i, 2, 1]) * s + C[i, 3, 1]
            z = ((C[i, 0, 2] * s + C[i, 1, 2]) * s + C[i, 2, 2]) * s + C[i, 3, 2]
            dx = (3.0 * C[i, 0, 0] * s + 2.0 * C[i, 1, 0]) * s + C[i, 2, 0]
            dy = (3.0 * C[i, 0, 1] * s + 2.0 * C[i, 1, 1]) * s + C[i, 2, 1]
            dz = (3.0 * C[i, 0, 2] * s + 2.0 * C[i, 1, 2]) * s + C[i, 2, 2]
            return x, y, z, dx, dy, dz
    if HAS_BODY:
        if kind == BODY_FRAME:
            return hermite(T, C, t)
    if HAS_FUNCTION:
        # the user's function: omega' given (FUNCTION_DOT) or a central difference (FUNCTION)
        call_vector(fn, t, buf)
        x = buf[0]
        y = buf[1]
        z = buf[2]
        if kind == FUNCTION_DOT:
            return x, y, z, buf[3], buf[4], buf[5]
        hh = (t + T[0]) - t  # the step of frame.derivative_step, exact in floats
        call_vector(fn, t - 2.0 * hh, buf)
        ax, ay, az = buf[0], buf[1], buf[2]
        call_vector(fn, t - hh, buf)
        bx, by, bz = buf[0], buf[1], buf[2]
        call_vector(fn, t + hh, buf)
        cx, cy, cz = buf[0], buf[1], buf[2]
        call_vector(fn, t + 2.0 * hh, buf)
        return (x, y, z, (ax - 8.0 * bx + 8.0 * cx - buf[0]) / (12.0 * hh), (ay - 8.0 * by + 8.0 * cy - buf[1]) / (12.0 * hh),
                (az - 8.0 * bz + 8.0 * cz - buf[2]) / (12.0 * hh))
    return math.nan, math.nan, math.nan, math.nan, math.nan, math.nan


@jit_uncounted
def hermite(T, C, t):
    """The quintic Hermite interpolant through a body's omega, omega', omega'' (C[i, 0..2]) and its derivative."""
    i = interval(T, t)
    h = T[i + 1] - T[i]
    s = (t - T[i]) / h
    s2 = s * s
    s3 = s2 * s
    s4 = s3 * s
    s5 = s4 * s
    h0 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5
    h1 = s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5
    h2 = 0.5 * (s2 - 3.0 * s3 + 3.0 * s4 - s5)
    h3 = 10.0 * s3 - 15.0 * s4 + 6.0 * s5
    h4 = -4.0 * s3 + 7.0 * s4 - 3.0 * s5
    h5 = 0.5 * (s3 - 2.0 * s4 + s5)
    d0 = -30.0 * s2 + 60.0 * s3 - 30.0 * s4
    d1 = 1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4
    d2 = 0.5 * (2.0 * s - 9.0 * s2 + 12.0 * s3 - 5.0 * s4)
    d3 = 30.0 * s2 - 60.0 * s3 + 30.0 * s4
    d4 = -12.0 * s2 + 28.0 * s3 - 15.0 * s4
    d5 = 0.5 * (3.0 * s2 - 8.0 * s3 + 5.0 * s4)
    return (mix(C, i, 0, h, h0, h1, h2, h3, h4, h5), mix(C, i, 1, h, h0, h1, h2, h3, h4, h5),
            mix(C, i, 2, h, h0, h1, h2, h3, h4, h5), mix(C, i, 0, h, d0, d1, d2, d3, d4, d5) / h,
            mix(C, i, 1, h, d0, d1, d2, d3, d4, d5) / h, mix(C, i, 2, h, d0, d1, d2, d3, d4, d5) / h)


# bound after `hermite` and `interval`: a copy's globals are those of the module when it is made
#: `vector_of_time` of every varying kind
varying_vector = jit_uncounted(bound(_varying_vector, "varying_vector"))
#: `varying_vector` into ``out[0:6]``: what the engine calls by address (`rotframe.problem.signatures.VARYING_SIG`),
#: for every kind (the GPU's kernel and the inlined loop rebuild it); a problem's own run calls `varying_into_for`'s
varying_into = jit_uncounted(bound(_varying_into, "varying_into", VARYING_VECTOR=varying_vector))
_VARYING_COPIES: dict = {}


def varying_into_for(kinds):
    """`varying_into` holding only the branches of the varying ``kinds`` (a frame's and an origin's): the table's
    spline, the body frame's Hermite interpolant or the user's function, each compiled only where a problem has
    it (measured: a body frame's alone compiles in 0.7 s, every kind in 1.3 s). The same arithmetic, so the same
    numbers; one copy a process for each set of kinds, cached on disk under its own name."""
    holds = (TABLE in kinds, BODY_FRAME in kinds, FUNCTION in kinds or FUNCTION_DOT in kinds)
    found = _VARYING_COPIES.get(holds)
    if found is None:
        name = "varying_" + "_".join(n for n, h in zip(("table", "body", "function"), holds) if h)
        vector = jit_uncounted(bound(_varying_vector, f"{name}_vector", HAS_TABLE=holds[0], HAS_BODY=holds[1],
                                     HAS_FUNCTION=holds[2]))
        found = _VARYING_COPIES[holds] = jit_uncounted(bound(_varying_into, f"{name}_into", VARYING_VECTOR=vector))
    return found


@jit_uncounted
def mix(C, i, k, h, a0, a1, a2, a3, a4, a5):
    """Component k of the Hermite sum with the weights a0..a5 (values, h times first, h^2 times second derivatives)."""
    return (a0 * C[i, 0, k] + a1 * h * C[i, 1, k] + a2 * h * h * C[i, 2, k] + a3 * C[i + 1, 0, k]
            + a4 * h * C[i + 1, 1, k] + a5 * h * h * C[i + 1, 2, k])
