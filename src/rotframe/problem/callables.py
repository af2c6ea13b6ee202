"""The user's functions: a fingerprint for the compile cache, numba compilation, checks in one line.

A user function (a force, a torque, an event, omega(t), a potential) is compiled with numba
inside a driver generated for the problem (`rotframe.problem.codegen`). The driver is
cached on disk under a name made from the fingerprints of the functions it calls, so a second
run (in any process) of the same functions compiles nothing, and an edited function gets a
new driver.

The fingerprint (`fingerprint`) covers the function's code object (bytecode, constants,
names, nested code), its defaults and closure values, and, recursively, every global it
names, each by value: numba freezes every value a compiled function reads, so a value that
changed must give a new driver. Numbers and numpy scalars are hashed by type and bytes, arrays
by their bytes, a module by the attributes the code names (``cfg.K``), functions by their code
and what they read; numba's version too. A value that cannot be hashed by value raises
`Unfingerprintable`, and the problem's driver is then compiled for this run alone, not cached.
"""

from __future__ import annotations

import enum
import functools
import hashlib
import inspect
import re
import types

import numpy as np

from rotframe.errors import ScenarioError

__all__ = ["blame_in_step", "raised_during_run", "fingerprint", "Unfingerprintable", "cache_key", "plain_function", "compiled_for_glue", "display_name", "check_call",
           "check_compilable", "UserFunctionError", "read_only_args", "raised_message", "readonly_view",
           "readonly_array", "event_names"]


class UserFunctionError(ScenarioError):
    """A user's function is unusable: wrong shape, non-finite, raises, or numba cannot compile it.

    Raised during a run, it carries ``t_reached`` and ``partial`` (the samples up to there), as an
    `rotframe.errors.IntegrationError` does (`raised_during_run`).
    """


def blame_in_step(candidates, t: float, dt: float):
    """Which user function raises or gives a non-finite value near a failed step, called again in plain Python.

    ``candidates``: ``(role, f, args_of, where)``, ``args_of(tp)`` the arguments of ``f`` at time
    ``tp`` (the last finite state's), ``where`` the state for the message. Each is probed at
    ``t`` and inside the failed step ``(t, t + dt]`` (a function that fails at a time, not a
    state, fails only there). Returns ``("; <one line>", raised)``, or ``("", False)`` when none
    fails.
    """
    probes = [t] + [t + s * dt for s in (1e-3, 0.1, 0.5, 1.0) if dt > 0.0]
    for role, f, args_of, where in candidates:
        for tp in probes:
            when = f"at t = {tp:.9g} s{where}"
            try:  # as plain Python a function may raise where compiled it gave NaN (math.sqrt(-1))
                value = np.asarray(plain_function(f)(*args_of(tp)), dtype=float)
            except Exception as exc:  # the user's function, reported in the message
                return "; " + raised_message(role, f, exc, when), True
            if not np.all(np.isfinite(value)):
                return f"; {role} ({display_name(f)}) returned {value.tolist()} {when}", False
    return "", False


def raised_during_run(message: str, t_reached: float, partial) -> UserFunctionError:
    """A `UserFunctionError` for a user function that raised during a run, with the time and the samples kept."""
    err = UserFunctionError(message)
    err.t_reached, err.partial = t_reached, partial
    return err


def plain_function(f):
    """The Python function behind ``f`` (a numba dispatcher's ``py_func``, else ``f``)."""
    return getattr(f, "py_func", f)


def compiled_for_glue(f):
    """``f`` as numba compiles it for a problem's glue (`rotframe.problem.glue`), which alone calls it.

    Inlined into the glue (numba's ``inline="always"``: one function to compile, not two) and
    without numba's CPython and C entry points (``no_cpython_wrapper``, ``no_cfunc_wrapper``):
    compiled code calls it, Python never does. Making those entry points was most of what a changed
    force waited for (measured: 0.37 s -> 0.15 s for a spring's force and its glue), and compiling
    the force apart from its glue a quarter of the rest (0.15 s -> 0.11 s).
    """
    import numba

    py = plain_function(f)
    # numba's inliner cannot take a function of *args (it fails with no message): such a function is compiled on
    # its own, as numba can (**keywords are refused before: `check_compilable`)
    starred = bool(getattr(py, "__code__", None) and py.__code__.co_flags & inspect.CO_VARARGS)
    return numba.njit(py, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True,
                      inline="never" if starred else "always")


def reads_argument(f, index: int) -> bool:
    """Whether the function ``f`` may read its argument number ``index`` (0-based), from its bytecode.

    True when the code loads the argument's name anywhere (a read, or a pass to another
    function), when an inner function captures it, or when ``index`` falls in ``*args``; so a
    False is certain: the argument is never looked at. Used to find the forces of ``(t, r)`` alone
    that a splitting can take as kicks.

    Examples
    --------
    >>> reads_argument(lambda t, r, v: (0.0, 0.0, -r[2]), 2), reads_argument(lambda t, r, v: v, 2)
    (False, True)
    """
    code = getattr(plain_function(f), "__code__", None)
    if code is None or index >= code.co_argcount:
        return True
    return _code_reads(code, index)


@functools.lru_cache(maxsize=1024)
def _code_reads(code, index: int) -> bool:
    """`reads_argument` of a function's ``code``, read once per code object (a run's set-up asks for each force)."""
    import dis

    name = code.co_varnames[index]
    if name in code.co_cellvars:
        return True
    for ins in dis.get_instructions(code):
        if ins.opname.startswith("LOAD_FAST") or ins.opname == "DELETE_FAST":
            value = ins.argval
            if value == name or (isinstance(value, tuple) and name in value):
                return True
    return False


def display_name(f) -> str:
    """``module.qualname`` of a user function, for messages."""
    f = plain_function(f)
    name = getattr(f, "__qualname__", None) or getattr(f, "__name__", None) or type(f).__name__
    module = getattr(f, "__module__", None)
    return f"{module}.{name}" if module and module not in ("__main__", "builtins") else name


class Unfingerprintable(Exception):
    """A value a user function reads that rotframe cannot hash by value (its driver is then not cached)."""


#: deeper than this, a value is not hashed but refused (never skipped)
_MAX_DEPTH = 60


def _feed(h, obj, seen, names=(), depth=0):
    """Hash ``obj`` by value into ``h``; ``names``: the attribute names the code that reads it uses.

    numba freezes every global, closure value and default a compiled function reads, so each is
    hashed by its value: numbers and numpy scalars by type and bytes, arrays by their bytes, a
    module by the attributes the code names (``cfg.K`` hashes ``cfg.K``'s value), functions by
    their code and what that reads. A value of any other kind raises `Unfingerprintable`.
    """
    if depth > _MAX_DEPTH:
        raise Unfingerprintable(f"values nested deeper than {_MAX_DEPTH} levels")
    if isinstance(obj, types.CodeType):
        h.update(b"code")
        h.update(obj.co_code)
        h.update(repr(obj.co_names).encode())
        h.update(repr(obj.co_varnames).encode())
        h.update(repr(obj.co_freevars).encode())
        for c in obj.co_consts:
            _feed(h, c, seen, names, depth + 1)
        return
    target = plain_function(obj)
    if isinstance(target, types.FunctionType):
        if id(target) in seen:
            h.update(f"<seen {target.__qualname__}>".encode())
            return
        seen.add(id(target))
        from rotframe.numerics.compiled import global_names

        code_names = sorted(global_names(target.__code__))
        h.update(f"fn {target.__module__}.{target.__qualname__}".encode())
        _feed(h, target.__code__, seen, code_names, depth + 1)
        _feed(h, target.__defaults__, seen, code_names, depth + 1)
        _feed(h, target.__kwdefaults__, seen, code_names, depth + 1)
        for cell in target.__closure__ or ():
            try:
                value = cell.cell_contents
            except ValueError:  # an empty cell
                h.update(b"<empty>")
                continue
            _feed(h, value, seen, code_names, depth + 1)
        for name in code_names:
            if name in target.__globals__:
                h.update(f"global {name}".encode())
                _feed(h, target.__globals__[name], seen, code_names, depth + 1)
        return
    if isinstance(obj, np.generic):  # before the Python numbers: np.float64 is a float
        h.update(f"scalar {obj.dtype.str} ".encode())
        h.update(obj.tobytes())
        return
    if obj is None or obj is Ellipsis or isinstance(obj, (bool, int, float, complex, str, bytes)):
        h.update(f"{type(obj).__module__}.{type(obj).__qualname__} {obj!r}".encode())
        return
    if isinstance(obj, np.ndarray):
        if obj.dtype.hasobject:
            raise Unfingerprintable("an array of Python objects")
        h.update(f"array {obj.dtype.str} {obj.shape}".encode())
        h.update(np.ascontiguousarray(obj).tobytes())
        return
    if isinstance(obj, (tuple, list)):
        h.update(f"seq {type(obj).__qualname__} {len(obj)}".encode())
        for item in obj:
            _feed(h, item, seen, names, depth + 1)
        return
    if isinstance(obj, dict) and all(isinstance(k, str) for k in obj):  # keyword defaults
        h.update(f"dict {len(obj)}".encode())
        for key in sorted(obj):
            h.update(key.encode())
            _feed(h, obj[key], seen, names, depth + 1)
        return
    if isinstance(obj, types.ModuleType):
        if id(obj) in seen:
            h.update(f"<seen module {obj.__name__}>".encode())
            return
        seen.add(id(obj))
        h.update(f"module {obj.__name__}".encode())
        for name in names:  # what the code can read of it: cfg.K, np.pi, math.sin
            if name in vars(obj):
                h.update(f"attr {name}".encode())
                _feed(h, vars(obj)[name], seen, names, depth + 1)
        return
    if isinstance(obj, enum.EnumMeta):  # numba freezes the members of an Enum class it reads
        h.update(f"enum {obj.__module__}.{obj.__qualname__}".encode())
        for member in obj:
            _feed(h, (member.name, member.value), seen, names, depth + 1)
        return
    if isinstance(obj, type):
        h.update(f"type {obj.__module__}.{obj.__qualname__}".encode())
        return
    if isinstance(obj, (types.BuiltinFunctionType, np.ufunc)):  # math.sin, np.sin: code, not values
        module = getattr(obj, "__module__", None) or type(obj).__name__
        h.update(f"builtin {module}.{getattr(obj, '__qualname__', obj.__name__)}".encode())
        return
    raise Unfingerprintable(f"a value of type {type(obj).__module__}.{type(obj).__qualname__}")


def fingerprint(*functions) -> str:
    """A hex digest that changes when any of ``functions`` (or what they read) changes.

    Raises
    ------
    Unfingerprintable
        A function reads a value that cannot be hashed by value (then its driver is not cached).
    """
    import numba

    h = hashlib.sha256(f"numba {numba.__version__}".encode())
    seen: set[int] = set()
    for f in functions:
        _feed(h, f, seen)
    return h.hexdigest()[:20]


def cache_key(roles, extra: str):
    """The driver's cache key from the fingerprints of ``roles`` (``[(role, function)]``), and a note.

    Returns ``(key, None)``, or ``(None, note)`` when a function reads a value that cannot be
    hashed by value: the driver is then compiled for this run alone (never reused with a stale
    value), and the note says which function and why.
    """
    try:
        return fingerprint(*(f for _, f in roles)) + extra, None
    except Unfingerprintable:
        pass
    for role, f in roles:
        try:
            fingerprint(f)
        except Unfingerprintable as exc:
            return None, (f"{role} ({display_name(f)}) reads {exc}, which rotframe cannot fingerprint: its "
                          "driver was compiled for this run alone (not cached)")
    return None, "a user function reads a value rotframe cannot fingerprint: its driver was not cached"


def check_compilable(role: str, f, jit: bool) -> None:
    """A function numba can compile is a plain ``def`` (or a numba dispatcher); anything else is refused by name.

    A ``functools.partial``, a bound method or an object with ``__call__`` runs with ``jit=False`` only.
    """
    target = plain_function(f)
    if not callable(target):
        raise UserFunctionError(f"{role}: {str(f)[:60]!r} is not callable")
    if jit and not isinstance(target, types.FunctionType):
        kind = type(target).__module__ + "." + type(target).__qualname__
        raise UserFunctionError(f"{role}: a {kind} ({display_name(f)}) is not a function numba can compile; write "
                                "it as a def (bound values go in params=, or a closure), or pass jit=False")
    if jit and target.__code__.co_flags & inspect.CO_VARKEYWORDS:
        raise UserFunctionError(f"{role} ({display_name(f)}) takes **keywords, which numba cannot compile; drop "
                                "them (its parameters come from params=, by position), or pass jit=False")


def check_call(role: str, f, args, shape, *, when: str) -> np.ndarray:
    """Call the plain Python ``f(*args)`` once and check its result's shape and finiteness.

    ``role`` names the argument (``forces[0]``), ``when`` the time and state (for messages).
    Returns the value as a float64 array.
    """
    args = read_only_args(args)
    try:
        out = plain_function(f)(*args)
    except Exception as exc:  # the user's function: whatever it raises is reported in one line
        raise UserFunctionError(raised_message(role, f, exc, when)) from None
    if hasattr(out, "unit") or (isinstance(out, (tuple, list)) and any(hasattr(x, "unit") for x in out)):
        raise UserFunctionError(f"{role} ({display_name(f)}) returned a Quantity {when}; a function returns plain "
                                "numbers in SI (m/s^2, rad/s, N m): its unit would be dropped")
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


def readonly_view(a):
    """A view of ``a`` that cannot be written (the plain-Python twin of `rotframe.problem.readonly.readonly`)."""
    view = a.view()
    view.flags.writeable = False
    return view


def readonly_array(a) -> np.ndarray:
    """A read-only float64 copy of ``a`` (a parameter, or an argument of a probe outside the drivers)."""
    out = np.array(a, dtype=float)
    out.flags.writeable = False
    return out


def read_only_args(args) -> tuple:
    """``args`` with each array a read-only float64 copy: a function's arguments are never its to write."""
    return tuple(readonly_array(a) if isinstance(a, np.ndarray) and a.flags.writeable else a for a in args)


#: what a write into a read-only argument says, in numpy (plain Python) and in numba (compiling)
_WRITE_SIGNS = ("assignment destination is read-only", "setitem(readonly array", "readonly array")


def writes_into_arguments(text: str) -> bool:
    """The message of a function that wrote into its read-only arguments (numpy's or numba's)."""
    return any(sign in text for sign in _WRITE_SIGNS)


def raised_message(role: str, f, exc: BaseException, when: str) -> str:
    """One line for a user function that raised: a write into its arguments is named as such."""
    if writes_into_arguments(str(exc)):
        return (f"{role} ({display_name(f)}) writes into one of its arguments {when}; they are read-only (the "
                "integrator's own state): work on a copy (r = r.copy())")
    return f"{role} ({display_name(f)}) raised {type(exc).__name__}: {exc} {when}"


_ANSI = re.compile(r"\x1b\[[0-9;]*m")
#: lines of numba's message that frame its reason rather than give it
_FRAMING = ("Failed in ", "During:", "File ", "^", "Traceback", "- Resolution failure", "<source missing",
            "Enable logging", "This error may have been caused", "There are ", "For more information",
            "Rewrite ", "raised from ", "No implementation of function Function(<built-in function setitem>)")


def numba_reason(exc: BaseException) -> str:
    """numba's reason for a failed compile, in one line: its informative lines, without colour codes.

    numba starts with the pipeline step that failed ("Failed in nopython mode pipeline (step:
    nopython frontend)"), which says where, not why; the lines after it say why ("Untyped global
    name 'cfg': Cannot determine Numba type of <class 'Cfg'>").
    """
    lines = [" ".join(_ANSI.sub("", line).split()) for line in str(exc).splitlines()]
    useful = []
    for line in lines:
        if line.startswith("File "):  # the source lines that follow are context, not the reason
            break
        if line and not line.startswith(_FRAMING):
            useful.append(line)
    if not useful:
        return type(exc).__name__
    return "; ".join(useful[:2])[:300]


def diagnose_compile(roles_and_functions, sample_args) -> str | None:
    """Which user function numba cannot compile alone, and why: ``"role (name): reason"`` or None."""
    import numba

    for role, f in roles_and_functions:
        args = read_only_args(sample_args(role))  # as the drivers pass them: read-only
        try:
            numba.njit(plain_function(f))(*args)
        except numba.core.errors.NumbaError as exc:
            if writes_into_arguments(str(exc)):
                return (f"{role} ({display_name(f)}) writes into one of its arguments; they are read-only (the "
                        "integrator's own state): work on a copy (r = r.copy())")
            return f"{role} ({display_name(f)}): numba cannot compile it: {numba_reason(exc)}"
        except Exception:  # it compiled; what it does at run time is checked elsewhere
            continue
    return None


def event_names(events):
    """Each event's name in ``Result.trajectory.event_times``: its function's ``__name__`` (``event_k`` for a lambda
    or none), numbered ``_2``, ``_3``... where names repeat."""
    names = []
    for k, g in enumerate(events):
        base = getattr(plain_function(g), "__name__", "") or f"event_{k}"
        if base == "<lambda>":
            base = f"event_{k}"
        name = base
        j = 2
        while name in names:
            name = f"{base}_{j}"
            j += 1
        names.append(name)
    return names
