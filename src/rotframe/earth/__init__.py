"""The Earth as a rotating frame: rotation rate, radius, gravity, sites and the local ENU frame.

A package of one concept per module, all re-exported here (``from rotframe.earth
import X`` for every name below; each module is imported when one of its names is
first used, so ``from rotframe.earth import omega_enu`` imports neither astropy nor
scipy):

* :mod:`rotframe.earth.constants`: ``OMEGA_EARTH``, ``R_EARTH``, ``GM_EARTH``, ``G0``,
  ``ERA_RATE_RATIO``, ``WGS84_E2``;
* :mod:`rotframe.earth.offline`: :func:`astropy_offline`;
* :mod:`rotframe.earth.parsing`: angles and lengths from user input
  (:func:`parse_angle`, :func:`parse_latitude`, :func:`parse_longitude`,
  :func:`parse_azimuth`, :func:`read_angle_text`, :func:`angle_kind`,
  ``HEMISPHERE_LETTERS``, :func:`parse_length`);
* :mod:`rotframe.earth.sites`: :class:`Site`, ``SITES``;
* :mod:`rotframe.earth.local_frame`: :func:`omega_enu`, :func:`normal_gravity`,
  :func:`geocentric_latitude`, :func:`ecef_to_enu_matrix`;
* :mod:`rotframe.earth.gravity`: :func:`effective_gravity_enu`, :func:`plumb_tilt`,
  :func:`gravity_uniform`, :func:`gravity_altitude`, :func:`gravity_central`;
* :mod:`rotframe.earth.ecef`: :func:`enu_to_ecef`, :func:`ecef_to_enu`.

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

astropy offline, and only when needed
-------------------------------------
astropy computes the constants and parses inputs. It is imported when first needed:
:mod:`astropy.units` and :mod:`astropy.constants` when ``R_EARTH``, ``GM_EARTH`` or
``G0`` is first read (also by importing :mod:`~rotframe.earth.gravity` or
:mod:`~rotframe.earth.ecef`, whose defaults they are), :mod:`astropy.coordinates`
when a parser reads an angle. Nothing here calls what needs the
network or the IERS tables (no ``EarthLocation.of_site``, ``Time.ut1``, GCRS); the
parsers run inside :func:`astropy_offline`, which sets ``allow_internet`` and
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
