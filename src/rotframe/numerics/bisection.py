"""The one rule that locates an event inside a step: bisection on the length of a re-step, to round-off.

A crossing of an event function g found over a step ``(t, t + h]`` is located by bisecting
``tau`` in ``(0, h]``: each trial is a re-step of length ``tau`` from the step's start by the
method's own one-step map, so the event time is exact for the method's discrete trajectory
(docs/physics/events.md). Every locator in rotframe bisects by this rule: the scenes'
fixed-step and DOP853 drivers (`rotframe.particles.events.locate_event`,
`rotframe.particles.dop853_particles.locate_event_dop853`) and the engine of your own problems
(`rotframe.problem.engine.locate`). They differ only in the trial step.

* `bisection_midpoint` halves the bracket ``[lo, hi]`` until it cannot shrink (round-off);
* `narrow` keeps the half that holds the crossing: ``hi`` is always at or past the event (a
  zero of g counts as crossed), so the state at ``hi`` is on the far side;
* `MAX_HALVINGS` bounds the loop far beyond any bracket's round-off, so that the bracket, not
  a count, ends it: a crossing at ``tau = 1e-100`` s inside a step of 0.01 s needs some 320
  halvings, and one near the smallest double some 1100. (The engine once stopped at 200 and
  reported such a crossing at 2e-62 s.)
"""

from __future__ import annotations

from rotframe.numerics.compiled import jit_internal

__all__ = ["MAX_HALVINGS", "bisection_midpoint", "narrow"]

#: Most halvings of a bracket: more than any double's round-off needs (from 1e308 to 5e-324, 2100 halvings)
MAX_HALVINGS = 2200


@jit_internal
def bisection_midpoint(lo, hi):
    """The midpoint of the bracket [lo, hi] (0 <= lo < hi), or -1.0 when it cannot shrink (round-off)."""
    mid = 0.5 * (lo + hi)
    if mid <= lo or mid >= hi:
        return -1.0
    return mid


@jit_internal
def narrow(lo, hi, g_lo, mid, g_mid):
    """The half of [lo, hi] that keeps the crossing, given g at ``mid``: ``(lo, hi, g_lo)``.

    The crossing is in [mid, hi] when g keeps the sign it has at ``lo`` (a zero
    counts as crossed), so ``hi`` is always at or past the event.
    """
    if (g_lo < 0.0) == (g_mid < 0.0) and g_mid != 0.0:
        return mid, hi, g_mid
    return lo, mid, g_lo
