"""A problem's arguments, checked at the door: one line naming the argument, its value and what is allowed.

The one home of the checks that `rotframe.simulate` and `rotframe.simulate_body` share (their
doors in `rotframe.app.problems` convert units first): a method name, the run's grid and work
limits, numbers, arrays, parameters and an event's settings. Each refusal is a
`rotframe.errors.ScenarioError` (exit code 2 on the command line), never a raw exception of
numpy's or numba's.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.errors import ScenarioError
from rotframe.problem import callables as uf
from rotframe.validation import refuse_units

__all__ = ["check_params", "check_event", "run_grid", "number", "sequence_of_callables", "check_flag", "check_inline",
           "array_of", "DEFAULT_RTOL", "DEFAULT_SAMPLES"]

DEFAULT_RTOL = 1e-10
DEFAULT_SAMPLES = 1000


def check_params(params):
    """``params`` as a tuple of floats and read-only float64 arrays, or a one-line ScenarioError naming the entry."""
    refuse_units(params, "params", ScenarioError)
    if isinstance(params, (str, bytes, dict)) or not isinstance(params, (tuple, list, np.ndarray)):
        raise ScenarioError(f"params={str(params)[:60]!r}: a tuple of numbers or float arrays, such as params=(4.0,) "
                            "(passed to every function after t, r, v)")
    out = []
    for k, p in enumerate(params):
        if isinstance(p, (bool, int, float, np.integer, np.floating)) and not isinstance(p, np.bool_):
            if not math.isfinite(float(p)):
                raise ScenarioError(f"params[{k}] = {p!r}: not finite; allowed: finite real numbers")
            out.append(float(p))
            continue
        arr = None
        if not isinstance(p, (str, bytes, dict, complex, np.complexfloating)):
            try:
                arr = np.asarray(p)
            except (TypeError, ValueError):  # a ragged list
                arr = None
        if arr is None or arr.dtype.kind not in "iuf" or arr.size == 0:
            raise ScenarioError(f"params[{k}]: {str(p)[:60]!r}; allowed: a real number or a non-empty array of real "
                                "numbers (not complex, ragged, text or a dict)")
        if not np.all(np.isfinite(arr)):
            raise ScenarioError(f"params[{k}]: not finite")
        out.append(uf.readonly_array(arr))  # C-contiguous, and no user function may write into it
    return tuple(out)


def check_flag(value, key: str) -> bool:
    """A True/False argument (``jit``), refused in one line when it is anything else (``"no"`` is truthy)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ScenarioError(f"{key}={value!r}: True or False")
    return bool(value)


def check_inline(inline, jit) -> None:
    """``inline`` (None, True or False; `rotframe.problem.inlined`), refused in one line where it is no flag or where
    it asks to compile the functions into the loop that ``jit=False`` runs in plain Python."""
    if inline is None:
        return
    if check_flag(inline, "inline") and not jit:
        raise ScenarioError("inline=True compiles your functions into the engine's loop, jit=False runs them in "
                            "plain Python: pass one of them")


def check_event(g, k):
    """An event's ``direction`` (its sign) and ``terminal``, checked: ``(float, bool)``."""
    direction = getattr(g, "direction", 0) or 0
    terminal = getattr(g, "terminal", False)
    if isinstance(direction, (str, bytes, bool, complex)) or not isinstance(direction, (int, float, np.integer,
                                                                                        np.floating)):
        raise ScenarioError(f"events[{k}].direction = {direction!r}: a number, its sign taken: 1 (rising), -1 "
                            "(falling) or 0 (both)")
    if not math.isfinite(float(direction)):
        raise ScenarioError(f"events[{k}].direction = {direction!r}: a finite number (1, -1 or 0)")
    if not isinstance(terminal, (bool, np.bool_)) and terminal not in (0, 1):
        raise ScenarioError(f"events[{k}].terminal = {terminal!r}: True or False")
    return float(np.sign(direction)), bool(terminal)


def run_grid(duration, samples, rtol, step, *, fixed, what, particles=1):
    """A run's checked settings, ``(duration, samples, times (samples + 1,), rtol, hfix)``, within the work limits.

    ``hfix`` is the fixed step of a fixed-step method (``fixed``): ``step`` (default a twentieth
    of the sample interval) shortened to divide the sample interval; 0.0 for DOP853. A bad value
    is a ScenarioError in one line; a run over the work limits a LimitError (`rotframe.limits`).
    """
    from rotframe import limits

    duration = number(duration, "duration", "s")
    if not (math.isfinite(duration) and duration > 0):
        raise ScenarioError(f"duration={duration!r}: must be finite and > 0 (s)")
    rtol = DEFAULT_RTOL if rtol is None else number(rtol, "rtol", "relative")
    if not (1e-15 <= rtol < 1):
        raise ScenarioError(f"rtol={rtol!r}: allowed 1e-15 <= rtol < 1")
    samples = DEFAULT_SAMPLES if samples is None else samples
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise ScenarioError(f"samples={samples!r}: a whole number >= 1")
    samples = int(samples)
    # an adaptive run's steps are checked at its pace as it goes (`rotframe.limits.check_pace`); the exact flow takes
    # none: only a fixed step's count is known before the run (a sample is no step, and its own limit names it)
    steps, hfix = 0.0, 0.0
    if fixed:
        step = duration / samples / 20 if step is None else number(step, "step", "s")
        if not (math.isfinite(step) and step > 0) or step < 1e-300:
            raise ScenarioError(f"step={step!r}: must be finite and > 0 (s)")
        per = (duration / samples) / step  # in floats: a step far below the sample interval gives a count no
        steps = float(samples) * math.ceil(per - 1e-9) if per < 1e300 else math.inf  # integer holds
    limits.check_run(steps=steps, samples=samples + 1, particles=particles, what=what)
    if fixed:
        hfix = (duration / samples) / max(1, math.ceil(per - 1e-9))
    return duration, samples, np.linspace(0.0, duration, samples + 1), rtol, hfix


def number(value, key, unit):
    """``value`` as a float, or a one-line ScenarioError naming ``key`` and the unit expected."""
    refuse_units(value, key, ScenarioError)
    if isinstance(value, bool):
        raise ScenarioError(f"{key}={value!r}: a number ({unit}) is expected")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ScenarioError(f"{key}={value!r}: a number ({unit}) is expected") from None


def sequence_of_callables(value, key):
    """``forces=f`` or ``events=g`` alone is taken as a list of one."""
    if value is None:
        return []
    if callable(value):
        return [value]
    try:
        return list(value)
    except TypeError:
        raise ScenarioError(f"{key}={value!r}: a list of functions is expected") from None


def array_of(value, key):
    refuse_units(value, key, ScenarioError)
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError(f"{key}: {str(value)[:80]!r} is not numbers") from None
