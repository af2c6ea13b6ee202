"""Read-only views for the user's functions: a write into ``r``, ``v``, ``L``, ``q`` or a parameter is refused.

A generated driver hands a user function views of its own state (``r = y[0:3]``). A function
that wrote into them (``r[2] = 0``) would change the integrator's state, or a stage of it,
silently. So the drivers pass them through `readonly`: compiled, it changes only the view's
numba type to a read-only array (no copy, no cost), and numba refuses to compile a function
that writes into one (``setitem(readonly array ...)``), which `rotframe.problem.callables`
reports by the function's name. In plain Python (``jit=False``) it is a view whose
``writeable`` flag is off (`rotframe.problem.callables.readonly_view`), and the write raises
there. Array parameters are passed as read-only copies (`rotframe.problem.callables.readonly_array`).
"""

from __future__ import annotations

from numba import types
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic

__all__ = ["readonly"]


@intrinsic
def readonly(typingctx, a):
    """The same array typed read-only (compiled code only; no copy)."""
    if not isinstance(a, types.Array):
        return None
    result = a.copy(readonly=True)

    def codegen(context, builder, signature, args):
        return impl_ret_borrowed(context, builder, signature.return_type, args[0])

    return result(a), codegen
