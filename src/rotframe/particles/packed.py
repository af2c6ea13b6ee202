"""The packed model and the state as the compiled particle kernels see them.

A [`rotframe.particles.model.ParticleModel`][rotframe.particles.model.ParticleModel] is packed (``ParticleModel.pack``)
into a flat float64 parameter vector ``P``; the drivers unpack it once per call
into a `PackedModel` of scalars. A particle's state is the tuple
``(x, y, z, vx, vy, vz)`` (rotating frame, SI), kept in registers.

Layout of ``P`` (see ``pack`` in [`rotframe.particles.model`][rotframe.particles.model])::

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

Every kernel of `rotframe.particles` is compiled with `jit_kernel`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from rotframe.numerics.compiled import jit_internal, jit_kernel  # the one configuration (see there)

__all__ = ["I_G", "I_AXIS", "I_CORIOLIS", "I_CENTRIFUGAL", "I_EULER", "I_KLIN", "I_KQUAD", "I_GMODE", "I_GM",
           "I_R", "I_PLEN", "I_PIVOT", "I_G0", "I_SPRING", "I_SCALE_H", "N_PARAMS", "N_EVENT_FIELDS", "NFEV",
           "jit_kernel", "jit_internal", "PackedModel", "unpack", "as_state", "is_finite", "store", "store_particle"]

# Parameter-vector indices (kept in one place; model.pack writes them).
I_G, I_AXIS, I_CORIOLIS, I_CENTRIFUGAL, I_EULER = 0, 3, 6, 7, 8
I_KLIN, I_KQUAD, I_GMODE, I_GM, I_R, I_PLEN, I_PIVOT, I_G0, I_SPRING, I_SCALE_H = 9, 10, 11, 12, 13, 14, 15, 18, 19, 20
N_PARAMS = 21

# Event description: (kind, component, value, direction, terminal)
#   kind 0: position component r[c] - value, kind 1: velocity component v[c] - value,
#   kind 2: altitude above the sphere of radius R about (0, 0, -R), minus value (curved ground)
#   direction: +1 rising only, -1 falling only, 0 both. terminal: 1 stops that particle.
N_EVENT_FIELDS = 5

#: Force evaluations per step of each fixed-step method code (0 splitting, 1 splitting4, 2 rk4).
NFEV = (1, 3, 4)


class PackedModel(NamedTuple):
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


@jit_internal
def unpack(P, wt, wv):
    """The `PackedModel` of the parameter vector ``P`` and the schedule ``(wt, wv)``."""
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
    return PackedModel(g, axis, P[I_CORIOLIS] != 0.0, centrifugal, euler, k1, k2, k1 != 0.0 or k2 != 0.0, gmode,
                  P[I_GM], P[I_R], P[I_G0], spring, P[I_SCALE_H], P[I_PLEN], pivot, uniform, steady, wv[0])


@jit_internal
def as_state(y):
    """The state vector y (6,) as a tuple."""
    return y[0], y[1], y[2], y[3], y[4], y[5]


@jit_internal
def is_finite(state):
    """Whether every component of the state tuple is finite."""
    for q in state:
        if not math.isfinite(q):
            return False
    return True


@jit_internal
def store(out_r, out_v, k, p, state):
    """Write a state (a 6-tuple or a (6,) array) into row k, particle p of ``out_r``, ``out_v`` (K, N, 3)."""
    for i in range(3):
        out_r[k, p, i] = state[i]
        out_v[k, p, i] = state[3 + i]


@jit_internal
def store_particle(r, v, p, state):
    """Write a state (a 6-tuple or a (6,) array) into row p of ``r``, ``v`` (N, 3)."""
    for i in range(3):
        r[p, i] = state[i]
        v[p, i] = state[3 + i]
