"""A rigid body's long splittings in the engine's compiled loop, their step compiled apart and called at its address.

A body's step under a splitting (`rotframe.problem.models.body_split`: the Lie-Poisson splitting or
the symmetric body's free flow, with its torque's kicks, composed to order 4, 6 or 8) is most of
what its fixed-step variant compiles (`heavy-top`'s first run: of 3.7 s, the step 1.6 s with the
rigid scenes' free step in it). numba links it into the loop and optimises it there again. Here the
step is an entry point of its own for the method (`STEP_SIG`), cached, and the compiled loop calls it
at its address (`rotframe.numerics.at_address`), the address after the problem's five
(`FUNCTIONS_STEP`): on a first run the step compiles in a second process while this one compiles
the loop (`rotframe.numerics.compile_apart.made`). A step costs one call more, the problem's data handed
by reference (`_with_reference`): nothing measurable against a step of Kahan & Li's compositions
(9 and 17 splitting steps), which alone take this route (`rotframe.problem.engine.STEP_APART`);
the splitting of order 2 on a symmetric body, a step of some 90 ns, took 1.07 to 1.13 of its time
so, and keeps its step inside. The same code runs, so the numbers are the loop's with the step in
it, to the bit (the engine's plain remake and the GPU's loop keep the step inside:
``tests/test_tiers.py``).
"""

from __future__ import annotations

import functools

from numba import njit, types

from rotframe.numerics.at_address import address, caller
from rotframe.numerics.compile_apart import made
from rotframe.numerics.compiled import ENTRY_OPTIONS, bound, jit_inline
from rotframe.problem.by_address import problem_functions
from rotframe.problem.calls import by_reference, dereference
from rotframe.problem.event_watch import watcher
from rotframe.problem.fixed_step import fixed_step_loop
from rotframe.problem.in_parts import LoopWithParts
from rotframe.problem.models import body_split
from rotframe.problem.signatures import A1, F8, I8, loop_with_parts
from rotframe.problem.steps import body_system

__all__ = ["body_split_loop", "compile_body_step", "STEP_SIG", "FUNCTIONS_STEP", "LOOP_SIGNATURE"]

#: a body's step of a splitting, ``step(ref, t, y, h, yn)``: from (t, y) into ``yn`` (`body_split`), the problem's
#: data ``(prob, fns, W)`` at the address ``ref`` (`rotframe.problem.calls.by_reference`, made once a call of the loop)
STEP_SIG = types.void(I8, F8, A1, F8, A1)
#: the problem's five addresses (`rotframe.problem.signatures.FUNCTIONS`), then the step's
FUNCTIONS_STEP = types.UniTuple(types.int64, 6)
#: the loop's signature: a variant's (`rotframe.problem.signatures.VARIANT_SIGNATURE`) with `FUNCTIONS_STEP`
LOOP_SIGNATURE = loop_with_parts(FUNCTIONS_STEP)

_uncounted_entry = njit(**ENTRY_OPTIONS)
_call_step = caller(STEP_SIG)

# the splitting's code that a copy of `_body_step` binds (`rotframe.numerics.compiled.bound`); 0 in the template
METHOD = 0


def _body_step(ref, t, y, h, yn):
    """The template of a body's step of the splitting ``METHOD`` (`rotframe.problem.models.body_split`)."""
    prob, fns, W = dereference(ref)
    body_split(METHOD, t, y, h, yn, prob, fns, W)


@jit_inline
def _with_reference(ctx):
    """The loop's context ``(prob, fns, W)`` with the problem's data at an address after it (made once a call of the
    loop, `rotframe.problem.calls.by_reference`): what `_take_at` hands the step. Passed by its 60-odd numbers at
    each step, the call took some 50 ns, half a step of the Lie-Poisson splitting."""
    return ctx[0], ctx[1], ctx[2], by_reference((ctx[0], problem_functions(ctx[1]), ctx[2]))


@jit_inline
def _take_at(step, body, t, y, h, K, yt, yn, ctx):
    """A step as `rotframe.problem.steps.take_step` takes it: the body's step at its address, ``ctx[1][5]``, the
    problem's data at ``ctx[3]`` (`_with_reference`)."""
    _call_step(ctx[1][5], ctx[3], t, y, h, yn)


@functools.cache
def _step_kernel(code, name):
    """The step of the splitting ``code`` (named ``name``), an entry point of `STEP_SIG`; once a process."""
    return _uncounted_entry(bound(_body_step, f"body_step_{name}", METHOD=code))


@functools.cache
def _loop_kernel(code, name, events, D):
    """The fixed-step loop of a body (`rotframe.problem.fixed_step.fixed_step_loop`) whose steps, the events'
    trials among them, are `_take_at` (its context `_with_reference`'s); an entry point of `LOOP_SIGNATURE`, once a
    process."""
    kind = f"advance_body{D}_{name}{'_events' if events else ''}_step_at"
    watch = watcher(kind, None, True, code, body_system, cold=True, take=_take_at) if events else None
    return _uncounted_entry(fixed_step_loop(kind, True, code, D, None, watch, take=_take_at, enter=_with_reference))


def body_split_loop(code, name, events, D, load_only=False):
    """The compiled loop of a body under the splitting ``code`` (named ``name``), with or without ``events``, for
    states of ``D`` numbers: a `rotframe.problem.in_parts.LoopWithParts` with its step's address. Loaded from
    numba's cache, else compiled, the step in a second process (`compile_body_step`); ``load_only``: None where
    anything would have to compile."""
    kernels = ((_step_kernel(int(code), name), STEP_SIG),
               (_loop_kernel(int(code), name, bool(events), int(D)), LOOP_SIGNATURE))
    if not made(kernels, __name__, load_only, {0: ("compile_body_step", (int(code), name))}):
        return None
    return LoopWithParts(kernels[1][0], (address(*kernels[0]),), kernels)


def compile_body_step(code, name):
    """Compile the step of the splitting ``code`` (named ``name``) into numba's cache: the second process of a first
    compile (`rotframe.numerics.compile_apart`)."""
    _step_kernel(int(code), name).compile(STEP_SIG)
