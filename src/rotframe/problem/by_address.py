"""The trajectory tier's stages and right-hand side, compiled apart from its loop and called at their addresses.

The trajectory tier (`rotframe.problem.dop853_split.trajectory_tier`) compiles its DOP853 trajectory loop
without the model's right-hand side in it: the loop calls the engine's stages, compiled on their own
with the right-hand side in them, at their address (`stages_at`), one call a step; an event's re-steps
take f at the step's start from the right-hand side at its address (`system_at`). So the two compile
in two processes at once on a first run (`rotframe.numerics.compile_apart`), and what runs is the
same code as the engine's whole loop, to the bit.

The callees take the problem's data ``(prob, fns, W)`` at an address (`rotframe.problem.calls.by_reference`),
made once a call of the trajectory (`with_reference`): passed by value, its some sixty numbers a call cost
more than a spring's arithmetic. Measured on the 2-core reference machine (2026-12-01, a spring, warm):
a run in the tier takes the time it took with the stages in the loop, within 3 %.
"""

from __future__ import annotations

from numba import njit

from rotframe.numerics.at_address import caller
from rotframe.numerics.compiled import ENTRY_OPTIONS, bound, jit_inline, jit_llvm_inline
from rotframe.problem.calls import by_reference, call_stages, call_system, dereference
from rotframe.problem.models import DOP853
from rotframe.problem.signatures import A1, A2, CONTEXT, F8, I8, STAGES_SIG, SYSTEM_SIG
from rotframe.problem.steps import body_system, particle_system, stepper

__all__ = ["stages_at", "system_at", "problem_data", "with_reference", "tier_callees", "trajectory_at",
           "system_by_address", "problem_functions"]

_uncounted_entry = njit(**ENTRY_OPTIONS)

# the names a callee binds (`rotframe.numerics.compiled.bound`): None in the templates, which are never compiled
SYSTEM = STAGES = CALL = None


@jit_llvm_inline  # compiled once, inlined by LLVM at each of its call sites (the step, an event's trials)
def stages_at(ctx, first, last, t, y, h, K, z, z12, t12):
    """The trajectory tier's DOP853 stages, ``ctx = (prob, fns, W, ref, stages, system)`` (`with_reference`): the
    engine's (`rotframe.problem.steps.stepper`), compiled on their own with the right-hand side in them, called at
    their address with the problem's data at ``ref`` (`rotframe.problem.calls.call_stages`): one call a step."""
    call_stages(ctx[4], ctx[3], first, last, t, y, h, K, z, z12, t12)


@jit_llvm_inline
def system_at(ctx, t, z, K, s):
    """The trajectory tier's right-hand side (`stages_at`): f at a step's start for an event's re-steps."""
    call_system(ctx[5], ctx[3], t, z, K, s)


@jit_inline
def problem_data(ctx):
    """The problem's data ``(prob, fns, W)`` that the right-hand side takes, of a trajectory's ``ctx`` (its first three:
    `with_reference`, `rotframe.problem.dop853_variant.dop853_parts`)."""
    return ctx[0], ctx[1], ctx[2]


@jit_inline
def with_reference(ctx):
    """The trajectory tier's ``ctx = (prob, fns, W, S, stages, system)``, its stops and the addresses of its compiled
    stages and right-hand side, as the loop hands it on: the problem's data also at an address, ``ref``, before the
    addresses (made once a call of the trajectory, `rotframe.problem.calls.by_reference`)."""
    return ctx[0], ctx[1], ctx[2], by_reference(problem_data(ctx)), ctx[4], ctx[5]


def _system_call(ctx, t, z, K, s):
    """The template of the right-hand side that Python calls, an entry point: ``K[s] = f(t, z)`` (``SYSTEM``)."""
    SYSTEM(ctx, t, z, K, s)


def _system_by_reference(ref, t, z, K, s):
    """`_system_call` with the problem's data ``(prob, fns, W)`` at the address ``ref`` (`system_at`)."""
    SYSTEM(dereference(ref), t, z, K, s)


def _stages_by_reference(ref, first, last, t, y, h, K, z, z12, t12):
    """The template of the stages, an entry point (``STAGES``), the problem's data at ``ref`` (`stages_at`)."""
    STAGES(dereference(ref), first, last, t, y, h, K, z, z12, t12)


def tier_callees(body, D):
    """The trajectory tier's callees for the model (``body``: None, a particle) and ``D`` numbers, entry points of
    their own, each with its arguments: the stages and the right-hand side that its trajectory calls at their
    addresses, and the right-hand side that Python calls (each particle's first f and Hairer's starting step)."""
    kind = f"{'particle' if body is None else 'body'}{D}"
    system = particle_system if body is None else body_system
    return ((_uncounted_entry(bound(_stages_by_reference, f"dop853_stages_by_reference_{kind}",
                                    STAGES=stepper(body, DOP853, D))), STAGES_SIG.args),
            (_uncounted_entry(bound(_system_by_reference, f"dop853_system_by_reference_{kind}", SYSTEM=system)),
             SYSTEM_SIG.args),
            (_uncounted_entry(bound(_system_call, f"dop853_system_engine_{kind}", SYSTEM=system)),
             (CONTEXT, F8, A1, A2, I8)))


@jit_inline
def problem_functions(fns):
    """The problem's five addresses (`rotframe.problem.signatures.FUNCTIONS`) of a loop's with its parts' after
    them (`rotframe.problem.in_parts`; the DOP853 whole loop's eight, `rotframe.problem.signatures.FUNCTIONS_AT`)."""
    return fns[0], fns[1], fns[2], fns[3], fns[4]


def _trajectory_at(ctx, t, y, h, t_end, h_max, times, k_out, out, p, rtol, atol, K, y_new, tmp, yt, F, wctx, budget):
    """The template of `trajectory_at`."""
    fns = ctx[1]
    return CALL(fns[5], (ctx[0], problem_functions(fns), ctx[2], ctx[3], fns[6], fns[7]), t, y, h, t_end, h_max,
                times, k_out, out, p, rtol, atol, K, y_new, tmp, yt, F, wctx, budget)


def trajectory_at(kind, signature):
    """The DOP853 whole loop's trajectory (`rotframe.problem.dop853_split.whole_loop`): the trajectory tier's, of
    ``signature``, called at its address, ``ctx = (prob, fns, W, S)`` with ``fns`` the whole loop's eight addresses
    (`rotframe.problem.signatures.FUNCTIONS_AT`: the tier's trajectory, stages and right-hand side after the
    problem's)."""
    return jit_inline(bound(_trajectory_at, f"trajectory_at_{kind}", CALL=caller(signature)))


@jit_inline
def system_by_address(ctx, t, z, K, s):
    """The DOP853 whole loop's right-hand side (each particle's first f and Hairer's starting step): the trajectory
    tier's at its address (``ctx[1][7]``, `trajectory_at`), the problem's data by reference."""
    call_system(ctx[1][7], by_reference((ctx[0], problem_functions(ctx[1]), ctx[2])), t, z, K, s)
