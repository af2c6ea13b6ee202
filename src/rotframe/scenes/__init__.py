"""Scenes: the Python side of the scenario files in ``scenarios/``.

A scenario file names its scene (``scene = "tower-drop"``); the scene module
turns validated parameter values into a model and initial state, runs it, and
computes the metrics, the closed-form theory and the diagnostics. Modules are
imported only when their scene runs, so listing scenarios stays instant.

The scene protocol
------------------
A scene is a module (or any object) with::

    METHODS = ("rk4", ...)                                  # optional: allowed method names
    PARAMETERS = SomeParameters                             # optional: a frozen dataclass of the parameters
    simulate(values, terms, method, run, progress) -> SceneResult
    analyse(values, result) -> {"metrics": {...}, "theory": {...}, "diagnostics": {...}, "notes": [...]}
    record(recording, values, result) -> None

``values`` maps parameter names to values in their documented units (the
scenario file's), ``terms`` is the list of model terms, ``method`` a name or
None (choose a default), ``run`` the run settings (``step``, ``rtol``,
``samples``), ``progress`` None or a callable taking the fraction done.
`SceneResult` wraps a trajectory with ``times``
and either ``r``, ``v`` (n, N, 3) for particles or ``L`` (n, 3), ``q`` (n, 4)
for a rigid body. ``record`` logs to a [`rotframe.app.record.Recording`][rotframe.app.record.Recording]
(passed in: scenes never import rerun nor anything from ``rotframe.app``).

``METHODS`` may be a `MethodNames` (canonical names
plus old names still accepted; a run reports the canonical one). The built-in
scenes declare ``PARAMETERS``, a frozen dataclass, and read ``values`` through
`with_parameters`, which builds it once per call
and refuses a key the dataclass does not have (exit 2).

Your own scene is registered with [`rotframe.register_scene`][rotframe.app.api.register_scene] (which calls
`register`). The command line imports the modules listed in the
environment variable ``ROTFRAME_PLUGINS`` (comma-separated module names or
paths to ``.py`` files) the first time it looks a scene up, so a module that
registers its scene at import is visible to ``rotframe run``.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import sys
from pathlib import Path
from typing import Any

__all__ = ["SCENES", "SCENARIO_FILES", "get", "register", "load_plugins"]

#: scene name -> module name, or the scene object itself (registered scenes)
SCENES: dict[str, Any] = {
    "turntable": "rotframe.scenes.turntable",
    "tower-drop": "rotframe.scenes.tower_drop",
    "foucault": "rotframe.scenes.foucault",
    "inertial-oscillation": "rotframe.scenes.inertial_oscillation",
    "projectile": "rotframe.scenes.projectile",
    "free-top": "rotframe.scenes.free_top",
    "dzhanibekov": "rotframe.scenes.dzhanibekov",
    "heavy-top": "rotframe.scenes.heavy_top",
}

#: scenario name -> scenario file, for scenarios registered with their scene
SCENARIO_FILES: dict[str, Path] = {}

_PROTOCOL = ("simulate", "analyse", "record")
_PLUGINS_LOADED: set[str] = set()


def get(name: str):
    """The scene ``name``: its module (imported now) or registered object."""
    load_plugins()
    scene = SCENES[name]
    return importlib.import_module(scene) if isinstance(scene, str) else scene


def register(name: str, scene: Any, scenario: str | Path | None = None) -> None:
    """Add scene ``name`` (an object or module with the scene protocol, or a module name).

    ``scenario``, a scenario file whose ``scene`` is ``name``, makes the
    scenario findable by its name (its file's ``name``, else its stem).
    """
    from rotframe.errors import ScenarioError

    if not isinstance(name, str) or not name or "/" in name:
        raise ScenarioError(f"register_scene: name {name!r} must be a non-empty string without '/'")
    if not isinstance(scene, str):
        missing = [f for f in _PROTOCOL if not callable(getattr(scene, f, None))]
        if missing:
            raise ScenarioError(f"register_scene({name!r}): the scene lacks {', '.join(missing)} "
                                "(see the scene protocol in rotframe.scenes)")
    SCENES[name] = scene
    if scenario is not None:
        import tomllib

        path = Path(scenario)
        if not path.is_file():
            raise ScenarioError(f"register_scene({name!r}): scenario file {str(path)!r} does not exist")
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        SCENARIO_FILES[str(data.get("name", path.stem))] = path


def load_plugins() -> None:
    """Import the modules in ``$ROTFRAME_PLUGINS`` once (module names or ``.py`` paths, comma-separated)."""
    from rotframe.errors import ScenarioError

    for item in filter(None, (s.strip() for s in os.environ.get("ROTFRAME_PLUGINS", "").split(","))):
        if item in _PLUGINS_LOADED:
            continue
        _PLUGINS_LOADED.add(item)
        try:
            if item.endswith(".py"):
                path = Path(item)
                spec = importlib.util.spec_from_file_location(f"rotframe_plugin_{path.stem}", path)
                if spec is None or not path.is_file():
                    raise ImportError(f"no file {item}")
                module = importlib.util.module_from_spec(spec)
                sys.modules[spec.name] = module  # so that the plugin can name itself (sys.modules[__name__])
                spec.loader.exec_module(module)
            else:
                importlib.import_module(item)
        except ImportError as exc:
            raise ScenarioError(f"ROTFRAME_PLUGINS: cannot import {item!r}: {exc}") from None
