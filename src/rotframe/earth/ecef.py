"""Positions on a spherical Earth: a site's local ENU coordinates <-> Earth-centred Earth-fixed (ECEF).

ENU: x east, y north, z up, origin on the surface at the site. ECEF: x towards
(lat 0, lon 0), z towards the north pole. The sphere's radius defaults to astropy's
``R_EARTH`` (`rotframe.earth.constants`); formulas in docs/physics/earth.md.
"""

from __future__ import annotations

import numpy as np

from rotframe.earth.constants import R_EARTH
from rotframe.earth.local_frame import ecef_to_enu_matrix
from rotframe.earth.sites import Site

__all__ = ["enu_to_ecef", "ecef_to_enu"]


def enu_to_ecef(site, enu, *, vector: bool = False, radius: float = R_EARTH) -> np.ndarray:
    """Map local ENU coordinates at a site to ECEF (spherical Earth).

    Position: ``r_ecef = (R + h) up + M.T @ r_enu`` (origin of ENU at the site, on the
    sphere of radius ``R`` raised by the site's height ``h``; ``M`` from
    [`ecef_to_enu_matrix`][rotframe.earth.ecef_to_enu_matrix] at the site's latitude, used as geocentric).
    With ``vector=True`` only the rotation is applied (velocities, accelerations).

    Parameters
    ----------
    site : Site or anything [`Site.from_any`][rotframe.earth.Site.from_any] accepts as a single argument
    enu : array_like, shape (..., 3)
        ENU coordinates, m (or vector components).
    vector : bool
        Treat ``enu`` as free vectors (no translation).
    radius : float
        Radius of the sphere, m.

    Returns
    -------
    ndarray, shape (..., 3)
        ECEF coordinates, m.
    """
    site = Site.from_any(site)
    m = ecef_to_enu_matrix(site.latitude, site.longitude)
    out = np.asarray(enu, dtype=float) @ m
    if not vector:
        out = out + (radius + site.height) * m[2]
    return out


def ecef_to_enu(site, ecef, *, vector: bool = False, radius: float = R_EARTH) -> np.ndarray:
    """Map ECEF coordinates to local ENU coordinates at a site (spherical Earth).

    Inverse of [`enu_to_ecef`][rotframe.earth.enu_to_ecef]: ``r_enu = M @ (r_ecef - (R + h) up)``; with
    ``vector=True`` only ``M @ v_ecef``.

    Parameters
    ----------
    site : Site or anything [`Site.from_any`][rotframe.earth.Site.from_any] accepts as a single argument
    ecef : array_like, shape (..., 3)
        ECEF coordinates, m.
    vector : bool
        Treat ``ecef`` as free vectors (no translation).
    radius : float
        Radius of the sphere, m.

    Returns
    -------
    ndarray, shape (..., 3)
        ENU coordinates, m.
    """
    site = Site.from_any(site)
    m = ecef_to_enu_matrix(site.latitude, site.longitude)
    x = np.asarray(ecef, dtype=float)
    if not vector:
        x = x - (radius + site.height) * m[2]
    return x @ m.T
