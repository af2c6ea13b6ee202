"""rotframe: dynamics seen from rotating frames.

The centre of the package is the transport theorem,
``(d/dt)_space = (d/dt)_body + omega x``. Importing `rotframe` is cheap:
it imports none of numpy's heavy neighbours (astropy, numba, rerun, scipy);
the functions below and the submodules are loaded when first used.

Running scenarios ([`rotframe.app.api`][rotframe.app.api])::

    import rotframe
    rotframe.scenarios()                        # names
    scn = rotframe.load("foucault")             # parameters: unit, default, bounds, doc
    r = rotframe.run("tower-drop", height="520 ft", latitude=50.9)
    r.metrics, r.theory, r.trajectory.r         # dicts and numpy arrays (SI)
    r.record("drop.rrd")                        # the same recording as the command line
    df = rotframe.sweep("tower-drop", grid={"height": [50, 100]})   # one row per run (pandas)

The house, from the core up (each layer imports only the layers above it in
this list; ``docs/architecture.md`` has the arrows):

=============================  ====================================================
[`rotframe.errors`][rotframe.errors]         the exceptions
[`rotframe.frames`][rotframe.frames]         rotations, Euler angles in 12 sequences, transport theorem
`rotframe.numerics`       tableaus, composition weights, rotation primitives
`rotframe.particles`      force models, compiled kernels, integrators, ensembles
`rotframe.rigid`          mass properties, free body, heavy top, sections
[`rotframe.earth`][rotframe.earth]          Earth's rotation, radius, gravity, sites, ENU frames
`rotframe.analytic`       closed forms the scenes are checked against
`rotframe.scenes`         one module per scenario: model, simulate, analyse
`rotframe.app`            scenario files, runner, recordings, CLI, sweep, bench
=============================  ====================================================
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

#: public name -> module that defines it (loaded on first access)
_LAZY = {
    "scenarios": "rotframe.app.api",
    "load": "rotframe.app.api",
    "run": "rotframe.app.api",
    "Result": "rotframe.app.api",
    "TrajectoryArrays": "rotframe.app.api",
    "register_scene": "rotframe.app.api",
    "simulate": "rotframe.app.problems",
    "simulate_body": "rotframe.app.problems",
    "Force": "rotframe.problem.terms",
    "Torque": "rotframe.problem.body",
    "methods": "rotframe.method_registry",
    "sweep": "rotframe.app.sweep.api",
    "RotframeError": "rotframe.errors",
    "ScenarioError": "rotframe.errors",
    "IntegrationError": "rotframe.errors",
    "RotframeWarning": "rotframe.errors",
}
_SUBMODULES = ("analytic", "app", "earth", "errors", "events", "forces", "frames", "limits", "method_registry", "numerics",
               "particles", "problem", "rigid", "scenes", "torques", "validation")

#: Where the modules of the first, flat layout live now: ``rotframe.inertia`` and
#: ``from rotframe import integrators`` keep working (``import rotframe.inertia`` does not).
_MOVED = {
    "inertia": "rotframe.rigid.mass_properties", "principal": "rotframe.rigid.principal",
    "sections": "rotframe.rigid.sections", "model": "rotframe.particles.model",
    "integrators": "rotframe.particles.integrators", "kernels": "rotframe.particles.kernels",
    "ensemble": "rotframe.particles.ensemble", "api": "rotframe.app.api", "runner": "rotframe.app.runner",
    "scenario": "rotframe.app.scenario", "record": "rotframe.app.record", "units": "rotframe.app.units",
    "export": "rotframe.app.export", "cli": "rotframe.app.cli",
}

__all__ = ["__version__", *_LAZY]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        return importlib.import_module(f"rotframe.{name}")
    if name in _MOVED:
        return importlib.import_module(_MOVED[name])
    raise AttributeError(f"module 'rotframe' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY) | set(_SUBMODULES))
