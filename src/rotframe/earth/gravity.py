"""Gravity models in the local ENU frame: uniform, weakening with altitude, central (numpy references for the compiled kernels)."""

from __future__ import annotations

import numpy as np

from rotframe.earth.constants import G0, GM_EARTH, R_EARTH

__all__ = ["gravity_uniform", "gravity_altitude", "gravity_central"]

def gravity_uniform(g=G0, r=None) -> np.ndarray:
    """Uniform gravity field, m/s^2, in the local ENU frame.

    Parameters
    ----------
    g : float or array_like of shape (3,)
        A magnitude (m/s^2), giving ``(0, 0, -g)`` (straight down), or a full vector such
        as :func:`effective_gravity_enu` returns.
    r : array_like of shape (..., 3), optional
        Positions, m; only their shape is used (the field is the same everywhere).

    Returns
    -------
    ndarray, shape (3,) or r.shape
    """
    g = np.asarray(g, dtype=float)
    vec = np.array([0.0, 0.0, -float(g)]) if g.ndim == 0 else g.reshape(3).copy()
    if r is None:
        return vec
    return np.broadcast_to(vec, np.shape(r)).copy()


def gravity_altitude(r, g0: float = G0, radius: float = R_EARTH) -> np.ndarray:
    """Gravity that weakens with altitude, pointing straight down, m/s^2.

    ``g(r) = (0, 0, -g0 (R / (R + z))^2)`` in the local ENU frame (origin on the surface,
    z up); it ignores the curvature of the field lines (see :func:`gravity_central`).

    Parameters
    ----------
    r : array_like, shape (..., 3)
        Positions in ENU, m.
    g0 : float
        Gravity at z = 0, m/s^2.
    radius : float
        Earth radius R, m.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    r = np.asarray(r, dtype=float)
    z = r[..., 2]
    out = np.zeros_like(r)
    out[..., 2] = -g0 * (radius / (radius + z)) ** 2
    return out


def gravity_central(r, gm: float = GM_EARTH, radius: float = R_EARTH) -> np.ndarray:
    """Point-mass gravitation towards the Earth's centre, in the local ENU frame, m/s^2.

    The centre is at ``c = (0, 0, -R)`` in ENU (origin on the surface, z up):
    ``g(r) = -GM (r - c) / |r - c|^3``. Gravitation only (no centrifugal term).

    Parameters
    ----------
    r : array_like, shape (..., 3)
        Positions in ENU, m.
    gm : float
        GM, m^3/s^2.
    radius : float
        Distance from the origin to the centre, m.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    d = np.asarray(r, dtype=float).copy()
    d[..., 2] += radius
    n = np.sqrt(np.sum(d * d, axis=-1, keepdims=True))
    return -gm * d / n**3
