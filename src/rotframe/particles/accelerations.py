"""The arithmetic of the built-in terms, written once: each a compiled function of scalars.

A term that the scenes and your own problems share has its acceleration computed here and nowhere
else (uniform gravity is a constant; the Lorentz force, which no scene uses, is `rotframe.forces`'
alone). Three kinds of caller inline these functions (numba IR,
`rotframe.numerics.compiled.jit_inline`: no call of their own on a hot path):

- the scenes' compiled forces (`rotframe.particles.forces`, on the packed model, and the steady
  DOP853 force `rotframe.particles.dop853_steady`; the general force keeps the Coriolis term in
  place, the same arithmetic as `coriolis_about_axis`: called, it measured slower on the ensembles'
  hot path);
- the built-in terms of your own problems (`rotframe.forces`), which are compiled with your forces
  into a problem's glue and run by the engine (`rotframe.problem.engine`), and their exact flows in
  the engine's splittings (`rotframe.problem.models`);
- their GPU versions, made from the same source (`rotframe.particles.gpu.device_function`).

Each function takes and returns floats, so a caller keeps its own layout of the data (the packed
model, the steady vector, a closure's constants). Conventions: SI units, per unit mass, the
rotating frame's axes; docs/physics/rotating-frames.md for the equation of motion. The frame's own
terms are here in two forms, each the fast one where it runs: about a fixed unit axis ``u`` with a
rate ``w`` (``*_about_axis``: the scenes' schedules, `rotframe.particles.model.OmegaSchedule`), and
for any vector omega, which may turn (`centrifugal`, `coriolis`, `euler`: the kick of the engine's splittings,
`rotframe.problem.models`, whose right-hand side writes the frame's terms in place, measured faster, and the
engine's steady loop, `rotframe.particles.dop853_steady`). The two give the same physics to round-off, not the
same bits.

Called from Python (a built-in term's ``accel``, plain-Python runs), numba compiles them on first use.
"""

from __future__ import annotations

import math

from rotframe.numerics.compiled import jit_inline

__all__ = ["altitude_gravity", "central_gravity", "spring_pull", "air_density", "drag_rate",
           "coriolis_about_axis", "euler_about_axis", "centrifugal", "coriolis", "euler", "string_tension"]


@jit_inline
def altitude_gravity(z, g0, R):
    """The vertical acceleration ``-g0 (R / (R + z))^2`` of gravity falling off with height ``z`` (m/s^2).

    ``g0`` the ground value (m/s^2), ``R`` the radius (m): the inverse-square law along the
    vertical of a flat ground (the scenes' term ``altitude-gravity``).
    """
    s = R / (R + z)
    return -g0 * s * s


@jit_inline
def central_gravity(dx, dy, dz, gm):
    """``-GM d / |d|^3`` (m/s^2): the pull of a point mass, ``d = r - centre`` (m), ``gm`` = GM (m^3/s^2)."""
    d2 = dx * dx + dy * dy + dz * dz
    f = -gm / (d2 * math.sqrt(d2))
    return f * dx, f * dy, f * dz


@jit_inline
def spring_pull(dx, dy, dz, k):
    """``-k d`` (m/s^2): a linear spring per unit mass, ``d = r - anchor`` (m), ``k`` over the mass (1/s^2)."""
    return -k * dx, -k * dy, -k * dz


@jit_inline
def air_density(z, H):
    """The relative air density ``exp(-z / H)`` at height ``z`` (m); 1 for uniform air (``H = 0``)."""
    if H > 0.0:
        return math.exp(-z / H)
    return 1.0


@jit_inline
def drag_rate(vx, vy, vz, k1, k2):
    """``k1 + k2 |v|`` (1/s): the drag's rate, ``a = -(k1 + k2 |v|) v``, with ``k1``, ``k2`` at the local air.

    ``k1`` (1/s) and ``k2`` (1/m) are the sea-level coefficients times `air_density`; the
    velocity is relative to the frame (still air turning with it). The exact flow of the same
    term, at fixed position, is `rotframe.particles.forces.drag_flow`.
    """
    return k1 + k2 * math.sqrt(vx * vx + vy * vy + vz * vz)


@jit_inline
def coriolis_about_axis(vx, vy, vz, ux, uy, uz, w):
    """``2 w x v`` for omega ``= w u`` about the unit axis ``u``: the Coriolis acceleration is minus this."""
    w2 = 2.0 * w
    cx = ux * w2
    cy = uy * w2
    cz = uz * w2
    return cy * vz - cz * vy, cz * vx - cx * vz, cx * vy - cy * vx


@jit_inline
def euler_about_axis(x, y, z, ux, uy, uz, wd):
    """``w' x r`` for omega' ``= w' u`` about the unit axis ``u`` (rad/s^2): the Euler acceleration is minus this."""
    return wd * (uy * z - uz * y), wd * (uz * x - ux * z), wd * (ux * y - uy * x)


@jit_inline
def centrifugal(x, y, z, wx, wy, wz):
    """``-w x (w x r) = |w|^2 r - (w . r) w`` for any vector omega ``w`` (rad/s)."""
    wr = wx * x + wy * y + wz * z
    w2 = wx * wx + wy * wy + wz * wz
    return w2 * x - wr * wx, w2 * y - wr * wy, w2 * z - wr * wz


@jit_inline
def coriolis(vx, vy, vz, wx, wy, wz):
    """``2 w x v`` for any vector omega ``w`` (rad/s): the Coriolis acceleration is minus this."""
    return 2.0 * (wy * vz - wz * vy), 2.0 * (wz * vx - wx * vz), 2.0 * (wx * vy - wy * vx)


@jit_inline
def euler(x, y, z, ex, ey, ez):
    """``w' x r`` for any vector omega' ``(ex, ey, ez)`` (rad/s^2): the Euler acceleration is minus this."""
    return ey * z - ez * y, ez * x - ex * z, ex * y - ey * x


@jit_inline
def string_tension(ax, ay, az, x, y, z, vx, vy, vz, px, py, pz, L):
    """The acceleration ``a`` kept on the pendulum's sphere ``|r - pivot| = L``: the string's tension added.

    The index-1 form of the constraint (docs/physics/rotating-frames.md): with ``n = (r - pivot) / L``,
    ``a <- a - (a . n + |v_t|^2 / L) n``, where ``|v_t|^2 = |v|^2 - (v . n)^2``; ``a`` is every other
    term's sum, the frame's included. Returns the constrained ``(ax, ay, az)``.
    """
    nx = (x - px) / L
    ny = (y - py) / L
    nz = (z - pz) / L
    an = ax * nx + ay * ny + az * nz
    vn = vx * nx + vy * ny + vz * nz
    v2t = vx * vx + vy * vy + vz * vz - vn * vn
    c = an + v2t / L
    return ax - c * nx, ay - c * ny, az - c * nz
