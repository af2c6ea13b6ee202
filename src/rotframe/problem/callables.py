"""The user's functions: a fingerprint for the compile cache, numba compilation, checks in one line.

A user function (a force, a torque, an event, omega(t), a potential) is compiled with numba
inside a driver generated for the problem (`rotframe.problem.codegen`). The driver is
cached on disk under a name made from the fingerprints of the functions it calls, so a second
run (in any process) of the same functions compiles nothing, and an edited function gets a
new driver.

The fingerprint (`fingerprint`) covers the function's code object (bytecode, constants,
names, nested code), its defaults and closure values, and, recursively, every global it
names that is a function, a numba dispatcher or a plain value (number, string, tuple, array);
numba's version too. A module the function reaches through an attribute (``np.sin``) is
named, not hashed.
"""

from __future__ import annotations

import hashlib
import types

import numpy as np

from rotframe.errors import ScenarioError

__all__ = ["fingerprint", "plain_function", "display_name", "check_call", "UserFunctionError"]


class UserFunctionError(ScenarioError):
    """A user's function is unusable: wrong shape, non-finite, raises, or numba cannot compile it."""


def plain_function(f):
    """The Python function behind ``f`` (a numba dispatcher's ``py_func``, else ``f``)."""
    return getattr(f, "py_func", f)


def display_name(f) -> str:
    """``module.qualname`` of a user function, for messages."""
    f = plain_function(f)
    name = getattr(f, "__qualname__", None) or getattr(f, "__name__", None) or type(f).__name__
    module = getattr(f, "__module__", None)
    return f"{module}.{name}" if module and module not in ("__main__", "builtins") else name


def _feed(h, obj, seen, depth=0):
    if depth > 20:
        h.update(b"<deep>")
        return
    if isinstance(obj, types.CodeType):
        h.update(b"code")
        h.update(obj.co_code)
        h.update(repr(obj.co_names).encode())
        h.update(repr(obj.co_varnames).encode())
        h.update(repr(obj.co_freevars).encode())
        for c in obj.co_consts:
            _feed(h, c, seen, depth + 1)
        return
    target = plain_function(obj)
    if isinstance(target, types.FunctionType):
        if id(target) in seen:
            h.update(b"<seen>")
            return
        seen.add(id(target))
        h.update(f"fn {target.__module__}.{target.__qualname__}".encode())
        _feed(h, target.__code__, seen, depth + 1)
        _feed(h, target.__defaults__, seen, depth + 1)
        for cell in target.__closure__ or ():
            try:
                _feed(h, cell.cell_contents, seen, depth + 1)
            except ValueError:  # an empty cell
                h.update(b"<empty>")
        for name in _global_names(target.__code__):
            if name in target.__globals__:
                h.update(f"global {name}".encode())
                _feed(h, target.__globals__[name], seen, depth + 1)
        return
    if isinstance(obj, np.ndarray):
        h.update(f"array {obj.dtype} {obj.shape}".encode())
        h.update(np.ascontiguousarray(obj).tobytes())
        return
    if isinstance(obj, (tuple, list)):
        h.update(f"seq {len(obj)}".encode())
        for item in obj:
            _feed(h, item, seen, depth + 1)
        return
    if obj is None or isinstance(obj, (bool, int, float, complex, str, bytes)):
        h.update(repr(obj).encode())
        return
    if isinstance(obj, types.ModuleType):
        h.update(f"module {obj.__name__}".encode())
        return
    h.update(f"object {type(obj).__module__}.{type(obj).__qualname__}".encode())


def _global_names(code):
    names = set(code.co_names)
    for c in code.co_consts:
        if isinstance(c, types.CodeType):
            names |= _global_names(c)
    return sorted(names)


def fingerprint(*functions) -> str:
    """A hex digest that changes when any of ``functions`` (or what they call) changes."""
    import numba

    h = hashlib.sha256(f"numba {numba.__version__}".encode())
    seen: set[int] = set()
    for f in functions:
        _feed(h, f, seen)
    return h.hexdigest()[:20]


def check_call(role: str, f, args, shape, *, when: str) -> np.ndarray:
    """Call the plain Python ``f(*args)`` once and check its result's shape and finiteness.

    ``role`` names the argument (``forces[0]``), ``when`` the time and state (for messages).
    Returns the value as a float64 array.
    """
    try:
        out = plain_function(f)(*args)
    except Exception as exc:  # the user's function: whatever it raises is reported in one line
        raise UserFunctionError(f"{role} ({display_name(f)}) raised {type(exc).__name__}: {exc} {when}") from None
    try:
        arr = np.asarray(out, dtype=float)
    except (TypeError, ValueError):
        raise UserFunctionError(f"{role} ({display_name(f)}) returned {type(out).__name__}, not numbers, "
                                f"{when}") from None
    if arr.shape != shape:
        want = "a number" if shape == () else f"shape {shape}"
        raise UserFunctionError(f"{role} ({display_name(f)}) returned shape {arr.shape} {when}; expected {want}")
    if not np.all(np.isfinite(arr)):
        raise UserFunctionError(f"{role} ({display_name(f)}) returned {arr.tolist()} {when} (not finite)")
    return arr


def numba_reason(exc: BaseException) -> str:
    """numba's reason for a failed compile, in one line (its first informative line)."""
    text = str(exc)
    for line in text.splitlines():
        line = line.strip()
        if line and not line.startswith(("During:", "File ", "^", "Traceback", "- Resolution failure",
                                         "[1m", "\x1b")):
            return line[:300]
    return type(exc).__name__


def diagnose_compile(roles_and_functions, sample_args) -> str | None:
    """Which user function numba cannot compile alone, and why: ``"role (name): reason"`` or None."""
    import numba

    for role, f in roles_and_functions:
        args = sample_args(role)
        try:
            numba.njit(plain_function(f))(*args)
        except numba.core.errors.NumbaError as exc:
            return f"{role} ({display_name(f)}): numba cannot compile it: {numba_reason(exc)}"
        except Exception:  # it compiled; what it does at run time is checked elsewhere
            continue
    return None
