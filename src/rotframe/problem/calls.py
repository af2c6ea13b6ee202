"""Calls from the compiled engine to a problem's own functions, by address.

A problem's functions (`rotframe.problem.glue`) are compiled with one fixed signature each
(`rotframe.problem.signatures`); the engine receives the address of each compiled function
as an integer (`address`) and calls it through numba's own calling convention (`call_terms`,
`call_event`, `call_potential`, `call_vector`), as numba does for a first-class function. An
exception raised in the user's function becomes NaN and a flag
(`rotframe.numerics.at_address.call_codegen`, `RAISED`), which ends the particle at that step;
Python then names the function, calling it again in plain Python. An integer costs nothing to
hand from function to function, where numba's first-class function values were measured at
some 20 ns a call they crossed, more than a term's arithmetic; and it is a run-time value, so
the engine compiled once serves every problem from numba's cache.

In plain Python (``jit=False``, `rotframe.numerics.plain`) the "address" is the Python function
itself and each call helper is a plain call (``.plain`` of the helper).

Where a loop is compiled with a problem's functions in it (the GPU's, `rotframe.problem.gpu`, and
the CPU's inlined loop of a long run, `rotframe.problem.inlined`), each helper is replaced by a
direct call of the problem's function: the templates `direct_terms`, `direct_event`,
`direct_vector` and `direct_varying`, whose names in capitals are bound per problem
(`rotframe.numerics.compiled.bound`). The frame's and the origin's functions are then told apart
by the tags `OMEGA_TAG` and `ORIGIN_TAG` where the addresses stand (`direct_functions`);
`direct_calls` says which template replaces which helper, bound to which of the problem's functions.
"""

from __future__ import annotations

import math

from numba import types
from numba.extending import intrinsic

from rotframe.numerics.at_address import address, call_codegen
from rotframe.numerics.compiled import jit_inline
from rotframe.problem.signatures import (EVENT_SIG, POTENTIAL_SIG, STAGES_SIG, SYSTEM_SIG, TERMS_SIG, VARYING_SIG,
                                         VECTOR_SIG)

__all__ = ["address", "call_terms", "call_event", "call_potential", "call_vector", "call_varying", "call_system",
           "call_stages", "by_reference", "dereference", "RAISED",
           "direct_terms", "direct_event", "direct_vector", "direct_varying", "direct_functions", "direct_calls",
           "OMEGA_TAG", "ORIGIN_TAG"]


@intrinsic
def _terms(typingctx, addr, t, y, p, out):
    return call_codegen(TERMS_SIG)


@intrinsic
def _event(typingctx, addr, k, t, y, p):
    return call_codegen(EVENT_SIG)


@intrinsic
def _potential(typingctx, addr, t, y, p):
    return call_codegen(POTENTIAL_SIG)


@intrinsic
def _vector(typingctx, addr, t, out):
    return call_codegen(VECTOR_SIG)


@intrinsic
def _varying(typingctx, addr, kind, T, C, fn, t, out):
    return call_codegen(VARYING_SIG)


@intrinsic
def _system(typingctx, addr, ref, t, z, K, s):
    return call_codegen(SYSTEM_SIG)


@intrinsic
def _stages(typingctx, addr, ref, first, last, t, y, h, K, z, z12, t12):
    return call_codegen(STAGES_SIG)


@intrinsic
def by_reference(typingctx, value):
    """The address of a copy of the context ``value`` (`CONTEXT`) on the caller's stack (`dereference` reads it),
    valid for the caller's call: how the trajectory tier hands its right-hand side the problem's data, once a call
    (`call_system`). Any other type is refused where it is typed."""
    from numba.core.errors import TypingError

    from rotframe.problem.signatures import CONTEXT

    if value != CONTEXT:
        raise TypingError(f"by_reference takes the context {CONTEXT}, not {value}")

    def codegen(context, builder, sig, args):
        from numba.core import cgutils

        slot = cgutils.alloca_once(builder, context.get_value_type(sig.args[0]))
        builder.store(args[0], slot)
        return builder.ptrtoint(slot, context.get_value_type(types.int64))

    return types.int64(value), codegen


@intrinsic
def dereference(typingctx, ref):
    """The context ``(prob, fns, W)`` at the address ``ref`` that `by_reference` gave (`SYSTEM_SIG`)."""
    from rotframe.problem.signatures import CONTEXT

    def codegen(context, builder, sig, args):
        return builder.load(builder.inttoptr(args[0], context.get_value_type(CONTEXT).as_pointer()))

    return CONTEXT(types.int64), codegen


#: the slot of the engine's scratch ``W`` (the ``out`` of the terms and the vectors) set to 1 when a user
#: function raised
RAISED = 6


@jit_inline
def call_terms(addr, t, y, p, out):
    """The terms at ``addr``: ``f(t, y, p, out)``; where it raised, NaN in ``out[0:3]`` and 1 in ``out[RAISED]``."""
    if _terms(addr, t, y, p, out):
        for k in range(3):
            out[k] = math.nan
        out[RAISED] = 1.0


@jit_inline
def call_event(addr, k, t, y, p):
    """Event ``k`` of the function at ``addr``: ``g(k, t, y, p)``; NaN where it raised."""
    return _event(addr, k, t, y, p)


@jit_inline
def call_potential(addr, t, y, p):
    """The potential at ``addr``: ``U(t, y, p)``; NaN where it raised."""
    return _potential(addr, t, y, p)


@jit_inline
def call_vector(addr, t, out):
    """The vector of time at ``addr``: ``w(t, out)``; where it raised, NaN in ``out[0:6]``, 1 in ``out[RAISED]``."""
    if _vector(addr, t, out):
        for k in range(6):
            out[k] = math.nan
        out[RAISED] = 1.0


@jit_inline
def call_varying(addr, kind, T, C, fn, t, out):
    """The engine's evaluator of a varying vector at ``addr`` into ``out[0:6]``; where it raised, NaN and ``out[RAISED]``."""
    if _varying(addr, kind, T, C, fn, t, out):
        for k in range(6):
            out[k] = math.nan
        out[RAISED] = 1.0


@jit_inline
def call_system(addr, ref, t, z, K, s):
    """The engine's right-hand side at ``addr``, compiled on its own (`rotframe.problem.dop853_split.trajectory_tier`):
    ``K[s] = f(t, z)``, the problem's data ``(prob, fns, W)`` at ``ref`` (`by_reference`); NaN in ``K[s]`` where it
    failed (a user function's failure is the right-hand side's own to flag, `call_terms`)."""
    if _system(addr, ref, t, z, K, s):
        for j in range(K.shape[1]):
            K[s, j] = math.nan


@jit_inline
def call_stages(addr, ref, first, last, t, y, h, K, z, z12, t12):
    """The engine's DOP853 stages at ``addr``, compiled on its own with the right-hand side in them
    (`rotframe.problem.dop853_split.trajectory_tier`), the problem's data at ``ref``: stages ``first .. last - 1`` of
    the step ``(t, y, h)`` (`rotframe.numerics.dop853_loop.dop853_stages`); NaN in ``K[first]`` where they failed."""
    if _stages(addr, ref, first, last, t, y, h, K, z, z12, t12):
        for j in range(K.shape[1]):
            K[first, j] = math.nan


def _plain_terms(f, t, y, p, out):
    f(t, y, p, out)


def _plain_event(f, k, t, y, p):
    return f(k, t, y, p)


def _plain_potential(f, t, y, p):
    return f(t, y, p)


def _plain_vector(f, t, out):
    f(t, out)


def _plain_varying(f, kind, T, C, fn, t, out):
    f(kind, T, C, fn, t, out)


for _helper, _python in ((call_terms, _plain_terms), (call_event, _plain_event), (call_potential, _plain_potential),
                         (call_vector, _plain_vector), (call_varying, _plain_varying)):
    _helper.plain = _python  # what rotframe.numerics.plain calls instead


#: the tags that stand for the addresses of the frame's and the origin's functions in a loop compiled with a
#: problem's functions in it (`direct_functions`, `direct_vector`)
OMEGA_TAG, ORIGIN_TAG = 1, 2


def direct_functions():
    """What such a loop takes where the engine's takes the addresses (`rotframe.problem.signatures.FUNCTIONS`): the
    tags of the frame's and the origin's functions, zero for the others (their direct calls ignore it)."""
    return 0, 0, OMEGA_TAG, ORIGIN_TAG, 0


def direct_calls(module, varying) -> dict:
    """The direct calls of a loop compiled with the problem's glue ``module`` in it: each helper -> its template and
    the functions its names in capitals are bound to.

    A role the glue lacks is the stub the engine would call (`rotframe.problem.stubs`); ``VARYING``
    is ``varying``, the engine's evaluator of a varying vector (`rotframe.problem.varying.varying_into`,
    which calls `call_vector` in turn). The caller compiles each for its target, callees first, in
    the order given (the GPU's kernel, `rotframe.problem.gpu`; the CPU's inlined loop,
    `rotframe.problem.inlined`).
    """
    from rotframe.problem import stubs

    def own(name, stub):
        found = getattr(module, name, None)
        return stub if found is None else found

    return {call_terms: (direct_terms, {"TERMS": own("terms", stubs.no_terms)}),
            call_event: (direct_event, {"EVENT": own("event", stubs.no_event)}),
            call_vector: (direct_vector, {"OMEGA": own("omega", stubs.no_vector),
                                          "ORIGIN": own("origin", stubs.no_vector)}),
            call_varying: (direct_varying, {"VARYING": varying})}


# the templates of the direct calls (module docstring): the names in capitals are bound per problem
def direct_terms(addr, t, y, p, out):
    """`call_terms` as a direct call of the problem's terms (``TERMS``)."""
    TERMS(t, y, p, out)  # noqa: F821


def direct_event(addr, k, t, y, p):
    """`call_event` as a direct call of the problem's events (``EVENT``)."""
    return EVENT(k, t, y, p)  # noqa: F821


def direct_vector(addr, t, out):
    """`call_vector` as a direct call of the frame's (``OMEGA``) or the origin's (``ORIGIN``) function, by tag."""
    if addr == OMEGA_TAG:
        OMEGA(t, out)  # noqa: F821
    else:
        ORIGIN(t, out)  # noqa: F821


def direct_varying(addr, kind, T, C, fn, t, out):
    """`call_varying` as a direct call of the engine's evaluator (``VARYING``)."""
    VARYING(kind, T, C, fn, t, out)  # noqa: F821
