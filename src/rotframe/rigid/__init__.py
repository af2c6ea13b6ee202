"""Rigid bodies: mass properties, principal axes, free and torqued motion, sections.

Layer 2 of the house (see ``docs/architecture.md``): imports only
:mod:`rotframe.numerics`, :mod:`rotframe.frames`, :mod:`rotframe.errors` and
:mod:`rotframe.limits`.
"""

from __future__ import annotations

import importlib
from typing import Any

#: Modules whose public names (``__all__``) are also reachable as ``rotframe.rigid.NAME``,
#: as they were when the rigid-body API was one module. Loaded on first access.
_PUBLIC_FROM = (
    "rotframe.rigid.checks",
    "rotframe.rigid.free_body",
    "rotframe.rigid.torqued",
    "rotframe.rigid.heavy_top",
    "rotframe.rigid.observables",
)


def __getattr__(name: str) -> Any:
    if not name.startswith("_"):
        for module_name in _PUBLIC_FROM:
            module = importlib.import_module(module_name)
            if name in getattr(module, "__all__", ()):
                return getattr(module, name)
    raise AttributeError(f"module 'rotframe.rigid' has no attribute {name!r}")
