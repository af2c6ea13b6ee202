"""The exact geodesic flow on a sphere: a particle held at a fixed distance from a pivot, free of other forces.

A pendulum's bob on a taut string of length ``L`` about a pivot moves, between kicks, along the
great circle through its position in the direction of its velocity, at constant speed. The flow
for a time ``tau`` turns the string's direction ``n = (r - pivot) / L`` towards the unit velocity
``u`` by the angle ``phi = |v| tau / L`` (docs/physics/splitting.md, the splitting on the sphere):

    n(tau) = n cos(phi) + u sin(phi),    v(tau) = |v| (u cos(phi) - n sin(phi)).

The scenes' pendulum splitting (`rotframe.particles.kernels`) and the engine of your own problems
(`rotframe.problem.models`) both call `great_circle`, inlined into them (numba IR): as a call of its
own it made the scenes' pendulum splitting 9 % slower, measured.
"""

from __future__ import annotations

import math

from rotframe.numerics.compiled import jit_inline

__all__ = ["great_circle", "kick_across"]


@jit_inline
def great_circle(x, y, z, vx, vy, vz, tau, px, py, pz, L):
    """The state after the geodesic flow for ``tau`` on the sphere of radius ``L`` about ``(px, py, pz)``.

    The velocity's component along the string is removed first (a state a round-off off the
    sphere's tangent plane is projected onto it), and the new position is put back on the sphere
    exactly (``n`` normalised). Returns ``(x, y, z, vx, vy, vz)``.
    """
    nx = (x - px) / L
    ny = (y - py) / L
    nz = (z - pz) / L
    vn = vx * nx + vy * ny + vz * nz
    vx = vx - vn * nx
    vy = vy - vn * ny
    vz = vz - vn * nz
    speed = math.sqrt(vx * vx + vy * vy + vz * vz)
    if speed > 0.0:
        ux = vx / speed
        uy = vy / speed
        uz = vz / speed
        phi = speed * tau / L
        c = math.cos(phi)
        s = math.sin(phi)
        mx = nx * c + ux * s
        my = ny * c + uy * s
        mz = nz * c + uz * s
        vx = speed * (ux * c - nx * s)
        vy = speed * (uy * c - ny * s)
        vz = speed * (uz * c - nz * s)
        nx, ny, nz = mx, my, mz
    norm = math.sqrt(nx * nx + ny * ny + nz * nz)
    nx /= norm
    ny /= norm
    nz /= norm
    vn = vx * nx + vy * ny + vz * nz
    return px + L * nx, py + L * ny, pz + L * nz, vx - vn * nx, vy - vn * ny, vz - vn * nz


@jit_inline
def kick_across(vx, vy, vz, ax, ay, az, nx, ny, nz, tau):
    """A kick for ``tau`` by the acceleration's part across the string (its part along ``n`` is the tension's).

    Returns that part and the kicked velocity, ``(ax, ay, az, vx, vy, vz)``.
    """
    an = ax * nx + ay * ny + az * nz
    ax -= an * nx
    ay -= an * ny
    az -= an * nz
    return ax, ay, az, vx + tau * ax, vy + tau * ay, vz + tau * az
