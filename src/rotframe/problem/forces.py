"""The built-in forces as ordinary user forces: one way to add a force.

Each factory returns a `rotframe.problem.particles.Force` whose function is written
exactly as a user would write one (plain arithmetic on ``t, r, v``), with its potential where
it has one, so that ``rotframe.simulate(forces=[uniform_gravity(g), quadratic_drag(k)])``
composes them with the user's own forces and the frame's fictitious terms. The physics is
that of the scenes' model terms ([`rotframe.particles.model.ParticleModel`][rotframe.particles.model.ParticleModel]);
``tests/test_problem_forces.py`` checks each against the scenes' compiled kernels.

The constants are captured by the function (a closure), so numba compiles them in as
constants: a run with other constants compiles its own driver once (cached on disk like any
other). Pass values that change from run to run through ``params`` in a force of your own.

The frame's own terms (Coriolis, centrifugal, Euler, the origin's acceleration) are not
forces to add: ``rotframe.simulate`` adds them from ``omega`` and ``origin_acceleration``.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.errors import ScenarioError
from rotframe.problem.particles import Force

__all__ = ["uniform_gravity", "altitude_gravity", "central_gravity", "linear_drag", "quadratic_drag",
           "horizontal_spring", "lorentz"]


def _finite(name, *values):
    for v in values:
        arr = np.asarray(v, dtype=float)
        if not np.all(np.isfinite(arr)):
            raise ScenarioError(f"{name}: {np.asarray(v).tolist()} is not finite")


def uniform_gravity(g) -> Force:
    """a = g (m/s^2, frame axes); U = -g . r (the model term ``gravity``)."""
    _finite("uniform_gravity", g)
    gx, gy, gz = (float(c) for c in np.asarray(g, dtype=float).reshape(3))

    def gravity(t, r, v):
        return gx, gy, gz

    def potential(t, r):
        return -(gx * r[0] + gy * r[1] + gz * r[2])

    return Force(gravity, potential=potential, name="uniform gravity")


def altitude_gravity(g0, radius) -> Force:
    """a_z = -g0 (R / (R + z))^2 above a flat ground; U = -g0 R^2 / (R + z) (the term ``altitude-gravity``)."""
    _finite("altitude_gravity", g0, radius)
    g0, R = float(g0), float(radius)
    if not R > 0:
        raise ScenarioError(f"altitude_gravity: radius={R!r} must be > 0 (m)")

    def gravity(t, r, v):
        s = R / (R + r[2])
        return 0.0, 0.0, -g0 * s * s

    def potential(t, r):
        return -g0 * R * R / (R + r[2])

    return Force(gravity, potential=potential, name="gravity falling off with altitude")


def central_gravity(gm, centre) -> Force:
    """a = -GM (r - c) / |r - c|^3; U = -GM / |r - c| (the term ``central-gravity`` with c = (0, 0, -R))."""
    _finite("central_gravity", gm, centre)
    GM = float(gm)
    cx, cy, cz = (float(c) for c in np.asarray(centre, dtype=float).reshape(3))

    def gravity(t, r, v):
        dx = r[0] - cx
        dy = r[1] - cy
        dz = r[2] - cz
        d2 = dx * dx + dy * dy + dz * dz
        f = -GM / (d2 * math.sqrt(d2))
        return f * dx, f * dy, f * dz

    def potential(t, r):
        dx = r[0] - cx
        dy = r[1] - cy
        dz = r[2] - cz
        return -GM / math.sqrt(dx * dx + dy * dy + dz * dz)

    return Force(gravity, potential=potential, name="central gravity")


def linear_drag(k, scale_height=0.0) -> Force:
    """a = -k rho(z) v (1/s), rho = exp(-z / H) (1 for H = 0) (the term ``linear-drag``)."""
    _finite("linear_drag", k, scale_height)
    k, H = float(k), float(scale_height)

    def drag(t, r, v):
        c = k * math.exp(-r[2] / H) if H > 0.0 else k
        return -c * v[0], -c * v[1], -c * v[2]

    return Force(drag, name="linear drag")


def quadratic_drag(k, scale_height=0.0) -> Force:
    """a = -k rho(z) |v| v (1/m), rho = exp(-z / H) (1 for H = 0) (the term ``quadratic-drag``)."""
    _finite("quadratic_drag", k, scale_height)
    k, H = float(k), float(scale_height)

    def drag(t, r, v):
        c = k * math.exp(-r[2] / H) if H > 0.0 else k
        s = c * math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
        return -s * v[0], -s * v[1], -s * v[2]

    return Force(drag, name="quadratic drag")


def horizontal_spring(w0_squared) -> Force:
    """a = -w0^2 (x, y, 0); U = w0^2 (x^2 + y^2) / 2 (the term ``spring``, the small-angle pendulum)."""
    _finite("horizontal_spring", w0_squared)
    w2 = float(w0_squared)

    def spring(t, r, v):
        return -w2 * r[0], -w2 * r[1], 0.0

    def potential(t, r):
        return 0.5 * w2 * (r[0] * r[0] + r[1] * r[1])

    return Force(spring, potential=potential, name="horizontal spring")


def lorentz(q_over_m, B, E=(0.0, 0.0, 0.0)) -> Force:
    """a = (q/m) (E + v x B), uniform fields in the frame's axes (v relative to the frame: the fields of a
    co-rotating plasma, where the corotation electric field cancels omega x r)."""
    _finite("lorentz", q_over_m, B, E)
    qm = float(q_over_m)
    bx, by, bz = (float(c) for c in np.asarray(B, dtype=float).reshape(3))
    ex, ey, ez = (float(c) for c in np.asarray(E, dtype=float).reshape(3))

    def force(t, r, v):
        return (qm * (ex + v[1] * bz - v[2] * by), qm * (ey + v[2] * bx - v[0] * bz),
                qm * (ez + v[0] * by - v[1] * bx))

    return Force(force, name="Lorentz force")
