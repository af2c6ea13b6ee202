"""The signatures through which the compiled engine calls a problem's own functions, by address.

The engine (`rotframe.problem.engine`, `rotframe.problem.models`) is compiled once, with
these types in its signatures, and cached on disk like every other kernel: it never sees the
user's functions, only their addresses (`rotframe.problem.calls`). What a problem compiles is
the few small functions of `rotframe.problem.glue` that call the user's own, each with one of
the fixed signatures below, as numbalsoda hands a solver the address of a right-hand side
compiled alone. Every array is float64 and C-contiguous.

==============  ==========================================  ==========================================
name            signature                                   what it computes
==============  ==========================================  ==========================================
`TERMS_SIG`     ``f(t, y, p, out) -> None``                 a particle: the sum of the user's forces
                                                            (m/s^2, frame axes) into ``out[0:3]``; a
                                                            body: the user's torque (N m, body axes)
`EVENT_SIG`     ``g(k, t, y, p) -> float``                  event ``k``'s function
`POTENTIAL_SIG` ``U(t, y, p) -> float``                     the sum of the forces' potentials, J/kg
`VECTOR_SIG`    ``w(t, out) -> None``                       a user's vector of time: omega (and
                                                            omega' in ``out[3:6]`` where given), or the
                                                            origin's acceleration
==============  ==========================================  ==========================================

``y`` is the state (a particle: ``r, v`` and the frame's attitude where a force is given in
inertial axes; a body: ``L, q``); ``p`` the user's ``params`` flattened into one array (the
glue hands each entry back in its own shape).

`PROBLEM` is the tuple of a problem's data that the engine reads: ``(model, M, p, FK, FT, FC,
OK, OT, OC)``, the model's code (`PARTICLE`, `BODY`) and constants (`rotframe.problem.models`),
the parameters, and the frame's and the origin's evaluators (a kind code and two arrays,
`rotframe.problem.models.vector_of_time`).
"""

from __future__ import annotations

from numba import types

__all__ = ["POTENTIAL", "FUNCTIONS", "FUNCTIONS_AT", "PROBLEM", "CONTEXT", "SYSTEM_SIG", "STAGES_SIG", "TERMS_SIG",
           "EVENT_SIG", "VARIANT_SIGNATURE", "loop_with_parts", "POTENTIAL_SIG", "VECTOR_SIG", "VARYING_SIG", "PARTICLE", "BODY", "F8",
           "I8", "A1", "A2", "A3", "I1", "I2", "B1"]

F8 = types.float64
I8 = types.int64
A1 = types.float64[::1]
A2 = types.float64[:, ::1]
A3 = types.float64[:, :, ::1]
I1 = types.int64[::1]
I2 = types.int64[:, ::1]
B1 = types.boolean[::1]

TERMS_SIG = types.void(F8, A1, A1, A1)
EVENT_SIG = F8(I8, F8, A1, A1)
POTENTIAL_SIG = F8(F8, A1, A1)
VECTOR_SIG = types.void(F8, A1)
#: the engine's own evaluator of a varying frame or origin (`rotframe.problem.varying.varying_into`): kind, knots,
#: coefficients, the user's function's address, t, out
VARYING_SIG = types.void(I8, A1, A3, I8, F8, A1)

#: what the stepping calls, by address (`rotframe.problem.calls`): the terms, the events, omega(t), the
#: origin's acceleration, and the engine's evaluator of a varying frame or origin (0 where none varies)
FUNCTIONS = types.UniTuple(types.int64, 5)
#: what the engine's DOP853 whole loop takes where the others take `FUNCTIONS`: those five addresses, then the addresses
#: of the trajectory tier's trajectory, stages and right-hand side, which it calls (`rotframe.problem.by_address`)
FUNCTIONS_AT = types.UniTuple(types.int64, 8)
#: the potential, by address
POTENTIAL = types.int64

#: (model, M, p, FK, FT, FC, OK, OT, OC)
PROBLEM = types.Tuple((I8, A1, A1, I8, A1, A3, I8, A1, A3))

#: what the engine's right-hand side reads besides the state, ``ctx = (prob, fns, W)``: the problem, the addresses of
#: its functions and the engine's scratch (`rotframe.problem.steps.particle_system`)
CONTEXT = types.Tuple((PROBLEM, FUNCTIONS, A1))
#: the engine's right-hand side and DOP853 stages as the trajectory tier calls them by address
#: (`rotframe.problem.calls.call_system`, `rotframe.problem.calls.call_stages`), the context at an address
#: (`rotframe.problem.calls.by_reference`): ``K[s] = f(t, z)``; stages ``first .. last - 1`` of the step ``(t, y, h)``
#: (`rotframe.numerics.dop853_loop.dop853_stages`)
SYSTEM_SIG = types.void(I8, F8, A1, A2, I8)
STAGES_SIG = types.void(I8, I8, I8, F8, A1, F8, A2, A1, A1, F8)
#: the one signature of every variant of the engine's loop (`rotframe.problem.engine.variant`): compiled (or loaded
#: from numba's cache) once, never for a problem
VARIANT_SIGNATURE = types.void(I8, I8, A1, A2, A1, A1, I1, I1, I1, A3, A2, A3, I2, I1, A2, I1, I1, I8, F8, A2, F8, A1,
                               B1, A1, PROBLEM, FUNCTIONS, A2, A2, A2, A2, A1)


def loop_with_parts(functions):
    """`VARIANT_SIGNATURE` of a loop compiled in parts (`rotframe.problem.in_parts.LoopWithParts`), which takes
    ``functions`` (the problem's five addresses and its parts') where a variant takes `FUNCTIONS`."""
    return types.void(*(functions if arg == FUNCTIONS else arg for arg in VARIANT_SIGNATURE.args))

#: model codes (``PROBLEM[0]``)
PARTICLE = 0
BODY = 1
