"""A value typed by a user: a plain number in the documented unit, or an astropy quantity string.

One parser for every value with a unit on the command line and in scenario files
(``--set height='520 ft'``, ``rotframe section tube --set thickness='0.25 inch'``):
a plain number is taken as already in the target unit; anything else is read by
`astropy.units.Quantity` with the imperial units enabled for this parse only
and converted to the target unit. astropy is imported only when a string is not a
plain number.
"""

from __future__ import annotations

__all__ = ["NotAQuantity", "WrongDimension", "value_in", "first_line", "as_quantities"]


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
