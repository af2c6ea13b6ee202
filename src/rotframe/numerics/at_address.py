"""Calls from compiled code to a function compiled apart, at its address.

numba links every compiled callee into its caller's machine code, and optimises it again there:
a loop that calls a trajectory compiles the trajectory twice, and in one process, one function at
a time. A function compiled as an entry point of its own, for one explicit signature, has an
address (`address`); compiled code may call it there through numba's own calling convention
(`caller`), as numba calls a first-class function. The two then compile apart, in two processes at
once on a first run (`rotframe.numerics.compile_apart`), each cached on its own, and the call costs
an indirect call (some nanoseconds), not a copy of the callee.

How rotframe uses it: the engine calls a problem's own functions at their addresses
(`rotframe.problem.calls`), the trajectory tier its stages (`rotframe.problem.by_address`), and the
steady DOP853 loop its trajectory (`rotframe.particles.dop853_steady`).
"""

from __future__ import annotations

import math

from numba import types
from numba.extending import intrinsic

__all__ = ["address", "call_codegen", "caller"]


def address(dispatcher, signature) -> int:
    """The address of ``dispatcher`` compiled for ``signature`` (numba's calling convention, not C's)."""
    compiled = dispatcher.get_compile_result(signature)
    return int(compiled.library.get_pointer_to_function(compiled.fndesc.llvm_func_name))


def call_codegen(signature, spread=False):
    """The code of a call of the function at the first argument, of ``signature``, and what the call returns.

    An exception raised there is not passed on (a caller in a hot loop would otherwise keep a
    reference count of every array alive around the call): a function without a result gives
    True where it raised, False else; a float result is NaN where it raised. Any other result is
    returned as it is, so such a callee must not raise (compiled with ``error_model="numpy"``
    and no ``raise``: the DOP853 trajectory loop). ``spread``: the arguments after the address
    come as one tuple (``*args``).
    """
    returns = signature.return_type
    if returns != types.void and not isinstance(returns, types.Float) and not isinstance(returns, types.BaseTuple):
        raise TypeError(f"a call at an address returns nothing, a float or a tuple, not {returns}")

    def codegen(context, builder, sig, args):
        values = args[1:]
        if spread:
            values = [builder.extract_value(args[1], k) for k in range(len(signature.args))]
        fnty = context.call_conv.get_function_type(returns, signature.args)
        fnptr = builder.inttoptr(args[0], fnty.as_pointer())
        status, result = context.call_conv.call_function(builder, fnptr, returns, signature.args, values)
        if returns == types.void:
            return status.is_error
        if isinstance(returns, types.Float):
            return builder.select(status.is_error, context.get_constant(returns, math.nan), result)
        return result

    result = types.boolean if returns == types.void else returns
    if spread:
        return result(types.int64, types.StarArgTuple.from_types(signature.args)), codegen
    return result(types.int64, *signature.args), codegen


def caller(signature):
    """A call of the function at an address, of ``signature``, from compiled code: ``call(addr, *args)``.

    The arguments are cast to ``signature``'s types where numba may (an array of any layout to one of
    layout ``A``), and refused where it is typed otherwise. What it returns: `call_codegen`.
    """

    @intrinsic
    def call(typingctx, addr, *args):
        if len(args) != len(signature.args):
            from numba.core.errors import TypingError

            raise TypingError(f"a call at an address of {signature} takes {len(signature.args)} arguments, "
                              f"not {len(args)}")
        return call_codegen(signature, spread=True)

    return call
