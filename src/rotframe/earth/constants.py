"""Earth constants: rotation rate, radius, GM, standard gravity, the WGS84 eccentricity.

Plain floats in SI units, computed once from :mod:`astropy.constants` (no network,
no IERS tables). Sources: IERS Conventions 2010 eq. 5.15 (the Earth Rotation Angle
rate), IAU 2015 Resolution B3 (nominal radius and GM), NIMA TR8350.2 (WGS84); see
docs/physics/earth.md.
"""

from __future__ import annotations

import astropy.constants as _const
import astropy.units as u
import numpy as np

__all__ = ["OMEGA_EARTH", "R_EARTH", "GM_EARTH", "G0", "ERA_RATE_RATIO", "WGS84_E2"]

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
