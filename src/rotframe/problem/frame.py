"""A frame that rotates any way: omega(t), its derivative, and an accelerating origin.

The transport theorem holds for any angular velocity ``omega(t)`` of the frame relative to
inertial space (docs/physics/rotating-frames.md). A particle seen from such a frame, with an
origin that accelerates at ``a0(t)``, obeys (all vectors in the frame's own axes)::

    r'' = f(t, r, v) - 2 omega x v - omega x (omega x r) - omega' x r - a0(t)

where ``omega'`` is the derivative of omega (the same in the frame's axes and in inertial
axes, since omega x omega = 0). `FrameSpec` turns the forms a user may give into
arrays that the compiled drivers read:

==========  =========================================================================
kind        data
==========  =========================================================================
constant    the vector omega; omega' = 0
table       a C2 cubic spline through ``(times, vectors)`` (scipy's ``CubicSpline``,
            not-a-knot): omega and omega' are the spline and its derivative; or, given
            as ``(times, vectors, "linear")``, the straight lines between the knots
            (omega' the slope of each: a motor's ramp, which a spline would round
            off and overshoot)
function    a user function ``t -> (3,)``; omega' given (``omega_dot=``) or derived
            by a fourth-order central difference with a fixed step
            h = 2^-9 min(1 s, 1 / |omega(0)|) (error about h^4 |omega^(5)| / 30, some
            1e-13 of omega's scale for a rate that changes over a second or more; give
            ``omega_dot`` for a faster one). ``data`` holds ``[h, 0, 0]``
body        the body axes of a rigid-body solution: omega = I^-1 L at each sample,
            omega' and omega'' from Euler's equations there, and a quintic Hermite
            interpolant between samples (cubic where the body had a torque)
==========  =========================================================================

The origin's acceleration ``a0(t)`` takes the constant, table and function forms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rotframe.errors import ScenarioError
from rotframe.problem.callables import check_call, plain_function
from rotframe.validation import check_vector3, refuse_units

__all__ = ["FrameSpec", "frame_spec", "origin_spec", "stop_times", "is_table", "KINDS", "TABLE_INTERPOLATIONS"]

KINDS = ("constant", "table", "function", "body")


@dataclass
class FrameSpec:
    """What the drivers need to evaluate a vector function of time and its derivative.

    Attributes
    ----------
    kind : str
        One of `KINDS` (``"zero"`` for a missing origin acceleration).
    data : tuple of float64 arrays
        The kind's arrays (see `frame_spec`); for ``function``, ``([h, 0, 0],)``: the step of a derived omega'.
    funcs : tuple of callables
        For ``function``: the user's ``omega(t)`` and, if given, ``omega_dot(t)``.
    t_range : (float, float)
        Times where the spec is defined (a table or a body solution); +-inf otherwise.
    is_constant : bool
        Constant in time (omega' = 0): with potentials, the Jacobi integral is conserved.
    """

    kind: str
    data: tuple = ()
    funcs: tuple = ()
    t_range: tuple = (-math.inf, math.inf)
    is_constant: bool = False
    notes: list = field(default_factory=list)
    #: for ``body``: the order in h (sample interval) of a trajectory's error from the interpolant
    #: (6 for the quintic Hermite of a free body, 4 where omega'' comes from differences: a torque)
    order: int = 0
    #: for ``table``: how it is interpolated between its knots (`TABLE_INTERPOLATIONS`)
    interpolation: str = ""
    #: for a ``"linear"`` table: its knots' vectors (n, 3), as given
    nodes: np.ndarray | None = None

    def coarsened(self):
        """The same body frame from every other sample (None for another kind, or too few samples).

        Comparing a run in this frame with the run in the full one estimates the error that the
        frame's interpolation between samples makes (`rotframe.problem.frame_error`, Richardson).
        """
        if self.kind != "body" or self.data[0].size < 5:
            return None
        times, w, wd, wdd = self.data
        keep = np.arange(0, times.size, 2)
        if keep[-1] != times.size - 1:
            keep = np.append(keep, times.size - 1)
        tc, wc, wdc = times[keep], w[keep], wd[keep]
        wddc = np.gradient(wdc, tc, axis=0) if self.order == 4 else wdd[keep]
        return FrameSpec("body", tuple(np.ascontiguousarray(a) for a in (tc, wc, wdc, wddc)), t_range=self.t_range,
                         order=self.order)

    def packed(self, derivative=True):
        """``(kind code, T, C)``: the spec as the engine reads it (`rotframe.problem.models.vector_of_time`).

        ``derivative=False`` (an origin's acceleration, whose derivative nothing reads): a function
        is not differenced.
        """
        from rotframe.problem import models

        none = np.zeros(1)
        if self.kind in ("zero", "constant"):
            C = np.zeros((1, 1, 3))
            if self.kind == "constant":
                C[0, 0] = self.data[0]
            return (models.CONSTANT if self.kind == "constant" else models.ZERO), none, C
        if self.kind == "table":
            return models.TABLE, self.data[0], self.data[1]
        if self.kind == "body":
            times, w, wd, wdd = self.data
            return models.BODY_FRAME, times, np.ascontiguousarray(np.stack([w, wd, wdd], axis=1))
        # a function: omega' given, or derived with the step of derivative_step
        given = len(self.funcs) > 1 or not derivative
        step = np.array([float(self.data[0][0])]) if self.data else none
        return (models.FUNCTION_DOT if given else models.FUNCTION), step, np.zeros((1, 1, 3))

    def knots(self) -> np.ndarray:
        """Times where the vector's higher derivatives jump: a table's knots, a body's samples (else none)."""
        if self.kind in ("table", "body"):
            return np.asarray(self.data[0], dtype=float)
        return np.empty(0)

    def vector_at(self, t):
        """The vector and its derivative at times ``t`` (numpy, for analysis and tests): two (n, 3) arrays."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if self.kind == "zero":
            return np.zeros((t.size, 3)), np.zeros((t.size, 3))
        if self.kind == "constant":
            return np.tile(self.data[0], (t.size, 1)), np.zeros((t.size, 3))
        if self.kind == "table":
            knots, coef = self.data
            out = np.empty((t.size, 3))
            der = np.empty((t.size, 3))
            for n, tt in enumerate(t):
                out[n], der[n] = spline_at(knots, coef, tt)
            return out, der
        if self.kind == "body":
            out = np.empty((t.size, 3))
            der = np.empty((t.size, 3))
            for n, tt in enumerate(t):
                out[n], der[n] = hermite_at(*self.data, tt)
            return out, der
        f = self.funcs[0]
        fd = self.funcs[1] if len(self.funcs) > 1 else None
        out = np.array([np.asarray(f(float(tt)), dtype=float) for tt in t])
        h = float(self.data[0][0]) if self.data else derivative_step(f)
        der = np.array([np.asarray(fd(float(tt)), dtype=float) if fd is not None
                        else central_difference(f, float(tt), h) for tt in t])
        return out, der


def stop_times(specs, duration: float) -> np.ndarray:
    """The sorted knots of ``specs`` inside (0, duration): no integrator step may cross one.

    A spline or Hermite interpolant is smooth between its knots only; a step across a knot
    integrates a function whose higher derivatives jump, and loses its order (a finer table then
    gives a larger error). The drivers end a step on each (``S`` of `rotframe.problem.engine`).
    """
    knots = np.concatenate([spec.knots() for spec in specs] + [np.empty(0)])
    knots = np.unique(knots[(knots > 0.0) & (knots < duration)])
    return np.ascontiguousarray(knots, dtype=float)


def derivative_step(f) -> float:
    """The step (s) of the central difference for omega' of a function ``f``: 2^-9 min(1 s, 1 / |f(0)|).

    Fixed in time: a step that grew with |t| would make omega' wrong by (h/tau)^4 late in a long
    run (h = 0.4 s at t = 200 s); 1 / |omega| is the frame's own time scale.
    """
    w0 = float(np.linalg.norm(np.asarray(f(0.0), dtype=float)))
    return 2.0 ** -9 * (min(1.0, 1.0 / w0) if w0 > 0.0 else 1.0)


def central_difference(f, t, h):
    """omega'(t) by the fourth-order central difference of step ``h`` (taken as (t + h) - t, exact in floats)."""
    h = (t + h) - t
    a = np.asarray(f(t - 2 * h), float)
    b = np.asarray(f(t - h), float)
    c = np.asarray(f(t + h), float)
    d = np.asarray(f(t + 2 * h), float)
    return (a - 8 * b + 8 * c - d) / (12 * h)


def spline_at(knots, coef, t):
    """A piecewise cubic ``coef[i, k, :] (t - knots[i])^(3 - k)`` and its derivative at ``t`` (numpy)."""
    i = int(np.clip(np.searchsorted(knots, t, side="right") - 1, 0, len(knots) - 2))
    s = t - knots[i]
    c = coef[i]
    return ((c[0] * s + c[1]) * s + c[2]) * s + c[3], (3 * c[0] * s + 2 * c[1]) * s + c[2]


def hermite_at(times, w, wd, wdd, t):
    """Quintic Hermite interpolant through (w, w', w'') at the samples, and its derivative (numpy)."""
    i = int(np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2))
    h = times[i + 1] - times[i]
    s = (t - times[i]) / h
    H = _quintic_basis(s)
    D = _quintic_basis_derivative(s)
    p = (H[0] * w[i] + H[1] * h * wd[i] + H[2] * h * h * wdd[i]
         + H[3] * w[i + 1] + H[4] * h * wd[i + 1] + H[5] * h * h * wdd[i + 1])
    dp = (D[0] * w[i] + D[1] * h * wd[i] + D[2] * h * h * wdd[i]
          + D[3] * w[i + 1] + D[4] * h * wd[i + 1] + D[5] * h * h * wdd[i + 1]) / h
    return p, dp


def _quintic_basis(s):
    s2, s3 = s * s, s * s * s
    s4, s5 = s3 * s, s3 * s2
    return (1 - 10 * s3 + 15 * s4 - 6 * s5, s - 6 * s3 + 8 * s4 - 3 * s5, 0.5 * (s2 - 3 * s3 + 3 * s4 - s5),
            10 * s3 - 15 * s4 + 6 * s5, -4 * s3 + 7 * s4 - 3 * s5, 0.5 * (s3 - 2 * s4 + s5))


def _quintic_basis_derivative(s):
    s2, s3, s4 = s * s, s * s * s, s * s * s * s
    return (-30 * s2 + 60 * s3 - 30 * s4, 1 - 18 * s2 + 32 * s3 - 15 * s4, 0.5 * (2 * s - 9 * s2 + 12 * s3 - 5 * s4),
            30 * s2 - 60 * s3 + 30 * s4, -12 * s2 + 28 * s3 - 15 * s4, 0.5 * (3 * s2 - 8 * s3 + 5 * s4))


#: how a table ``(times, vectors, how)`` is interpolated between its knots (the default: "cubic")
TABLE_INTERPOLATIONS = ("cubic", "linear")


def _table(value, what):
    times, vectors = value[0], value[1]
    how = value[2] if len(value) == 3 else "cubic"
    if not isinstance(how, str) or how not in TABLE_INTERPOLATIONS:
        raise ScenarioError(f"{what}: the table's interpolation {how!r}; allowed: "
                            f"{', '.join(map(repr, TABLE_INTERPOLATIONS))}")
    refuse_units(times, f"{what} (the table's times)", ScenarioError)
    refuse_units(vectors, f"{what} (the table's vectors)", ScenarioError)
    try:
        times = np.asarray(times, dtype=float)
        vectors = np.asarray(vectors, dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError(f"{what}: a table is (times (n,), vectors (n, 3)) of real numbers; got "
                            f"{' '.join(str(value).split())[:80]!r} (ragged, text or complex)") from None
    if times.ndim != 1 or times.size < 2 or vectors.shape != (times.size, 3):
        raise ScenarioError(f"{what}: a table is (times (n,), vectors (n, 3)) with n >= 2; got shapes "
                            f"{times.shape} and {vectors.shape}")
    if not (np.all(np.isfinite(times)) and np.all(np.isfinite(vectors))):
        raise ScenarioError(f"{what}: the table has non-finite entries")
    bad = np.flatnonzero(np.diff(times) <= 0)
    if bad.size:
        k = int(bad[0])
        raise ScenarioError(f"{what}: the table's times must increase; times[{k + 1}] = {times[k + 1]:g} s "
                            f"follows times[{k}] = {times[k]:g} s")
    if how == "linear":  # the cubic's form with two coefficients zero: v_i + slope_i (t - t_i) on each interval
        coef = np.zeros((times.size - 1, 4, 3))
        coef[:, 2] = np.diff(vectors, axis=0) / np.diff(times)[:, None]
        coef[:, 3] = vectors[:-1]
    else:
        from scipy.interpolate import CubicSpline

        spline = CubicSpline(times, vectors, axis=0, bc_type="not-a-knot" if times.size > 3 else "natural")
        coef = np.ascontiguousarray(np.transpose(spline.c, (1, 0, 2)))  # (n - 1, 4, 3)
    return FrameSpec("table", (np.ascontiguousarray(times), coef), t_range=(times[0], times[-1]),
                     is_constant=bool(np.all(vectors == vectors[0])), interpolation=how,
                     nodes=vectors.copy() if how == "linear" else None)


def _body(result, what):
    """The body axes of a rigid-body Result: omega = I^-1 L, with omega', omega'' from Euler's equations."""
    traj = getattr(result, "trajectory", None)
    L = getattr(traj, "L", None)
    q = getattr(traj, "q", None)
    inertia = getattr(result, "inertia", None)
    if L is None or q is None:
        raise ScenarioError(f"{what}: the result has no attitudes (trajectory.L and trajectory.q): give the "
                            "Result of a rigid-body run (rotframe.simulate_body or a rigid scene)")
    if inertia is None:
        raise ScenarioError(f"{what}: the result does not carry its body's inertia (result.inertia)")
    times = np.asarray(traj.times, dtype=float)
    L = np.asarray(L, dtype=float)
    if times.size < 2:
        raise ScenarioError(f"{what}: the body solution has fewer than two samples")
    I = np.asarray(inertia, dtype=float)
    Iinv = np.linalg.inv(I)
    w = L @ Iinv.T
    torque = getattr(result, "torque_samples", None)
    tau = np.zeros_like(L) if torque is None else np.asarray(torque, float)
    Ld = np.cross(L, w) + tau  # body-frame dL/dt = L x omega + tau
    wd = Ld @ Iinv.T
    notes = []
    if torque is None:
        Ldd = np.cross(Ld, w) + np.cross(L, wd)
        wdd = Ldd @ Iinv.T
    else:
        wdd = np.gradient(wd, times, axis=0)
        notes.append("the body had a torque: omega'' between samples from differences of omega' (cubic accuracy)")
    return FrameSpec("body", tuple(np.ascontiguousarray(a) for a in (times, w, wd, wdd)),
                     t_range=(times[0], times[-1]), notes=notes, order=6 if torque is None else 4)


def is_table(value) -> bool:
    """``(times, vectors)``: a pair whose first entry is 1-D and whose second is a sequence of sequences (even ragged);
    or ``(times, vectors, how)``, the same with its interpolation named (`TABLE_INTERPOLATIONS`)."""
    if not (isinstance(value, (tuple, list)) and len(value) in (2, 3)):
        return False
    try:
        first = np.ndim(value[0]) == 1
    except ValueError:  # ragged
        return False
    second = value[1]
    try:
        return first and np.ndim(second) == 2
    except ValueError:  # a ragged (n, 3): a table still, refused by _table in one line
        return first and len(second) > 0 and all(hasattr(row, "__len__") for row in second)


def frame_spec(value, omega_dot=None, what="omega") -> FrameSpec:
    """Normalise a frame's angular velocity (rad/s, frame axes) to a `FrameSpec`.

    Parameters
    ----------
    value : 3-vector, (times, vectors), callable or rigid-body Result
        The forms of ``rotframe.simulate(omega=...)``.
    omega_dot : callable, optional
        ``t -> (3,)``, the derivative of a callable omega (else it is derived).
    """
    if callable(value) and not hasattr(value, "trajectory"):
        if omega_dot is not None and not callable(omega_dot):
            raise ScenarioError(f"{what}_dot: must be a callable t -> (3,) beside a callable {what}")
        for f, name in ((value, what), (omega_dot, f"{what}_dot")):
            if f is not None:
                check_call(name, f, (0.0,), (3,), when="at t = 0")
        funcs = (value,) if omega_dot is None else (value, omega_dot)
        step = derivative_step(plain_function(value)) if omega_dot is None else 0.0
        return FrameSpec("function", (np.array([step, 0.0, 0.0]),), funcs)
    if omega_dot is not None:
        raise ScenarioError(f"{what}_dot is only for a callable {what}")
    if hasattr(value, "trajectory"):
        return _body(value, what)
    if is_table(value):
        return _table(value, what)
    refuse_units(value, what, ScenarioError)
    return FrameSpec("constant", (np.ascontiguousarray(check_vector3(value, what, ScenarioError)),), is_constant=True)


def origin_spec(value, what="origin_acceleration") -> FrameSpec:
    """The origin's acceleration (m/s^2, frame axes): None, a 3-vector, a table or a callable."""
    if value is None:
        return FrameSpec("zero", (np.zeros(3),), is_constant=True)
    if hasattr(value, "trajectory"):
        raise ScenarioError(f"{what}: a rigid-body Result is a form of omega only")
    spec = frame_spec(value, what=what)
    if spec.kind == "constant" and not np.any(spec.data[0]):
        return FrameSpec("zero", (np.zeros(3),), is_constant=True)
    return spec
