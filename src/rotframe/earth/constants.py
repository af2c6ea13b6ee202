"""Earth constants: rotation rate, radius, GM, standard gravity, the WGS84 eccentricity.

Plain floats in SI units. ``R_EARTH``, ``GM_EARTH`` and ``G0`` are read from
`astropy.constants` (no network, no IERS tables) the first time one of them is
used, once per process (module ``__getattr__``, PEP 562): importing this module does
not import astropy, so a scene that never needs them does not pay for astropy's units.
``OMEGA_EARTH``, ``ERA_RATE_RATIO`` and ``WGS84_E2`` are defining numbers of the IERS
Conventions and WGS84, not in astropy. Sources: IERS Conventions 2010 eq. 5.15 (the
Earth Rotation Angle rate), IAU 2015 Resolution B3 (nominal radius and GM), NIMA
TR8350.2 (WGS84); see docs/physics/earth.md.
"""

from __future__ import annotations

import math

__all__ = ["OMEGA_EARTH", "R_EARTH", "GM_EARTH", "G0", "ERA_RATE_RATIO", "WGS84_E2"]

ERA_RATE_RATIO = 1.00273781191135448
"""Ratio of the Earth Rotation Angle rate to one turn per UT1 day (IERS Conventions 2010,
eq. 5.15: ERA = 2 pi (0.7790572732640 + 1.00273781191135448 Tu))."""

OMEGA_EARTH: float = 2.0 * math.pi * ERA_RATE_RATIO / 86400.0
"""Earth's rotation rate relative to inertial space, rad/s: the rate of the Earth Rotation
Angle, ``2 pi x 1.00273781191135448 / 86400 s`` = 7.2921151467e-5 rad/s (the same float as
astropy's ``(2 pi u.rad x ratio / (86400 u.s)).to_value(u.rad / u.s)``; tests/test_earth.py
checks it). Not ``2 pi / u.sday`` (7.2921159e-5): astropy's sidereal day is measured against
the precessing equinox, so that rate includes general precession (about 1e-7 relative too
high). Not ``2 pi / 86400 s``: that is one turn per solar day, 0.27 % too low, since the
Earth turns once more per year relative to the stars than relative to the Sun."""

WGS84_E2 = 0.00669437999013
"""First eccentricity squared of the WGS84 ellipsoid (dimensionless)."""

R_EARTH: float
"""Nominal equatorial radius of the Earth, m (``astropy.constants.R_earth``, IAU 2015 B3)."""
GM_EARTH: float
"""Nominal geocentric gravitational constant GM, m^3/s^2 (``astropy.constants.GM_earth``)."""
G0: float
"""Standard acceleration of gravity, m/s^2 (``astropy.constants.g0``)."""

#: name -> (astropy.constants attribute, SI unit it is read in)
_FROM_ASTROPY = {"R_EARTH": ("R_earth", "m"), "GM_EARTH": ("GM_earth", "m3 / s2"), "G0": ("g0", "m / s2")}


def _read_astropy_constants() -> dict[str, float]:
    """``R_EARTH``, ``GM_EARTH``, ``G0`` as plain floats from `astropy.constants` (offline)."""
    import astropy.constants as const
    import astropy.units as u

    return {name: float(getattr(const, attr).to_value(u.Unit(unit))) for name, (attr, unit) in _FROM_ASTROPY.items()}


def __getattr__(name: str) -> float:
    if name in _FROM_ASTROPY:
        values = _read_astropy_constants()
        globals().update(values)  # read once: later look-ups find plain module attributes
        return values[name]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
