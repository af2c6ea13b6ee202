"""Hand-written loops that set the ceiling for ensemble throughput (``rotframe bench ensemble``).

The exact-rotation splitting for gravity + constant Coriolis (Strang: half
drift, half kick, exact rotation of the velocity by ``-2 |w| h`` about ``w``,
half kick, half drift), written out by hand with every particle's state in
registers: once on one core, once with ``prange`` over particles on all.
"""

from __future__ import annotations

from numba import njit, prange


def _loop(r, v, g, axis, c, s, h, steps, p):
    ax, ay, az = axis[0], axis[1], axis[2]
    hh = 0.5 * h
    x, y, z = r[p, 0], r[p, 1], r[p, 2]
    vx, vy, vz = v[p, 0], v[p, 1], v[p, 2]
    for _ in range(steps):
        x += hh * vx
        y += hh * vy
        z += hh * vz
        vx += hh * g[0]
        vy += hh * g[1]
        vz += hh * g[2]
        d = ax * vx + ay * vy + az * vz
        cx = ay * vz - az * vy
        cy = az * vx - ax * vz
        cz = ax * vy - ay * vx
        vx, vy, vz = (vx * c + cx * s + ax * d * (1 - c), vy * c + cy * s + ay * d * (1 - c),
                      vz * c + cz * s + az * d * (1 - c))
        vx += hh * g[0]
        vy += hh * g[1]
        vz += hh * g[2]
        x += hh * vx
        y += hh * vy
        z += hh * vz
    r[p, 0], r[p, 1], r[p, 2] = x, y, z
    v[p, 0], v[p, 1], v[p, 2] = vx, vy, vz


_one = njit(cache=True, inline="always")(_loop)


@njit(cache=True)
def serial(r, v, g, axis, c, s, h, steps):
    """All particles on one core."""
    for p in range(r.shape[0]):
        _one(r, v, g, axis, c, s, h, steps, p)


@njit(cache=True, parallel=True)
def parallel(r, v, g, axis, c, s, h, steps):
    """Particles spread over numba's threads with ``prange``."""
    for p in prange(r.shape[0]):
        _one(r, v, g, axis, c, s, h, steps, p)
