"""The run settings of a scenario and their defaults (standard library only: cheap to import).

A scenario file's ``[run]`` table, ``--set step=...`` and ``rotframe.run(..., rtol=...)`` give
these settings; the scenario loader (`rotframe.app.scenario`) fills in the defaults and
every scene reads a missing one through `run_setting`. One source for both.
"""

from __future__ import annotations

__all__ = ["RUN_DEFAULTS", "run_setting"]

#: ``method`` None: the scene's default; ``step`` None: the scene's choice; ``rtol`` for
#: adaptive methods; ``samples``: output samples (scenes may need more to resolve a period).
RUN_DEFAULTS = {"method": None, "step": None, "rtol": 1e-10, "samples": 2000}


def run_setting(run, key):
    """``run[key]``, or its default from `RUN_DEFAULTS` where it is missing, None or zero.

    >>> run_setting({"samples": 500}, "samples"), run_setting({}, "rtol")
    (500, 1e-10)
    """
    return (run or {}).get(key) or RUN_DEFAULTS[key]
