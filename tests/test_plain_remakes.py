"""The plain-Python remakes of compiled functions (rotframe.numerics.plain) belong to the function they remake.

The remakes are kept by the id of what they remake. A function whose globals do not hold it (a
loop bound to a system's functions, `rotframe.numerics.compiled.bound`; a problem's glue) can be
freed, and a later function given its id: the remake kept must not be handed to that one (it
would run the freed function's code and values: a run's events calling another problem's).
"""

import gc
import types

from rotframe.numerics.plain import plain


def test_a_remake_is_never_handed_to_a_later_function_with_a_reused_id():
    code = compile("def f():\n    return I\n", "<remade>", "exec").co_consts[0]
    got = []
    for i in range(200):
        f = types.FunctionType(code, {"I": i, "__builtins__": __builtins__}, "f")  # its globals do not hold it
        got.append(plain(f)())
        del f
        gc.collect()  # frees it: the next function may take its id
    assert got == list(range(200))
