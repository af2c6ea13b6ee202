"""The functions a problem does not have, compiled once: no torque, no event, no potential, no vector of time.

Each has the signature of its role (`rotframe.problem.signatures`), so that the engine takes it
where a problem's own function would go (`rotframe.problem.glue` writes only the ones a
problem has). None of them is called where the problem lacks the role (no events: the engine
evaluates none; a frame that is not a function: the engine reads its arrays), except
`no_terms`, the free body's torque.
"""

from __future__ import annotations

from numba import njit

from rotframe.problem.signatures import EVENT_SIG, POTENTIAL_SIG, TERMS_SIG, VECTOR_SIG

__all__ = ["no_terms", "no_event", "no_potential", "no_vector"]

#: called by address alone (`rotframe.problem.calls`): no CPython or C entry point to build
_jit = {"cache": True, "error_model": "numpy", "nogil": True, "no_cpython_wrapper": True, "no_cfunc_wrapper": True}


@njit(TERMS_SIG, **_jit)
def no_terms(t, y, p, out):
    out[0] = 0.0
    out[1] = 0.0
    out[2] = 0.0


@njit(EVENT_SIG, **_jit)
def no_event(k, t, y, p):
    return 0.0


@njit(POTENTIAL_SIG, **_jit)
def no_potential(t, y, p):
    return 0.0


@njit(VECTOR_SIG, **_jit)
def no_vector(t, out):
    for k in range(6):
        out[k] = 0.0
