"""The local ENU frame on the rotating Earth: Earth's angular velocity, effective gravity, plumb tilt, ECEF<->ENU.

ENU: x east, y north, z up, origin on the surface at the site. ECEF: x towards
(lat 0, lon 0), z towards the north pole. Which latitude each function takes
(geocentric or geodetic) is stated in :mod:`rotframe.earth` and in each docstring;
formulas in docs/physics/earth.md.
"""

from __future__ import annotations

import numpy as np

from rotframe.earth.constants import G0, GM_EARTH, OMEGA_EARTH, R_EARTH, WGS84_E2
from rotframe.earth.parsing import as_radians
from rotframe.earth.sites import Site
from rotframe.errors import ScenarioError

__all__ = [
    "omega_enu",
    "normal_gravity",
    "effective_gravity_enu",
    "plumb_tilt",
    "geocentric_latitude",
    "ecef_to_enu_matrix",
    "enu_to_ecef",
    "ecef_to_enu",
]

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


def effective_gravity_enu(
    latitude,
    model: str = "spherical",
    *,
    omega: float = OMEGA_EARTH,
    gm: float = GM_EARTH,
    radius: float = R_EARTH,
) -> np.ndarray:
    """Effective gravity (gravitation plus centrifugal) in the local ENU frame, m/s^2.

    Models
    ------
    ``"spherical"``
        A spherical Earth of radius R whose gravitation is ``GM / R^2`` towards the centre.
        At the surface point at GEOCENTRIC latitude ``lat``, in the ENU frame whose up is
        the radial direction:
        ``g_eff = g_grav - omega x (omega x R)
        = (0, -Omega^2 R cos(lat) sin(lat), -GM/R^2 + Omega^2 R cos^2(lat))``.
        The centrifugal part pushes away from the axis, so ``g_eff`` leans towards the
        equator (southward in the north): see :func:`plumb_tilt`.
    ``"wgs84"``
        ``(0, 0, -normal_gravity(lat))`` in the GEODETIC ENU frame (up along the ellipsoid
        normal, which is the direction of normal gravity on the ellipsoid).
    ``"standard"``
        ``(0, 0, -G0)``, standard gravity straight down.

    Parameters
    ----------
    latitude : float or array_like
        Latitude, rad (geocentric for "spherical", geodetic for "wgs84").
    model : {"spherical", "wgs84", "standard"}
    omega, gm, radius : float
        Rotation rate (rad/s), GM (m^3/s^2) and radius (m) of the spherical model.

    Returns
    -------
    ndarray, shape (..., 3)
        Effective gravity vector, m/s^2, ENU components. A scene that uses it as a uniform
        field must not add the centrifugal term again.
    """
    lat = as_radians(latitude)
    zero = np.zeros_like(lat)
    if model == "spherical":
        c, s = np.cos(lat), np.sin(lat)
        a_c = omega * omega * radius
        return np.stack([zero, -a_c * c * s, -gm / radius**2 + a_c * c * c], axis=-1)
    if model == "wgs84":
        return np.stack([zero, zero, -np.asarray(normal_gravity(lat))], axis=-1)
    if model == "standard":
        return np.stack([zero, zero, zero - G0], axis=-1)
    raise ScenarioError(
        f"gravity model {model!r} is unknown; allowed: 'spherical', 'wgs84', 'standard'"
    )


def plumb_tilt(
    latitude,
    *,
    omega: float = OMEGA_EARTH,
    gm: float = GM_EARTH,
    radius: float = R_EARTH,
):
    """Angle between the plumb line and the radial direction on a spherical Earth, rad.

    ``tilt = atan2(Omega^2 R cos(lat) sin(lat), GM/R^2 - Omega^2 R cos^2(lat))``: the
    apparent up ``-g_eff`` (:func:`effective_gravity_enu`, "spherical") leans from the
    radial up towards the nearer pole by this angle, so the astronomical latitude is
    ``lat + tilt``. Positive in the north, negative in the south, zero on the equator and
    at the poles; largest (about 0.1 deg) near 45 deg.

    Parameters
    ----------
    latitude : float or array_like
        GEOCENTRIC latitude, rad.
    omega, gm, radius : float
        Rotation rate (rad/s), GM (m^3/s^2), radius (m).

    Returns
    -------
    float or ndarray
        Signed tilt, rad.
    """
    lat = as_radians(latitude)
    a_c = omega * omega * radius
    c, s = np.cos(lat), np.sin(lat)
    t = np.arctan2(a_c * c * s, gm / radius**2 - a_c * c * c)
    return float(t) if np.ndim(t) == 0 else t


def geocentric_latitude(geodetic_latitude, e2: float = WGS84_E2):
    """Geocentric latitude of a point on the ellipsoid from its geodetic latitude, rad.

    ``tan(psi) = (1 - e^2) tan(phi)``, computed as ``atan2((1 - e^2) sin phi, cos phi)``
    (exact at the poles). WGS84 by default.
    """
    phi = as_radians(geodetic_latitude)
    psi = np.arctan2((1.0 - e2) * np.sin(phi), np.cos(phi))
    return float(psi) if np.ndim(psi) == 0 else psi


# --------------------------------------------------------------------------------------
# ENU <-> ECEF (spherical Earth)
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


def enu_to_ecef(site, enu, *, vector: bool = False, radius: float = R_EARTH) -> np.ndarray:
    """Map local ENU coordinates at a site to ECEF (spherical Earth).

    Position: ``r_ecef = (R + h) up + M.T @ r_enu`` (origin of ENU at the site, on the
    sphere of radius ``R`` raised by the site's height ``h``; ``M`` from
    :func:`ecef_to_enu_matrix` at the site's latitude, used as geocentric).
    With ``vector=True`` only the rotation is applied (velocities, accelerations).

    Parameters
    ----------
    site : Site or anything :meth:`Site.from_any` accepts as a single argument
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

    Inverse of :func:`enu_to_ecef`: ``r_enu = M @ (r_ecef - (R + h) up)``; with
    ``vector=True`` only ``M @ v_ecef``.

    Parameters
    ----------
    site : Site or anything :meth:`Site.from_any` accepts as a single argument
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
