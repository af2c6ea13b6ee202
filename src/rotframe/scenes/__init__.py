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
    "cr3bp": "rotframe.scenes.cr3bp",
    "tumbling-ball": "rotframe.scenes.tumbling_ball",
}

#: scenario name -> scenario file, for scenarios registered with their scene
SCENARIO_FILES: dict[str, Path] = {}
#: the built-in scene names: a plugin may not take one unless it says so (``override=True``)
BUILTIN = frozenset(SCENES)

_PROTOCOL = ("simulate", "analyse", "record")
_PLUGINS_LOADED: set[str] = set()


def get(name: str):
    """The scene ``name``: its module (imported now) or registered object."""
    load_plugins()
    scene = SCENES[name]
    return importlib.import_module(scene) if isinstance(scene, str) else scene


def register(name: str, scene: Any, scenario: str | Path | None = None, override: bool = False) -> None:
    """Add scene ``name`` (an object or module with the scene protocol, or a module name).

    ``scenario``, a scenario file whose ``scene`` is ``name``, makes the
    scenario findable by its name (its file's ``name``, else its stem).

    The fence every plugin passes (one [`ScenarioError`][rotframe.errors.ScenarioError] line naming
    it, exit 2 on the command line): a module name is imported now (a missing module, or
    one that raises on import, is refused); the scene must have the protocol's functions;
    the scenario file must be TOML; a name that is a built-in scene or scenario is refused
    unless ``override=True``.
    """
    from rotframe.errors import ScenarioError

    if not isinstance(name, str) or not name or "/" in name:
        raise ScenarioError(f"register_scene: name {name!r} must be a non-empty string without '/'")
    if name in BUILTIN and not override:
        raise ScenarioError(f"register_scene({name!r}): {name!r} is a built-in scene; choose another name, or "
                            "pass override=True to replace it")
    target = scene
    if isinstance(scene, str):
        target = _import_plugin(scene, f"register_scene({name!r})")
    missing = [f for f in _PROTOCOL if not callable(getattr(target, f, None))]
    if missing:
        raise ScenarioError(f"register_scene({name!r}): the scene {_shown(scene)} lacks {', '.join(missing)} "
                            "(see the scene protocol in rotframe.scenes)")
    scenario_name = path = None
    if scenario is not None:
        import tomllib

        path = Path(scenario)
        if not path.is_file():
            raise ScenarioError(f"register_scene({name!r}): scenario file {str(path)!r} does not exist")
        try:
            if path.stat().st_size > 1 << 20:  # as rotframe.app.scenario.MAX_SCENARIO_BYTES: refused unread
                raise ValueError(f"{path.stat().st_size} bytes, more than a scenario file's 1048576")
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError) as exc:
            raise ScenarioError(f"register_scene({name!r}): scenario file {str(path)!r} is not a TOML scenario "
                                f"file ({_cut(exc)})") from None
        scenario_name = str(data.get("name", path.stem))
        # each built-in scenario file is named as its scene
        if scenario_name in BUILTIN and not override and SCENARIO_FILES.get(scenario_name) != path:
            raise ScenarioError(f"register_scene({name!r}): scenario name {scenario_name!r} (from {str(path)!r}) is a "
                                "built-in scenario; give the file another name, or pass override=True")
    SCENES[name] = scene
    if scenario_name is not None:
        SCENARIO_FILES[scenario_name] = path


def _shown(scene) -> str:
    return repr(scene) if isinstance(scene, str) else repr(getattr(scene, "__name__", type(scene).__name__))


def _cut(exc, limit=160) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= limit else text[:limit] + "..."


def _import_plugin(item: str, who: str):
    """Import a plugin module (a name or a ``.py`` path), its prints sent to stderr; ScenarioError on any failure."""
    import contextlib

    from rotframe.errors import ScenarioError

    try:
        with contextlib.redirect_stdout(sys.stderr):  # a plugin's prints never join --json's one document
            if item.endswith(".py"):
                path = Path(item)
                spec = importlib.util.spec_from_file_location(f"rotframe_plugin_{path.stem}", path)
                if spec is None or not path.is_file():
                    raise ImportError(f"no file {item}")
                module = importlib.util.module_from_spec(spec)
                sys.modules[spec.name] = module  # so that the plugin can name itself (sys.modules[__name__])
                try:
                    spec.loader.exec_module(module)
                except BaseException:
                    sys.modules.pop(spec.name, None)
                    raise
                return module
            return importlib.import_module(item)
    except ScenarioError as exc:  # the plugin's own register_scene refused something: say which plugin
        raise ScenarioError(f"{who}: plugin {item!r}: {exc}") from None
    except SyntaxError as exc:
        raise ScenarioError(f"{who}: plugin {item!r} has a syntax error (line {exc.lineno}: "
                            f"{_cut(exc.msg)})") from None
    except ImportError as exc:
        raise ScenarioError(f"{who}: cannot import {item!r}: {_cut(exc)}") from None
    except (Exception, SystemExit) as exc:  # noqa: BLE001 -- a plugin may raise anything at import: fenced
        raise ScenarioError(f"{who}: plugin {item!r} failed on import ({type(exc).__name__}: {_cut(exc)})") from None


def load_plugins() -> None:
    """Import the modules in ``$ROTFRAME_PLUGINS`` once (module names or ``.py`` paths, comma-separated).

    Each goes through `_import_plugin`: any failure is one ScenarioError naming the plugin.
    """
    for item in filter(None, (s.strip() for s in os.environ.get("ROTFRAME_PLUGINS", "").split(","))):
        if item in _PLUGINS_LOADED:
            continue
        _PLUGINS_LOADED.add(item)
        _import_plugin(item, "ROTFRAME_PLUGINS")
