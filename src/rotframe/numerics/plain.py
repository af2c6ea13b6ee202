"""Compiled functions as plain Python: the same functions, with every compiled callee its Python original.

The engine of your own problems runs this way with ``jit=False``; the rigid body's starting step
runs the shared `rotframe.numerics.step_control` functions this way (a few microseconds, nothing
to compile).

A numba dispatcher's ``py_func`` is the Python function it was made from, but that function
still calls its module's compiled neighbours, which cannot take plain Python functions as
arguments. `plain` remakes a function over a copy of its globals in which every numba dispatcher is itself
remade this way (and so are the dispatchers a closure holds), so a whole call tree runs as Python (slow: for a
user function numba cannot compile). No source is copied: the code objects are the modules' own.
"""

from __future__ import annotations

import sys
import types

from numba.core.dispatcher import Dispatcher

__all__ = ["plain"]

_SPACES: dict[str, dict] = {}
_PLAIN: dict[int, types.FunctionType] = {}


def _space(py) -> dict:
    """The globals of function ``py`` with each numba dispatcher replaced by its plain remake (made once).

    Its module's, or its own where it has globals of its own (a loop bound to a system's functions:
    `rotframe.numerics.compiled.bound`).
    """
    original = py.__globals__
    module = sys.modules.get(py.__module__)
    key = py.__module__ if module is not None and vars(module) is original else f"{py.__module__}:{id(original)}"
    space = _SPACES.get(key)
    if space is None:
        space = dict(original)
        _SPACES[key] = space  # before the remakes: a module's functions call each other
        for name, value in original.items():
            if isinstance(value, Dispatcher):
                space[name] = plain(value)
    return space


def _plain_cells(closure):
    """A closure's cells, each that holds a numba dispatcher holding its plain remake instead (a loop compiled per
    system holds its system's functions there: `rotframe.numerics.dop853_loop`)."""
    if not closure:
        return closure
    return tuple(types.CellType(plain(cell.cell_contents)) if isinstance(cell.cell_contents, Dispatcher) else cell
                 for cell in closure)


def plain(f):
    """``f`` (a numba dispatcher or a function) as a Python function whose compiled callees are plain too."""
    override = getattr(f, "plain", None)  # a helper that has no Python form of its own (rotframe.problem.calls)
    if override is not None:
        return override
    py = getattr(f, "py_func", f)
    made = _PLAIN.get(id(py))
    if made is None:
        made = types.FunctionType(py.__code__, _space(py), py.__name__, py.__defaults__,
                                  _plain_cells(py.__closure__))
        made.__doc__ = py.__doc__
        _PLAIN[id(py)] = made
    return made
