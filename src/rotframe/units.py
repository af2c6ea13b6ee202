"""Quantities at the doors: a value with an astropy unit converted to SI, or refused in one line.

The numerical core takes plain float64 in SI. Every public door converts what it is given: the
Python API (`rotframe.app.quantities`, which re-exports these), the built-in terms' and torques'
factories (`rotframe.forces`, `rotframe.torques`: `si_number`, `si_vector`). astropy is imported
only where a value carries a unit.
"""

from __future__ import annotations

import numbers

import numpy as np

from rotframe.errors import ScenarioError

__all__ = ["is_quantity", "holds_quantity", "to_si", "si_number", "si_vector"]


def is_quantity(value) -> bool:
    """An astropy Quantity (or anything that carries a unit and converts like one)."""
    return hasattr(value, "unit") and hasattr(value, "to_value")


def holds_quantity(value, depth: int = 0) -> bool:
    """``value`` is a Quantity, or a list, tuple or object array that holds one (at any depth up to 4)."""
    if is_quantity(value):
        return True
    if depth > 4:
        return False
    if isinstance(value, (list, tuple)):
        return any(holds_quantity(item, depth + 1) for item in value)
    if getattr(value, "dtype", None) is not None and getattr(value.dtype, "hasobject", False):
        return any(holds_quantity(item, depth + 1) for item in value.flat)
    return False


def to_si(value, unit: str, key: str):
    """``value`` with every Quantity in it converted to ``unit`` (a number, a list or a vector of them).

    The one converter of the Python doors (`rotframe.simulate`, `rotframe.simulate_body`): a
    plain value passes unchanged (SI already); a Quantity, or a list or tuple holding some, is
    converted element by element (angles as radians), so that no Quantity reaches the numerical
    core with its unit dropped. A Quantity of another dimension is a one-line `ScenarioError`
    naming ``key``, its unit and ``unit``.
    """
    if not holds_quantity(value):
        return value
    if is_quantity(value):
        import astropy.units as u

        try:
            return value.to_value(u.Unit(unit) if unit else u.dimensionless_unscaled,
                                  equivalencies=u.dimensionless_angles())
        except (u.UnitsError, TypeError, ValueError):
            shown = " ".join(str(value).split())[:60]
            raise ScenarioError(f"{key}: {value.unit.to_string() or 'dimensionless'} cannot be converted to "
                                f"{unit or 'a plain number'} ({shown})") from None
    return [to_si(item, unit, f"{key}[{k}]") for k, item in enumerate(value)]  # a list, tuple or object array


def si_number(caller: str, key: str, value, unit: str) -> float:
    """A scalar argument of ``caller`` in SI: a real number (taken as ``unit`` already) or a Quantity converted
    to ``unit``; finite. A bool, a string, a complex or a Quantity of another dimension is a one-line
    ScenarioError naming ``caller``, ``key`` and ``unit``."""
    x = to_si(value, unit, f"{caller}: {key}") if is_quantity(value) else value
    real = isinstance(x, numbers.Real) or (np.ndim(x) == 0 and getattr(np.asarray(x).dtype, "kind", "") in "iuf")
    if isinstance(x, (bool, np.bool_)) or not real or np.ndim(x) != 0:
        raise ScenarioError(f"{caller}: {key}={value!r} is not a number; it must be a real number ({unit}) or a "
                            f"Quantity of it")
    x = float(x)
    if not np.isfinite(x):
        raise ScenarioError(f"{caller}: {key}={value!r} is not finite")
    return x


def si_vector(caller: str, key: str, value, unit: str) -> tuple:
    """A 3-vector argument of ``caller`` in SI, as three floats: numbers taken as ``unit`` already, or a Quantity
    (or a list of them) converted; `rotframe.validation.check_vector3`'s one-line refusal of any other shape, a
    string or a non-finite component."""
    from rotframe.validation import check_vector3

    if isinstance(value, (str, bytes)):
        raise ScenarioError(f"{caller}: {key} = {value!r} is not numbers; it must be 3 numbers ({unit}) or a "
                            "Quantity of them")
    value = to_si(value, unit, f"{caller}: {key}")
    return tuple(float(c) for c in check_vector3(value, key, ScenarioError, caller=caller, unit=unit))
