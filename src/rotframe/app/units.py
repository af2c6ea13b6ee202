"""Units of the numbers in a run summary: the ``units`` map of ``rotframe run --json``.

Parameters carry their unit in the scenario file. Metric, theory and
diagnostic names end in their unit (``east_deflection_m``,
``precession_rate_deg_per_hour``, ``energy_rel_drift``); [`quantity_unit`][rotframe.app.units.quantity_unit]
reads it from the name. Pure standard library: importing this module is free.

Examples
--------
>>> quantity_unit("east_deflection_m")
'm'
>>> quantity_unit("precession_rate_deg_per_hour")
'deg/h'
>>> quantity_unit("energy_rel_drift")
''
>>> quantity_unit("sleeping_top_stable") is None
True
"""

from __future__ import annotations

from typing import Any, Mapping

__all__ = ["quantity_unit", "summary_units"]

#: Name endings and their unit strings (astropy spelling), longest first.
_SUFFIXES = (
    ("_deg_per_hour", "deg/h"),
    ("_rad_s2", "rad/s^2"),
    ("_rad_s", "rad/s"),
    ("_rel_drift", ""),
    ("_rel_error", ""),
    ("_sidereal_days", "sidereal day"),
    ("_hours", "h"),
    ("_urad", "urad"),
    ("_deg", "deg"),
    ("_rad", "rad"),
    ("_km", "km"),
    ("_mm", "mm"),
    ("_m", "m"),
    ("_s", "s"),
)
#: Names without a unit ending that are pure numbers.
_DIMENSIONLESS = ("turns", "flips")


def quantity_unit(name: str) -> str | None:
    """The unit string of a metric or diagnostic named ``name``, ``''`` if dimensionless, None if unknown."""
    for suffix, unit in _SUFFIXES:
        if name.endswith(suffix):
            return unit
    if name in _DIMENSIONLESS:
        return ""
    if name.startswith("hours_per_"):
        return "h"
    return None


def summary_units(parameters: Mapping[str, Any], summary: Mapping[str, Any]) -> dict[str, str]:
    """``{name: unit}`` for every parameter (from the scenario) and every metric and diagnostic it can name.

    Parameters
    ----------
    parameters : mapping
        ``{name: Parameter}`` of the scenario (objects with a ``unit`` attribute).
    summary : mapping
        A run summary with ``params``, ``metrics`` and ``diagnostics``.
    """
    units: dict[str, str] = {}
    for key in summary.get("params", {}):
        p = parameters.get(key)
        units[key] = getattr(p, "unit", "") or ""
    for section in ("metrics", "diagnostics"):
        for key in summary.get(section, {}) or {}:
            unit = quantity_unit(key)
            if unit is not None:
                units.setdefault(key, unit)
    return units
