"""Scenes: the Python side of the scenario files in ``scenarios/``.

A scenario file names its scene (``scene = "tower-drop"``); the scene module
turns validated parameter values into a model and initial state, runs it, and
computes the metrics, the closed-form theory and the diagnostics. Modules are
imported only when their scene runs, so listing scenarios stays instant.

Every scene module provides::

    simulate(values, terms, method, run, progress) -> SceneResult
    analyse(values, result) -> {"metrics": {...}, "theory": {...}, "diagnostics": {...}}
    record(recording, values, result) -> None
"""

from __future__ import annotations

import importlib

#: scene name -> module
SCENES = {
    "turntable": "rotframe.scenes.turntable",
    "tower-drop": "rotframe.scenes.tower_drop",
    "foucault": "rotframe.scenes.foucault",
    "inertial-oscillation": "rotframe.scenes.inertial_oscillation",
    "projectile": "rotframe.scenes.projectile",
    "free-top": "rotframe.scenes.free_top",
    "dzhanibekov": "rotframe.scenes.dzhanibekov",
    "heavy-top": "rotframe.scenes.heavy_top",
}


def get(name: str):
    """Import and return the module of scene ``name``."""
    return importlib.import_module(SCENES[name])
