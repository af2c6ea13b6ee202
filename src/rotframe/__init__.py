"""rotframe: dynamics seen from rotating frames.

The centre of the package is the transport theorem,
``(d/dt)_space = (d/dt)_body + omega x``. Importing :mod:`rotframe` is cheap:
it imports none of numpy's heavy neighbours (astropy, numba, rerun, scipy);
the functions below and the submodules are loaded when first used.

Running scenarios (:mod:`rotframe.api`)::

    import rotframe
    rotframe.scenarios()                        # names
    scn = rotframe.load("foucault")             # parameters: unit, default, bounds, doc
    r = rotframe.run("tower-drop", height="520 ft", latitude=50.9)
    r.metrics, r.theory, r.trajectory.r         # dicts and numpy arrays (SI)
    r.record("drop.rrd")                        # the same recording as the command line

Building blocks (stable names, each module has ``__all__``):

=====================  ==========================================================
:mod:`rotframe.frames`  rotations, Euler angles in 12 sequences, transport theorem
:mod:`rotframe.earth`   Earth's rotation, radius, gravity, sites, ENU frames
:mod:`rotframe.model`   particle force models (:class:`~rotframe.model.ParticleModel`)
:mod:`rotframe.integrators`  :func:`~rotframe.integrators.integrate_particles`
:mod:`rotframe.rigid`   free body (exact, Lie-Poisson), heavy top, torqued bodies
:mod:`rotframe.inertia` mass properties of bodies
:mod:`rotframe.errors`  the exceptions
=====================  ==========================================================
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

#: public name -> module that defines it (loaded on first access)
_LAZY = {
    "scenarios": "rotframe.api",
    "load": "rotframe.api",
    "run": "rotframe.api",
    "Result": "rotframe.api",
    "TrajectoryArrays": "rotframe.api",
    "register_scene": "rotframe.api",
    "RotframeError": "rotframe.errors",
    "ScenarioError": "rotframe.errors",
    "IntegrationError": "rotframe.errors",
}
_SUBMODULES = ("api", "analytic", "earth", "errors", "export", "frames", "inertia", "integrators", "model",
               "principal", "record", "rigid", "runner", "scenario", "scenes", "sections", "units")

__all__ = ["__version__", *_LAZY]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        return importlib.import_module(f"rotframe.{name}")
    raise AttributeError(f"module 'rotframe' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY) | set(_SUBMODULES))
