"""Compiled kernels for particles in a rotating frame (numba, cached on disk).

Everything here works on plain float64 arrays in SI units and radians; there is
no I/O and no Python object in a step loop. The Python side
(:mod:`rotframe.particles.integrators`) packs a :class:`rotframe.particles.model.ParticleModel` into
the flat parameter vector ``P`` described below and calls the drivers in
chunks of output samples, so that a progress bar, Ctrl-C and a numerical
failure can be handled between chunks without losing data.

Equation of motion (rotating frame, docs/physics/rotating-frames.md)::

    r'' = g(r) - 2 w(t) x v - w x (w x r) - w'(t) x r - k1 v - k2 |v| v  [+ tension]

with ``w(t) = w_hat * w(t)``, a fixed unit axis times a magnitude that is
piecewise linear in time (a constant is a one-node table). Each term is
switched by a flag in ``P``; a term that is off costs one branch.

Layout of ``P`` (see ``pack`` in :mod:`rotframe.particles.model`)::

    0:3   uniform gravity vector g (m/s^2)          [used when gravity mode == 0]
    3:6   unit rotation axis w_hat
    6     coriolis on (1.0) / off (0.0)
    7     centrifugal on / off
    8     euler term on / off
    9     linear drag k1 (1/s)
    10    quadratic drag k2 (1/m)
    11    gravity mode: -1 none, 0 uniform, 1 altitude (g0 (R/(R+z))^2 down), 2 central
    12    GM (m^3/s^2)            13  R, Earth radius (m); the centre is at (0, 0, -R)
    14    pendulum length L (m), 0 for a free particle
    15:18 pendulum pivot (m)
    18    g0 for the altitude model (m/s^2)
    19    horizontal spring w0^2 (1/s^2): a += -w0^2 (x, y, 0), the small-angle pendulum
    20    density scale height H (m) of the drag: k -> k exp(-z / H); 0 for uniform air

The rotation-rate magnitude table is ``wt`` (node times, increasing) and
``wv`` (values, rad/s); outside the table the end values are held. ``wint``
holds the integral of w from ``wt[0]`` to each node, so the rotation angle
over any interval is exact for the piecewise-linear schedule.

The drivers unpack ``P`` and the schedule once into a :class:`_Model` of
scalars. A particle's state is the tuple ``(x, y, z, vx, vy, vz)``, kept in
registers: the step kernels take and return it and take no array. What a step
needs from the schedule (the rate and its derivative at each stage, the angle
turned over each sub-step and the cosine and sine of the Coriolis rotation)
is its plan (:func:`_plan`). At a steady rate the plan is the same for every
step and particle, so it is made once per call and the steps between two
samples are one loop (:func:`_free_steps`, for a free particle, is the
throughput path); a varying schedule is read once per step. A division by
zero gives inf or nan, reported by the drivers as a non-finite state.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from rotframe.numerics.composition import YOSHIDA4_INNER, YOSHIDA4_OUTER
from rotframe.numerics.dop853 import dop853_error_norm

# Parameter-vector indices (kept in one place; model.pack writes them).
I_G, I_AXIS, I_CORIOLIS, I_CENTRIFUGAL, I_EULER = 0, 3, 6, 7, 8
I_KLIN, I_KQUAD, I_GMODE, I_GM, I_R, I_PLEN, I_PIVOT, I_G0, I_SPRING, I_SCALE_H = 9, 10, 11, 12, 13, 14, 15, 18, 19, 20
N_PARAMS = 21

# Event description: (kind, component, value, direction, terminal)
#   kind 0: position component r[c] - value, kind 1: velocity component v[c] - value,
#   kind 2: altitude above the sphere of radius R about (0, 0, -R), minus value (curved ground)
#   direction: +1 rising only, -1 falling only, 0 both. terminal: 1 stops that particle.
N_EVENT_FIELDS = 5

# Every kernel: cached on disk; a division by zero gives inf or nan (caught as a
# non-finite state) instead of raising, which also lets numba drop the reference counting
# of arrays passed to small functions that it inlines.
_jit = njit(cache=True, error_model="numpy", nogil=True)  # nogil: ensembles run blocks on threads

# Force evaluations per step of each method code (0 splitting, 1 splitting4, 2 rk4).
_NFEV = (1, 3, 4)


# ---------------------------------------------------------------------------
# rotation-rate schedule
# ---------------------------------------------------------------------------


@_jit
def omega_magnitude(t, wt, wv):
    """Magnitude w(t) of the piecewise-linear schedule (rad/s)."""
    n = wt.shape[0]
    if n == 1 or t <= wt[0]:
        return wv[0]
    if t >= wt[n - 1]:
        return wv[n - 1]
    k = np.searchsorted(wt, t) - 1
    s = (t - wt[k]) / (wt[k + 1] - wt[k])
    return wv[k] + s * (wv[k + 1] - wv[k])


@_jit
def omega_rate(t, wt, wv):
    """Time derivative w'(t) of the schedule (rad/s^2); zero outside the table."""
    n = wt.shape[0]
    if n == 1 or t < wt[0] or t >= wt[n - 1]:
        return 0.0
    k = np.searchsorted(wt, t, side="right") - 1
    return (wv[k + 1] - wv[k]) / (wt[k + 1] - wt[k])


@_jit
def omega_angle(t, wt, wv, wint):
    """Integral of w from ``wt[0]`` to t (rad), exact for the piecewise-linear schedule."""
    n = wt.shape[0]
    if n == 1 or t <= wt[0]:
        return wv[0] * (t - wt[0])
    if t >= wt[n - 1]:
        return wint[n - 1] + wv[n - 1] * (t - wt[n - 1])
    k = np.searchsorted(wt, t) - 1
    dt = t - wt[k]
    slope = (wv[k + 1] - wv[k]) / (wt[k + 1] - wt[k])
    return wint[k] + wv[k] * dt + 0.5 * slope * dt * dt


# ---------------------------------------------------------------------------
# the model as scalars
# ---------------------------------------------------------------------------

class _Model(NamedTuple):
    """``P`` and the rotation schedule as scalars, unpacked once per driver call.

    Booleans are the term switches of ``P``; vectors are 3-tuples.
    """

    g: tuple  # uniform gravity (m/s^2); zero unless the gravity mode is 0
    axis: tuple  # unit rotation axis
    coriolis: bool
    centrifugal: bool
    euler: bool
    k1: float  # linear drag (1/s)
    k2: float  # quadratic drag (1/m)
    drag: bool  # k1 or k2 non-zero
    gmode: float  # gravity mode, as in P
    gm: float
    radius: float
    g0: float
    spring: float
    scale_h: float
    length: float  # pendulum length, 0 for a free particle
    pivot: tuple
    uniform: bool  # the position-dependent acceleration is just g: no other gravity, spring, centrifugal, Euler
    steady: bool  # every node of the schedule has the same value w
    w: float  # that rate (rad/s)


@_jit
def _unpack(P, wt, wv):
    """The :class:`_Model` of the parameter vector ``P`` and the schedule ``(wt, wv)``."""
    gmode = P[I_GMODE]
    g = (P[I_G], P[I_G + 1], P[I_G + 2]) if gmode == 0.0 else (0.0, 0.0, 0.0)
    axis = (P[I_AXIS], P[I_AXIS + 1], P[I_AXIS + 2])
    pivot = (P[I_PIVOT], P[I_PIVOT + 1], P[I_PIVOT + 2])
    centrifugal = P[I_CENTRIFUGAL] != 0.0
    euler = P[I_EULER] != 0.0
    k1 = P[I_KLIN]
    k2 = P[I_KQUAD]
    spring = P[I_SPRING]
    uniform = gmode != 1.0 and gmode != 2.0 and spring == 0.0 and not centrifugal and not euler
    steady = True
    for k in range(1, wv.shape[0]):
        if wv[k] != wv[0]:
            steady = False
    return _Model(g, axis, P[I_CORIOLIS] != 0.0, centrifugal, euler, k1, k2, k1 != 0.0 or k2 != 0.0, gmode,
                  P[I_GM], P[I_R], P[I_G0], spring, P[I_SCALE_H], P[I_PLEN], pivot, uniform, steady, wv[0])


# A compiled function that passes an array on to another one that is not inlined
# increfs and decrefs it at every call (atomic operations, tens of ns in all). So what
# runs for every sub-step or stage passes no array on: the step kernels take none (the
# state is a tuple, the model a _Model), the schedule readers below only read theirs,
# and the functions that pass arrays on (_plan, _dop853_step, the drivers) run at most
# once per step.


@_jit
def _rates(t, steady, w, wt, wv):
    """Rotation rate w(t) and its derivative (rad/s, rad/s^2): ``(w, 0)`` when ``steady``, else from the table."""
    if steady:
        return w, 0.0
    return omega_magnitude(t, wt, wv), omega_rate(t, wt, wv)


@_jit
def _stage(t, wt, wv):
    """Rotation data of a Runge-Kutta stage at time t, laid out as :func:`_sub`: ``(w, w', 0, 1, 0)``."""
    return omega_magnitude(t, wt, wv), omega_rate(t, wt, wv), 0.0, 1.0, 0.0


@_jit
def _lookup(t, h, wt, wv, wint):
    """The schedule over [t, t + h]: w and w' at t + h/2, and the angle turned (the integral of w)."""
    tm = t + 0.5 * h
    return (omega_magnitude(tm, wt, wv), omega_rate(tm, wt, wv),
            omega_angle(t + h, wt, wv, wint) - omega_angle(t, wt, wv, wint))


@_jit
def _sub(looked_up, m):
    """Rotation data ``(w, w', turn, cos, sin)`` of a splitting sub-step from its :func:`_lookup`.

    ``cos`` and ``sin`` are those of the Coriolis rotation angle ``-2 turn`` of
    a free particle (1 and 0 when there is none).
    """
    w, wd, turn = looked_up
    c = 1.0
    s = 0.0
    if m.coriolis and not m.length > 0.0:
        angle = -2.0 * turn
        c = np.cos(angle)
        s = np.sin(angle)
    return w, wd, turn, c, s


@_jit
def _plan(method, t, h, m, wt, wv, wint):
    """The rotation data a step [t, t + h] of ``method`` needs: three tuples laid out as :func:`_sub`.

    Splitting: the step (three times); splitting4: its three sub-steps; rk4:
    the rates at t, t + h/2 and t + h (turn 0, cos 1, sin 0). At a steady
    rate the plan does not depend on t (the angle turned over a sub-step h' is
    w h'), so it is made once per step size and its sines and cosines are reused.
    """
    if m.steady:
        return _steady_plan(method, h, m)
    if method == 1:
        h1, h0 = _sub_steps(1, h)[1][:2]
        return (_sub(_lookup(t, h1, wt, wv, wint), m), _sub(_lookup(t + h1, h0, wt, wv, wint), m),
                _sub(_lookup(t + h1 + h0, h1, wt, wv, wint), m))
    if method == 2:
        return _stage(t, wt, wv), _stage(t + 0.5 * h, wt, wv), _stage(t + h, wt, wv)
    sub = _sub(_lookup(t, h, wt, wv, wint), m)
    return sub, sub, sub


@_jit
def _steady_plan(method, h, m):
    """:func:`_plan` at the steady rate ``m.w``."""
    if method == 1:
        h1, h0 = _sub_steps(1, h)[1][:2]
        outer = _sub((m.w, 0.0, m.w * h1), m)
        return outer, _sub((m.w, 0.0, m.w * h0), m), outer
    if method == 2:
        rates = (m.w, 0.0, 0.0, 1.0, 0.0)
        return rates, rates, rates
    sub = _sub((m.w, 0.0, m.w * h), m)
    return sub, sub, sub


# ---------------------------------------------------------------------------
# accelerations
# ---------------------------------------------------------------------------


@_jit
def _position_acceleration(x, y, z, m, w, wd):
    """Forces that depend on position and time only: gravity, spring, centrifugal, Euler.

    ``w`` and ``wd`` are the rotation rate and its derivative at the time of evaluation.
    """
    mode = m.gmode
    if mode == 1.0:
        R = m.radius
        s = R / (R + z)
        ax = 0.0
        ay = 0.0
        az = -m.g0 * s * s
    elif mode == 2.0:
        dz = z + m.radius
        d2 = x * x + y * y + dz * dz
        f = -m.gm / (d2 * np.sqrt(d2))
        ax = f * x
        ay = f * y
        az = f * dz
    else:
        ax, ay, az = m.g
    k = m.spring
    if k != 0.0:
        ax -= k * x
        ay -= k * y
    ux, uy, uz = m.axis
    if m.centrifugal:
        # -w x (w x r) = w^2 (r - (w_hat . r) w_hat)
        d = ux * x + uy * y + uz * z
        w2 = w * w
        ax += w2 * (x - d * ux)
        ay += w2 * (y - d * uy)
        az += w2 * (z - d * uz)
    if m.euler:
        # -w' x r with w' = w'(t) w_hat (fixed axis)
        ax -= wd * (uy * z - uz * y)
        ay -= wd * (uz * x - ux * z)
        az -= wd * (ux * y - uy * x)
    return ax, ay, az


@_jit
def _acceleration(state, m, w, wd):
    """Total acceleration in the rotating frame at ``state``; see :func:`acceleration`."""
    x, y, z, vx, vy, vz = state
    ax, ay, az = _position_acceleration(x, y, z, m, w, wd)
    if m.coriolis:
        w2 = 2.0 * w
        ux = m.axis[0] * w2
        uy = m.axis[1] * w2
        uz = m.axis[2] * w2
        ax -= uy * vz - uz * vy
        ay -= uz * vx - ux * vz
        az -= ux * vy - uy * vx
    if m.drag:
        air = _air(z, m)
        k1 = m.k1 * air
        k2 = m.k2 * air
        speed = np.sqrt(vx * vx + vy * vy + vz * vz)
        k = k1 + k2 * speed
        ax -= k * vx
        ay -= k * vy
        az -= k * vz
    L = m.length
    if L > 0.0:
        nx = (x - m.pivot[0]) / L
        ny = (y - m.pivot[1]) / L
        nz = (z - m.pivot[2]) / L
        an = ax * nx + ay * ny + az * nz
        vn = vx * nx + vy * ny + vz * nz
        v2t = vx * vx + vy * vy + vz * vz - vn * vn
        c = an + v2t / L
        ax -= c * nx
        ay -= c * ny
        az -= c * nz
    return ax, ay, az


@_jit
def acceleration(r, v, t, P, wt, wv, out):
    """Total acceleration in the rotating frame (for Runge-Kutta methods), into ``out``.

    For a pendulum (``P[14] > 0``) the string constraint is kept by the
    index-1 form: the normal component of the applied acceleration is removed
    and the centripetal term ``-|v_t|^2 / L n`` added.
    """
    m = _unpack(P, wt, wv)
    w, wd = _rates(t, m.steady, m.w, wt, wv)
    out[0], out[1], out[2] = _acceleration((r[0], r[1], r[2], v[0], v[1], v[2]), m, w, wd)


# ---------------------------------------------------------------------------
# small vector helpers
# ---------------------------------------------------------------------------


@_jit
def _rotate(vx, vy, vz, ax, ay, az, c, s):
    """v rotated about the unit axis (ax, ay, az) by the angle with cos c, sin s."""
    d = ax * vx + ay * vy + az * vz
    cx = ay * vz - az * vy
    cy = az * vx - ax * vz
    cz = ax * vy - ay * vx
    one_c = 1.0 - c
    return (vx * c + cx * s + ax * d * one_c, vy * c + cy * s + ay * d * one_c,
            vz * c + cz * s + az * d * one_c)


@_jit
def _air(z, m):
    """Relative air density exp(-z / H) at height z, or 1 for uniform air (H = 0)."""
    H = m.scale_h
    if H > 0.0:
        return np.exp(-z / H)
    return 1.0


@_jit
def _drag_flow(vx, vy, vz, k1, k2, h):
    """Exact flow of v' = -(k1 + k2 |v|) v over h at fixed position (direction kept, speed decays)."""
    if k1 == 0.0 and k2 == 0.0:
        return vx, vy, vz
    speed = np.sqrt(vx * vx + vy * vy + vz * vz)
    if speed == 0.0:
        return vx, vy, vz
    if k1 == 0.0:
        new = speed / (1.0 + k2 * speed * h)
    else:
        e = np.exp(-k1 * h)
        new = k1 * speed * e / (k1 + k2 * speed * (1.0 - e))
    f = new / speed
    return vx * f, vy * f, vz * f


# ---------------------------------------------------------------------------
# the methods, on the state tuple (x, y, z, vx, vy, vz); each kernel advances
# n steps of size h that share one plan (see _plan)
# ---------------------------------------------------------------------------


@_jit
def _sub_steps(method, h):
    """Number and lengths of the splitting sub-steps of a step h: one of h, or Yoshida's h1, h0, h1."""
    if method == 1:
        h1 = YOSHIDA4_OUTER * h
        return 3, (h1, YOSHIDA4_INNER * h, h1)
    return 1, (h, h, h)


@_jit
def _free_steps(state, n, method, h, m, plan):
    """Exact-rotation splitting of a free particle; see :func:`step_splitting`.

    Per sub-step: drift r += v h/2; kick v += a_pos(r) h/2 and exact drag;
    rotate v about w_hat by -2 turn (cos and sin from the plan); drag and kick
    again; drift h/2. With nothing but scalars in the loop, this is the
    throughput path of the ensemble driver.
    """
    x, y, z, vx, vy, vz = state
    ux, uy, uz = m.axis
    n_sub, lengths = _sub_steps(method, h)
    for _ in range(n):
        for i in range(n_sub):
            hh = 0.5 * lengths[i]
            w, wd, turn, c, s = plan[i]
            x += hh * vx
            y += hh * vy
            z += hh * vz
            if m.uniform:
                ax, ay, az = m.g
            else:
                ax, ay, az = _position_acceleration(x, y, z, m, w, wd)
            vx += hh * ax
            vy += hh * ay
            vz += hh * az
            k1 = 0.0
            k2 = 0.0
            if m.drag:
                air = _air(z, m)
                k1 = m.k1 * air
                k2 = m.k2 * air
                vx, vy, vz = _drag_flow(vx, vy, vz, k1, k2, hh)
            if m.coriolis:
                vx, vy, vz = _rotate(vx, vy, vz, ux, uy, uz, c, s)
            if m.drag:
                vx, vy, vz = _drag_flow(vx, vy, vz, k1, k2, hh)
            vx += hh * ax
            vy += hh * ay
            vz += hh * az
            x += hh * vx
            y += hh * vy
            z += hh * vz
    return x, y, z, vx, vy, vz


@_jit
def _sphere_steps(state, n, method, h, m, plan):
    """Splitting on the sphere |r - pivot| = L; see :func:`step_sphere`."""
    n_sub, lengths = _sub_steps(method, h)
    for _ in range(n):
        for i in range(n_sub):
            state = _sphere_step(state, lengths[i], m, plan[i])
    return state


@_jit
def _sphere_step(state, h, m, sub):
    """One sub-step of :func:`_sphere_steps` with the rotation data ``sub``."""
    x, y, z, vx, vy, vz = state
    L = m.length
    hh = 0.5 * h
    x, y, z, vx, vy, vz = _great_circle(x, y, z, vx, vy, vz, hh, m)
    ax, ay, az = _position_acceleration(x, y, z, m, sub[0], sub[1])
    nx = (x - m.pivot[0]) / L
    ny = (y - m.pivot[1]) / L
    nz = (z - m.pivot[2]) / L
    an = ax * nx + ay * ny + az * nz
    ax -= an * nx
    ay -= an * ny
    az -= an * nz
    vx += hh * ax
    vy += hh * ay
    vz += hh * az
    k1 = 0.0
    k2 = 0.0
    if m.drag:
        air = _air(z, m)
        k1 = m.k1 * air
        k2 = m.k2 * air
        vx, vy, vz = _drag_flow(vx, vy, vz, k1, k2, hh)
    if m.coriolis:
        wn = m.axis[0] * nx + m.axis[1] * ny + m.axis[2] * nz
        angle = -2.0 * wn * sub[2]
        vx, vy, vz = _rotate(vx, vy, vz, nx, ny, nz, np.cos(angle), np.sin(angle))
    if m.drag:
        vx, vy, vz = _drag_flow(vx, vy, vz, k1, k2, hh)
    vx += hh * ax
    vy += hh * ay
    vz += hh * az
    return _great_circle(x, y, z, vx, vy, vz, hh, m)


@_jit
def _great_circle(x, y, z, vx, vy, vz, tau, m):
    """Exact geodesic flow on the sphere of radius L about the pivot, for time tau."""
    L = m.length
    px, py, pz = m.pivot
    nx = (x - px) / L
    ny = (y - py) / L
    nz = (z - pz) / L
    vn = vx * nx + vy * ny + vz * nz
    vx = vx - vn * nx
    vy = vy - vn * ny
    vz = vz - vn * nz
    speed = np.sqrt(vx * vx + vy * vy + vz * vz)
    if speed > 0.0:
        ux = vx / speed
        uy = vy / speed
        uz = vz / speed
        phi = speed * tau / L
        c = np.cos(phi)
        s = np.sin(phi)
        mx = nx * c + ux * s
        my = ny * c + uy * s
        mz = nz * c + uz * s
        vx = speed * (ux * c - nx * s)
        vy = speed * (uy * c - ny * s)
        vz = speed * (uz * c - nz * s)
        nx, ny, nz = mx, my, mz
    norm = np.sqrt(nx * nx + ny * ny + nz * nz)
    nx /= norm
    ny /= norm
    nz /= norm
    vn = vx * nx + vy * ny + vz * nz
    return px + L * nx, py + L * ny, pz + L * nz, vx - vn * nx, vy - vn * ny, vz - vn * nz


@_jit
def _rk4_steps(state, n, h, m, plan):
    """Classical Runge-Kutta, the rates at t, t + h/2 and t + h from the plan; see :func:`step_rk4`."""
    x, y, z, vx, vy, vz = state
    hh = 0.5 * h
    h6 = h / 6.0
    w1, wd1 = plan[0][0], plan[0][1]
    w2, wd2 = plan[1][0], plan[1][1]
    w4, wd4 = plan[2][0], plan[2][1]
    for _ in range(n):
        a1x, a1y, a1z = _acceleration((x, y, z, vx, vy, vz), m, w1, wd1)
        x2 = x + hh * vx
        y2 = y + hh * vy
        z2 = z + hh * vz
        v2x = vx + hh * a1x
        v2y = vy + hh * a1y
        v2z = vz + hh * a1z
        a2x, a2y, a2z = _acceleration((x2, y2, z2, v2x, v2y, v2z), m, w2, wd2)
        x3 = x + hh * v2x
        y3 = y + hh * v2y
        z3 = z + hh * v2z
        v3x = vx + hh * a2x
        v3y = vy + hh * a2y
        v3z = vz + hh * a2z
        a3x, a3y, a3z = _acceleration((x3, y3, z3, v3x, v3y, v3z), m, w2, wd2)
        x4 = x + h * v3x
        y4 = y + h * v3y
        z4 = z + h * v3z
        v4x = vx + h * a3x
        v4y = vy + h * a3y
        v4z = vz + h * a3z
        a4x, a4y, a4z = _acceleration((x4, y4, z4, v4x, v4y, v4z), m, w4, wd4)
        x, y, z, vx, vy, vz = (x + h6 * (vx + 2.0 * v2x + 2.0 * v3x + v4x),
                               y + h6 * (vy + 2.0 * v2y + 2.0 * v3y + v4y),
                               z + h6 * (vz + 2.0 * v2z + 2.0 * v3z + v4z),
                               vx + h6 * (a1x + 2.0 * a2x + 2.0 * a3x + a4x),
                               vy + h6 * (a1y + 2.0 * a2y + 2.0 * a3y + a4y),
                               vz + h6 * (a1z + 2.0 * a2z + 2.0 * a3z + a4z))
    return x, y, z, vx, vy, vz


@_jit
def _steps(method, state, n, h, m, plan):
    """``n`` steps of size h of method 0 splitting, 1 splitting4 or 2 rk4, all with the same ``plan``.

    One step for a varying rate (the plan is the step's own); any number at a
    steady rate, where every step has the same plan.
    """
    if method == 2:
        return _rk4_steps(state, n, h, m, plan)
    if m.length > 0.0:
        return _sphere_steps(state, n, method, h, m, plan)
    return _free_steps(state, n, method, h, m, plan)


@_jit
def _advance(method, state, t0, k0, n, h, m, wt, wv, wint, plan):
    """Steps k0 .. k0 + n - 1 of size h from t0 (step k starts at t0 + k h).

    ``plan`` is the :func:`_plan` of every step when the rate is steady; a
    varying schedule is sampled here, once per step, so that the step
    kernels take no array.
    """
    if m.steady:
        return _steps(method, state, n, h, m, plan)
    for k in range(k0, k0 + n):
        state = _steps(method, state, 1, h, m, _plan(method, t0 + k * h, h, m, wt, wv, wint))
    return state


@_jit
def _step_in_place(method, r, v, t, h, P, wt, wv, wint):
    """One step [t, t + h] on the state arrays r, v (updated in place); returns the force evaluations."""
    m = _unpack(P, wt, wv)
    state = _steps(method, (r[0], r[1], r[2], v[0], v[1], v[2]), 1, h, m, _plan(method, t, h, m, wt, wv, wint))
    r[0], r[1], r[2], v[0], v[1], v[2] = state
    return _NFEV[method]


@_jit
def step_splitting(r, v, t, h, P, wt, wv, wint, a):
    """Exact-rotation splitting, order 2 (drift, kick, rotate, kick, drift).

    Strang composition of exact sub-flows (docs/physics/splitting.md): drift
    r += v h/2; kick v += a_pos(r, t + h/2) h/2 and exact drag; rotate v about
    w_hat by -2 * integral of w over the step (the exact Coriolis flow, no
    tan() as in Boris); drag and kick again; drift h/2. Explicit, symmetric
    (time-reversible), volume-preserving; one force evaluation per step.
    For a pendulum the constrained version :func:`step_sphere` is used.

    ``r`` and ``v`` (3,) are updated in place; ``a`` (3,) is unused (the
    kernels keep their scratch in registers). Returns the force evaluations.
    """
    return _step_in_place(0, r, v, t, h, P, wt, wv, wint)


@_jit
def step_sphere(r, v, t, h, P, wt, wv, wint, a):
    """Splitting on the sphere |r - pivot| = L (spherical pendulum), order 2.

    Sub-flows, each exact on the constraint manifold T S^2:
    A: free motion on the sphere (a great circle at constant speed);
    B: applied forces at fixed r, projected on the tangent plane (the string
       takes the normal part); drag exact;
    C: Coriolis at fixed r: its tangential part rotates v about the normal n by
       -2 (w . n) times the elapsed angle (the normal part is taken by the string).
    Composition A(h/2) B(h/2) C(h) B(h/2) A(h/2): symmetric, second order, the
    constraint kept to round-off (n is renormalised after every great-circle move).
    Arguments and result as :func:`step_splitting`.
    """
    m = _unpack(P, wt, wv)
    state = _sphere_step((r[0], r[1], r[2], v[0], v[1], v[2]), h, m, _plan(0, t, h, m, wt, wv, wint)[0])
    r[0], r[1], r[2], v[0], v[1], v[2] = state
    return 1


@_jit
def step_splitting4(r, v, t, h, P, wt, wv, wint, a):
    """Fourth-order symmetric composition (Yoshida 1990) of :func:`step_splitting`."""
    return _step_in_place(1, r, v, t, h, P, wt, wv, wint)


@_jit
def step_rk4(r, v, t, h, P, wt, wv, wint, a):
    """Classical Runge-Kutta, order 4, four force evaluations; conserves nothing exactly."""
    return _step_in_place(2, r, v, t, h, P, wt, wv, wint)


@_jit
def select_step(method, r, v, t, h, P, wt, wv, wint, a):
    """Dispatch on the method code: 0 splitting, 1 splitting4, 2 rk4."""
    return _step_in_place(method, r, v, t, h, P, wt, wv, wint)


# ---------------------------------------------------------------------------
# events
# ---------------------------------------------------------------------------


@_jit
def _event_value(events, e, state, radius):
    """Event function of row ``e`` of the event table at ``state``."""
    kind = events[e, 0]
    c = int(events[e, 1])
    if kind == 0.0:
        return state[c] - events[e, 2]
    if kind == 1.0:
        return state[3 + c] - events[e, 2]
    x, y, z = state[0], state[1], state[2]
    dz = z + radius
    return np.sqrt(x * x + y * y + dz * dz) - radius - events[e, 2]


@_jit
def _start_value(events, e, state, m, w, wd):
    """Event function of row ``e`` at the start of a run or chunk, for crossing detection.

    The rule for a function that is exactly zero at the start (a shell fired
    from the ground, z = 0): it takes the sign it has just after the start,
    the sign of its first non-zero time derivative (first or second); the
    start itself is never an event. A shell fired upward from z = 0 thus
    lands at its first return to z = 0, however soon (even inside the first
    step), and a ``direction = -1`` ground event is not triggered by the
    launch. Only the sign of the returned value is meaningful when ``g = 0``
    (see docs/physics/events.md).
    """
    g = _event_value(events, e, state, m.radius)
    if g != 0.0:
        return g
    kind = events[e, 0]
    c = int(events[e, 1])
    x, y, z, vx, vy, vz = state
    a = _acceleration(state, m, w, wd)
    if kind == 0.0:
        d1 = state[3 + c]
        d2 = a[c]
    elif kind == 1.0:
        d1 = a[c]
        d2 = 0.0
    else:
        dx, dy, dz = x, y, z + m.radius
        n = np.sqrt(dx * dx + dy * dy + dz * dz)
        dv = dx * vx + dy * vy + dz * vz
        da = dx * a[0] + dy * a[1] + dz * a[2]
        d1 = dv / n
        d2 = (vx * vx + vy * vy + vz * vz + da) / n - dv * dv / (n * n * n)
    if d1 != 0.0:
        return 1e-300 if d1 > 0.0 else -1e-300
    if d2 != 0.0:
        return 1e-300 if d2 > 0.0 else -1e-300
    return 0.0


@_jit
def _crossed(direction, g0, g1):
    """Whether the event function went from g0 to g1 across zero in the given direction."""
    if direction > 0.0:
        return g0 < 0.0 and g1 >= 0.0
    if direction < 0.0:
        return g0 > 0.0 and g1 <= 0.0
    return (g0 < 0.0 and g1 >= 0.0) or (g0 > 0.0 and g1 <= 0.0)


@_jit
def _is_finite(state):
    """Whether every component of the state tuple is finite."""
    for q in state:
        if not np.isfinite(q):
            return False
    return True


# ---------------------------------------------------------------------------
# fixed-step driver
# ---------------------------------------------------------------------------


@_jit
def run_fixed(method, r, v, alive, t0, h, steps_per_sample, n_samples, P, wt, wv, wint,
              events, out_r, out_v, ev_t, ev_r, ev_v, ev_count, ev_which, max_events):
    """Advance an ensemble with a fixed-step method and store samples.

    Parameters
    ----------
    method : int
        0 splitting, 1 splitting4, 2 rk4.
    r, v : (N, 3) arrays
        State at ``t0`` (rotating frame, m and m/s); updated in place.
    alive : (N,) bool array
        Particles still moving; a terminal event clears the flag (in place).
    h : float
        Step (s). Samples are stored every ``steps_per_sample`` steps.
    events : (E, 5) array
        Event table (see module docstring). Crossings are located by
        re-stepping from the last state before the crossing with a shorter step
        (bisection to round-off), so an event time is exact for the method's own
        discrete trajectory.
    out_r, out_v : (n_samples, N, 3) arrays
        Filled with the state after each sample interval; a stopped particle
        keeps its state at the terminal event.
    ev_t, ev_r, ev_v, ev_count, ev_which : event records per particle (time, state, event index).

    Returns
    -------
    n_done : int
        Samples completed (``n_samples`` unless a state became non-finite).
    bad : int
        Index of the first particle with a non-finite state, or -1.
    nfev : int
        Force evaluations of particle 0 (the cost of one trajectory).
    """
    m = _unpack(P, wt, wv)
    plan = _plan(method, t0, h, m, wt, wv, wint)
    nfev_step = _NFEV[method]
    n = r.shape[0]
    n_ev = events.shape[0]
    g_old = np.empty(n_ev)
    nfev0 = 0
    n_done = n_samples
    bad = -1
    for p in range(n):
        state = (r[p, 0], r[p, 1], r[p, 2], v[p, 0], v[p, 1], v[p, 2])
        is_alive = alive[p]
        k_step = 0
        if n_ev > 0:
            w0, wd0 = _rates(t0, m.steady, m.w, wt, wv)
            for e in range(n_ev):
                g_old[e] = _start_value(events, e, state, m, w0, wd0)
        for s in range(n_samples):
            if is_alive:
                if n_ev == 0:
                    # no event to watch: the whole sample interval in one call
                    state = _advance(method, state, t0, k_step, steps_per_sample, h, m, wt, wv, wint, plan)
                    k_step += steps_per_sample
                    if p == 0:
                        nfev0 += nfev_step * steps_per_sample
                else:
                    for _ in range(steps_per_sample):
                        t = t0 + k_step * h
                        start = state
                        step_plan = plan if m.steady else _plan(method, t, h, m, wt, wv, wint)
                        state = _steps(method, state, 1, h, m, step_plan)
                        if p == 0:
                            nfev0 += nfev_step
                        k_step += 1
                        stop = False
                        for e in range(n_ev):
                            g_new = _event_value(events, e, state, m.radius)
                            if _crossed(events[e, 3], g_old[e], g_new):
                                tau, hit = _locate(method, events, e, start, g_old[e], t, h, m, wt, wv, wint)
                                k = ev_count[p]
                                if k < max_events:
                                    ev_t[p, k] = t + tau
                                    for i in range(3):
                                        ev_r[p, k, i] = hit[i]
                                        ev_v[p, k, i] = hit[3 + i]
                                    ev_which[p, k] = e
                                ev_count[p] = k + 1
                                if events[e, 4] != 0.0:
                                    stop = True
                                    state = hit
                            g_old[e] = g_new
                        if stop:
                            is_alive = False
                            break
                if not _is_finite(state):
                    if s < n_done:
                        n_done = s
                    if bad < 0:
                        bad = p
                    break
            for i in range(3):
                out_r[s, p, i] = state[i]
                out_v[s, p, i] = state[3 + i]
        for i in range(3):
            r[p, i] = state[i]
            v[p, i] = state[3 + i]
        alive[p] = is_alive
    return n_done, bad, nfev0


@_jit
def _locate(method, events, e, start, g_start, t, h, m, wt, wv, wint):
    """Sub-step tau in (0, h] at which the event function of the one-step map vanishes.

    Bisection on tau of g(step(start, tau)), halving until the bracket cannot
    shrink (round-off of tau itself, even for a crossing at tau ~ 1e-161 s, which
    a fixed 60 halvings of h would miss by 1e140). ``g_start`` is the event function at ``start`` as used for
    the crossing test (its sign just after the start when it is zero there,
    :func:`_start_value`). Returns tau and the state at the event.
    """
    lo = 0.0
    hi = h
    g_lo = g_start
    for _ in range(2200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        trial = _steps(method, start, 1, mid, m, _plan(method, t, mid, m, wt, wv, wint))
        g_mid = _event_value(events, e, trial, m.radius)
        if (g_lo < 0.0) == (g_mid < 0.0) and g_mid != 0.0:
            lo = mid
            g_lo = g_mid
        else:
            hi = mid
    return hi, _steps(method, start, 1, hi, m, _plan(method, t, hi, m, wt, wv, wint))


# ---------------------------------------------------------------------------
# adaptive Dormand-Prince 8(5,3)
# ---------------------------------------------------------------------------


@_jit
def _as_state(y):
    """The state vector y (6,) as a tuple."""
    return y[0], y[1], y[2], y[3], y[4], y[5]


@_jit
def _deriv(state, m, w, wd):
    """Right-hand side (v, a) of the first-order system at ``state`` for the rates w, w', as a 6-tuple."""
    ax, ay, az = _acceleration(state, m, w, wd)
    return state[3], state[4], state[5], ax, ay, az


@_jit
def _dop853_step(t, y, f0, h, m, wt, wv, A, B, C, K, y_new, tmp):
    """One DOP853 step from (t, y) with f0 = f(t, y) (a 6-tuple); K (13, 6) receives the stages, tmp (6,) is scratch."""
    K[0, 0], K[0, 1], K[0, 2], K[0, 3], K[0, 4], K[0, 5] = f0
    for s in range(1, 12):
        for j in range(6):
            acc = 0.0
            for q in range(s):
                acc += A[s, q] * K[q, j]
            tmp[j] = y[j] + h * acc
        w, wd = _rates(t + C[s] * h, m.steady, m.w, wt, wv)
        K[s, 0], K[s, 1], K[s, 2], K[s, 3], K[s, 4], K[s, 5] = _deriv(_as_state(tmp), m, w, wd)
    for j in range(6):
        acc = 0.0
        for q in range(12):
            acc += B[q] * K[q, j]
        y_new[j] = y[j] + h * acc
    w, wd = _rates(t + h, m.steady, m.w, wt, wv)
    K[12, 0], K[12, 1], K[12, 2], K[12, 3], K[12, 4], K[12, 5] = _deriv(_as_state(y_new), m, w, wd)


@_jit
def _store(out_r, out_v, k, p, y):
    """Write the state vector y (6,) into sample k of particle p."""
    for i in range(3):
        out_r[k, p, i] = y[i]
        out_v[k, p, i] = y[3 + i]


@_jit
def run_dop853(r, v, alive, t0, sample_times, P, wt, wv, rtol, atol, h0, A, B, C, E3, E5,
               events, out_r, out_v, ev_t, ev_r, ev_v, ev_count, ev_which, max_events, h_state):
    """Adaptive Dormand-Prince 8(5,3) (Hairer, Norsett & Wanner, II.10) for an ensemble.

    Error control as in Hairer's DOP853 (5th- and 3rd-order estimates combined).
    Output at ``sample_times``: the state at a sample time inside an accepted
    step is computed by one extra DOP853 step of the right length from the
    step's start (an interpolant of the same order as the method). Events are
    located the same way, by bisection on the length of that extra step.
    ``h_state`` (N,) carries each particle's step size between calls.

    Returns (n_done, bad, nfev, steps) like :func:`run_fixed` (cost of particle 0).
    """
    m = _unpack(P, wt, wv)
    n = r.shape[0]
    n_out = sample_times.shape[0]
    n_ev = events.shape[0]
    K = np.empty((13, 6))
    atol_vec = np.full(6, atol)
    Kt = np.empty((13, 6))
    y = np.empty(6)
    y_new = np.empty(6)
    yt = np.empty(6)
    tmp = np.empty(6)
    g_old = np.empty(n_ev)
    nfev0 = 0
    steps0 = 0
    n_done = n_out
    bad = -1
    t_end = sample_times[n_out - 1]
    for p in range(n):
        for i in range(3):
            y[i] = r[p, i]
            y[3 + i] = v[p, i]
        t = t0
        h = h_state[p]
        if h <= 0.0:
            h = h0
        is_alive = alive[p]
        w, wd = _rates(t, m.steady, m.w, wt, wv)
        f0 = _deriv(_as_state(y), m, w, wd)
        nf = 1
        for e in range(n_ev):
            g_old[e] = _start_value(events, e, _as_state(y), m, w, wd)
        k_out = 0
        while k_out < n_out and sample_times[k_out] <= t:
            _store(out_r, out_v, k_out, p, y)
            k_out += 1
        failed = False
        while is_alive and t < t_end:
            # one accepted step
            accepted = False
            at_end = False
            truncated = False
            while not accepted:
                h_ctrl = h
                truncated = t + h > t_end
                if truncated:
                    h = t_end - t
                min_h = 10.0 * abs(np.nextafter(t, np.inf) - t)
                if h < min_h:
                    if t_end - t < min_h:
                        # the steps summed to within a few ulp of the end: it is reached (the state
                        # is off by |f| * 10 ulp(t), far below any tolerance); not a collapsed step
                        at_end = True
                        h = h_ctrl  # the next call starts from the controller's step, not from the ulps
                    else:
                        failed = True
                    break
                _dop853_step(t, y, f0, h, m, wt, wv, A, B, C, K, y_new, tmp)
                nf += 12
                err = dop853_error_norm(K, h, y, y_new, rtol, atol_vec, E3, E5)
                if not np.isfinite(err):
                    h *= 0.2
                    continue
                if err < 1.0:
                    fac = 10.0 if err == 0.0 else min(10.0, 0.9 * err ** (-1.0 / 8.0))
                    accepted = True
                else:
                    fac = max(0.2, 0.9 * err ** (-1.0 / 8.0))
                h_used = h
                h = h * fac
            if failed:
                break
            if at_end:
                t = t_end
                break
            # a step cut to land on t_end ends there exactly (t + (t_end - t) may round below it)
            t_new = t_end if truncated else t + h_used
            if p == 0:
                steps0 += 1
            # events inside (t, t_new]
            stop = False
            t_stop = t_new
            for e in range(n_ev):
                g_new = _event_value(events, e, _as_state(y_new), m.radius)
                if _crossed(events[e, 3], g_old[e], g_new):
                    lo = 0.0
                    hi = h_used
                    g_lo = g_old[e]
                    for _ in range(2200):
                        mid = 0.5 * (lo + hi)
                        if mid <= lo or mid >= hi:
                            break
                        _dop853_step(t, y, f0, mid, m, wt, wv, A, B, C, Kt, yt, tmp)
                        g_mid = _event_value(events, e, _as_state(yt), m.radius)
                        if (g_lo < 0.0) == (g_mid < 0.0) and g_mid != 0.0:
                            lo = mid
                            g_lo = g_mid
                        else:
                            hi = mid
                    _dop853_step(t, y, f0, hi, m, wt, wv, A, B, C, Kt, yt, tmp)
                    k = ev_count[p]
                    if k < max_events:
                        ev_t[p, k] = t + hi
                        for i in range(3):
                            ev_r[p, k, i] = yt[i]
                            ev_v[p, k, i] = yt[3 + i]
                        ev_which[p, k] = e
                    ev_count[p] = k + 1
                    if events[e, 4] != 0.0 and t + hi <= t_stop:
                        stop = True
                        t_stop = t + hi
                g_old[e] = g_new
            # samples inside (t, t_stop]
            while k_out < n_out and sample_times[k_out] <= t_stop:
                ts = sample_times[k_out]
                if ts == t_new:
                    _store(out_r, out_v, k_out, p, y_new)
                else:
                    _dop853_step(t, y, f0, ts - t, m, wt, wv, A, B, C, Kt, yt, tmp)
                    nf += 12
                    _store(out_r, out_v, k_out, p, yt)
                k_out += 1
            if stop:
                _dop853_step(t, y, f0, t_stop - t, m, wt, wv, A, B, C, Kt, yt, tmp)
                for j in range(6):
                    y[j] = yt[j]
                t = t_stop
                is_alive = False
                break
            for j in range(6):
                y[j] = y_new[j]
            f0 = _as_state(K[12])
            t = t_new
            if not _is_finite(_as_state(y)):
                failed = True
                break
        if failed:
            if bad < 0:
                bad = p
            if k_out < n_done:
                n_done = k_out
        # a stopped particle keeps its final state in the remaining samples
        while k_out < n_out:
            _store(out_r, out_v, k_out, p, y)
            k_out += 1
        for i in range(3):
            r[p, i] = y[i]
            v[p, i] = y[3 + i]
        alive[p] = is_alive
        h_state[p] = h
        if p == 0:
            nfev0 = nf
    return n_done, bad, nfev0, steps0
