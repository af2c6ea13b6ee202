"""The events' watcher of the engine's loops: each event's crossings over a step, located on the method's re-steps.

Templates (`rotframe.numerics.compiled.bound` rebinds their upper-case globals) that each variant of
the engine's loop (`rotframe.problem.engine.variant_loop`) binds to its own method and model
(`watcher`): the DOP853 loop (`rotframe.problem.dop853_variant`) calls the watcher after each
accepted step, the fixed-step loop (`rotframe.problem.fixed_step`) after each step. The rule at the
start and the locator are docs/physics/events.md's, the locator rotframe's one
(`rotframe.numerics.bisection.locator`).
"""

from __future__ import annotations

import math

from rotframe.numerics.bisection import MAX_HALVINGS, crossed, locator
from rotframe.numerics.compiled import bound, jit_inline, jit_uncounted
from rotframe.problem.calls import call_event
from rotframe.problem.steps import take_step

__all__ = ["watcher", "event_trial", "start_sign", "watch_events"]

# the names a variant binds (`watcher`): None in the templates themselves, which are never compiled
SYSTEM = STEPPER = TAKE = BODY_FLAG = TRIAL = LOCATE = START_SIGN = None


def event_trial(tctx, tau):
    """The template of a variant's event trial: event k's value after a re-step of length ``tau``.

    ``tctx = (k, t, y, Kb, ytb, ybuf, ctx)``: the re-step is the variant's method from ``(t, y)``
    (``TAKE``, the method's step of `take_step`, with the variant's ``STEPPER`` and ``BODY_FLAG``;
    ``Kb[0]`` is f(t, y)), its state left in ``ybuf``. The trial of rotframe's one event locator
    (`rotframe.numerics.bisection.locator`) and of `start_sign`.
    """
    k, t, y, Kb, ytb, ybuf, ctx = tctx
    TAKE(STEPPER, BODY_FLAG, t, y, tau, Kb, ytb, ybuf, ctx)
    return call_event(ctx[1][1], k, t + tau, ybuf, ctx[0][2])


def start_sign(tctx, h):
    """The template of a variant's start rule: event k's value just after the start, for a function zero there.

    The rule of every locator (docs/physics/events.md): the start itself is never an event, and
    a function that is zero there takes the sign it has just after it. The trials (``TRIAL``, the
    variant's `event_trial` with ``tctx``) are re-steps by the method from ``(t, y)`` of lengths
    ``h / 2, h / 4, ...``; the value kept is the one nearest the start that is not zero. The
    halving stops where g halves with tau (its first derivative rules below there: one or two
    trials for a shot fired from the ground), else where a trial no longer moves the state or tau
    underflows (a function whose first derivative is zero at the start: some thousand trials,
    once). A projectile fired from the ground thus lands at its first return to it however soon,
    inside the first step too, and one fired into the ground is not an event. Returns 0.0 when g
    stays zero (no sign to take).
    """
    y = tctx[2]
    ybuf = tctx[5]
    g_near = 0.0
    g_before = 0.0  # g at the trial before (twice as long)
    tau = h
    for _ in range(MAX_HALVINGS):
        tau = 0.5 * tau
        if tau == 0.0:
            break
        g = TRIAL(tctx, tau)
        if not math.isfinite(g):
            g = 0.0
        if g != 0.0:
            g_near = g
            if g_before != 0.0 and 1.75 <= g_before / g <= 2.25:  # a positive ratio: the same sign
                # g halves with tau: its first derivative rules, and its sign holds nearer the start (a hop
                # shorter than tau would have g fall faster than tau, or change sign, between the two trials)
                break
        g_before = g
        moved = False
        for j in range(y.shape[0]):
            if ybuf[j] != y[j]:
                moved = True
        if not moved:
            break
    return g_near


def watch_events(wctx, ctx, p, t, h, t_new, y, y_new, K):
    """The template of a variant's watcher: the crossings over the step ``(t, y) -> (t_new, y_new)`` of particle ``p``.

    ``wctx = (GPREV, EVT, EVY, EVK, EVN, EDIR, ETERM, t0, Kb, ytb, yhi, ybuf)``: each event's value
    at ``t`` (updated), the records, the directions and terminal flags, the run's start and the
    locator's scratch; ``ctx`` the system's (``(prob, fns, W)``, more in the trajectory tier's), ``SYSTEM`` its
    right-hand side (f at ``t`` for the re-steps). A crossing (with its direction) is located by
    rotframe's one event locator (``LOCATE``, `rotframe.numerics.bisection.locator`) on re-steps by
    the variant's method (``TRIAL``, `event_trial`), a zero at the start by ``START_SIGN``
    (`start_sign`); the state at a crossing is the re-step there (the step's own end where the
    crossing is at it); each is recorded, and the records after the earliest terminal crossing are
    dropped. Returns ``(stop, tau)``: whether a terminal event ends the particle in the step and its
    offset from ``t``, or ``(True, NaN)`` where an event function gave NaN or raised (the particle
    stops at ``t``; Python names the function). The watcher of both loops (`watcher`):
    `rotframe.numerics.dop853_loop` calls it after each accepted step, the fixed-step loop after
    each step.
    """
    GPREV, EVT, EVY, EVK, EVN, EDIR, ETERM, t0, Kb, ytb, yhi, ybuf = wctx
    prob, fns = ctx[0], ctx[1]
    D = y.shape[0]
    stop = False
    tau_stop = h
    started = False  # whether Kb[0] holds f(t, y), the re-steps' first stage (made once, where a trial needs it)
    for k in range(EDIR.shape[0]):
        g_new = call_event(fns[1], k, t_new, y_new, prob[2])
        if not math.isfinite(g_new):  # NaN, or the event function raised
            return True, math.nan
        g_old = GPREV[p, k]
        tctx = (k, t, y, Kb, ytb, ybuf, ctx)
        if g_old == 0.0 and t == t0:  # zero at the start: the sign just after it (`start_sign`)
            if not started:
                SYSTEM(ctx, t, y, Kb, 0)
                started = True
            g_old = START_SIGN(tctx, h)
        if crossed(EDIR[k], g_old, g_new):
            if not started:
                SYSTEM(ctx, t, y, Kb, 0)
                started = True
            tau = LOCATE(tctx, h, g_old)
            if tau < h:  # the state there: the trial that set the bracket's end, made again
                TRIAL(tctx, tau)
                for j in range(D):
                    yhi[j] = ybuf[j]
            else:
                for j in range(D):
                    yhi[j] = y_new[j]
            m = EVN[p]
            if m < EVT.shape[1]:
                EVT[p, m] = t + tau
                EVK[p, m] = k
                for j in range(D):
                    EVY[p, m, j] = yhi[j]
            EVN[p] = m + 1
            if ETERM[k] and (not stop or tau < tau_stop):
                stop = True
                tau_stop = tau
        GPREV[p, k] = g_new
    if stop:  # drop the records of non-terminal crossings after the terminal one
        keep = 0
        for r in range(min(EVN[p], EVT.shape[1])):
            if EVT[p, r] <= t + tau_stop:
                EVT[p, keep] = EVT[p, r]
                EVK[p, keep] = EVK[p, r]
                for j in range(D):
                    EVY[p, keep, j] = EVY[p, r, j]
                keep += 1
        EVN[p] = keep
    return stop, tau_stop


def watcher(kind, step, body, method, system, cold=False, take=None):
    """The events' watcher of a variant (`watch_events`) with its trial, locator and start rule, bound to them.

    ``kind`` names the variant's copies; ``step`` (the variant's `rotframe.problem.steps.stepper`), ``body`` and the
    ``method``'s step (`rotframe.problem.steps.take_step`) are constants of its trial (`event_trial`);
    ``system`` is the right-hand side the stages call (`rotframe.problem.dop853_variant.dop853_parts`).
    Inlined into the DOP853 loop; ``cold``, a function of its own that the fixed-step loop calls only
    where a step may cross (`rotframe.problem.fixed_step.quiet_step`): inlined, its locator's
    re-steps took the registers of the loop's state (the tower drop's ensemble with the ground
    event, 1.65 to 1.52 times the scenes' kernels' time, 2026-11-30). ``take``: the trial's step where it is
    not the method's (`rotframe.problem.fixed_step.fixed_step_loop`).
    """
    trial = jit_inline(bound(event_trial, f"event_trial_{kind}", STEPPER=step, BODY_FLAG=body,
                             TAKE=take or take_step(method)))
    sign = jit_inline(bound(start_sign, f"start_sign_{kind}", TRIAL=trial))
    made = bound(watch_events, f"watch_{kind}", SYSTEM=system, TRIAL=trial, LOCATE=locator(kind, trial),
                 START_SIGN=sign)
    return jit_uncounted(made) if cold else jit_inline(made)
