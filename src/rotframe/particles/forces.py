"""Accelerations of a particle in a rotating frame, compiled (one source for every method).

Equation of motion (rotating frame, docs/physics/rotating-frames.md)::

    r'' = g(r) - 2 w(t) x v - w x (w x r) - w'(t) x r - k1 v - k2 |v| v  [+ tension]

with ``w(t) = w_hat * w(t)``, a fixed unit axis times a magnitude that is
piecewise linear in time (a constant is a one-node table). Each term is
switched by a flag in ``P``; a term that is off costs one branch. The arithmetic of each term is
`rotframe.particles.accelerations`' (written once, for the scenes and your own problems alike); here
it is summed over the packed model's terms. One exception, measured: the Coriolis term is written in
place (`state_acceleration`), the same arithmetic as `coriolis_about_axis`.

The step kernels (`rotframe.particles.kernels`), the DOP853 stages
(`rotframe.particles.dop853_particles`) and the event rules
(`rotframe.particles.events`) all evaluate forces here.
"""

from __future__ import annotations

import math

from numba import njit

from rotframe.particles.accelerations import (air_density, altitude_gravity, central_gravity, centrifugal, drag_rate,
                                              euler_about_axis, spring_pull, string_tension)
from rotframe.particles.packed import jit_internal, jit_kernel, unpack
from rotframe.particles.schedule import rates

__all__ = ["position_acceleration", "state_acceleration", "acceleration", "drag_coefficients", "drag_flow",
           "string_normal"]


def _forces_of_position(x, y, z, m):
    """The forces of position alone: gravity (uniform, with altitude or central) and the spring."""
    mode = m.gmode
    if mode == 1.0:
        ax = 0.0
        ay = 0.0
        az = altitude_gravity(z, m.g0, m.radius)
    elif mode == 2.0:
        ax, ay, az = central_gravity(x, y, z + m.radius, m.gm)  # Earth's centre at (0, 0, -R)
    else:
        ax, ay, az = m.g
    k = m.spring
    if k != 0.0:  # horizontal, anchored at the origin (the small-angle pendulum)
        sx, sy, _ = spring_pull(x, y, 0.0, k)
        ax += sx
        ay += sy
    return ax, ay, az


def _frame_terms_of_position(ax, ay, az, x, y, z, m, w, wd):
    """``(ax, ay, az)`` with the frame's terms of position added: centrifugal, then Euler."""
    ux, uy, uz = m.axis
    if m.centrifugal:
        # the vector form of any omega, the engine's (`rotframe.problem.models`): on a steady frame whose axis
        # times its rate is omega again, these drivers are the engine's to the bit (`rotframe.problem.steady`)
        cx, cy, cz = centrifugal(x, y, z, ux * w, uy * w, uz * w)
        ax += cx
        ay += cy
        az += cz
    if m.euler:
        ex, ey, ez = euler_about_axis(x, y, z, ux, uy, uz, wd)
        ax -= ex
        ay -= ey
        az -= ez
    return ax, ay, az


#: the two parts of `position_acceleration`, inlined into it and into `state_acceleration`
_forces_of = njit(inline="always", error_model="numpy", nogil=True)(_forces_of_position)
_frame_terms_of = njit(inline="always", error_model="numpy", nogil=True)(_frame_terms_of_position)


@jit_internal
def position_acceleration(x, y, z, m, w, wd):
    """Forces that depend on position and time only: gravity, spring, centrifugal, Euler (the splittings' kick).

    ``w`` and ``wd`` are the rotation rate and its derivative at the time of evaluation.
    """
    ax, ay, az = _forces_of(x, y, z, m)
    return _frame_terms_of(ax, ay, az, x, y, z, m, w, wd)


@jit_internal
def state_acceleration(state, m, w, wd):
    """Total acceleration in the rotating frame at ``state``; see `acceleration`.

    Summed in the order of the engine's right-hand side (`rotframe.problem.models`): the forces (gravity, the
    spring, drag), then the frame's terms (Coriolis, centrifugal, Euler), then the string's tension. So on a steady
    problem of gravity and the frame's terms RK4 on these drivers is the engine's RK4 to the bit
    (`rotframe.problem.steady`)."""
    x, y, z, vx, vy, vz = state
    ax, ay, az = _forces_of(x, y, z, m)
    if m.drag:
        k1, k2 = drag_coefficients(z, m)
        k = drag_rate(vx, vy, vz, k1, k2)
        ax -= k * vx
        ay -= k * vy
        az -= k * vz
    if m.coriolis:
        # -2 w x v written in place, the arithmetic of accelerations.coriolis_about_axis: called (inlined), it made
        # the RK4 ensemble with the ground event 7 to 9 % slower (3 interleaved runs a tree, 2026-11-29)
        w2 = 2.0 * w
        ux = m.axis[0] * w2
        uy = m.axis[1] * w2
        uz = m.axis[2] * w2
        ax -= uy * vz - uz * vy
        ay -= uz * vx - ux * vz
        az -= ux * vy - uy * vx
    ax, ay, az = _frame_terms_of(ax, ay, az, x, y, z, m, w, wd)
    L = m.length
    if L > 0.0:
        ax, ay, az = string_tension(ax, ay, az, x, y, z, vx, vy, vz, m.pivot[0], m.pivot[1], m.pivot[2], L)
    return ax, ay, az


@jit_kernel
def acceleration(r, v, t, P, wt, wv, out):
    """Total acceleration in the rotating frame (for Runge-Kutta methods), into ``out``.

    For a pendulum (``P[14] > 0``) the string constraint is kept by the
    index-1 form: the normal component of the applied acceleration is removed
    and the centripetal term ``-|v_t|^2 / L n`` added.
    """
    m = unpack(P, wt, wv)
    w, wd = rates(t, m.steady, m.w, wt, wv)
    out[0], out[1], out[2] = state_acceleration((r[0], r[1], r[2], v[0], v[1], v[2]), m, w, wd)


@jit_internal
def drag_flow(vx, vy, vz, k1, k2, h):
    """Exact flow of v' = -(k1 + k2 |v|) v over h at fixed position (direction kept, speed decays)."""
    if k1 == 0.0 and k2 == 0.0:
        return vx, vy, vz
    speed = math.sqrt(vx * vx + vy * vy + vz * vz)
    if speed == 0.0:
        return vx, vy, vz
    if k1 == 0.0:
        new = speed / (1.0 + k2 * speed * h)
    else:
        e = math.exp(-k1 * h)
        new = k1 * speed * e / (k1 + k2 * speed * (1.0 - e))
    f = new / speed
    return vx * f, vy * f, vz * f


@jit_internal
def drag_coefficients(z, m):
    """Drag coefficients (k1 (1/s), k2 (1/m)) at height z: the sea-level ones times `air_density`."""
    air = air_density(z, m.scale_h)
    return m.k1 * air, m.k2 * air


@jit_internal
def string_normal(x, y, z, m):
    """Unit normal (r - pivot) / L of the pendulum's sphere at (x, y, z) (exact only on the sphere)."""
    L = m.length
    return (x - m.pivot[0]) / L, (y - m.pivot[1]) / L, (z - m.pivot[2]) / L
