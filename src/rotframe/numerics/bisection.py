"""The one event locator of rotframe: bisection on the length of a re-step, to round-off.

A crossing of an event function g found over a step ``(t, t + h]`` is located by bisecting
``tau`` in ``(0, h]``: each trial is a re-step of length ``tau`` from the step's start by the
method's own one-step map, so the event time is exact for the method's discrete trajectory
(docs/physics/events.md). The loop is written once (`locator`) and compiled for each trial:

    trial(ctx, tau) -> g

the event function after a re-step of length ``tau`` (a compiled function; ``ctx`` is the
caller's tuple of whatever the re-step needs). The trials: the scenes' fixed-step drivers
(`rotframe.particles.events.locate_event`, on the CPU and the GPU), their DOP853 driver
(`rotframe.particles.dop853_particles.locate_event_dop853`) and the engine of your own problems
(`rotframe.problem.engine`, each variant's method). Each caller then takes the state at the
returned ``tau`` by one more re-step (the same arithmetic as the trial that set it, so the same
numbers).

* `bisection_midpoint` halves the bracket ``[lo, hi]`` until it cannot shrink (round-off);
* `narrow` keeps the half that holds the crossing: ``hi`` is always at or past the event (a
  zero of g counts as crossed), so the state at ``hi`` is on the far side;
* `MAX_HALVINGS` bounds the loop far beyond any bracket's round-off, so that the bracket, not
  a count, ends it: a crossing at ``tau = 1e-100`` s inside a step of 0.01 s needs some 320
  halvings, and one near the smallest double some 1100. (The engine once stopped at 200 and
  reported such a crossing at 2e-62 s.)
"""

from __future__ import annotations

from rotframe.numerics.compiled import bound, jit_inline, jit_internal

__all__ = ["MAX_HALVINGS", "crossed", "bisection_midpoint", "narrow", "locator"]

#: Most halvings of a bracket: more than any double's round-off needs (from 1e308 to 5e-324, 2100 halvings)
MAX_HALVINGS = 2200


@jit_internal
def crossed(direction, g0, g1):
    """Whether an event function went from g0 to g1 across zero in ``direction`` (> 0 rising, < 0 falling, 0 either;
    a zero reached counts as crossed, a zero left does not): the rule of every watcher (the scenes' drivers,
    `rotframe.particles.events`; the engine's, `rotframe.problem.engine`, `rotframe.problem.fixed_step`)."""
    if direction > 0.0:
        return g0 < 0.0 and g1 >= 0.0
    if direction < 0.0:
        return g0 > 0.0 and g1 <= 0.0
    return (g0 < 0.0 and g1 >= 0.0) or (g0 > 0.0 and g1 <= 0.0)


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


#: the trial of a locator, bound per caller (`locator`); None in the template, which is never compiled
TRIAL = None


def _locate(ctx, h, g_start):
    """The template of `locator`: tau in (0, h] where the trial's event function crosses zero."""
    lo = 0.0
    hi = h
    g_lo = g_start
    for _ in range(MAX_HALVINGS):
        mid = bisection_midpoint(lo, hi)
        if mid < 0.0:
            break
        lo, hi, g_lo = narrow(lo, hi, g_lo, mid, TRIAL(ctx, mid))
    return hi


def locator(name, trial):
    """The event locator for ``trial`` (module docstring): ``locate(ctx, h, g_start) -> tau``.

    Bisects ``tau`` in ``(0, h]`` on the sign of ``trial(ctx, tau)`` until the bracket cannot shrink
    (`bisection_midpoint`, `narrow`), and returns its upper end: at or past the crossing, so the
    state there is on the event's far side. ``g_start`` is the event function at the step's start as
    the crossing test used it (its sign just after the start, where it is zero there). Inlined into
    its caller (numba's IR: the trial's constants prune its branches there); the trial is a global
    of a copy of the template named ``locate_<name>`` (`rotframe.numerics.compiled.bound`), so the
    GPU's compiler rebinds it to its own version (`rotframe.particles.gpu.device_function`).
    """
    return jit_inline(bound(_locate, f"locate_{name}", TRIAL=trial))
