"""The engine of a problem of your own: DOP853, RK4, the models' splittings and events, compiled once.

Every particle problem of ``rotframe.simulate`` and every body of ``rotframe.simulate_body``
runs these functions, compiled with numba and cached on disk (``cache=True``): a problem
hands them the addresses of its own compiled functions (`rotframe.problem.calls`) and its data
as the `rotframe.problem.signatures.PROBLEM` tuple (`rotframe.problem.glue` compiles those few small
functions, and nothing else, per problem). The equations are `rotframe.problem.models`'.

The loop is one function, written once, compiled as a *variant* per model (particle or body),
method and whether there are events (`variant`): those three are constants of a variant's code,
so numba prunes everything else before it compiles (a first DOP853 particle problem compiles no
body, no splitting, no RK4 and no event locator). Each variant compiles the first time any
problem needs it, then loads from numba's cache; no problem ever compiles the loop again.

* DOP853: Hairer's step control and starting step (hinit), written once for every DOP853 loop in
  `rotframe.numerics.step_control`; a step lands on the run's end and on the stops, and the
  samples inside a step are Hairer's dense output of order 7 (three more stages in a step that
  holds one; `rotframe.numerics.dop853_dense`), as in every DOP853 loop of rotframe. Tableau
  and error norm: `rotframe.numerics.dop853`.
* RK4 (method ``RK4``) and the model's own fixed-step methods (`rotframe.problem.models.own_step`,
  ``SPLITTING`` and ``SPLITTING4``): a fixed step that divides each sample interval.
* Events: a sign change of g over a step (with its direction) is bisected on the step's
  length, each trial a re-step from the step's start by the same method, to round-off in
  time on the method's own discrete trajectory (as the built-in ground event,
  docs/physics/events.md). The earliest terminal crossing ends the particle; samples after
  it keep the state at the event.
* Stops: ``S``, sorted times inside the run where the right-hand side is not smooth (the knots
  of an omega or origin table, the samples of a body frame: the interpolant's higher
  derivatives jump there). No step crosses one: a step that would is cut to end on it, as
  DifferentialEquations.jl's ``tstops``, so each step integrates a smooth function and keeps its
  order; RK4's grid goes on from the knot. Without this, a finer table gave larger errors.
* ``atol`` is (N, D), one row per particle (its own scales).
* Each particle is integrated alone, ``budget`` steps per call, so results do not depend on
  the thread count and Python sees signals between calls. ``advance(lo, hi, ...)`` takes the
  particles ``lo:hi``; Python runs blocks of them on threads (the engine holds no GIL). numba's
  ``prange`` was measured at 15 ms a call on the 2-core reference machine (its OpenMP pool
  waking), more than a whole single-particle run.
* The kernels compile without reference counting (`rotframe.numerics.compiled.jit_uncounted`:
  the counts, at every call that could raise, cost more than the arithmetic; measured 2 to 3
  times a step's time), the variants' loops too: ``advance`` (Python) makes their work arrays
  (`scratch`) and owns every array for the call.

Status codes per particle: 0 running, 1 finished, 2 stopped by a terminal event,
3 non-finite state, 4 step size collapsed, 5 an event function gave NaN (or raised), 6 a user
function raised (`rotframe.problem.calls`: the engine stops the particle at the step where it did).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types

from rotframe.numerics import bisection, dop853_dense, step_control
from rotframe.numerics.compiled import inlined, jit_inline, jit_uncounted, uncounted
from rotframe.numerics.dop853 import coefficients, dop853_error_norm as _counted_error_norm
from rotframe.numerics.step_control import next_step, step_collapsed
from rotframe.problem.calls import RAISED, call_event
from rotframe.problem.models import DOP853, RK4, SCRATCH, SPLITTING, SPLITTING4, own_step, particle_energy, rhs
from rotframe.problem.signatures import A1, A2, A3, B1, F8, FUNCTIONS, I1, I2, I8, PARTICLE, POTENTIAL, PROBLEM

__all__ = ["advance", "variant", "variant_loop", "scratch", "start_events", "energies", "ready"]

A, C, DW = dop853_dense.extended_tableau()  # the stages, row 12 the order-8 weights, rows 13-15 the dense output's
E3, E5 = coefficients()[3:]
# the shared kernels that take arrays, compiled as the engine's own (without reference counts), the small ones inlined
# into their one caller (a function compiled apart costs a first run more than its lines: 1 to 2 s for these three)
dop853_error_norm = uncounted(_counted_error_norm)
first_step_trial = inlined(step_control.first_step_trial)
first_step_final = inlined(step_control.first_step)
dense_coefficients = inlined(dop853_dense.dense_coefficients)
dense_value = dop853_dense.dense_value  # inlined into its callers
bisection_midpoint = inlined(bisection.bisection_midpoint)
narrow = inlined(bisection.narrow)
MAX_HALVINGS = bisection.MAX_HALVINGS

_entry = njit(cache=True, error_model="numpy", nogil=True)
#: the variants' loops: entry points without reference counts (`rotframe.numerics.compiled.jit_uncounted`), their work
#: arrays made by the caller (`scratch`)
_uncounted_entry = njit(cache=True, error_model="numpy", nogil=True, _nrt=False)


@jit_inline
def stage_state(z, y, h, K, s, D):
    """z = y + h sum_m a_m K[m] for stage s (12: the step's end, weights B; 13-15 the dense output's), in order."""
    for j in range(D):
        z[j] = 0.0
    for m in range(s):
        a = A[s, m]
        for j in range(D):
            z[j] += a * K[m, j]
    for j in range(D):
        z[j] = y[j] + h * z[j]


@jit_uncounted
def dop853_step(body, t, y, h, t_end, K, yt, yn, prob, fns, W):
    """One DOP853 step from (t, y) with K[0] = f(t, y): yn and K[1..12] (K[12] = f(t + h, yn))."""
    D = y.shape[0]
    for s in range(1, 13):  # the stages, then f at the step's end (one call site of the right-hand side)
        z = yt if s < 12 else yn
        if D == 6:  # a particle: the loops of 6 known to the compiler (unrolled), the same arithmetic
            stage_state(z, y, h, K, s, 6)
        else:
            stage_state(z, y, h, K, s, D)
        ts = t + C[s] * h if s < 12 else t_end  # the last: the time the step ends on (a sample time where it lands)
        rhs(body, ts, z, K[s], prob, fns, W)


@jit_uncounted
def dense_output(body, t, y, yn, h, K, z, F, prob, fns, W):
    """The interpolant's coefficients ``F`` (7, D) of an accepted DOP853 step (t, y) -> (t + h, yn).

    Its three more stages into ``K[13..15]`` (`rotframe.numerics.dop853_dense`), then Hairer's
    coefficients; `dense_value` evaluates them.
    """
    D = y.shape[0]
    for s in range(13, 16):
        stage_state(z, y, h, K, s, D)
        rhs(body, t + C[s] * h, z, K[s], prob, fns, W)
    dense_coefficients(y, yn, K, h, DW, F)


@jit_uncounted
def rk4_step(body, t, y, h, K, yt, yn, prob, fns, W):
    """One classical Runge-Kutta step from (t, y) with K[0] = f(t, y)."""
    D = y.shape[0]
    for s in range(1, 4):  # one call site of the right-hand side
        c = 0.5 if s < 3 else 1.0
        for j in range(D):
            yt[j] = y[j] + c * h * K[s - 1, j]
        rhs(body, t + c * h, yt, K[s], prob, fns, W)
    for j in range(D):
        yn[j] = y[j] + h * (K[0, j] + 2.0 * K[1, j] + 2.0 * K[2, j] + K[3, j]) / 6.0


@jit_inline
def take_step(body, method, t, y, h, t_end, K, yt, yn, prob, fns, W):
    if method == DOP853:
        dop853_step(body, t, y, h, t_end, K, yt, yn, prob, fns, W)
    elif method == RK4:
        rk4_step(body, t, y, h, K, yt, yn, prob, fns, W)
    else:  # the model's own splitting, of order 2 or 4
        own_step(body, method, t, y, h, yn, prob, fns, W)


@jit_inline
def all_finite(y):
    for j in range(y.shape[0]):
        if not math.isfinite(y[j]):
            return False
    return True


@jit_uncounted
def first_step(body, t, y, K, yt, rtol, atol, prob, fns, W, span):
    """Hairer's starting step (`rotframe.numerics.step_control`), K[0] = f(t, y) given; K[1] = f at the trial step."""
    h0 = first_step_trial(y, K[0], rtol, atol, span)
    for j in range(y.shape[0]):
        yt[j] = y[j] + h0 * K[0, j]
    rhs(body, t + h0, yt, K[1], prob, fns, W)
    return first_step_final(y, K[0], K[1], h0, rtol, atol, span)


@jit_inline
def next_stop(S, t):
    """The first stop time in the sorted S after t (inf if none): a knot where the right-hand side is not smooth."""
    n = S.shape[0]
    if n == 0 or S[n - 1] <= t:
        return math.inf
    lo = 0
    hi = n - 1
    while lo < hi:  # the first S[k] > t
        mid = (lo + hi) // 2
        if S[mid] > t:
            hi = mid
        else:
            lo = mid + 1
    return S[lo]


@jit_inline
def locate(body, method, k, t, y, h, g_lo, Kb, ytb, yhi, ybuf, prob, fns, W):
    """Bisect for event k's crossing inside the step (t, t + h], re-stepping from (t, y) with the method.

    Returns tau in (0, h]; ``yhi`` holds the state there (the full step's end on entry). The
    crossing is bracketed to round-off in time on the method's own discrete trajectory, by
    rotframe's one bisection rule (`rotframe.numerics.bisection`), as the scenes' locators.
    """
    lo = 0.0
    hi = h
    rhs(body, t, y, Kb[0], prob, fns, W)
    for _ in range(MAX_HALVINGS):
        mid = bisection_midpoint(lo, hi)
        if mid < 0.0:
            break
        take_step(body, method, t, y, mid, t + mid, Kb, ytb, ybuf, prob, fns, W)
        lo, hi, g_lo = narrow(lo, hi, g_lo, mid, call_event(fns[1], k, t + mid, ybuf, prob[2]))
        if hi == mid:  # the crossing is in [lo, mid]: the state at hi is this trial's
            for j in range(y.shape[0]):
                yhi[j] = ybuf[j]
    return hi


@jit_inline
def start_sign(body, method, k, t, y, h, Kb, ytb, ybuf, prob, fns, W):
    """Event k's value just after the start ``(t, y)``, for a function that is exactly zero there.

    The rule of every locator (docs/physics/events.md): the start itself is never an event, and
    a function that is zero there takes the sign it has just after it. The trials are re-steps
    by the method from ``(t, y)`` of lengths ``h / 2, h / 4, ...``; the value kept is the one
    nearest the start that is not zero. The halving stops where g halves with tau (its first
    derivative rules below there: one or two trials for a shot fired from the ground), else
    where a trial no longer moves the state or tau underflows (a function whose first
    derivative is zero at the start: some thousand trials, once). A projectile fired from the
    ground thus lands at its first return to it however soon, inside the first step too, and one
    fired into the ground is not an event. Returns 0.0 when g stays zero (no sign to take).
    """
    rhs(body, t, y, Kb[0], prob, fns, W)
    g_near = 0.0
    g_before = 0.0  # g at the trial before (twice as long)
    tau = h
    for _ in range(MAX_HALVINGS):
        tau = 0.5 * tau
        if tau == 0.0:
            break
        take_step(body, method, t, y, tau, t + tau, Kb, ytb, ybuf, prob, fns, W)
        g = call_event(fns[1], k, t + tau, ybuf, prob[2])
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


def _variant_kernel(model, method, events):
    """The compiled loop of one variant (`variant_loop`), for the CPU: an entry point without reference counts."""
    return _uncounted_entry(variant_loop(model, method, events))


def variant_loop(model, method, events):
    """The loop of one variant, as Python: the model, ``method`` and ``events`` are constants of its code.

    numba prunes the branches of the other model, the other methods and the events before it types
    the function (a closure's variables are constants to it; the model reaches the steps as
    ``body``, None for a particle, True for a rigid body: `rotframe.problem.models.rhs`), so a
    variant compiles only its own right-hand side, step and dense output: a first DOP853 particle
    problem compiles no body, no splitting and no event locator. Each variant is cached on disk
    apart (its name, and its constants in numba's cache key). The GPU compiles the same function
    (`rotframe.problem.gpu`).
    """
    body = None if model == PARTICLE else True

    def advance(lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, rtol,
                atol, hfix, EDIR, ETERM, S, prob, fns, K, Kb, V, F, W):
        # K (16, D), Kb (13, D) stages, V (7, D) state vectors, F (7, D) the dense output's coefficients, W the
        # models' scratch: the caller's (`scratch`), one set for the block
        n = T.shape[0]
        D = Y.shape[1]
        NE = EDIR.shape[0]
        y = V[0]
        yt = V[1]
        yn = V[2]
        ytb = V[3]
        yhi = V[4]
        ybuf = V[5]
        yev = V[6]
        p = prob[2]
        for i in range(lo, hi):
            if ST[i] != 0:
                continue
            atol_i = atol[i]
            for j in range(D):
                y[j] = Y[i, j]
            t = TC[i]
            h = H[i]
            idx = IDX[i]
            sub = SUB[i]
            W[RAISED] = 0.0
            rhs(body, t, y, K[0], prob, fns, W)
            NFEV[i] += 1
            if method == DOP853 and h <= 0.0:
                h = first_step(body, t, y, K, yt, rtol, atol_i, prob, fns, W, T[n - 1] - T[0])
                NFEV[i] += 1
            steps = 0
            # DOP853 keeps in SUB whether its last try was rejected (no growth right after a rejection), so that
            # the steps, and the numbers, do not depend on where the budget cut the calls
            rejected = method == DOP853 and sub != 0
            status = 0
            while idx < n and steps < budget:
                if t >= T[idx]:
                    for j in range(D):
                        OUT[idx, i, j] = y[j]
                    idx += 1
                    sub = 0
                    continue
                stop = next_stop(S, t)
                if method == DOP853:
                    # a step ends on the next stop (a knot of a table or a body frame) or the run's end, whichever is
                    # first; the samples inside a step are its dense output
                    target = stop if stop < T[n - 1] else T[n - 1]
                    span = target - t
                    hh = h if h < span else span
                    landing = hh == span
                else:
                    # a step ends on the next sample or the next stop, whichever is first
                    at_knot = stop < T[idx]
                    target = stop if at_knot else T[idx]
                    interval = T[idx] - T[idx - 1]
                    on_grid = t == (T[idx - 1] + sub * hfix if sub > 0 else T[idx - 1])
                    last = (sub + 1) * hfix >= interval * (1.0 - 1e-12)
                    grid_next = T[idx] if last else T[idx - 1] + (sub + 1) * hfix
                    if at_knot and stop < grid_next:
                        hh = stop - t  # to the knot; the grid goes on from there
                        landing = True
                    else:
                        target = T[idx]
                        hh = hfix if on_grid else grid_next - t
                        sub += 1
                        landing = last
                take_step(body, method, t, y, hh, target if landing else t + hh, K, yt, yn, prob, fns, W)
                steps += 1
                NSTEP[i] += 1
                NFEV[i] += 12 if method == DOP853 else 3 if method == RK4 else 2
                if W[RAISED] != 0.0:  # a user function raised in this step: stop here, Python names it
                    status = 6
                    break
                ok = all_finite(yn)
                h_next = h
                if method == DOP853:
                    err = dop853_error_norm(K, hh, y, yn, rtol, atol_i, E3, E5) if ok else math.nan
                    ok = math.isfinite(err)
                    accepted, h_next = next_step(hh, h, err, rejected)
                    if not accepted:
                        h = h_next
                        rejected = True
                        if step_collapsed(h, t):
                            status = 4 if ok else 3
                            break
                        continue
                if not ok:
                    status = 3
                    break
                t_new = target if landing else t + hh
                if method != DOP853 and not landing:
                    t_new = T[idx - 1] + sub * hfix
                # events over (t, t_new]: every crossing located; the earliest terminal one ends the particle
                stop_tau = -1.0
                stop_k = -1
                if events:  # a constant of the variant: without events, none of this is compiled
                    for k in range(NE):
                        g_new = call_event(fns[1], k, t_new, yn, p)
                        if not math.isfinite(g_new):  # NaN, or the event function raised: stop here, Python names it
                            status = 5
                            break
                        g_old = GPREV[i, k]
                        if g_old == 0.0 and t == T[0]:  # zero at the start: the sign just after it (start_sign)
                            g_old = start_sign(body, method, k, t, y, t_new - t, Kb, ytb, ybuf, prob, fns, W)
                        rising = g_old < 0.0 and g_new >= 0.0
                        falling = g_old > 0.0 and g_new <= 0.0
                        if (rising and EDIR[k] >= 0) or (falling and EDIR[k] <= 0):
                            for j in range(D):
                                yhi[j] = yn[j]
                            tau = locate(body, method, k, t, y, t_new - t, g_old, Kb, ytb, yhi, ybuf, prob, fns, W)
                            m = EVN[i]
                            if m < EVT.shape[1]:
                                EVT[i, m] = t + tau
                                EVK[i, m] = k
                                for j in range(D):
                                    EVY[i, m, j] = yhi[j]
                            EVN[i] = m + 1
                            if ETERM[k] and (stop_tau < 0.0 or tau < stop_tau):
                                stop_tau = tau
                                stop_k = k
                                for j in range(D):
                                    yev[j] = yhi[j]
                        GPREV[i, k] = g_new
                if status == 5:
                    break
                # DOP853's samples inside the step (up to a terminal event's time): its dense output, of order 7
                t_last = t + stop_tau if stop_k >= 0 else t_new
                if method == DOP853 and idx < n and T[idx] < t_new and T[idx] <= t_last:
                    dense_output(body, t, y, yn, hh, K, yt, F, prob, fns, W)
                    NFEV[i] += 3
                    if W[RAISED] != 0.0:
                        status = 6
                        break
                    while idx < n and T[idx] < t_new and T[idx] <= t_last:
                        x = (T[idx] - t) / hh
                        for j in range(D):
                            OUT[idx, i, j] = dense_value(F, y, x, j)
                        idx += 1
                if stop_k >= 0:
                    # drop records of non-terminal crossings after the terminal one
                    m = EVN[i]
                    keep = 0
                    for r in range(min(m, EVT.shape[1])):
                        if EVT[i, r] <= t + stop_tau:
                            EVT[i, keep] = EVT[i, r]
                            EVK[i, keep] = EVK[i, r]
                            for j in range(D):
                                EVY[i, keep, j] = EVY[i, r, j]
                            keep += 1
                    EVN[i] = keep
                    t = t + stop_tau
                    for j in range(D):
                        y[j] = yev[j]
                    while idx < n:
                        for j in range(D):
                            OUT[idx, i, j] = y[j]
                        idx += 1
                    status = 2
                    break
                if method == DOP853:
                    h = h_next
                    rejected = False
                    for j in range(D):
                        K[0, j] = K[12, j]
                t = t_new
                for j in range(D):
                    y[j] = yn[j]
                if method != DOP853:
                    rhs(body, t, y, K[0], prob, fns, W)
                    NFEV[i] += 1
            if status == 0 and idx >= n:
                status = 1
            for j in range(D):
                Y[i, j] = y[j]
            TC[i] = t
            H[i] = h
            IDX[i] = idx
            SUB[i] = sub if method != DOP853 else (1 if rejected else 0)
            ST[i] = status

    name = f"advance_{'particle' if body is None else 'body'}_{METHOD_NAMES[method]}{'_events' if events else ''}"
    advance.__name__ = name
    advance.__qualname__ = name
    return advance


#: the engine's method codes by name, for the variants' names (the codes never leave this package)
METHOD_NAMES = {DOP853: "dop853", RK4: "rk4", SPLITTING: "splitting", SPLITTING4: "splitting4"}
_VARIANTS: dict = {}


def variant(model, method, events, compiled=True):
    """The loop of ``model`` (`PARTICLE`, `BODY`), ``method`` (a code of `rotframe.problem.models`) and
    ``events`` (whether the problem has any): compiled for `VARIANT_SIGNATURE` (or loaded from numba's cache)
    when first asked for; with ``compiled=False`` its plain Python remake (`rotframe.numerics.plain`)."""
    key = (int(model), int(method), bool(events), bool(compiled))
    kernel = _VARIANTS.get(key)
    if kernel is None:
        kernel = _variant_kernel(*key[:3])
        if compiled:
            kernel.compile(VARIANT_SIGNATURE)
            kernel.disable_compile()
        else:
            from rotframe.numerics.plain import plain

            kernel = plain(kernel)
        _VARIANTS[key] = kernel
    return kernel


def scratch(D):
    """The loop's work arrays for states of D numbers: stages ``K`` (16, D) and ``Kb`` (13, D), state vectors
    ``V`` (7, D), the dense output's coefficients ``F`` (7, D) and the models' scratch ``W``."""
    return np.empty((16, D)), np.empty((13, D)), np.empty((7, D)), np.empty((7, D)), np.zeros(SCRATCH)


def advance(lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, method, rtol,
            atol, hfix, EDIR, ETERM, S, prob, fns, compiled=True):
    """Advance the particles ``lo:hi`` by at most ``budget`` steps each (module docstring); the state is in the arrays.

    ``T`` the sample times; ``Y`` (N, D) the states to go on from, ``TC``, ``H``, ``IDX``, ``SUB``,
    ``ST`` each particle's time, step, next sample, fixed-step count and status; ``OUT`` (n, N, D)
    the samples; ``EVT``, ``EVY``, ``EVK``, ``EVN`` the event records; ``GPREV`` (N, NE) each
    event's last value; ``EDIR``, ``ETERM`` (NE,) the events' directions and terminal flags.
    Runs the problem's `variant` of the loop (``compiled=False``: as plain Python) with work arrays of its own.
    """
    kernel = variant(prob[0], method, EDIR.shape[0] > 0, compiled)
    kernel(lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, rtol, atol, hfix,
           EDIR, ETERM, S, prob, fns, *scratch(Y.shape[1]))


@_entry
def start_events(t, Y, GPREV, prob, fns):
    """Each event's value at the start, per particle, into ``GPREV`` (N, NE)."""
    for i in range(Y.shape[0]):
        for k in range(GPREV.shape[1]):
            GPREV[i, k] = call_event(fns[1], k, t, Y[i], prob[2])


@_entry
def energies(T, OUT, prob, fns, potential, rotating):
    """Energy (rotating = False) or the Jacobi integral (rotating = True) per sample and particle, per unit mass."""
    n = OUT.shape[0]
    N = OUT.shape[1]
    E = np.empty((n, N))
    W = np.zeros(SCRATCH)
    for a in range(n):
        for i in range(N):
            E[a, i] = particle_energy(T[a], OUT[a, i], prob, fns, potential, rotating, W)
    return E


#: the one signature of every variant's loop (`variant`): compiled (or loaded from numba's cache) once, never for a
#: problem
VARIANT_SIGNATURE = types.void(I8, I8, A1, A2, A1, A1, I1, I1, I1, A3, A2, A3, I2, I1, A2, I1, I1, I8, F8, A2, F8, A1,
                               B1, A1, PROBLEM, FUNCTIONS, A2, A2, A2, A2, A1)
#: the one signature of each other entry point
SIGNATURES = {
    start_events: types.void(F8, A2, A2, PROBLEM, FUNCTIONS),
    energies: A2(A1, A3, PROBLEM, FUNCTIONS, POTENTIAL, types.boolean),
}


def ready(kernel):
    """The entry point ``kernel`` compiled for its one signature (loaded from numba's cache after the first time).

    Each is compiled when a run first needs it (a problem without events or potentials never
    compiles `start_events` or `energies`), then closed to new compiles: a problem's functions
    reach it as addresses (`rotframe.problem.calls`), never as a new specialisation.
    """
    if not kernel.signatures:
        kernel.compile(SIGNATURES[kernel])
        kernel.disable_compile()
    return kernel
