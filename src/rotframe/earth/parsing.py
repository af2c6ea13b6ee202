"""Reading user input (the edge): numbers, astropy quantities and strings -> SI floats and radians.

Plain numbers are degrees (angles) or metres (lengths); strings are read by astropy
(`astropy.coordinates.Angle`, `astropy.units.Quantity` with the imperial
units enabled for the call), inside [`astropy_offline`][rotframe.earth.astropy_offline].
astropy is imported by the parsers when they run, not with this module, so importing
it (and the core's `as_radians`) loads neither `astropy.units` nor
`astropy.coordinates`.
A hemisphere letter may follow an angle (S and W negate); each kind of angle takes
only its own letters (`HEMISPHERE_LETTERS`). Every refusal is a
[`ScenarioError`][rotframe.errors.ScenarioError] naming the parameter, the value and what is
allowed.
"""

from __future__ import annotations

import math
import re
import sys
from typing import TYPE_CHECKING

import numpy as np

from rotframe.earth.offline import astropy_offline
from rotframe.errors import ScenarioError

if TYPE_CHECKING:
    from astropy.coordinates import Angle

__all__ = [
    "HEMISPHERE_LETTERS",
    "parse_angle",
    "parse_latitude",
    "parse_longitude",
    "parse_azimuth",
    "angle_kind",
    "read_angle_text",
    "parse_length",
    "as_radians",
]

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
        by `astropy.coordinates.Angle` (``"48d50m46s N"``, ``"50d53m"``,
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
    import astropy.units as u

    ang = _to_angle(value, name)
    return float(ang.to_value(u.rad))


def parse_latitude(value, name: str = "latitude") -> float:
    """Parse a latitude and return it in radians, in [-pi/2, pi/2].

    Accepts the same forms as [`parse_angle`][rotframe.earth.parse_angle] (numbers are degrees, north positive;
    ``"33.9 S"`` is -33.9 deg). A trailing E or W is refused.

    Raises
    ------
    ScenarioError
        If the value cannot be read as an angle or lies beyond +-90 deg; the message names
        the value and the allowed range.
    """
    import astropy.units as u
    from astropy.coordinates import Latitude

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

    Accepts the same forms as [`parse_angle`][rotframe.earth.parse_angle]; a trailing N or S is refused.
    """
    import astropy.units as u
    from astropy.coordinates import Longitude

    ang = _to_angle(value, name, "longitude")
    with astropy_offline():
        lon = Longitude(ang, wrap_angle=180 * u.deg)
    return float(lon.to_value(u.rad))


def parse_azimuth(value, name: str = "azimuth") -> float:
    """Parse an azimuth or heading (clockwise from north) and return it in radians (not wrapped).

    Accepts the same forms as [`parse_angle`][rotframe.earth.parse_angle]; a trailing E or W reads as
    east or west of north (``"30 W"`` is -30 deg, astropy's sign), N or S is refused.
    """
    import astropy.units as u

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

    Every string that `astropy.coordinates.Angle` reads (with degrees as
    the default unit) means what astropy says: ``"48d50m46s"`` is +48.846 deg
    (the ``s`` is seconds), ``"48 50 46"``, ``"48:50:46"``, ``"48°50′46″"``,
    ``"0.8 rad"``, ``"12h30m"``; also any astropy Quantity string with an
    angular unit (``"3e1 deg"``, ``"100 arcmin"``). An upper-case hemisphere
    letter may follow the value, after a plain number too (``"33.9 S"``,
    ``"45N"``, ``"48d50m46s N"``): S and W negate. Refused with
    [`ScenarioError`][rotframe.errors.ScenarioError] naming ``name``, the value and what is allowed: a
    letter the kind does not take (N/S only for latitudes, E/W only for
    longitudes and azimuths, none for other named angles, any for ``kind="any"``,
    as astropy does) and a minus sign together
    with a letter (``"-45d S"``, a contradiction).

    Returns
    -------
    astropy.coordinates.Angle
    """
    import astropy.units as u
    from astropy.coordinates import Angle

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
    import astropy.units as u
    from astropy.coordinates import Angle

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
        `astropy.units.Quantity` with the imperial units enabled for the call
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
    import astropy.units as u

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



def as_radians(x):
    """Plain radians (float, or float64 array) from a float/array, or from an astropy angle Quantity.

    Core functions call it, so it does not import astropy: a Quantity can only exist once
    `astropy.units` has been imported by whoever made it.
    """
    u = sys.modules.get("astropy.units")
    if u is not None and isinstance(x, u.Quantity):
        x = x.to_value(u.rad)
    a = np.asarray(x, dtype=float)
    return float(a) if a.ndim == 0 else a


def _to_angle(value, name: str, kind: str = "any") -> Angle:
    """Read a scalar angle (numbers in degrees) as an astropy Angle; ScenarioError if not."""
    import astropy.units as u
    from astropy.coordinates import Angle

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
