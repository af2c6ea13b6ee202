"""Sites: places on the Earth (geodetic latitude, longitude, height) and the named table `SITES`."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from rotframe.earth.parsing import parse_latitude, parse_length, parse_longitude
from rotframe.errors import ScenarioError

__all__ = ["Site", "SITES"]

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
            A [`Site`][rotframe.earth.Site] (returned as is), the name of an entry of `SITES`
            (case-insensitive, ``"Pantheon Paris"`` = ``"pantheon-paris"``; then ``lon`` and
            ``height`` are ignored), or a latitude as read by [`parse_latitude`][rotframe.earth.parse_latitude]
            (numbers in degrees).
        lon : float, str, astropy Angle/Quantity
            Longitude as read by [`parse_longitude`][rotframe.earth.parse_longitude] (numbers in degrees, east positive).
        height : float, str, astropy Quantity
            Height as read by [`parse_length`][rotframe.earth.parse_length] (numbers in metres).
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
