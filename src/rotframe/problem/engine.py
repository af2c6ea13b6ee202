"""The engine of a problem of your own: DOP853, RK4, the models' splittings and events, compiled once.

Every particle problem of ``rotframe.simulate`` and every body of ``rotframe.simulate_body``
runs these functions, compiled with numba and cached on disk (``cache=True``): a problem
hands them the addresses of its own compiled functions (`rotframe.problem.calls`) and its data
as the `rotframe.problem.signatures.PROBLEM` tuple (`rotframe.problem.glue` compiles those few small
functions, and nothing else, per problem). The equations are `rotframe.problem.models`'.

The loop is compiled as a *variant* per model (particle or body), method and whether there are
events (`variant`): those three are constants of a variant's code, so numba prunes everything
else before it compiles (a first DOP853 particle problem compiles no body, no splitting, no RK4
and no event locator). Each variant compiles the first time any problem needs it, then loads
from numba's cache; no problem ever compiles the loop again.

* DOP853: the one DOP853 loop of rotframe (`rotframe.numerics.dop853_loop`, which the scenes'
  particles and rigid bodies run too), compiled for the model's right-hand side: Hairer's step
  control and starting step, a step that lands on the run's end and on the stops, the samples
  inside a step from Hairer's dense output of order 7, the events watched after each accepted
  step (`_watch_events`), a budget of accepted steps per call (`_dop853_loop`). Its *trajectory
  tier* (`trajectory_tier`, a first run of a few particles: `rotframe.problem.tiers`) compiles
  that trajectory loop and the right-hand side alone, the loop over the particles plain Python.
* RK4 (method ``RK4``) and the model's own fixed-step methods (`rotframe.problem.models.own_step`,
  ``SPLITTING`` and its compositions ``SPLITTING4``, ``SPLITTING6``, ``SPLITTING8``): a fixed step that
  divides each sample interval.
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
* ``atol`` is (N, D), one row per particle; a row of NaN is filled with the particle's own
  tolerances where the loop first takes it (`own_tolerances`).
* Each particle is integrated alone, ``budget`` steps per call (DOP853's accepted ones), so
  results do not depend on the thread count and Python sees signals between calls. ``advance(lo, hi, ...)`` takes the
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

from rotframe.numerics.bisection import MAX_HALVINGS, crossed, locator
from rotframe.numerics.compiled import ENTRY_OPTIONS, bound, jit_inline, jit_uncounted
from rotframe.numerics.dop853_loop import (ABORTED, COLLAPSED, DIVERGED, NONFINITE, PAUSED, REACHED, STOPPED,
                                           WATCH_FAILED, dop853_start, dop853_trajectory)
from rotframe.numerics.step_control import own_tolerances
from rotframe.problem.by_address import stages_at, system_at, tier_callees, with_reference
from rotframe.problem.calls import RAISED, address, call_event, direct_functions
from rotframe.problem.models import (DOP853, RK4, SCRATCH, SPLITTING, SPLITTING4, SPLITTING6, SPLITTING8,
                                     particle_energy)
from rotframe.problem.signatures import (A1, A2, A3, B1, BODY, F8, FUNCTIONS, I1, I2, I8, PARTICLE,
                                         POTENTIAL, PROBLEM, STAGES_SIG, SYSTEM_SIG)
from rotframe.problem.fixed_step import fixed_step_loop
from rotframe.problem.loop_state import load_particle, save_particle, watcher_context
from rotframe.problem.steps import body_system, particle_system, stepper, take_step
from rotframe.problem.stops import next_stop

__all__ = ["advance", "variant", "variant_loop", "trajectory_tier", "TRAJECTORY_TIER", "scratch", "start_events",
           "energies", "ready"]

#: the entry points Python calls (no C entry point: nothing calls them from C)
_entry = njit(cache=True, error_model="numpy", nogil=True, no_cfunc_wrapper=True)
#: the variants' loops: entry points without reference counts (`rotframe.numerics.compiled.ENTRY_OPTIONS`), their
#: work arrays made by the caller (`scratch`); a problem's inlined loop too (`rotframe.problem.inlined`)
_uncounted_entry = njit(**ENTRY_OPTIONS)
#: the length of the state of each model, a constant of its DOP853 loop (a particle whose forces act in inertial
#: axes carries the frame's attitude too: 10)
STATE_LENGTH = {PARTICLE: 6, BODY: 7}


@jit_inline
def store_rows(out, k, p, y):
    """Sample ``k`` of particle ``p``: ``out[k, p] = y``."""
    for j in range(y.shape[0]):
        out[k, p, j] = y[j]


@jit_inline
def raised(ctx):
    """Whether a user function raised since the flag was cleared (`rotframe.problem.calls`)."""
    return ctx[2][RAISED] != 0.0


# the names a variant binds (`variant_loop`): None, 0 or False in the templates themselves, which are never compiled
SYSTEM = TRAJECTORY = STEPPER = TAKE = BODY_FLAG = TRIAL = LOCATE = START_SIGN = WATCH = None
METHOD = DIM = 0
EVENTS = False


def _event_trial(tctx, tau):
    """The template of a variant's event trial: event k's value after a re-step of length ``tau``.

    ``tctx = (k, t, y, Kb, ytb, ybuf, ctx)``: the re-step is the variant's method from ``(t, y)``
    (``TAKE``, the method's step of `take_step`, with the variant's ``STEPPER`` and ``BODY_FLAG``;
    ``Kb[0]`` is f(t, y)), its state left in ``ybuf``. The trial of rotframe's one event locator
    (`rotframe.numerics.bisection.locator`) and of `_start_sign`.
    """
    k, t, y, Kb, ytb, ybuf, ctx = tctx
    TAKE(STEPPER, BODY_FLAG, t, y, tau, Kb, ytb, ybuf, ctx)
    return call_event(ctx[1][1], k, t + tau, ybuf, ctx[0][2])


def _start_sign(tctx, h):
    """The template of a variant's start rule: event k's value just after the start, for a function zero there.

    The rule of every locator (docs/physics/events.md): the start itself is never an event, and
    a function that is zero there takes the sign it has just after it. The trials (``TRIAL``, the
    variant's `_event_trial` with ``tctx``) are re-steps by the method from ``(t, y)`` of lengths
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


def _watch_events(wctx, ctx, p, t, h, t_new, y, y_new, K):
    """The template of a variant's watcher: the crossings over the step ``(t, y) -> (t_new, y_new)`` of particle ``p``.

    ``wctx = (GPREV, EVT, EVY, EVK, EVN, EDIR, ETERM, t0, Kb, ytb, yhi, ybuf)``: each event's value
    at ``t`` (updated), the records, the directions and terminal flags, the run's start and the
    locator's scratch; ``ctx`` the system's (``(prob, fns, W)``, more in the trajectory tier's), ``SYSTEM`` its
    right-hand side (f at ``t`` for the re-steps). A crossing (with its direction) is located by
    rotframe's one event locator (``LOCATE``, `rotframe.numerics.bisection.locator`) on re-steps by
    the variant's method (``TRIAL``, `_event_trial`), a zero at the start by ``START_SIGN``
    (`_start_sign`); the state at a crossing is the re-step there (the step's own end where the
    crossing is at it); each is recorded, and the records after the earliest terminal crossing are
    dropped. Returns ``(stop, tau)``: whether a terminal event ends the particle in the step and its
    offset from ``t``, or ``(True, NaN)`` where an event function gave NaN or raised (the particle
    stops at ``t``; Python names the function). The watcher of both loops (`_watcher`):
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
        if g_old == 0.0 and t == t0:  # zero at the start: the sign just after it (_start_sign)
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


def _variant_kernel(model, method, events, D):
    """The compiled loop of one variant (`variant_loop`), for the CPU: an entry point without reference counts."""
    return _uncounted_entry(variant_loop(model, method, events, D))


def variant_loop(model, method, events, D=None):
    """The loop of one variant, as Python: the model, ``method`` (a name of `METHOD_CODES`), ``events`` and ``D``
    constants of its code.

    numba prunes the branches of the other model, the other methods and the events before it types
    the function (a closure's variables are constants to it; the model reaches the steps as
    ``body``, None for a particle, True for a rigid body: `rotframe.problem.models.rhs`), so a
    variant compiles only its own right-hand side and step: a first DOP853 particle problem
    compiles no body, no splitting and no event locator. Each variant is cached on disk apart (its
    name, and its constants in numba's cache key).

    DOP853 runs the one DOP853 loop of rotframe (`rotframe.numerics.dop853_loop`, `_dop853_loop`)
    for the model's right-hand side, from stop to stop. The fixed-step methods run
    `rotframe.problem.fixed_step`'s loop, which the GPU compiles too (`rotframe.problem.gpu`). ``D`` (default
    `STATE_LENGTH`) is the length of the state (a particle's is 10 where a force acts in inertial
    axes), a constant of the steps' code too (`stepper`).
    """
    body = None if model == PARTICLE else True
    method = METHOD_CODES[method]
    D = STATE_LENGTH[model] if D is None else int(D)
    suffix = "" if D == STATE_LENGTH[model] else str(D)
    name = (f"advance_{'particle' if body is None else 'body'}{suffix}_{METHOD_NAMES[method]}"
            f"{'_events' if events else ''}")
    if method == DOP853:
        return _dop853_loop(name, body, events, D)
    step = stepper(body, method, D)
    system = particle_system if body is None else body_system
    return fixed_step_loop(name, body, method, D, step,
                           _watcher(name, step, body, method, system, cold=True) if events else None)


def _watcher(kind, step, body, method, system, cold=False):
    """The events' watcher of a variant (`_watch_events`) with its trial, locator and start rule, bound to them.

    ``kind`` names the variant's copies; ``step`` (the variant's `stepper`), ``body`` and the
    ``method``'s step (`rotframe.problem.steps.take_step`) are constants of its trial (`_event_trial`);
    ``system`` is the right-hand side the stages call (`_dop853_parts`).
    Inlined into the DOP853 loop; ``cold``, a function of its own that the fixed-step loop calls only
    where a step may cross (`rotframe.problem.fixed_step.quiet_step`): inlined, its locator's
    re-steps took the registers of the loop's state (the tower drop's ensemble with the ground
    event, 1.65 to 1.52 times the scenes' kernels' time, 2026-11-30).
    """
    trial = jit_inline(bound(_event_trial, f"event_trial_{kind}", STEPPER=step, BODY_FLAG=body,
                             TAKE=take_step(method)))
    start_sign = jit_inline(bound(_start_sign, f"start_sign_{kind}", TRIAL=trial))
    made = bound(_watch_events, f"watch_{kind}", SYSTEM=system, TRIAL=trial, LOCATE=locator(kind, trial),
                 START_SIGN=start_sign)
    return jit_uncounted(made) if cold else jit_inline(made)


def _dop853_parts(body, events, D, entry=False):
    """The DOP853 variant's trajectory loop: `rotframe.numerics.dop853_loop`'s trajectory compiled for the model's
    right-hand side (`particle_system`, `body_system`, ``ctx = (prob, fns, W)``), the events watched by
    `_watch_events`, a user function that raised ending the trajectory at the step (`raised`).
    ``entry``: the trajectory tier's (`trajectory_tier`), callable from Python, which calls the stages and the
    right-hand side at their addresses (`rotframe.problem.by_address`), cached apart."""
    system = particle_system if body is None else body_system
    kind = f"engine_{'particle' if body is None else 'body'}{D}"
    if entry:
        kind += "_by_address"
        stages, system = stages_at, system_at
    else:
        stages = stepper(body, DOP853, D)
    watch = _watcher(kind, stages, body, DOP853, system) if events else None
    name = kind + ("_events" if events else "") + ("_entry" if entry else "")
    return dop853_trajectory(name, stages, store_rows, D, watch, entry=entry, aborted=raised,
                             **({"enter": with_reference} if entry else {}))


def _dop853_loop(name, body, events, D):
    """The DOP853 variant's loop: `rotframe.numerics.dop853_loop`'s trajectory, per particle, from stop to stop.

    The system and the trajectory are `_dop853_parts`'. A call takes at most ``budget`` accepted steps per particle
    and ends after an accepted step, so the steps do not depend on where the budget cut the calls. The template
    `_dop853_advance` reads the system's functions as globals (`rotframe.numerics.compiled.bound`).
    """
    system = particle_system if body is None else body_system
    trajectory = _dop853_parts(body, events, D)
    return bound(_dop853_advance, name, SYSTEM=system, TRAJECTORY=trajectory, DIM=int(D), EVENTS=bool(events))


def _dop853_advance(lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, rtol,
                    atol, hfix, EDIR, ETERM, S, prob, fns, K, Kb, V, F, W):
    """The template of the DOP853 variant's loop (`_dop853_loop`)."""
    n = T.shape[0]
    t_last = T[n - 1]
    y, yt, yn, tmp = V[0], V[1], V[2], V[3]
    ctx = (prob, fns, W)
    wctx = watcher_context(GPREV, EVT, EVY, EVK, EVN, EDIR, ETERM, T, Kb, V) if EVENTS else 0
    for i in range(lo, hi):
        if ST[i] != 0:
            continue
        atol_i = atol[i]
        t, h, idx = load_particle(i, Y, TC, H, IDX, y)
        if atol_i[0] != atol_i[0]:  # NaN: the particle's own tolerances, from the state it starts from
            own_tolerances(y, t_last - T[0], rtol, atol_i)
        W[RAISED] = 0.0
        SYSTEM(ctx, t, y, K, 0)
        NFEV[i] += 1
        if h <= 0.0:
            h = dop853_start(SYSTEM, ctx, t, y, K, yt, rtol, atol_i, t_last - T[0])
            NFEV[i] += 1
        end = REACHED
        left = budget
        while idx < n and left > 0:
            # to the next stop (a knot of a table or a body frame) or the run's end, whichever is first
            stop = next_stop(S, t)
            t, h, idx, end, nf, steps = TRAJECTORY(ctx, t, y, h, stop if stop < t_last else t_last, math.inf, T,
                                                   idx, OUT, i, rtol, atol_i, K, yn, tmp, yt, F, wctx, left)
            NFEV[i] += nf
            NSTEP[i] += steps
            left -= steps
            if end != REACHED:
                break
        status = 0
        if end == REACHED or end == PAUSED:
            status = 1 if idx >= n else 0
        elif end == STOPPED:
            status = 2
            while idx < n:  # samples after a terminal event keep the state at the event
                for j in range(DIM):
                    OUT[idx, i, j] = y[j]
                idx += 1
        elif end == NONFINITE or end == DIVERGED:
            status = 3
        elif end == COLLAPSED:
            status = 4
        elif end == WATCH_FAILED:
            status = 5
        elif end == ABORTED:
            status = 6
        save_particle(i, Y, TC, H, IDX, SUB, ST, y, t, h, idx, 0, status)


#: the engine's method codes by the registry's names (the codes never leave the engine and its equations,
#: `rotframe.problem.models`): every splitting is the model's own, composed to its order
METHOD_CODES = {"dop853": DOP853, "rk4": RK4, "rotation-splitting": SPLITTING, "rotation-splitting4": SPLITTING4,
                "lie-poisson": SPLITTING, "lie-poisson4": SPLITTING4, "lie-poisson6": SPLITTING6, "lie-poisson8": SPLITTING8,
                "top-splitting": SPLITTING, "top-splitting4": SPLITTING4, "top-splitting6": SPLITTING6,
                "top-splitting8": SPLITTING8}
#: the variants' names of the codes
METHOD_NAMES = {DOP853: "dop853", RK4: "rk4", SPLITTING: "splitting", SPLITTING4: "splitting4", SPLITTING6: "splitting6",
                SPLITTING8: "splitting8"}
_VARIANTS: dict = {}
#: `variant`'s third form of a DOP853 loop beside compiled (True) and plain Python (False), `trajectory_tier`; the fifth
#: of a variant where `rotframe.problem.tiers` asks whether it is made
TRAJECTORY_TIER = "trajectory"


def variant(model, method, events, compiled=True, D=None, load_only=False):
    """The loop of ``model`` (`PARTICLE`, `BODY`), ``method`` (a name of `METHOD_CODES`) and
    ``events`` (whether the problem has any): compiled for `VARIANT_SIGNATURE` (or loaded from numba's cache)
    when first asked for; with ``compiled=False`` its plain Python remake (`rotframe.numerics.plain`); with
    ``compiled=TRAJECTORY_TIER`` (DOP853 alone) its trajectories compiled and the rest plain (`trajectory_tier`). ``D``,
    the length of the state, is a constant of the loop's code (default the model's, `STATE_LENGTH`). With
    ``load_only``: None where the loop would have to compile (neither made in this process nor in the cache), what
    tells a run to begin in the plain tier (`rotframe.problem.tiers`)."""
    from rotframe.numerics.compiled import load_cached

    D = STATE_LENGTH[int(model)] if D is None else int(D)
    key = (int(model), method, bool(events), D, compiled if compiled == TRAJECTORY_TIER else bool(compiled))
    kernel = _VARIANTS.get(key)
    if kernel is None:
        if key[-1] == TRAJECTORY_TIER:
            kernel = trajectory_tier(*key[:4], load_only=load_only)
            if kernel is None:
                return None
        else:
            kernel = _variant_kernel(*key[:4])
            if compiled:
                if not load_cached(kernel, VARIANT_SIGNATURE):
                    if load_only:
                        return None
                    kernel.compile(VARIANT_SIGNATURE)
                kernel.disable_compile()
            else:
                from rotframe.numerics.plain import plain

                kernel = plain(kernel)
        _VARIANTS[key] = kernel
    return kernel


def _python_call(kernel):
    """The compiled entry point ``kernel`` behind a Python function, which `rotframe.numerics.plain` keeps as it is."""

    def call(*args):
        return kernel(*args)

    return call


def trajectory_tier(model, method, events, D, load_only=False):
    """The DOP853 loop of ``model`` and ``events`` with its trajectories compiled and the rest as Python.

    The template of the compiled loop (`_dop853_advance`) remade as plain Python
    (`rotframe.numerics.plain`) but for its callees, each compiled on its own as an entry point for
    its one signature and cached: the trajectory loop (`_dop853_parts`: every step of a run, from
    stop to stop, `TRAJECTORY_ARGS`), which calls the stages and the right-hand side at their
    addresses, and those (`rotframe.problem.by_address.tier_callees`), with the right-hand side that
    Python calls for each particle's first f and Hairer's starting step. The loop over the particles
    and the stops, each particle's loading, tolerances and saving run as Python: some 25 to 45 us a
    particle and call, and a call of the trajectory a stop. The same code runs, so the numbers are the
    whole loop's to the bit (``tests/test_tiers.py``).

    Where none is cached, the trajectory compiles in a second process while this one compiles the
    callees (`rotframe.numerics.compile_apart`). Measured on the 2-core reference machine (a first long
    run, 2026-12-01): 2.1 to 2.7 s, where the whole loop took 7.3 s (it compiles the trajectory again
    inside its own code, and an entry point that unboxes thirty arguments) and the tier with its stages
    inside the trajectory, in one process, 3.4 s. ``load_only``: None where anything would have to
    compile. `rotframe.problem.tiers` runs a first run of a few particles on it. ``method`` is DOP853's
    (the fixed-step loops have no such tier).
    """
    from rotframe.numerics.compile_apart import CompiledApart
    from rotframe.numerics.compiled import load_cached
    from rotframe.numerics.plain import plain

    if method != "dop853":
        raise ValueError(f"the trajectory tier is DOP853's, not {method}'s")
    body = None if model == PARTICLE else True
    trajectory = _dop853_parts(body, events, D, entry=True)
    kernels = ((trajectory, TRAJECTORY_ARGS[bool(events)]),) + tier_callees(body, D)
    cached = [load_cached(kernel, args) for kernel, args in kernels]
    if not all(cached):
        if load_only:
            return None
        if not any(cached):  # the callees here, the trajectory in a second process (compile_apart)
            with CompiledApart(__name__, "compile_tier_trajectory", model, int(bool(events)), D) as apart:
                for kernel, args in kernels[1:]:
                    kernel.compile(args)
            apart.load(*kernels[0])
        else:
            for (kernel, args), done in zip(kernels, cached):
                if not done:
                    kernel.compile(args)
    for kernel, _ in kernels:
        kernel.disable_compile()
    (_, _), (stages, _), (system, _), (system_call, _) = kernels
    at = (address(stages, STAGES_SIG), address(system, SYSTEM_SIG))

    def trajectory_call(ctx, *rest):
        """The trajectory with the addresses of its stages and right-hand side in its ``ctx`` (`with_reference`)."""
        return trajectory((ctx[0], ctx[1], ctx[2]) + at, *rest)

    trajectory_call.kernels = kernels  # the addresses live as long as the compiled functions
    kind = f"{'particle' if body is None else 'body'}{D}"
    return plain(bound(_dop853_advance, f"advance_{kind}_dop853{'_events' if events else ''}_trajectory_tier",
                       SYSTEM=_python_call(system_call), TRAJECTORY=trajectory_call, DIM=int(D), EVENTS=bool(events)))


def compile_tier_trajectory(model, events, D):
    """Compile the trajectory tier's trajectory loop for model code ``model``, ``events`` (0 or 1) and ``D`` numbers
    into numba's cache: the second process of a first tier compile (`trajectory_tier`,
    `rotframe.numerics.compile_apart`)."""
    events = bool(int(events))
    _dop853_parts(None if int(model) == PARTICLE else True, events, int(D), entry=True).compile(TRAJECTORY_ARGS[events])


def scratch(D):
    """The loop's work arrays for states of D numbers: stages ``K`` (16, D) and ``Kb`` (13, D), state vectors
    ``V`` (7, D), the dense output's coefficients ``F`` (7, D) and the models' scratch ``W``."""
    block = np.zeros(43 * D + SCRATCH)
    K = block[:16 * D].reshape(16, D)
    Kb = block[16 * D:29 * D].reshape(13, D)
    V = block[29 * D:36 * D].reshape(7, D)
    F = block[36 * D:43 * D].reshape(7, D)
    return K, Kb, V, F, block[43 * D:]


def advance(lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, method, rtol,
            atol, hfix, EDIR, ETERM, S, prob, fns, compiled=True, kernel=None, work=None):
    """Advance the particles ``lo:hi`` by at most ``budget`` steps each (module docstring); the state is in the arrays.

    ``T`` the sample times; ``Y`` (N, D) the states to go on from, ``TC``, ``H``, ``IDX``, ``SUB``,
    ``ST`` each particle's time, step, next sample, fixed-step count and status; ``OUT`` (n, N, D)
    the samples; ``EVT``, ``EVY``, ``EVK``, ``EVN`` the event records; ``GPREV`` (N, NE) each
    event's last value; ``EDIR``, ``ETERM`` (NE,) the events' directions and terminal flags.
    ``method`` is the method's name (`METHOD_CODES`). Runs the problem's `variant` of the loop (``compiled=False``: as
    plain Python) with work arrays of its own (or ``work``, `scratch`'s, which a prepared run keeps); or ``kernel``, the
    same variant with the problem's functions compiled into it (`rotframe.problem.inlined.inlined_loop`), which takes
    tags where ``fns`` has addresses.
    """
    if kernel is None:
        kernel = variant(prob[0], method, EDIR.shape[0] > 0, compiled, Y.shape[1])
    else:
        fns = direct_functions()
    kernel(lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, rtol, atol, hfix,
           EDIR, ETERM, S, prob, fns, *(scratch(Y.shape[1]) if work is None else work))


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
#: the trajectory tier's trajectory loop's arguments (`trajectory_tier`), without and with events (``ctx = (prob,
#: fns, W, stages, system)``, `rotframe.problem.by_address.with_reference`; ``wctx``,
#: `rotframe.problem.loop_state.watcher_context`'s tuple)
TRAJECTORY_ARGS = {events: (types.Tuple((PROBLEM, FUNCTIONS, A1, I8, I8)), F8, A1, F8, F8, F8, A1, I8, A3, I8, F8,
                            A1, A2, A1, A1, A1, A2,
                            types.Tuple((A2, A2, A3, I2, I1, A1, B1, F8, A2, A1, A1, A1)) if events else I8, I8)
                   for events in (False, True)}

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
