"""A value typed by a user: a plain number in the documented unit, or an astropy quantity string.

One parser for every value with a unit on the command line and in scenario files
(``--set height='520 ft'``, ``rotframe section tube --set thickness='0.25 inch'``):
a plain number is taken as already in the target unit; anything else is read by
`astropy.units.Quantity` with the imperial units enabled for this parse only
and converted to the target unit. astropy is imported only when a string is not a
plain number.
"""

from __future__ import annotations

# the converter of every door (the Python API, the built-in terms' factories) lives below the layers that use it
from rotframe.units import holds_quantity, is_quantity, to_si  # noqa: F401  (re-exported: their home is rotframe.units)

__all__ = ["NotAQuantity", "WrongDimension", "value_in", "first_line", "as_quantities", "is_quantity", "holds_quantity",
           "to_si", "vector_or_table_si", "params_si", "astropy_unit"]


class NotAQuantity(ValueError):
    """The text is neither a number nor a quantity (the message: astropy's first line)."""


class WrongDimension(ValueError):
    """A quantity of another dimension than the target unit's: ``unit`` is the one found."""

    def __init__(self, message, unit):
        super().__init__(message)
        self.unit = unit


def value_in(text: str, unit: str) -> float:
    """``text`` as a float in ``unit`` (``""``: dimensionless).

    Parameters
    ----------
    text : str
        ``"158.5"`` (already in ``unit``) or a quantity such as ``"520 ft"``.
    unit : str
        An astropy unit name.

    Raises
    ------
    NotAQuantity
        ``text`` does not parse, or the conversion fails arithmetically.
    WrongDimension
        ``text`` parses to a quantity that does not convert to ``unit``.
    """
    try:
        return float(text)
    except ValueError:
        pass
    import astropy.units as u
    from astropy.units import imperial

    q = None
    with imperial.enable():  # "520 ft", "4 inch", "30 mi/h", only for this parse
        try:
            q = u.Quantity(text)
            target = u.Unit(unit) if unit else u.dimensionless_unscaled
            return float(q.to_value(target))
        except (u.UnitConversionError, u.UnitTypeError) as exc:
            raise WrongDimension(first_line(exc), getattr(q, "unit", None)) from None
        except (ValueError, TypeError, ArithmeticError) as exc:
            raise NotAQuantity(first_line(exc)) from None


def first_line(exc) -> str:
    """The first sentence of an exception's message (astropy's run to several lines of advice)."""
    text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return text.split(". ")[0].rstrip(".")


#: unit strings of the summary (`rotframe.app.units`) that astropy spells otherwise
_ASTROPY_SPELLING = {"sidereal day": "sday"}


def as_quantities(values, units) -> dict:
    """``{name: value}`` with each number as an astropy Quantity in ``units[name]``.

    A name without a known unit, and a value that is not a number (a bool, None,
    a string), stay as they are; ``""`` gives a dimensionless Quantity.
    """
    import astropy.units as u

    out = {}
    for name, value in values.items():
        unit = units.get(name)
        if unit is None or isinstance(value, bool) or not isinstance(value, (int, float)):
            out[name] = value
            continue
        try:
            out[name] = u.Quantity(float(value), u.Unit(_ASTROPY_SPELLING.get(unit, unit)) if unit else u.one)
        except ValueError:
            out[name] = value
    return out


def astropy_unit(unit: str) -> str:
    """A summary unit string as astropy spells it (``"sidereal day"`` -> ``"sday"``)."""
    return _ASTROPY_SPELLING.get(unit, unit)


def vector_or_table_si(value, unit: str, key: str):
    """A 3-vector or a table ``(times, vectors[, how])`` in SI: times in s, vectors in ``unit``; other forms
    unchanged."""
    from rotframe.problem.frame import is_table

    if callable(value) or hasattr(value, "trajectory"):
        return value  # a function (its return is checked: plain numbers) or a rigid-body Result
    if is_table(value):
        return (to_si(value[0], "s", f"{key} (the table's times)"), to_si(value[1], unit, f"{key} (the table's vectors)"),
                *value[2:])
    return to_si(value, unit, key)


def params_si(params, key: str = "params"):
    """``params`` with each Quantity in SI base units (astropy's ``.si``: km/h -> m/s, deg -> rad).

    A user's function receives plain numbers; rotframe cannot know which unit it wants but SI,
    the unit of everything else it is given.
    """
    if not holds_quantity(params):
        return params
    if is_quantity(params):  # one Quantity array: its values are the parameters
        params = list(params)
    if not isinstance(params, (list, tuple)):
        return params

    def si(item, where):
        if is_quantity(item):
            return to_si(item, item.si.unit.to_string(), where)
        if isinstance(item, (list, tuple)) and holds_quantity(item):
            return [si(x, f"{where}[{j}]") for j, x in enumerate(item)]
        return item

    return tuple(si(item, f"{key}[{k}]") for k, item in enumerate(params))
