"""The closed form of the inertial oscillation, the oracle of the tests that run the Coriolis term alone.

On an f-plane (omega vertical, ``f = 2 w_z``), a particle starting at the origin with a horizontal
velocity ``v0`` feels only ``-2 w x v``: its velocity turns clockwise at the rate ``f`` and it
circles with radius ``|v0| / f``::

    v(t) = R(-f t) v0,    r(t) = integral_0^t v = (sin(f t) v0x + (1 - cos(f t)) v0y,
                                                  (cos(f t) - 1) v0x + sin(f t) v0y, 0) / f
"""

from __future__ import annotations

import numpy as np


def inertial_circle(f, v0, t):
    """``(r, v)`` (len(t), 3) of the inertial oscillation at times ``t`` from the origin (module docstring)."""
    c, s = np.cos(f * t), np.sin(f * t)
    v = np.stack([c * v0[0] + s * v0[1], -s * v0[0] + c * v0[1], 0.0 * t], axis=1)
    r = np.stack([(s * v0[0] + (1 - c) * v0[1]) / f, ((c - 1) * v0[0] + s * v0[1]) / f, 0.0 * t], axis=1)
    return r, v
