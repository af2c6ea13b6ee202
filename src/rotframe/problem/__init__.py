"""Your own problem: your forces, torques and events, in any rotating frame.

Layer 3 of the house (``docs/architecture.md``), beside ``earth`` and ``analytic``: it
imports the numerical cores (``particles``, ``rigid``, ``numerics``) and nothing above.
``rotframe.simulate`` and ``rotframe.simulate_body`` wrap these functions in a
``rotframe.Result``.

Modules, one concept each:

* ``frame``: a frame that rotates any way (omega as a constant, a table, a function, or a
  rigid body's axes) and an accelerating origin;
* ``callables``: the user's functions: fingerprints, numba compilation, one-line errors;
* ``engine``: the one compiled engine (DOP853, RK4, the models' splittings, events), compiled
  once and cached, for every problem; ``models``: the equations it steps (a particle in any
  rotating frame, a rigid body) and their splittings; ``signatures``: the fixed signatures of a
  problem's own functions; ``calls``: the engine's calls to them, by address;
* ``glue``: the source of a problem's own small functions (its forces summed, its events...);
  ``codegen``: that glue compiled and cached on disk as a module of its own; ``stubs``: the
  functions a problem does not have; and the engine as plain Python (``jit=False``) is `rotframe.numerics.plain`;
* ``terms``: a force, the pendulum's string, what a splitting takes;
* ``particles``: `simulate_particles`, `Force`;
* ``body``: `simulate_rigid_body`;
* ``forces``: the built-in forces as ordinary members of the same system.
"""

from __future__ import annotations

import importlib
from typing import Any

_NAMES = {
    "Force": "rotframe.problem.particles",
    "simulate_particles": "rotframe.problem.particles",
    "simulate_rigid_body": "rotframe.problem.body",
    "frame_spec": "rotframe.problem.frame",
}

__all__ = list(_NAMES)


def __getattr__(name: str) -> Any:
    if name in _NAMES:
        return getattr(importlib.import_module(_NAMES[name]), name)
    raise AttributeError(f"module 'rotframe.problem' has no attribute {name!r}")
