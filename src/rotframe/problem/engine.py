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
  step (`rotframe.problem.event_watch`), a budget of accepted steps per call
  (`rotframe.problem.dop853_variant`). It compiles in parts that call one another at their addresses
  (`rotframe.problem.dop853_split`): the trajectory loop, and around it the loop over the particles,
  compiled (the whole loop) or, for a first run of a few particles, plain Python (the *trajectory
  tier*, `rotframe.problem.tiers`).
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

import numpy as np
from numba import njit, types

from rotframe.numerics.compiled import ENTRY_OPTIONS
from rotframe.problem.calls import call_event, direct_functions
from rotframe.problem.dop853_variant import dop853_loop
from rotframe.problem.event_watch import watcher
from rotframe.problem.fixed_step import fixed_step_loop
from rotframe.problem.models import (DOP853, RK4, SCRATCH, SPLITTING, SPLITTING4, SPLITTING6, SPLITTING8,
                                     particle_energy)
from rotframe.problem.signatures import (A1, A2, A3, BODY, F8, FUNCTIONS, PARTICLE, POTENTIAL, PROBLEM,
                                         VARIANT_SIGNATURE)
from rotframe.problem.steps import body_system, particle_system, stepper

__all__ = ["advance", "variant", "variant_loop", "TRAJECTORY_TIER", "scratch", "start_events",
           "energies", "ready"]

#: the entry points Python calls (no C entry point: nothing calls them from C)
_entry = njit(cache=True, error_model="numpy", nogil=True, no_cfunc_wrapper=True)
#: the variants' loops: entry points without reference counts (`rotframe.numerics.compiled.ENTRY_OPTIONS`), their
#: work arrays made by the caller (`scratch`); a problem's inlined loop too (`rotframe.problem.inlined`)
_uncounted_entry = njit(**ENTRY_OPTIONS)
#: the length of the state of each model, a constant of its DOP853 loop (a particle whose forces act in inertial
#: axes carries the frame's attitude too: 10)
STATE_LENGTH = {PARTICLE: 6, BODY: 7}


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

    DOP853 runs the one DOP853 loop of rotframe (`rotframe.numerics.dop853_loop`,
    `rotframe.problem.dop853_variant.dop853_loop`) for the model's right-hand side, from stop to stop. The fixed-step
    methods run `rotframe.problem.fixed_step`'s loop, which the GPU compiles too (`rotframe.problem.gpu`). ``D``
    (default `STATE_LENGTH`) is the length of the state (a particle's is 10 where a force acts in inertial axes), a
    constant of the steps' code too (`stepper`).
    """
    body = None if model == PARTICLE else True
    method = METHOD_CODES[method]
    D = STATE_LENGTH[model] if D is None else int(D)
    suffix = "" if D == STATE_LENGTH[model] else str(D)
    name = (f"advance_{'particle' if body is None else 'body'}{suffix}_{METHOD_NAMES[method]}"
            f"{'_events' if events else ''}")
    if method == DOP853:
        return dop853_loop(name, body, events, D)
    step = stepper(body, method, D)
    system = particle_system if body is None else body_system
    return fixed_step_loop(name, body, method, D, step,
                           watcher(name, step, body, method, system, cold=True) if events else None)


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
#: the variants that `variant` with ``load_only`` found neither made nor in numba's cache, in this process: not looked
#: for there again (each run in the trajectory tier asks whether the whole loop is made, and a look in the cache took
#: some 1 ms of a 1.5 ms run); one that another process compiles meanwhile is found by the next process
_NOT_CACHED: set = set()
#: a body's splittings whose compiled loop calls its step at its address (`rotframe.problem.body_split_step`): Kahan
#: & Li's compositions, of 9 and 17 splitting steps a step, where that call costs nothing measurable (0.91 to 1.01 of
#: the time with the step inside, 2026-12-02); a step of the splitting of order 2 or 4 is short enough that the call
#: shows (1.03 to 1.13)
STEP_APART = (SPLITTING6, SPLITTING8)
#: `variant`'s third form of a DOP853 loop beside compiled (True) and plain Python (False),
#: `rotframe.problem.dop853_split.trajectory_tier`; the fifth of a variant where `rotframe.problem.tiers` asks
#: whether it is made
TRAJECTORY_TIER = "trajectory"


def variant(model, method, events, compiled=True, D=None, load_only=False):
    """The loop of ``model`` (`PARTICLE`, `BODY`), ``method`` (a name of `METHOD_CODES`) and
    ``events`` (whether the problem has any): compiled for `VARIANT_SIGNATURE` (or loaded from numba's cache)
    when first asked for (DOP853's in parts, `rotframe.problem.dop853_split.whole_loop`; a body's splitting with its
    step apart, `rotframe.problem.body_split_step`); with ``compiled=False`` its
    plain Python remake (`rotframe.numerics.plain`); with ``compiled=TRAJECTORY_TIER`` (DOP853 alone) its
    trajectories compiled and the rest plain (`rotframe.problem.dop853_split.trajectory_tier`). ``D``, the length of
    the state, is a constant of the loop's code (default the model's, `STATE_LENGTH`). With
    ``load_only``: None where the loop would have to compile (neither made in this process nor in the cache), what
    tells a run to begin in the plain tier (`rotframe.problem.tiers`)."""
    from rotframe.numerics.compiled import load_cached

    D = STATE_LENGTH[int(model)] if D is None else int(D)
    key = (int(model), method, bool(events), D, compiled if compiled == TRAJECTORY_TIER else bool(compiled))
    kernel = _VARIANTS.get(key)
    if kernel is None and load_only and key in _NOT_CACHED:
        return None
    if kernel is None:
        if key[-1] == TRAJECTORY_TIER:
            from rotframe.problem.dop853_split import trajectory_tier

            kernel = trajectory_tier(*key[:4], load_only=load_only)
        elif compiled and method == "dop853":
            from rotframe.problem.dop853_split import whole_loop

            kernel = whole_loop(*key[:4], load_only=load_only)
        elif compiled and key[0] == BODY and METHOD_CODES[method] in STEP_APART:
            from rotframe.problem.body_split_step import body_split_loop

            code = METHOD_CODES[method]
            kernel = body_split_loop(code, METHOD_NAMES[code], key[2], key[3], load_only=load_only)
        elif compiled:
            kernel = _variant_kernel(*key[:4])
            if not load_cached(kernel, VARIANT_SIGNATURE):
                if load_only:
                    return None
                kernel.compile(VARIANT_SIGNATURE)
            kernel.disable_compile()
        else:
            from rotframe.numerics.plain import plain

            kernel = plain(_variant_kernel(*key[:4]))
        if kernel is None:  # load_only, and a part is not made
            _NOT_CACHED.add(key)
            return None
        _VARIANTS[key] = kernel
        _NOT_CACHED.discard(key)
    return kernel


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
