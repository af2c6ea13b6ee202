"""Command-line values shared by the commands: ``--set KEY=VALUE`` pairs and JSON-safe output.

Standard library only, so that importing it keeps ``rotframe --help`` instant.
"""

from __future__ import annotations

import math
from pathlib import PurePath

__all__ = ["split_set", "parse_sets", "jsonable"]


def split_set(item):
    """``"KEY=VALUE"`` as ``(KEY, VALUE)``, both stripped, split at the first ``=``; ``None`` without ``=``."""
    key, sep, value = str(item).partition("=")
    return (key.strip(), value.strip()) if sep else None


def parse_sets(items, *, on_error=None) -> dict:
    """``["k=v", ...]`` as ``{k: v}`` (both stripped; the value is split at the first ``=``; a later key wins).

    Parameters
    ----------
    items : iterable of str
        The ``--set`` arguments, in order.
    on_error : callable(item) -> Exception, optional
        Builds the exception raised for an item without ``=``; by default a
        [`rotframe.errors.ScenarioError`][rotframe.errors.ScenarioError] saying ``--set 'item': expected KEY=VALUE``.
    """
    sets = {}
    for item in items:
        pair = split_set(item)
        if pair is None:
            if on_error is not None:
                raise on_error(item)
            from rotframe.errors import ScenarioError

            raise ScenarioError(f"--set {item!r}: expected KEY=VALUE")
        sets[pair[0]] = pair[1]
    return sets


def jsonable(obj):
    """``obj`` with numpy scalars as Python numbers, every non-finite float as ``None`` (JSON's null),
    dictionary keys and paths as strings.

    JSON has no inf or nan: an infinite period (no rotation) or a missing value is written as null.
    """
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if hasattr(obj, "item") and callable(obj.item):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, PurePath):
        return str(obj)
    return obj
