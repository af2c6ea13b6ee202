"""The local ENU frame on the rotating Earth: Earth's angular velocity, WGS84 normal gravity, the ENU axes in ECEF.

ENU: x east, y north, z up, origin on the surface at the site. ECEF: x towards
(lat 0, lon 0), z towards the north pole. Which latitude each function takes
(geocentric or geodetic) is stated in [`rotframe.earth`][rotframe.earth] and in each docstring;
formulas in docs/physics/earth.md. Nothing here needs astropy's constants (the
spherical-Earth models that take ``R_EARTH`` and ``GM_EARTH`` as defaults are in
`rotframe.earth.gravity` and `rotframe.earth.ecef`), so the scenes that
only need the rotation and normal gravity do not import astropy.
"""

from __future__ import annotations

import numpy as np

from rotframe.earth.constants import OMEGA_EARTH, WGS84_E2
from rotframe.earth.parsing import as_radians

__all__ = ["omega_enu", "normal_gravity", "geocentric_latitude", "ecef_to_enu_matrix"]

# WGS84 Somigliana normal gravity (NIMA TR8350.2, eq. 4-1): equatorial normal gravity
# (m/s^2) and the constant k = (b gamma_p) / (a gamma_e) - 1.
_WGS84_GAMMA_E = 9.7803253359
_WGS84_K = 0.00193185265241

# --------------------------------------------------------------------------------------
# Earth's rotation in the local frame; gravity
# --------------------------------------------------------------------------------------


def omega_enu(latitude, omega: float = OMEGA_EARTH) -> np.ndarray:
    """Earth's angular velocity in the local ENU frame.

    ``omega_vec = omega (0, cos lat, sin lat)`` (x east, y north, z up): horizontal and
    northward on the equator, vertical at the poles (up in the north, down in the south).

    Parameters
    ----------
    latitude : float or array_like
        Latitude, rad (astropy Angle/Quantity also accepted). The angle between the
        frame's "up" and the equatorial plane: geocentric for a radial up, geodetic for
        the ellipsoid normal.
    omega : float
        Rotation rate, rad/s.

    Returns
    -------
    ndarray, shape (..., 3)
        Angular velocity, rad/s, in ENU components.
    """
    lat = as_radians(latitude)
    return omega * np.stack([np.zeros_like(lat), np.cos(lat), np.sin(lat)], axis=-1)


def normal_gravity(latitude):
    """WGS84 normal gravity on the ellipsoid (Somigliana's formula), m/s^2.

    ``g(phi) = 9.7803253359 (1 + 0.00193185265241 sin^2 phi)
    / sqrt(1 - 0.00669437999013 sin^2 phi)``, from 9.7803253359 m/s^2 at the equator to
    9.8321849379 m/s^2 at the poles. It includes the centrifugal term and points along the
    ellipsoid normal (down in the geodetic ENU frame).

    Parameters
    ----------
    latitude : float or array_like
        GEODETIC latitude, rad.

    Returns
    -------
    float or ndarray
        Magnitude of the effective gravity on the ellipsoid surface, m/s^2.
    """
    s2 = np.sin(as_radians(latitude)) ** 2
    g = _WGS84_GAMMA_E * (1.0 + _WGS84_K * s2) / np.sqrt(1.0 - WGS84_E2 * s2)
    return float(g) if np.ndim(g) == 0 else g

def geocentric_latitude(geodetic_latitude, e2: float = WGS84_E2):
    """Geocentric latitude of a point on the ellipsoid from its geodetic latitude, rad.

    ``tan(psi) = (1 - e^2) tan(phi)``, computed as ``atan2((1 - e^2) sin phi, cos phi)``
    (exact at the poles). WGS84 by default.
    """
    phi = as_radians(geodetic_latitude)
    psi = np.arctan2((1.0 - e2) * np.sin(phi), np.cos(phi))
    return float(psi) if np.ndim(psi) == 0 else psi


# --------------------------------------------------------------------------------------
# The ENU axes in ECEF
# --------------------------------------------------------------------------------------


def ecef_to_enu_matrix(lat, lon) -> np.ndarray:
    """Rotation matrix from ECEF components to local ENU components.

    Rows are the ENU unit vectors in ECEF components::

        east  = (-sin lon,          cos lon,          0      )
        north = (-sin lat cos lon, -sin lat sin lon,  cos lat)
        up    = ( cos lat cos lon,  cos lat sin lon,  sin lat)

    so ``v_enu = M @ v_ecef`` and ``v_ecef = M.T @ v_enu``. ``up`` is the radial
    direction for GEOCENTRIC ``lat`` (the ellipsoid normal for geodetic ``lat``).

    Parameters
    ----------
    lat, lon : float or array_like
        Latitude and longitude, rad; broadcast together.

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    la, lo = np.broadcast_arrays(as_radians(lat), as_radians(lon))
    sla, cla, slo, clo = np.sin(la), np.cos(la), np.sin(lo), np.cos(lo)
    zero = np.zeros_like(la)
    east = np.stack([-slo, clo, zero], axis=-1)
    north = np.stack([-sla * clo, -sla * slo, cla], axis=-1)
    up = np.stack([cla * clo, cla * slo, sla], axis=-1)
    return np.stack([east, north, up], axis=-2)


#: Names that lived here before the split, and their modules now (old imports keep working).
_MOVED = {"effective_gravity_enu": "rotframe.earth.gravity", "plumb_tilt": "rotframe.earth.gravity",
          "enu_to_ecef": "rotframe.earth.ecef", "ecef_to_enu": "rotframe.earth.ecef"}


def __getattr__(name):
    """``rotframe.earth.local_frame.NAME`` for a name that moved, imported from its module on first use."""
    if name in _MOVED:
        import importlib

        return getattr(importlib.import_module(_MOVED[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
