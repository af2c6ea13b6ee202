"""The Earth as a rotating frame: rotation rate, radius, gravity, sites and the local ENU frame.

A package of one concept per module, all re-exported here (``from rotframe.earth
import X`` for every name below; each module is imported when one of its names is
first used, so ``from rotframe.earth import omega_enu`` imports neither astropy nor
scipy):

* `rotframe.earth.constants`: ``OMEGA_EARTH``, ``R_EARTH``, ``GM_EARTH``, ``G0``,
  ``ERA_RATE_RATIO``, ``WGS84_E2``;
* `rotframe.earth.offline`: [`astropy_offline`][rotframe.earth.astropy_offline];
* `rotframe.earth.parsing`: angles and lengths from user input
  ([`parse_angle`][rotframe.earth.parse_angle], [`parse_latitude`][rotframe.earth.parse_latitude], [`parse_longitude`][rotframe.earth.parse_longitude],
  [`parse_azimuth`][rotframe.earth.parse_azimuth], [`read_angle_text`][rotframe.earth.read_angle_text], [`angle_kind`][rotframe.earth.angle_kind],
  ``HEMISPHERE_LETTERS``, [`parse_length`][rotframe.earth.parse_length]);
* `rotframe.earth.sites`: [`Site`][rotframe.earth.Site], ``SITES``;
* `rotframe.earth.local_frame`: [`omega_enu`][rotframe.earth.omega_enu], [`normal_gravity`][rotframe.earth.normal_gravity],
  [`geocentric_latitude`][rotframe.earth.geocentric_latitude], [`ecef_to_enu_matrix`][rotframe.earth.ecef_to_enu_matrix];
* `rotframe.earth.gravity`: [`effective_gravity_enu`][rotframe.earth.effective_gravity_enu], [`plumb_tilt`][rotframe.earth.plumb_tilt],
  [`gravity_uniform`][rotframe.earth.gravity_uniform], [`gravity_altitude`][rotframe.earth.gravity_altitude], [`gravity_central`][rotframe.earth.gravity_central];
* `rotframe.earth.ecef`: [`enu_to_ecef`][rotframe.earth.enu_to_ecef], [`ecef_to_enu`][rotframe.earth.ecef_to_enu].

Conventions
-----------
* Core values are plain floats (or float64 arrays) in SI units and radians. The
  parsing helpers ([`parse_angle`][rotframe.earth.parse_angle], [`parse_latitude`][rotframe.earth.parse_latitude], [`parse_longitude`][rotframe.earth.parse_longitude],
  [`parse_length`][rotframe.earth.parse_length], [`Site.from_any`][rotframe.earth.Site.from_any]) are the edge: they accept numbers,
  astropy quantities and strings, check dimensions and convert once.
* Local frame: ENU, x east, y north, z up, origin on the surface at the site.
  Earth's angular velocity in it is ``Omega (0, cos lat, sin lat)``.
* Earth-centred Earth-fixed (ECEF) frame: x towards (lat 0, lon 0), z towards the
  north pole, y completing the right-handed triad.
* Which latitude. ``omega_enu(lat)`` holds for any local frame whose "up" makes the
  angle ``lat`` with the equatorial plane: the geocentric latitude for the radial up of
  a spherical Earth, the geodetic latitude for the ellipsoid normal, the astronomical
  latitude for the plumb line. The spherical-Earth functions here
  ([`effective_gravity_enu`][rotframe.earth.effective_gravity_enu] with ``model="spherical"``, [`plumb_tilt`][rotframe.earth.plumb_tilt],
  [`ecef_to_enu_matrix`][rotframe.earth.ecef_to_enu_matrix], [`enu_to_ecef`][rotframe.earth.enu_to_ecef], [`ecef_to_enu`][rotframe.earth.ecef_to_enu],
  [`gravity_central`][rotframe.earth.gravity_central]) take the GEOCENTRIC latitude (on a sphere it is also the
  geodetic one); [`normal_gravity`][rotframe.earth.normal_gravity] (WGS84 Somigliana) takes the GEODETIC latitude.
  The coordinates in `SITES` are geodetic (map) coordinates;
  [`geocentric_latitude`][rotframe.earth.geocentric_latitude] converts on the WGS84 ellipsoid (difference at most
  0.19 deg, at 45 deg).

astropy offline, and only when needed
-------------------------------------
astropy computes the constants and parses inputs. It is imported when first needed:
`astropy.units` and `astropy.constants` when ``R_EARTH``, ``GM_EARTH`` or
``G0`` is first read (also by importing `gravity` or
`ecef`, whose defaults they are), `astropy.coordinates`
when a parser reads an angle. Nothing here calls what needs the
network or the IERS tables (no ``EarthLocation.of_site``, ``Time.ut1``, GCRS); the
parsers run inside [`astropy_offline`][rotframe.earth.astropy_offline], which sets ``allow_internet`` and
``iers.conf.auto_download`` to False only for the duration of the call, so the user's
global astropy configuration is never changed.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # what the lazy names below resolve to, for readers and type checkers
    from rotframe.earth.constants import ERA_RATE_RATIO, G0, GM_EARTH, OMEGA_EARTH, R_EARTH, WGS84_E2
    from rotframe.earth.ecef import ecef_to_enu, enu_to_ecef
    from rotframe.earth.gravity import (effective_gravity_enu, gravity_altitude, gravity_central, gravity_uniform,
                                        plumb_tilt)
    from rotframe.earth.local_frame import ecef_to_enu_matrix, geocentric_latitude, normal_gravity, omega_enu
    from rotframe.earth.offline import astropy_offline
    from rotframe.earth.parsing import (HEMISPHERE_LETTERS, angle_kind, parse_angle, parse_azimuth, parse_latitude,
                                        parse_length, parse_longitude, read_angle_text)
    from rotframe.earth.sites import SITES, Site

#: module that defines each public name, imported on first access (PEP 562)
_LAZY = {
    **dict.fromkeys(("OMEGA_EARTH", "R_EARTH", "GM_EARTH", "G0", "ERA_RATE_RATIO", "WGS84_E2"), "constants"),
    "astropy_offline": "offline",
    **dict.fromkeys(("parse_angle", "parse_latitude", "parse_longitude", "parse_azimuth", "read_angle_text",
                     "angle_kind", "HEMISPHERE_LETTERS", "parse_length"), "parsing"),
    **dict.fromkeys(("Site", "SITES"), "sites"),
    **dict.fromkeys(("omega_enu", "normal_gravity", "geocentric_latitude", "ecef_to_enu_matrix"), "local_frame"),
    **dict.fromkeys(("effective_gravity_enu", "plumb_tilt", "gravity_uniform", "gravity_altitude",
                     "gravity_central"), "gravity"),
    **dict.fromkeys(("enu_to_ecef", "ecef_to_enu"), "ecef"),
}
_SUBMODULES = ("constants", "offline", "parsing", "sites", "local_frame", "gravity", "ecef")

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
    "angle_kind",
    "HEMISPHERE_LETTERS",
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


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
