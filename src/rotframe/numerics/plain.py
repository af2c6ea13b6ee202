"""Compiled functions as plain Python: the same functions, with every compiled callee its Python original.

The engine of your own problems runs this way with ``jit=False``; the rigid body's starting step
runs the shared `rotframe.numerics.step_control` functions this way (a few microseconds, nothing
to compile).

A numba dispatcher's ``py_func`` is the Python function it was made from, but that function
still calls its module's compiled neighbours, which cannot take plain Python functions as
arguments. `plain` remakes a function over a copy of its globals in which every numba
dispatcher is itself remade this way, so a whole call tree runs as Python (slow: for a user
function numba cannot compile). No source is copied: the code objects are the modules' own.
"""

from __future__ import annotations

import types

from numba.core.dispatcher import Dispatcher

__all__ = ["plain"]

# the remakes, by the id of what they remake, each beside that object itself: held, it keeps its id, which another
# object (a later problem's glue, a loop bound to other functions) would otherwise reuse once it was freed, and
# be given this one's remake (found: a run's events called another problem's functions)
_SPACES: dict[int, tuple[dict, dict]] = {}  # id of a globals dict (a module's, or a bound copy's) -> (it, its remake)
_PLAIN: dict[int, tuple[types.FunctionType, types.FunctionType]] = {}  # id of a function -> (it, its remake)


def _space(py) -> dict:
    """The globals of function ``py`` with each numba dispatcher replaced by its plain remake (made once).

    Its module's, or its own where it has globals of its own (a loop bound to a system's functions:
    `rotframe.numerics.compiled.bound`).
    """
    original = py.__globals__
    held, space = _SPACES.get(id(original), (None, None))
    if held is not original:
        space = dict(original)
        _SPACES[id(original)] = (original, space)  # before the remakes: a module's functions call each other
        for name, value in original.items():
            if isinstance(value, Dispatcher):
                space[name] = plain(value)
    return space


def plain(f):
    """``f`` (a numba dispatcher or a function) as a Python function whose compiled callees are plain too."""
    override = getattr(f, "plain", None)  # a helper that has no Python form of its own (rotframe.problem.calls)
    if override is not None:
        return override
    py = getattr(f, "py_func", f)
    held, made = _PLAIN.get(id(py), (None, None))
    if held is not py:
        made = types.FunctionType(py.__code__, _space(py), py.__name__, py.__defaults__, py.__closure__)
        made.__doc__ = py.__doc__
        _PLAIN[id(py)] = (py, made)
    return made
