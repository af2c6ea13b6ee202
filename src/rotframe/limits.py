"""Work limits: estimate a run's steps, samples and rows before starting; refuse what cannot finish.

A run is refused, in one line with the estimate and the limit, when it would
take more integration steps than `Limits.max_steps` (about a minute of
compiled work for one particle) or keep more output samples than
`Limits.max_samples` (memory), or allocate more than `Limits.max_memory` bytes in
all; a sweep when it has more rows than `Limits.max_rows`. The command line raises them
with ``--max-steps``, ``--max-samples``, ``--max-memory`` and ``--max-rows``; Python with
``with rotframe.limits.applied(rotframe.limits.current().with_overrides(max_steps=1e10)):``.

The limits in force are held in a `contextvars.ContextVar` set for the
duration of one command (`applied`), so nothing outlives it; code that
runs outside any command (the Python API, tests) gets `DEFAULT`.
"""

from __future__ import annotations

import contextlib
import contextvars
from dataclasses import dataclass, replace

from rotframe.errors import ScenarioError

__all__ = ["Limits", "LimitError", "DEFAULT", "current", "applied", "check_run", "check_rows", "check_memory",
           "check_pace"]


class LimitError(ScenarioError):
    """The work asked for exceeds a limit (exit code 2); the message gives the estimate and the flag."""


@dataclass(frozen=True)
class Limits:
    """Upper bounds on one command's work.

    Attributes
    ----------
    max_steps : float
        Integration steps times particles of one run.
    max_samples : float
        Output samples of one run (each particle's state, 48 bytes, twice over while analysed).
    max_rows : float
        Rows of one sweep.
    max_memory : float
        Bytes of the large arrays one run allocates together (samples, event slots, per-particle
        state), counted before they are made (`check_memory`).
    """

    max_steps: float = 2e9
    max_samples: float = 5e6
    max_rows: float = 2e6
    max_memory: float = 4e9

    def with_overrides(self, **kw) -> "Limits":
        return replace(self, **{k: float(v) for k, v in kw.items() if v is not None})


DEFAULT = Limits()
_CURRENT: contextvars.ContextVar[Limits] = contextvars.ContextVar("rotframe_limits", default=DEFAULT)


def current() -> Limits:
    """The limits in force."""
    return _CURRENT.get()


@contextlib.contextmanager
def applied(limits: Limits):
    """Make ``limits`` the ones in force inside the block."""
    token = _CURRENT.set(limits)
    try:
        yield limits
    finally:
        _CURRENT.reset(token)


def _fmt(x: float) -> str:
    return f"{x:.3g}"


def check_run(*, steps: float = 0.0, samples: float = 0.0, particles: int = 1, what: str = "run",
              remedy: str = "shorten duration or enlarge step") -> None:
    """Refuse a run whose estimated ``steps`` (per particle) or ``samples`` exceed the limits; ``remedy`` is what
    the message asks for first where the steps do."""
    lim = current()
    work = float(steps) * max(int(particles), 1)
    if work > lim.max_steps:
        raise LimitError(f"{what}: about {_fmt(work)} integration steps, over the limit of {_fmt(lim.max_steps)}; "
                         f"{remedy}, or raise the limit with --max-steps N")
    stored = float(samples) * max(int(particles), 1)
    if stored > lim.max_samples:
        gb = stored * 6 * 8 * 2 / 1e9
        raise LimitError(f"{what}: {_fmt(stored)} output samples (about {gb:.3g} GB), over the limit of "
                         f"{_fmt(lim.max_samples)}; lower samples or duration, or raise the limit with "
                         "--max-samples N")


def check_rows(rows: float, what: str = "sweep") -> None:
    """Refuse a sweep of more than ``max_rows`` rows."""
    lim = current()
    if float(rows) > lim.max_rows:
        raise LimitError(f"{what}: {_fmt(float(rows))} rows, over the limit of {_fmt(lim.max_rows)}; use fewer "
                         "points, or raise the limit with --max-rows N")


def check_pace(what: str, duration: float, steps, t_reached, repeated: bool = False, step=None) -> bool:
    """The running work estimate of an adaptive run: its steps so far plus the rest at each particle's pace.

    The pace is a particle's average step so far, or its next ``step`` (per particle, where given) where that is
    longer: not the next step alone, which shrinks near a singularity, where the run is about to fail and say
    why; not the average alone, which a run whose steps still grow from a short first one (a time scale far
    from 1 s: DOP853's first step begins at 1e-6 s where f is tiny) would project many times too long. Returns
    whether the estimate is over max_steps; raises `LimitError` when it is and was at the previous check too
    (``repeated``).
    """
    import numpy as np

    lim = current()
    steps = np.asarray(steps, dtype=float)
    t_reached = np.asarray(t_reached, dtype=float)
    pace = np.where(t_reached > 0.0, t_reached / np.maximum(steps, 1.0), np.inf)
    if step is not None:
        pace = np.maximum(pace, np.abs(np.asarray(step, dtype=float)))
    remaining = np.maximum(float(duration) - t_reached, 0.0) / pace
    estimate = float(np.sum(steps) + np.sum(remaining))
    over = estimate > lim.max_steps
    if over and repeated:
        raise LimitError(f"{what}: about {_fmt(estimate)} integration steps (at the pace of its first "
                         f"{int(np.sum(steps))} steps), over the limit of {_fmt(lim.max_steps)}; shorten the run, "
                         "loosen rtol, or raise the limit (--max-steps N; from Python, rotframe.limits.applied)")
    return over


def check_memory(what: str, arrays: dict) -> None:
    """Refuse a run whose arrays (name -> bytes) together exceed the memory limit, naming the largest."""
    lim = current()
    total = float(sum(arrays.values()))
    if total > lim.max_memory:
        largest = max(arrays, key=arrays.get)
        raise LimitError(
            f"{what}: its arrays need about {total / 1e9:.3g} GB ({largest}: {arrays[largest] / 1e9:.3g} GB), over the "
            f"limit of {lim.max_memory / 1e9:.3g} GB; fewer particles, samples or event slots, or raise the limit "
            "(--max-memory BYTES)")
