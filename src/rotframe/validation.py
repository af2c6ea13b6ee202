"""Input validation shared by every layer: 3-vectors, and the guard of public functions.

`check_vector3` is the one check of a 3-vector (or a stack of them) for
every module; its error names the caller, the argument, the value and what is
allowed, in the error class the caller gives.

Public functions refuse text, complex and object input with a RotframeError.

`guard_public` wraps the plain-Python functions a module exports so that

* an argument holding complex numbers is refused before anything is computed
  (``np.asarray(z, dtype=float)`` would silently drop the imaginary part: a
  complex matrix is not a rotation);
* a ``TypeError`` / ``ValueError`` / ``IndexError`` raised while numpy converts
  junk (a string, ``None``, an object, a ragged list) becomes the module's
  [`RotframeError`][rotframe.errors.RotframeError] subclass, which is still a
  ``ValueError``, with one line naming the function; so does an arithmetic error
  (an integer too large for a float, a division by zero in object input);
* a result holding a NaN (from a NaN or infinite input, an overflow, a degenerate
  body) is refused the same way, never returned silently.

Errors the functions raise on purpose pass unchanged. Compiled (numba)
functions are left alone.
"""

from __future__ import annotations

import functools
import inspect
import types

import numpy as np

from rotframe.errors import RotframeError

__all__ = ["guard_public", "check_vector3"]


def _has_complex(value) -> bool:
    if isinstance(value, (complex, np.complexfloating)):
        return True
    if isinstance(value, np.ndarray):
        return np.iscomplexobj(value)
    if isinstance(value, (list, tuple)) and len(value) <= 100_000:
        return any(_has_complex(v) for v in value)
    return False


def _has_nan(value) -> bool:
    """True if ``value`` (a number, an array, or a tuple or list of them) holds a NaN."""
    if isinstance(value, (float, np.floating)):
        return value != value
    if isinstance(value, np.ndarray):
        return value.dtype.kind in "fc" and bool(np.isnan(value).any())
    if isinstance(value, (tuple, list)) and len(value) <= 64:
        return any(_has_nan(v) for v in value)
    return False


def _guard(func, error_cls, error_for=None):
    names = list(inspect.signature(func).parameters)

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        for i, value in enumerate(args):
            if _has_complex(value):
                name = names[i] if i < len(names) else f"argument {i + 1}"
                raise _error(error_cls, error_for, func.__name__, f"{name} has complex values; allowed: real numbers")
        for name, value in kwargs.items():
            if _has_complex(value):
                raise _error(error_cls, error_for, func.__name__, f"{name} has complex values; allowed: real numbers")
        try:
            # numpy's warnings of an invalid or infinite input (cos(inf)) are not the answer: the NaN check below is,
            # in one line (a warning turned into an error by the caller's filters would escape as a traceback)
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                result = func(*args, **kwargs)
        except RotframeError:
            raise
        except (TypeError, ValueError, IndexError, ArithmeticError) as exc:
            text = " ".join(str(exc).split())[:200] or type(exc).__name__
            raise _error(error_cls, error_for, func.__name__,
                         f"invalid input ({text}); allowed: real numbers or arrays of them as documented") from exc

        if _has_nan(result):
            raise _error(error_cls, error_for, func.__name__,
                         "the result is not a number (NaN): an input is NaN or infinite, too large, or "
                         "degenerate; allowed: finite inputs in the documented ranges")
        return result

    wrapper.__wrapped_public__ = True
    return wrapper


def _error(error_cls, error_for, fname, message):
    cls = (error_for or {}).get(fname, error_cls)
    return cls(f"{fname}: {message}")


def guard_public(namespace: dict, names, error_cls, error_for=None) -> None:
    """Wrap, in ``namespace``, every plain function among ``names`` (see the module docstring).

    ``error_for`` maps a function name to a more specific error class.
    """
    for name in names:
        func = namespace.get(name)
        if isinstance(func, types.FunctionType) and not getattr(func, "__wrapped_public__", False):
            namespace[name] = _guard(func, error_cls, error_for)


def check_vector3(value, name: str, error_cls: type[Exception] = ValueError, *, stack: bool = False,
                  finite: bool = True, unit: str = "", caller: str = "") -> np.ndarray:
    """``value`` as a float64 3-vector, shape ``(3,)`` (or ``(..., 3)`` with ``stack=True``).

    Parameters
    ----------
    value : array_like
        The argument as given.
    name : str
        Its name, as the caller's signature spells it.
    error_cls : type
        Error raised (a [`RotframeError`][rotframe.errors.RotframeError] subclass in the
        public API, so that the CLI exits with code 2).
    stack : bool
        Accept any leading shape ``(..., 3)`` instead of exactly ``(3,)``.
    finite : bool
        Also refuse NaN and infinite components.
    unit : str
        Unit named in the message (e.g. ``"m"``).
    caller : str
        Function named at the start of the message.

    Returns
    -------
    ndarray
        ``np.asarray(value, dtype=float64)``.

    Raises
    ------
    error_cls
        One line: ``[caller: ]name = VALUE has shape S; it must be ...`` (e.g.
        ``(..., 3)``, ``3 finite numbers (m)``).
    """
    where = f"{caller}: " if caller else ""
    units = f" ({unit})" if unit else ""
    if _has_complex(value):  # before the conversion, which would drop the imaginary part with a warning (a ragged
        # list too, which numpy's own test of complexity cannot read: it is refused below, as not numbers)
        raise error_cls(f"{where}{name} = {value!r} is complex; it must be real{units}")
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):  # text, a ragged list, complex, an object
        shown = " ".join(str(value).split())[:60]
        raise error_cls(f"{where}{name} = {shown!r} is not numbers; it must be "
                        f"{'(..., 3) numbers' if stack else '3 numbers'}{units}") from None
    shape_ok = (a.ndim >= 1 and a.shape[-1] == 3) if stack else a.shape == (3,)
    if shape_ok and (not finite or np.all(np.isfinite(a))):
        return a
    shown = np.asarray(value).ravel()[:6].tolist()
    if np.asarray(value).size > 6:
        shown = str(shown)[:-1] + ", ...]"
    allowed = "(..., 3)" if stack else "3 numbers"
    if finite:
        allowed = ("finite, " if stack else "3 finite numbers") + (allowed if stack else "")
    raise error_cls(f"{where}{name} = {shown} has shape {a.shape}; it must be {allowed}{units}")


def refuse_units(value, key: str, error_cls: type[Exception] = ValueError, depth: int = 0) -> None:
    """Refuse a value that carries a unit (an astropy Quantity, or a list or tuple holding one).

    The numerical core takes plain float64 in SI; `numpy.asarray` would drop a Quantity's unit
    without a word (milliseconds read as seconds). The Python doors convert Quantities first
    (`rotframe.app.quantities.to_si`), so one that reaches the core was not converted: it is
    refused in one line naming ``key``.
    """
    if hasattr(value, "unit") and hasattr(value, "to_value"):
        raise error_cls(f"{key}: a Quantity ({value.unit}) is not converted here; pass plain SI numbers (the "
                        "public doors, rotframe.simulate and simulate_body, convert Quantities)")
    if depth < 4 and isinstance(value, (list, tuple)):
        for k, item in enumerate(value):
            refuse_units(item, f"{key}[{k}]", error_cls, depth + 1)
