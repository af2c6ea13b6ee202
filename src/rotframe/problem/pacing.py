"""How a user's problem is paced: compiled calls sized in time, the work estimated before and as it goes.

A compiled driver call holds the thread until it returns, and Python sees a signal (Ctrl-C,
SIGTERM) and reports progress only between calls. Calls sized in steps made a slow user
function (0.2 ms an evaluation) hold a signal for minutes. `Pacer` sizes them in time instead:
the first call takes a few steps (it compiles, too), each later one as many steps as about
`CALL_SECONDS` of work took before, or `BETWEEN_CALLS_FACTOR` times the host's own work between
two calls where that is longer (a million particles' copies and checks), up to
`LONGEST_CALL_SECONDS`. The numbers do not depend on where a call ends: the drivers keep
everything a step needs in their arrays (`rotframe.problem.engine`).

The work is estimated against `rotframe.limits`:

* before the run: a fixed step's count exactly (`rotframe.problem.arguments.run_grid`), and at
  least one step per knot of a table or body frame (`rotframe.limits.check_run`);
* as it goes (`Pacer.check`, the rule in `rotframe.limits.check_pace`), within the first calls
  (a fraction of a second): each particle's steps so far plus its remaining span at its average
  pace, once DOP853's step has settled (`SETTLED_STEPS`). No a-priori bound holds for an adaptive step (a polynomial solution is
  integrated exactly in a few growing steps), so this one is measured.

An estimate over ``max_steps`` is refused with a `rotframe.limits.LimitError` in one line,
as ``rotframe run`` refuses a scene's run, instead of running for hours. `rotframe.limits.check_memory`
counts every large array a run allocates, not only its samples.
"""

from __future__ import annotations

import time

import numpy as np

__all__ = ["Pacer", "CALL_SECONDS", "BETWEEN_CALLS_FACTOR", "LONGEST_CALL_SECONDS", "FIRST_BUDGET", "FIRST_BUDGET_OWN"]

#: wall time of one compiled call once paced: signals and progress are seen at least this often
CALL_SECONDS = 0.1
#: ... or this many times the host's work between two calls, where that is longer: the copies and checks between calls
#: grow with the particles (some 0.05 s a call for a million on a GPU, where 0.1 s is a thousand steps), and a call of
#: CALL_SECONDS would spend as much time between the calls as in them
BETWEEN_CALLS_FACTOR = 10.0
#: ... but never longer than this (s): a signal is still answered within a second
LONGEST_CALL_SECONDS = 1.0
#: steps of the first call (which also compiles the driver)
FIRST_BUDGET = 16
#: steps of the first call where the loop is compiled already and runs no function of the user's (a free body, the
#: built-in torques): some milliseconds at most, and a short run (a scene's bench row) in one call
FIRST_BUDGET_OWN = 4096
#: the running estimate refuses only after this many steps per particle (DOP853's step has settled by then)
SETTLED_STEPS = 32
#: a step that grew more than this since the last check is still growing (from DOP853's first step, which begins
#: at 1e-6 s where f is tiny: a run on a time scale far from 1 s grows its steps by 1e100 over some 200 steps); its
#: pace is not projected until it settles
GROWING = 2.0


class Pacer:
    """The step budget of each compiled call, and the running work estimate.

    Parameters
    ----------
    what : str
        What runs, for messages (``"method dop853"``, as the fixed-step methods' count before the run names it).
    duration : float
        The run's span (s).
    adaptive : bool
        An adaptive step, whose work is estimated as the run goes (a fixed step's was counted
        before the run).
    first_budget : int
        The steps of the first call (`FIRST_BUDGET`; more where the loop is compiled and no function
        of the user's can be slow: `FIRST_BUDGET_OWN`).
    """

    def __init__(self, what: str, duration: float, adaptive: bool, first_budget: int = FIRST_BUDGET):
        self.what = what
        self.duration = float(duration)
        self.adaptive = bool(adaptive)
        self.budget = int(first_budget)
        self.calls = 0
        #: the wall time of the last call (s)
        self.last_seconds = 0.0
        self._started = 0.0
        self._ended = None  # when the last call ended (`done`)
        #: the host's wall time between the last two calls (s): the copies and checks of the run's loop
        self.between_seconds = 0.0
        self._over = False
        self._last_step = None

    def start(self) -> int:
        """Mark a call's start; returns its budget (steps per particle)."""
        self._started = time.perf_counter()
        if self._ended is not None:
            self.between_seconds = self._started - self._ended
        return self.budget

    def done(self, steps_in_call: float) -> None:
        """After a call that took ``steps_in_call`` steps (all particles): size the next one to CALL_SECONDS, or to
        `BETWEEN_CALLS_FACTOR` times the host's work between the calls where that is longer (at most
        `LONGEST_CALL_SECONDS`)."""
        self._ended = time.perf_counter()
        elapsed = self.last_seconds = self._ended - self._started
        self.calls += 1
        if self.calls == 1 or steps_in_call <= 0:  # the first call compiled: its time says nothing of a step's
            return
        target = min(max(CALL_SECONDS, BETWEEN_CALLS_FACTOR * self.between_seconds), LONGEST_CALL_SECONDS)
        wanted = self.budget * target / max(elapsed, 1e-9)
        self.budget = int(max(1, min(wanted, self.budget * 8, 1_000_000)))

    def check(self, steps, t_reached, step) -> None:
        """Refuse the run when its projected steps exceed max_steps at two checks in a row (`rotframe.limits.check_pace`).

        ``steps``, ``t_reached``, ``step``: per-particle arrays of the running particles (their steps taken, time
        reached and next step).
        """
        from rotframe import limits

        if not self.adaptive:  # a fixed step's count was checked before the run
            return
        steps = np.asarray(steps, dtype=float)
        step = np.abs(np.asarray(step, dtype=float))
        growing = self._last_step is not None and self._last_step.shape == step.shape and bool(
            np.any(step > GROWING * self._last_step))
        self._last_step = step.copy()
        if steps.size == 0 or float(np.min(steps)) < SETTLED_STEPS or growing:
            self._over = False  # a step still growing from a short first one: no pace to project yet
            return
        self._over = limits.check_pace(self.what, self.duration, steps, t_reached, repeated=self._over, step=step)
