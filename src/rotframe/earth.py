"""The Earth as a rotating frame: rotation rate, radius, gravity, sites and the local ENU frame.

Conventions
-----------
* Core values are plain floats (or float64 arrays) in SI units and radians. The
  parsing helpers (:func:`parse_angle`, :func:`parse_latitude`, :func:`parse_longitude`,
  :func:`parse_length`, :meth:`Site.from_any`) are the edge: they accept numbers,
  astropy quantities and strings, check dimensions and convert once.
* Local frame: ENU, x east, y north, z up, origin on the surface at the site.
  Earth's angular velocity in it is ``Omega (0, cos lat, sin lat)``.
* Earth-centred Earth-fixed (ECEF) frame: x towards (lat 0, lon 0), z towards the
  north pole, y completing the right-handed triad.
* Which latitude. ``omega_enu(lat)`` holds for any local frame whose "up" makes the
  angle ``lat`` with the equatorial plane: the geocentric latitude for the radial up of
  a spherical Earth, the geodetic latitude for the ellipsoid normal, the astronomical
  latitude for the plumb line. The spherical-Earth functions here
  (:func:`effective_gravity_enu` with ``model="spherical"``, :func:`plumb_tilt`,
  :func:`ecef_to_enu_matrix`, :func:`enu_to_ecef`, :func:`ecef_to_enu`,
  :func:`gravity_central`) take the GEOCENTRIC latitude (on a sphere it is also the
  geodetic one); :func:`normal_gravity` (WGS84 Somigliana) takes the GEODETIC latitude.
  The coordinates in :data:`SITES` are geodetic (map) coordinates;
  :func:`geocentric_latitude` converts on the WGS84 ellipsoid (difference at most
  0.19 deg, at 45 deg).

astropy offline
---------------
astropy computes the constants and parses inputs. Nothing here calls what needs the
network or the IERS tables (no ``EarthLocation.of_site``, ``Time.ut1``, GCRS); the
parsers run inside :func:`astropy_offline`, which sets ``allow_internet`` and
``iers.conf.auto_download`` to False only for the duration of the call, so the user's
global astropy configuration is never changed.
"""

from __future__ import annotations

import contextlib
import math
import re
import threading
from dataclasses import dataclass, field

import astropy.constants as _const
import astropy.units as u
import numpy as np
from astropy.coordinates import Angle, Latitude, Longitude

from rotframe.errors import ScenarioError

__all__ = [
    "OMEGA_EARTH",
    "R_EARTH",
    "GM_EARTH",
    "G0",
    "ERA_RATE_RATIO",
    "WGS84_E2",
    "astropy_offline",
    "parse_angle",
    "parse_latitude",
    "parse_longitude",
    "parse_azimuth",
    "read_angle_text",
    "parse_length",
    "Site",
    "SITES",
    "omega_enu",
    "normal_gravity",
    "effective_gravity_enu",
    "plumb_tilt",
    "geocentric_latitude",
    "ecef_to_enu_matrix",
    "enu_to_ecef",
    "ecef_to_enu",
    "gravity_uniform",
    "gravity_altitude",
    "gravity_central",
]

# --------------------------------------------------------------------------------------
# Constants
# --------------------------------------------------------------------------------------

#: Ratio of the Earth Rotation Angle rate to one turn per UT1 day (IERS Conventions 2010,
#: eq. 5.15: ERA = 2 pi (0.7790572732640 + 1.00273781191135448 Tu)).
ERA_RATE_RATIO = 1.00273781191135448

#: Earth's rotation rate relative to inertial space, rad/s: the rate of the Earth
#: Rotation Angle, ``2 pi x 1.00273781191135448 / 86400 s`` = 7.2921151467e-5 rad/s.
#: Not ``2 pi / u.sday`` (7.2921159e-5): astropy's sidereal day is measured against the
#: precessing equinox, so that rate includes general precession (about 1e-7 relative too
#: high). Not ``2 pi / 86400 s``: that is one turn per solar day, 0.27 % too low, since
#: the Earth turns once more per year relative to the stars than relative to the Sun.
OMEGA_EARTH: float = float(
    (2.0 * np.pi * u.rad * ERA_RATE_RATIO / (86400.0 * u.s)).to_value(u.rad / u.s)
)

#: Nominal equatorial radius of the Earth, m (``astropy.constants.R_earth``, IAU 2015 B3).
R_EARTH: float = float(_const.R_earth.to_value(u.m))

#: Nominal geocentric gravitational constant GM, m^3/s^2 (``astropy.constants.GM_earth``).
GM_EARTH: float = float(_const.GM_earth.to_value(u.m**3 / u.s**2))

#: Standard acceleration of gravity, m/s^2 (``astropy.constants.g0``).
G0: float = float(_const.g0.to_value(u.m / u.s**2))

#: First eccentricity squared of the WGS84 ellipsoid (dimensionless).
WGS84_E2 = 0.00669437999013

# WGS84 Somigliana normal gravity (NIMA TR8350.2, eq. 4-1): equatorial normal gravity
# (m/s^2) and the constant k = (b gamma_p) / (a gamma_e) - 1.
_WGS84_GAMMA_E = 9.7803253359
_WGS84_K = 0.00193185265241

# --------------------------------------------------------------------------------------
# astropy offline
# --------------------------------------------------------------------------------------

_OFFLINE_LOCK = threading.RLock()


@contextlib.contextmanager
def astropy_offline():
    """Run a block with astropy forbidden to reach the network or download IERS tables.

    Sets ``astropy.utils.data.conf.allow_internet`` and
    ``astropy.utils.iers.conf.auto_download`` to False with ``set_temp``, restoring the
    previous values on exit; a re-entrant lock keeps concurrent threads from restoring
    each other's values, so the user's configuration is never changed.
    """
    from astropy.utils import data as _data
    from astropy.utils import iers as _iers

    with _OFFLINE_LOCK:
        with _data.conf.set_temp("allow_internet", False), _iers.conf.set_temp(
            "auto_download", False
        ):
            yield


# --------------------------------------------------------------------------------------
# Parsing (the edge): numbers, quantities and strings -> floats in SI and radians
# --------------------------------------------------------------------------------------

_NUMBER_RE = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_ANGLE_HELP = (
    "a number in degrees, an astropy Angle/Quantity, or a string such as "
    "'48d50m46s N', '50d53m' or '48.846 deg'"
)


def parse_angle(value, name: str = "angle") -> float:
    """Parse an angle given in any accepted form and return it in radians.

    Parameters
    ----------
    value : float, int, str, astropy Angle or Quantity
        Plain numbers and bare numeric strings (``"-33.9"``) are degrees. Strings are read
        by :class:`astropy.coordinates.Angle` (``"48d50m46s N"``, ``"50d53m"``,
        ``"48.846 deg"``, ``"0.8 rad"``; a trailing S or W makes the angle negative).
        Quantities must have angular units.
    name : str
        Name of the parameter, used in error messages.

    Returns
    -------
    float
        The angle in radians (not wrapped).

    Raises
    ------
    ScenarioError
        If the value is not a finite scalar angle.
    """
    ang = _to_angle(value, name)
    return float(ang.to_value(u.rad))


def parse_latitude(value, name: str = "latitude") -> float:
    """Parse a latitude and return it in radians, in [-pi/2, pi/2].

    Accepts the same forms as :func:`parse_angle` (numbers are degrees, north positive;
    ``"33.9 S"`` is -33.9 deg). A trailing E or W is refused.

    Raises
    ------
    ScenarioError
        If the value cannot be read as an angle or lies beyond +-90 deg; the message names
        the value and the allowed range.
    """
    ang = _to_angle(value, name, "latitude")
    try:
        with astropy_offline():
            lat = Latitude(ang)
    except ValueError as exc:
        raise ScenarioError(
            f"{name} {value!r} = {ang.to_value(u.deg):.10g} deg is outside the allowed "
            "range -90 deg <= latitude <= 90 deg"
        ) from exc
    return float(lat.to_value(u.rad))


def parse_longitude(value, name: str = "longitude") -> float:
    """Parse a longitude (east positive) and return it in radians, wrapped to [-pi, pi).

    Accepts the same forms as :func:`parse_angle`; a trailing N or S is refused.
    """
    ang = _to_angle(value, name, "longitude")
    with astropy_offline():
        lon = Longitude(ang, wrap_angle=180 * u.deg)
    return float(lon.to_value(u.rad))


def parse_azimuth(value, name: str = "azimuth") -> float:
    """Parse an azimuth or heading (clockwise from north) and return it in radians (not wrapped).

    Accepts the same forms as :func:`parse_angle`; a trailing E or W reads as
    east or west of north (``"30 W"`` is -30 deg, astropy's sign), N or S is refused.
    """
    return float(_to_angle(value, name, "azimuth").to_value(u.rad))


#: Hemisphere letters each kind of angle accepts after its value.
HEMISPHERE_LETTERS = {"latitude": "NS", "longitude": "EW", "azimuth": "EW", "angle": "", "any": "NSEW"}


def angle_kind(name: str) -> str:
    """The kind of angle a parameter named ``name`` holds: latitude, longitude, azimuth or angle."""
    key = name.lower()
    if "latitude" in key or key in ("lat", "phi"):
        return "latitude"
    if "longitude" in key or key in ("lon", "lng"):
        return "longitude"
    if any(w in key for w in ("azimuth", "heading", "bearing")):
        return "azimuth"
    return "angle"


def read_angle_text(text: str, name: str = "angle", kind: str = "angle"):
    """Read an angle string as astropy does, with hemisphere letters checked for ``kind``.

    Every string that :class:`astropy.coordinates.Angle` reads (with degrees as
    the default unit) means what astropy says: ``"48d50m46s"`` is +48.846 deg
    (the ``s`` is seconds), ``"48 50 46"``, ``"48:50:46"``, ``"48°50′46″"``,
    ``"0.8 rad"``, ``"12h30m"``; also any astropy Quantity string with an
    angular unit (``"3e1 deg"``, ``"100 arcmin"``). An upper-case hemisphere
    letter may follow the value, after a plain number too (``"33.9 S"``,
    ``"45N"``, ``"48d50m46s N"``): S and W negate. Refused with
    :class:`ScenarioError` naming ``name``, the value and what is allowed: a
    letter the kind does not take (N/S only for latitudes, E/W only for
    longitudes and azimuths, none for other named angles, any for ``kind="any"``,
    as astropy does) and a minus sign together
    with a letter (``"-45d S"``, a contradiction).

    Returns
    -------
    astropy.coordinates.Angle
    """
    text = text.strip()
    allowed = HEMISPHERE_LETTERS.get(kind, "")
    if _NUMBER_RE.match(text):
        return Angle(float(text), unit=u.deg)
    letter = None
    m = re.fullmatch(r"(.*?[^\s])\s*([NSEW])", text)
    if m:
        body = m.group(1)
        try:
            base = Angle(float(body), unit=u.deg) if _NUMBER_RE.match(body.strip()) else _astropy_angle(body)
        except (ValueError, TypeError, u.UnitsError):
            base = None
        if base is not None:
            sign = -1.0 if m.group(2) in "SW" else 1.0
            try:
                whole = _astropy_angle(text)
            except (ValueError, TypeError, u.UnitsError):
                whole = None
            # a letter astropy reads as a hemisphere (or that only makes sense as one)
            if whole is None or whole.deg == sign * base.deg or (body.lstrip().startswith("-")):
                letter = m.group(2)
    if letter is not None:
        what = {"latitude": "a latitude", "longitude": "a longitude", "azimuth": "an azimuth"}.get(kind, "this angle")
        if letter not in allowed:
            takes = f"takes only {'/'.join(allowed)}" if allowed else "takes no hemisphere letter (give a signed number)"
            raise ScenarioError(f"{name} {text!r}: {what} {takes}; e.g. "
                                f"{_ANGLE_EXAMPLES.get(kind, _ANGLE_EXAMPLES['angle'])}")
        if m.group(1).lstrip().startswith(("-", "+")):
            raise ScenarioError(f"{name} {text!r}: a sign and a hemisphere letter together; give either "
                                f"'{m.group(1).lstrip()[1:].strip()} {letter}' or a signed number")
        return Angle((-1.0 if letter in "SW" else 1.0) * base.deg, unit=u.deg)
    return _astropy_angle(text)


_ANGLE_EXAMPLES = {
    "latitude": "'48d50m46s N', '33.9 S', '-33.9' or '48.846 deg'",
    "longitude": "'2d21m E', '70.6 W', '-70.6' or '2.35 deg'",
    "azimuth": "'232', '52 W' (west of north), '232 deg' or '4.05 rad'",
    "angle": "'50', '50d30m', '50.5 deg' or '0.88 rad'",
}


def _astropy_angle(text: str):
    """astropy's reading of ``text`` (degrees by default); a Quantity string with an angular unit as fallback."""
    with astropy_offline():
        try:
            return Angle(text, unit=u.deg)
        except (ValueError, TypeError, u.UnitsError):
            q = u.Quantity(text)
            if not q.unit.is_equivalent(u.rad):
                raise u.UnitTypeError(f"unit {q.unit} is not an angle") from None
            return Angle(q)


def parse_length(value, name: str = "length", *, positive: bool = False) -> float:
    """Parse a length and return it in metres.

    Parameters
    ----------
    value : float, int, str or astropy Quantity
        Plain numbers and bare numeric strings are metres; strings with a unit are read by
        :class:`astropy.units.Quantity` with the imperial units enabled for the call
        (``"520 ft"``, ``"1.2 km"``); Quantities must have the dimension of length.
    name : str
        Name of the parameter, used in error messages.
    positive : bool
        If True, refuse zero and negative lengths.

    Raises
    ------
    ScenarioError
        Wrong dimension, unreadable or non-finite value, or (with ``positive``) not > 0.
    """
    help_ = "a length in metres, or a quantity such as '520 ft' or '158.5 m'"
    if isinstance(value, (bool, np.bool_)):
        raise ScenarioError(f"{name} {value!r} is not a length; give {help_}")
    if isinstance(value, u.Quantity):
        q = value
    elif isinstance(value, str):
        text = value.strip()
        if _NUMBER_RE.match(text):
            q = float(text) * u.m
        else:
            try:
                with astropy_offline(), u.add_enabled_units(u.imperial):
                    q = u.Quantity(text)
            except (ValueError, TypeError) as exc:
                raise ScenarioError(f"{name} {value!r} is not readable; give {help_}") from exc
            if q.unit == u.dimensionless_unscaled:
                q = q.value * u.m
    elif np.ndim(value) == 0 and isinstance(value, (int, float, np.integer, np.floating)):
        q = float(value) * u.m
    else:
        raise ScenarioError(f"{name} {value!r} is not a length; give {help_}")
    if not q.isscalar:
        raise ScenarioError(f"{name} {value!r} must be a single value; give {help_}")
    try:
        metres = float(q.to_value(u.m))
    except u.UnitConversionError as exc:
        raise ScenarioError(
            f"{name} {value!r} has unit '{q.unit}', not a length; give {help_}"
        ) from exc
    if not math.isfinite(metres):
        raise ScenarioError(f"{name} {value!r} is not finite; give {help_}")
    if positive and metres <= 0.0:
        raise ScenarioError(f"{name} {value!r} must be > 0 m")
    return metres


# --------------------------------------------------------------------------------------
# Sites
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Site:
    """A place on the Earth.

    Attributes
    ----------
    latitude : float
        Latitude, rad, north positive, in [-pi/2, pi/2]. Geodetic (map) latitude for real
        places; the spherical-Earth functions use it as the latitude on the sphere.
    longitude : float
        Longitude, rad, east positive.
    height : float
        Height above the reference surface, m.
    name, note : str
        Label and source of the coordinates (not compared).
    """

    latitude: float
    longitude: float = 0.0
    height: float = 0.0
    name: str = field(default="", compare=False)
    note: str = field(default="", compare=False)

    def __post_init__(self):
        lat = float(self.latitude)
        if not (-0.5 * math.pi <= lat <= 0.5 * math.pi):
            raise ScenarioError(
                f"Site latitude {lat!r} rad = {math.degrees(lat):.10g} deg is outside "
                "-pi/2..pi/2 rad (-90..90 deg); Site takes radians, Site.from_any degrees"
            )
        object.__setattr__(self, "latitude", lat)
        object.__setattr__(self, "longitude", float(self.longitude))
        object.__setattr__(self, "height", float(self.height))

    @classmethod
    def from_any(cls, lat, lon=0, height=0, name: str = "") -> "Site":
        """Build a site from user input.

        Parameters
        ----------
        lat : Site, str, float, astropy Angle/Quantity
            A :class:`Site` (returned as is), the name of an entry of :data:`SITES`
            (case-insensitive, ``"Pantheon Paris"`` = ``"pantheon-paris"``; then ``lon`` and
            ``height`` are ignored), or a latitude as read by :func:`parse_latitude`
            (numbers in degrees).
        lon : float, str, astropy Angle/Quantity
            Longitude as read by :func:`parse_longitude` (numbers in degrees, east positive).
        height : float, str, astropy Quantity
            Height as read by :func:`parse_length` (numbers in metres).
        """
        if isinstance(lat, Site):
            return lat
        if isinstance(lat, str):
            key = re.sub(r"[\s_]+", "-", lat.strip().lower())
            if key in SITES:
                return SITES[key]
        return cls(
            parse_latitude(lat),
            parse_longitude(lon),
            parse_length(height, "height"),
            name=name,
        )

    @property
    def latitude_deg(self) -> float:
        """Latitude in degrees."""
        return math.degrees(self.latitude)

    @property
    def longitude_deg(self) -> float:
        """Longitude in degrees."""
        return math.degrees(self.longitude)


def _site(lat_deg, lon_deg, name, note, height=0.0):
    return Site(math.radians(lat_deg), math.radians(lon_deg), height, name=name, note=note)


#: Named sites (offline table; geodetic coordinates, heights 0 m).
SITES: dict[str, Site] = {
    # Foucault's pendulum, Pantheon, Paris, 1851 (L = 67 m). 48d50m46s N 2d20m46s E.
    "pantheon-paris": _site(
        48.846, 2.346, "pantheon-paris",
        "Pantheon, Paris: Foucault's pendulum 1851; 48d50m46s N, 2d20m46s E",
    ),
    # Reich's drop experiments, 1831, Drei-Brueder-Schacht near Freiberg, Saxony:
    # 50 deg 53 min N as given by Reich; the longitude is that of Freiberg (approximate).
    "freiberg": _site(
        50.883, 13.34, "freiberg",
        "Freiberg, Saxony: F. Reich's drop experiments 1831 (158.5 m shaft); "
        "latitude 50d53m N from Reich, longitude approximate",
    ),
    # Paris Gun (Paris-Geschuetz) firing position 1918 near Crepy(-en-Laonnois), ~120 km
    # from Paris; coordinates approximate.
    "paris-gun": _site(
        49.6, 3.5, "paris-gun",
        "Crepy near Laon: Paris Gun firing position 1918; approximate coordinates",
    ),
    "equator": _site(0.0, 0.0, "equator", "example: on the equator, Omega horizontal"),
    "north-pole": _site(90.0, 0.0, "north-pole", "example: north pole, Omega vertical"),
    "south-pole": _site(-90.0, 0.0, "south-pole", "example: south pole, Omega downward"),
}


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
    lat = _as_radians(latitude)
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
    s2 = np.sin(_as_radians(latitude)) ** 2
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
    lat = _as_radians(latitude)
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
    lat = _as_radians(latitude)
    a_c = omega * omega * radius
    c, s = np.cos(lat), np.sin(lat)
    t = np.arctan2(a_c * c * s, gm / radius**2 - a_c * c * c)
    return float(t) if np.ndim(t) == 0 else t


def geocentric_latitude(geodetic_latitude, e2: float = WGS84_E2):
    """Geocentric latitude of a point on the ellipsoid from its geodetic latitude, rad.

    ``tan(psi) = (1 - e^2) tan(phi)``, computed as ``atan2((1 - e^2) sin phi, cos phi)``
    (exact at the poles). WGS84 by default.
    """
    phi = _as_radians(geodetic_latitude)
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
    la, lo = np.broadcast_arrays(_as_radians(lat), _as_radians(lon))
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


# --------------------------------------------------------------------------------------
# Gravity models in the local ENU frame (numpy references for the compiled kernels)
# --------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------------------


def _as_radians(x):
    """Plain radians from a float/array, or from an astropy angle Quantity."""
    if isinstance(x, u.Quantity):
        x = x.to_value(u.rad)
    a = np.asarray(x, dtype=float)
    return float(a) if a.ndim == 0 else a


def _to_angle(value, name: str, kind: str = "any") -> Angle:
    """Read a scalar angle (numbers in degrees) as an astropy Angle; ScenarioError if not."""
    if isinstance(value, (bool, np.bool_)):
        raise ScenarioError(f"{name} {value!r} is not an angle; give {_ANGLE_HELP}")
    try:
        with astropy_offline():
            if isinstance(value, u.Quantity):
                if not value.unit.is_equivalent(u.rad):
                    raise ScenarioError(
                        f"{name} {value!r} has unit '{value.unit}', not an angle; "
                        f"give {_ANGLE_HELP}"
                    )
                ang = Angle(value)
            elif isinstance(value, str):
                ang = read_angle_text(value, name, kind)
            elif np.ndim(value) == 0 and isinstance(
                value, (int, float, np.integer, np.floating)
            ):
                ang = Angle(float(value), unit=u.deg)
            else:
                raise TypeError(type(value).__name__)
    except ScenarioError:
        raise
    except (ValueError, TypeError, u.UnitsError) as exc:
        raise ScenarioError(
            f"{name} {value!r} is not readable as an angle; give {_ANGLE_HELP}"
        ) from exc
    if not ang.isscalar:
        raise ScenarioError(f"{name} {value!r} must be a single angle; give {_ANGLE_HELP}")
    if not np.isfinite(ang.value):
        raise ScenarioError(f"{name} {value!r} is not finite; give {_ANGLE_HELP}")
    return ang
