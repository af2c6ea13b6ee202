"""Gravity in the local ENU frame: the rotating Earth's effective gravity and plumb tilt; uniform, altitude and central models.

[`effective_gravity_enu`][rotframe.earth.effective_gravity_enu] and [`plumb_tilt`][rotframe.earth.plumb_tilt] give the effective gravity of the
rotating Earth at a latitude; [`gravity_uniform`][rotframe.earth.gravity_uniform], [`gravity_altitude`][rotframe.earth.gravity_altitude] and
[`gravity_central`][rotframe.earth.gravity_central] are the numpy references for the compiled force kernels.
Formulas in docs/physics/earth.md. Their defaults are astropy's ``R_EARTH``,
``GM_EARTH``, ``G0`` (`rotframe.earth.constants`), read when this module is imported.
"""

from __future__ import annotations

import numpy as np

from rotframe.earth.constants import G0, GM_EARTH, OMEGA_EARTH, R_EARTH
from rotframe.earth.local_frame import normal_gravity
from rotframe.earth.parsing import as_radians
from rotframe.errors import ScenarioError

__all__ = ["effective_gravity_enu", "plumb_tilt", "gravity_uniform", "gravity_altitude", "gravity_central"]


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
        equator (southward in the north): see [`plumb_tilt`][rotframe.earth.plumb_tilt].
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
    apparent up ``-g_eff`` ([`effective_gravity_enu`][rotframe.earth.effective_gravity_enu], "spherical") leans from the
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


def gravity_uniform(g=G0, r=None) -> np.ndarray:
    """Uniform gravity field, m/s^2, in the local ENU frame.

    Parameters
    ----------
    g : float or array_like of shape (3,)
        A magnitude (m/s^2), giving ``(0, 0, -g)`` (straight down), or a full vector such
        as [`effective_gravity_enu`][rotframe.earth.effective_gravity_enu] returns.
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
    z up); it ignores the curvature of the field lines (see [`gravity_central`][rotframe.earth.gravity_central]).

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
