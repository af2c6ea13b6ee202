"""DOP853's step-size control and starting step, written once for every DOP853 loop of rotframe.

Hairer's rules, as in ``dop853.f`` (Hairer, Norsett & Wanner, *Solving Ordinary Differential
Equations I*, 2nd ed., II.4 and II.10; docs/physics/dop853.md), with the code's defaults
(``safe = 0.9``, ``fac1 = 0.333``, ``fac2 = 6``, ``beta = 0``):

* a step whose error norm ``err`` (`rotframe.numerics.dop853.dop853_error_norm`) is at most 1
  is accepted, and the next one is ``h / fac`` with ``fac = err^(1/8) / 0.9`` held within
  ``[1/6, 1/0.333]``: it grows at most 6 times and shrinks at most 3.003 times;
* right after a rejection the step does not grow;
* a rejected step is tried again with ``h / min(1/0.333, err^(1/8) / 0.9)``;
* a step that gave a non-finite state (an overflow: far too long a step) is tried again 10 times
  shorter (``dop853.f`` leaves this case undefined);
* a step cut short to land on a sample or a knot (``h < h_ctrl``, the controller's own) hands the
  controller's step on, not one made from the short step's error (``dop853.f`` lands only on the
  end of the run; here the loops land on every sample, so this keeps the steps those of the
  controller);
* the starting step is Hairer's ``hinit`` of order 8: an explicit Euler trial step from the
  sizes of ``y`` and ``f(y)``, then the step at which the second derivative, estimated from
  one more evaluation, keeps the local error at the tolerance;
* a particle's default absolute tolerances are rotframe's own rule (`own_tolerances`), from its
  start state and the run's length, so that its steps do not depend on the ensemble it runs in;
  the scenes' ensembles take one scale for all, ``rtol`` times `ensemble_scale`.

The particle scenes (`rotframe.particles.drivers`, `rotframe.particles.dop853_steady`), the
rigid bodies (`rotframe.rigid.adaptive`) and the engine of your own problems
(`rotframe.problem.engine`) all call these functions: one controller, so a method named
``dop853`` takes the same steps whatever runs it. ``tests/test_step_control.py`` checks them
against the rules above written out independently.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.numerics.compiled import jit_inline, jit_internal, jit_kernel

__all__ = ["next_step", "first_step_trial", "first_step", "step_collapsed", "grid_time", "steps_to_event",
           "start_short_of", "own_tolerances", "own_tolerance_rows", "ensemble_scale", "SAFE", "FACC1", "FACC2",
           "NONFINITE_SHRINK"]

SAFE = 0.9  # dop853.f's safety factor
FACC1 = 1.0 / 0.333  # the most a step shrinks after an error estimate (1 / fac1)
FACC2 = 1.0 / 6.0  # 1 / fac2: the most a step grows is 6 times
NONFINITE_SHRINK = 0.1  # a step that gave a non-finite state is tried again this much shorter


@jit_inline
def next_step(h, h_ctrl, err, rejected):
    """Whether a step of length ``h`` with error norm ``err`` is accepted, and the next step to try.

    Parameters
    ----------
    h : float
        The step just taken (s).
    h_ctrl : float
        The controller's step before it was cut to land on a target (``h <= h_ctrl``; ``h`` where
        it was not cut).
    err : float
        Hairer's error norm of the step (1 is the tolerance); non-finite for a non-finite state.
    rejected : bool
        Whether the try before this one was rejected (then the step does not grow).

    Returns
    -------
    (accepted, h_next) : (bool, float)
    """
    if not math.isfinite(err):
        return False, h * NONFINITE_SHRINK
    fac = err ** 0.125 / SAFE
    if fac > FACC1:  # comparisons, not min/max: no overloads to compile
        fac = FACC1
    if err > 1.0:
        return False, h / fac
    if fac < FACC2:
        fac = FACC2
    h_next = h / fac
    if rejected and h_next > h:
        h_next = h
    if h < h_ctrl and h_next < h_ctrl:  # a step cut to land: go on with the controller's
        h_next = h_ctrl
    return True, h_next


@jit_inline
def grid_time(times, s, j, h):
    """The start of step ``j`` of sample interval ``s`` of a fixed step ``h``: ``times[s] + j h``.

    The one rule of every fixed-step loop (the engine's, `rotframe.problem.fixed_step`; the scenes' drivers,
    `rotframe.particles.drivers`): a step's time is counted on its own sample interval's grid, so it does not
    depend on the call the step falls in, and a run cut into calls anywhere takes its steps, plans and event
    times at the same times to the bit (``t0 + k h`` from each call's own start did not).
    """
    return times[s] + j * h if j > 0 else times[s]


def steps_to_event(t_event, times, sps, h):
    """The steps each particle took to the one in which its terminal event at ``t_event`` fell: step ``j`` of sample
    interval ``k`` runs from ``times[k] + j h`` (`grid_time`) to the next step's start
    (``times[k + 1]`` for the last), and the event is in ``(start, end]``: the counts that the steady runs of the
    fixed-step methods report (`rotframe.problem.particles`, `rotframe.problem.steady_gpu`), as the engine's loop
    counts them."""
    k = np.clip(np.searchsorted(times, t_event, side="left") - 1, 0, times.size - 2)
    j = np.clip(np.floor((t_event - times[k]) / h).astype(np.int64), 0, sps - 1)
    for _ in range(2):  # the floor's rounding: at most one step either way, moved to the grid's own start times
        start = np.where(j > 0, times[k] + j * h, times[k])
        j = np.where((start >= t_event) & (j > 0), j - 1, j)
        nxt = times[k] + (j + 1) * h
        j = np.where((nxt < t_event) & (j + 1 < sps), j + 1, j)
    return k * sps + j + 1


@jit_inline
def start_short_of(t, h, t_end):
    """The start time to hand a step's stages so that its end, ``start + h``, falls just short of ``t_end``.

    For an RK4 step from ``t`` that ends on a knot of the engine's (`rotframe.numerics.stops`) at
    ``t_end``: its fourth stage is f at ``t + h``, and at the knot itself a table reads the next
    interval (`rotframe.problem.varying.interval`). Where the rate turns there (a piecewise-linear
    table: omega' jumps), f from the wrong side cost the step an error of order h at every knot.
    Handed a start an ulp or two earlier, every stage reads f at a time that many ulps earlier
    (nothing, for f smooth inside the interval) and the last one reads the step's own interval.
    The step itself keeps its length ``h`` and ends on the knot: a shorter step instead lagged the
    state by ulps at every knot, which a body frame's thousands of knots summed to 1e-9 m.
    """
    start = t
    d = 2.220446049250313e-16 * abs(t_end) + 5e-324
    while start + h >= t_end:
        start -= d
    return start


@jit_inline
def step_collapsed(h, t):
    """Whether a step ``h`` from time ``t`` is below round-off: under 10 units in the last place of ``t``."""
    return h < 10.0 * (math.nextafter(abs(t), math.inf) - abs(t))


@jit_inline
def scaled_rms(x, y, rtol, atol):
    """The RMS norm of ``x`` scaled componentwise by ``atol[j] + rtol |y[j]|`` (Hairer's hinit)."""
    n = y.shape[0]
    acc = 0.0
    for j in range(n):
        c = x[j] / (atol[j] + rtol * abs(y[j]))
        acc += c * c
    return math.sqrt(acc / n)


@jit_internal
def first_step_trial(y, f0, rtol, atol, h_max):
    """Hairer's starting step, first part: the explicit Euler trial step ``h0`` (at most ``h_max``).

    ``y``, ``f0 = f(t, y)`` and ``atol`` (one per component) of length n; the scale of component
    j is ``atol[j] + rtol |y[j]|``. The caller evaluates ``f1 = f(t + h0, y + h0 f0)`` and
    passes it to `first_step`.
    """
    d0 = scaled_rms(y, y, rtol, atol)
    d1 = scaled_rms(f0, y, rtol, atol)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    return h0 if h0 < h_max else h_max


@jit_internal
def first_step(y, f0, f1, h0, rtol, atol, h_max):
    """Hairer's starting step of order 8 from the trial step ``h0`` of `first_step_trial` and ``f1`` there.

    Returns ``min(100 h0, h1, h_max)`` with ``h1 = (0.01 / max(|f0|, |f1 - f0| / h0))^(1/8)`` in
    the scaled norm (``max(1e-6, 1e-3 h0)`` where both are below 1e-15); 0 when ``h0`` is 0 (a
    run of no length).
    """
    if h0 == 0.0:
        return 0.0
    n = y.shape[0]
    d1 = scaled_rms(f0, y, rtol, atol)
    d2 = 0.0
    for j in range(n):
        c = (f1[j] - f0[j]) / (atol[j] + rtol * abs(y[j]))
        d2 += c * c
    d2 = math.sqrt(d2 / n) / h0
    big = d1 if d1 > d2 else d2
    h1 = (1e-6 if 1e-6 > h0 * 1e-3 else h0 * 1e-3) if big <= 1e-15 else (0.01 / big) ** 0.125
    h = 100.0 * h0
    if h1 < h:
        h = h1
    return h if h < h_max else h_max


@jit_inline
def own_tolerances(y, duration, rtol, atol):
    """A particle's absolute tolerances from its start state ``y`` (r, v, ...) into ``atol`` (D,), where a DOP853 loop
    first takes it (NaN until then: `rotframe.problem.particle_setup.tolerance_rows`; the engine's loop,
    `rotframe.problem.engine`), or before the loop (`own_tolerance_rows`: the steady loop's, `rotframe.problem.steady`):
    ``rtol s_r`` for r, ``rtol s_v`` for v, ``rtol`` for the rest (the frame's attitude); ``s_r = max(max|r|, max|v|
    duration)``, ``s_v = max(max|v|, s_r / duration)``, 1 and 1 / duration at rest at the origin. Its own scales: its
    numbers do not depend on the ensemble."""
    ar = 0.0
    av = 0.0
    for j in range(3):
        a = abs(y[j])
        b = abs(y[3 + j])
        ar = a if a > ar else ar
        av = b if b > av else av
    sr = av * duration
    sr = ar if ar >= sr else sr
    sv = sr / duration
    sv = av if av >= sv else sv
    if sr == 0.0:
        sr = 1.0
        sv = 1.0 / duration
    for j in range(atol.shape[0]):
        atol[j] = rtol * (sr if j < 3 else sv if j < 6 else 1.0)


@jit_kernel
def own_tolerance_rows(y, duration, rtol, rows):
    """`own_tolerances` of every state ``y[i]`` (N, D) into ``rows[i]`` (N, D): a large ensemble's, before its loop."""
    for i in range(y.shape[0]):
        own_tolerances(y[i], duration, rtol, rows[i])


def ensemble_scale(r, v):
    """max(1, |r|, |v|) over every component of the states ``r``, ``v`` (numpy; any shapes): the scale of the
    absolute tolerance (``rtol`` times it, r and v alike) that the scenes' DOP853 ensembles take for all their
    particles (`rotframe.particles.chunked.KernelSetup.abs_tol`, `rotframe.particles.ensemble`)."""
    return max(1.0, float(np.max(np.abs(r), initial=0.0)), float(np.max(np.abs(v), initial=0.0)))
