"""The engine's DOP853 loop compiled in parts: its trajectory tier and its whole loop by address.

numba links every callee into its caller's code and optimises it again there. The engine's DOP853
loop (`rotframe.problem.dop853_variant.dop853_advance`, a loop over the particles and their stops around
the trajectory loop, `rotframe.numerics.dop853_loop`) compiled as one piece optimised the trajectory
twice, on one core. Here it is compiled in parts, each an entry point for its one signature, cached,
which call one another at their addresses (`rotframe.problem.by_address`, `rotframe.numerics.at_address`):

- the trajectory loop (`TRAJECTORY_SIGNATURES`), which calls the stages and the right-hand side at
  their addresses (`rotframe.problem.by_address.tier_callees`);
- the **trajectory tier** (`trajectory_tier`): the loop over the particles as plain Python
  (`rotframe.numerics.plain`) around the compiled trajectory, for a first run of a few particles
  (`rotframe.problem.tiers`);
- the **whole loop** (`whole_loop`): the loop over the particles compiled too
  (`WHOLE_LOOP_SIGNATURE`), calling the trajectory at its address.

Where more than one part is to compile, the others compile in second processes while this one
compiles its share (`rotframe.numerics.compile_apart.made`, `rotframe.numerics.compile_apart`), then load
from numba's cache. The same code runs in each form, so the numbers agree to the bit
(``tests/test_tiers.py``).
`rotframe.problem.engine.variant` hands out both forms.
"""

from __future__ import annotations

import functools

from numba import njit, types

from rotframe.numerics.compile_apart import made
from rotframe.numerics.compiled import ENTRY_OPTIONS, bound
from rotframe.numerics.dop853_loop import TRAJECTORY_RETURNS
from rotframe.problem.by_address import system_by_address, tier_callees, trajectory_at
from rotframe.problem.calls import address
from rotframe.problem.dop853_variant import dop853_advance, dop853_parts
from rotframe.problem.in_parts import LoopWithParts
from rotframe.problem.signatures import (A1, A2, A3, B1, F8, FUNCTIONS, FUNCTIONS_AT, I1, I2, I8, PARTICLE,
                                         PROBLEM, STAGES_SIG, SYSTEM_SIG, loop_with_parts)

__all__ = ["trajectory_tier", "whole_loop", "compile_tier_trajectory", "compile_whole_loop", "compile_tier_stages",
           "begin_tier", "TRAJECTORY_ARGS", "TRAJECTORY_SIGNATURES", "WHOLE_LOOP_SIGNATURE"]

#: the compiled parts: entry points without reference counts (`rotframe.numerics.compiled.ENTRY_OPTIONS`)
_uncounted_entry = njit(**ENTRY_OPTIONS)


def _python_call(kernel):
    """The compiled entry point ``kernel`` behind a Python function, which `rotframe.numerics.plain` keeps as it is."""

    def call(*args):
        return kernel(*args)

    return call


def trajectory_tier(model, method, events, D, load_only=False):
    """The DOP853 loop of ``model`` and ``events`` with its trajectories compiled and the rest as Python.

    The template of the compiled loop (`dop853_advance`) remade as plain Python
    (`rotframe.numerics.plain`) but for its callees, each compiled on its own as an entry point for
    its one signature and cached: the trajectory loop (`dop853_parts`: every step of a run, from
    stop to stop, `TRAJECTORY_ARGS`), which calls the stages and the right-hand side at their
    addresses, and those (`rotframe.problem.by_address.tier_callees`), with the right-hand side that
    Python calls for each particle's first f and Hairer's starting step. The loop over the particles
    and the stops, each particle's loading, tolerances and saving run as Python: some 25 to 45 us a
    particle and call, and a call of the trajectory a stop. The same code runs, so the numbers are the
    whole loop's to the bit (``tests/test_tiers.py``).

    Where none is cached, the trajectory compiles in a second process while this one compiles the
    callees (`rotframe.numerics.compile_apart`). Measured on the 2-core reference machine (a first long
    run, 2026-12-01): 2.1 to 2.7 s, where the whole loop as one piece took 7.3 s (it compiled the trajectory
    again inside its own code, and an entry point that unboxes thirty arguments) and the tier with its stages
    inside the trajectory, in one process, 3.4 s. ``load_only``: None where anything would have to
    compile. `rotframe.problem.tiers` runs a first run of a few particles on it. ``method`` is DOP853's
    (the fixed-step loops have no such tier).
    """
    from rotframe.numerics.plain import plain

    if method != "dop853":
        raise ValueError(f"the trajectory tier is DOP853's, not {method}'s")
    body = None if model == PARTICLE else True
    kernels = _tier_kernels(body, events, D)
    args = (model, int(bool(events)), D)
    if not made(kernels, __name__, load_only, {k: (function, args) for k, function in _TIER_APART.items()}):
        return None
    (trajectory, _), (stages, _), (system, _), (system_call, _) = kernels
    at = (address(stages, STAGES_SIG), address(system, SYSTEM_SIG))

    def trajectory_call(ctx, *rest):
        """The trajectory with the addresses of its stages and right-hand side in its ``ctx`` (`with_reference`)."""
        return trajectory(ctx + at, *rest)

    trajectory_call.kernels = kernels  # the addresses live as long as the compiled functions
    kind = f"{'particle' if body is None else 'body'}{D}"
    return plain(bound(dop853_advance, f"advance_{kind}_dop853{'_events' if events else ''}_trajectory_tier",
                       SYSTEM=_python_call(system_call), TRAJECTORY=trajectory_call, DIM=int(D), EVENTS=bool(events)))


@functools.cache
def _tier_kernels(body, events, D):
    """The trajectory tier's kernels, each with its signature: the trajectory loop (`dop853_parts`, an entry point
    of `TRAJECTORY_SIGNATURES`), then its callees (`rotframe.problem.by_address.tier_callees`). Made once a process
    (`rotframe.numerics.compile_apart.made` loads each once, the whole loop shares them)."""
    return ((dop853_parts(body, events, D, entry=True), TRAJECTORY_SIGNATURES[bool(events)]),) + tier_callees(body, D)


def _tier_kernels_of(model, events, D):
    """`_tier_kernels` for model code ``model``, ``events`` (0 or 1) and ``D`` numbers, as a second process is given
    them (strings) or a caller has them."""
    return _tier_kernels(None if int(model) == PARTICLE else True, bool(int(events)), int(D))


def compile_tier_trajectory(model, events, D):
    """Compile the trajectory tier's trajectory loop for model code ``model``, ``events`` (0 or 1) and ``D`` numbers
    into numba's cache: the second process of a first tier compile (`trajectory_tier`, `whole_loop`,
    `rotframe.numerics.compile_apart`)."""
    trajectory, signature = _tier_kernels_of(model, events, D)[0]
    trajectory.compile(signature)


def compile_tier_stages(model, events, D):
    """Compile the trajectory tier's stages (with the right-hand side in them) and its two right-hand sides
    (`rotframe.problem.by_address.tier_callees`, which share that right-hand side's compile) for model code ``model``,
    ``events`` (0 or 1) and ``D`` numbers into numba's cache: a second process of a first tier compile (`_TIER_APART`,
    `begin_tier`)."""
    for kernel, signature in _tier_kernels_of(model, events, D)[1:]:
        kernel.compile(signature)


#: the functions that compile the trajectory tier's kernels in second processes, by the kernels' index in
#: `_tier_kernels`: the trajectory loop, and its callees (stages and right-hand sides, which share the right-hand
#: side's compile), each some 1.2 to 1.4 s of a first compile on the 2-core reference machine
_TIER_APART = {0: "compile_tier_trajectory", 1: "compile_tier_stages", 2: "compile_tier_stages",
               3: "compile_tier_stages"}


def begin_tier(model, events, D) -> bool:
    """Begin compiling the trajectory tier's trajectory loop and its callees (`_TIER_APART`), those not in numba's
    cache, in second processes now: for a first run that will likely compile the tier once its own functions are
    compiled and its first call has run as plain Python (`rotframe.problem.tiers.begin_ahead`,
    `rotframe.numerics.compile_apart.begin`). Whether any was begun."""
    from rotframe.numerics.compile_apart import begin, begun, is_made

    args = (model, int(bool(events)), D)
    kernels = _tier_kernels_of(*args)
    todo = dict.fromkeys(function for k, function in _TIER_APART.items()
                         if not begun(__name__, function, *args)  # by an earlier run: no look in the cache again
                         and not is_made(*kernels[k]))
    return any([begin(__name__, function, *args) for function in todo])


def whole_loop(model, method, events, D, load_only=False):
    """The compiled DOP853 loop of ``model`` and ``events`` (`rotframe.problem.engine.variant`): `dop853_advance`
    compiled with the trajectory tier's trajectory and right-hand side called at their addresses
    (`rotframe.problem.by_address.trajectory_at`, `rotframe.problem.by_address.system_by_address`), a
    `rotframe.problem.in_parts.LoopWithParts`.

    numba links each callee into its caller's code and optimises it again there: the loop with its trajectory in it
    compiled the trajectory twice, and on one core (`tumbling-ball`'s first run: 7.1 s of compile, of which the
    trajectory 2.9). This one shares the trajectory tier's kernels (`trajectory_tier`; loaded where a first run
    compiled them) and adds its own small loop over the particles and stops, which compiles beside the trajectory on a
    first run (`rotframe.numerics.compile_apart.made`). A step costs one call at an address more than with the stages in
    the trajectory (some 1 to 3 % of a spring's step, `rotframe.problem.by_address`). ``load_only``: None where
    anything would have to compile.
    """
    if method != "dop853":
        raise ValueError(f"the whole loop by address is DOP853's, not {method}'s")
    body = None if model == PARTICLE else True
    kernels = _tier_kernels(body, events, D)[:3] + ((_whole_loop_kernel(body, events, D), WHOLE_LOOP_SIGNATURE),)
    args = (model, int(bool(events)), D)
    if not made(kernels, __name__, load_only, {0: ("compile_tier_trajectory", args), 3: ("compile_whole_loop", args)}):
        return None
    (trajectory, signature), (stages, _), (system, _), (loop, _) = kernels
    return LoopWithParts(loop, (address(trajectory, signature), address(stages, STAGES_SIG),
                                address(system, SYSTEM_SIG)), kernels)


@functools.cache
def _whole_loop_kernel(body, events, D):
    """The compiled loop of `whole_loop`: `dop853_advance` with the tier's trajectory and right-hand side at their
    addresses."""
    kind = f"{'particle' if body is None else 'body'}{D}{'_events' if events else ''}"
    return _uncounted_entry(bound(dop853_advance, f"advance_{kind}_dop853_at", SYSTEM=system_by_address,
                                  TRAJECTORY=trajectory_at(kind, TRAJECTORY_SIGNATURES[bool(events)]), DIM=int(D),
                                  EVENTS=bool(events)))


def compile_whole_loop(model, events, D):
    """Compile `whole_loop`'s own loop for model code ``model``, ``events`` (0 or 1) and ``D`` numbers into numba's
    cache: a process of a first compile (`rotframe.numerics.compile_apart`)."""
    _whole_loop_kernel(None if int(model) == PARTICLE else True, bool(int(events)), int(D)).compile(
        WHOLE_LOOP_SIGNATURE)


#: the trajectory tier's trajectory loop's arguments (`trajectory_tier`), without and with events (``ctx = (prob,
#: fns, W, S, stages, system)``, `rotframe.problem.by_address.with_reference`; ``wctx``,
#: `rotframe.problem.loop_state.watcher_context`'s tuple)
TRAJECTORY_ARGS = {events: (types.Tuple((PROBLEM, FUNCTIONS, A1, A1, I8, I8)), F8, A1, F8, F8, F8, A1, I8, A3, I8, F8,
                            A1, A2, A1, A1, A1, A2,
                            types.Tuple((A2, A2, A3, I2, I1, A1, B1, F8, A2, A1, A1, A1)) if events else I8, I8)
                   for events in (False, True)}
#: the trajectory tier's trajectory loop's signatures, what it returns with its arguments (it is called at its address
#: by the whole loop, `whole_loop`)
TRAJECTORY_SIGNATURES = {events: TRAJECTORY_RETURNS(*args) for events, args in TRAJECTORY_ARGS.items()}
#: the DOP853 whole loop's signature (`whole_loop`): a variant's, the addresses of the tier's kernels after
#: the problem's (`FUNCTIONS_AT`)
WHOLE_LOOP_SIGNATURE = loop_with_parts(FUNCTIONS_AT)

