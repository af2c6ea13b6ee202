"""One step of each of the engine's methods, for each model: the systems, the steppers, `take_step`.

A model's right-hand side (`rotframe.problem.models.rhs`) is a *system* of rotframe's one DOP853
loop (`rotframe.numerics.dop853_loop`) and its one RK4 step (`rotframe.numerics.rk4`): a
compiled function ``f(ctx, t, z, K, s)`` writing ``K[s]``, with ``ctx = (prob, fns, W)``
(`particle_system`, `body_system`). `stepper` compiles the method's step for a system and a
length of state; `take_step` is the method's step with it: the engine's fixed-step loop steps
with it, and its event locators re-step with it (`rotframe.problem.engine`).

A particle's RK4 step (6 numbers) is the one RK4 step of a particle, the scenes' too
(`rotframe.numerics.rk4.rk4_particle_step`), with its stages in registers; it writes each stage's
state to ``yt`` for the problem's functions, which take arrays (`particle_rk4`). A particle that
carries the frame's attitude (10 numbers) and a body take the one RK4 step of a system
(`rotframe.numerics.rk4.rk4_step`).
"""

from __future__ import annotations

import functools

from rotframe.numerics.compiled import bound, jit_inline, jit_llvm_inline
from rotframe.numerics.dop853_loop import dop853_stages, dop853_step
from rotframe.numerics.rk4 import rk4_particle_step, rk4_step
from rotframe.problem.models import DOP853, RK4, own_step, rhs

__all__ = ["particle_system", "body_system", "particle_rk4", "carried_rk4", "particle_acceleration", "stepper",
           "take_step"]


@jit_inline
def particle_system(ctx, t, z, K, s):
    """A particle's right-hand side as the one DOP853 loop calls it: ``K[s] = f(t, z)``, ``ctx = (prob, fns, W)``."""
    prob, fns, W = ctx
    rhs(None, t, z, K[s], prob, fns, W)


@jit_inline
def body_system(ctx, t, z, K, s):
    """A rigid body's right-hand side as the one DOP853 loop calls it (`particle_system`)."""
    rhs(True, t, z, K[s], ctx[0], ctx[1], ctx[2])


@jit_llvm_inline  # compiled once: numba's inlining put it, and the right-hand side's call, in the step three times
def _stage_acceleration(ctx, t, state):
    """A particle's acceleration at an RK4 stage, ``ctx = (prob, fns, W, yt, dy)``: the stage's ``state`` written to
    ``yt``, the array the problem's functions take, and its rates to ``dy`` by the right-hand side (the one the DOP853
    loop calls: no second copy to compile), read back at once (LLVM forwards the stores to the loads)."""
    prob, fns, W, yt, dy = ctx
    yt[0] = state[0]
    yt[1] = state[1]
    yt[2] = state[2]
    yt[3] = state[3]
    yt[4] = state[4]
    yt[5] = state[5]
    rhs(None, t, yt, dy, prob, fns, W)
    return dy[3], dy[4], dy[5]


#: the one RK4 step of a particle with the engine's acceleration (inlined by numba into `particle_rk4`, its one caller)
_particle_step = rk4_particle_step("engine", _stage_acceleration, jit_inline)


@jit_inline
def carried_rk4(stage, t, s, h, a1):
    """A particle's RK4 step on its six numbers ``s`` at t, ``a1`` its acceleration there, ``stage = (prob, fns, W, yt,
    dy)`` (`particle_acceleration`'s): the state after ``h``, in registers (the fixed-step loop carries it,
    `rotframe.problem.fixed_step`)."""
    return _particle_step(stage, stage, t, s, h, a1)


#: a particle's acceleration at ``(t, s)`` with ``stage = (prob, fns, W, yt, dy)``: the right-hand side's, through ``yt``
particle_acceleration = _stage_acceleration


@jit_llvm_inline  # not numba's inlining: take_step passes each variant's step to the other method's branches too
def particle_rk4(ctx, t, y, h, K, yt, yn):
    """A particle's RK4 step (6 numbers) in the protocol of `rotframe.numerics.rk4.rk4_step`: from ``(t, y)``, with
    ``K[0] = f(t, y)``, the state after ``h`` into ``yn``; ``yt`` the stages' states and ``K[1]`` their rates, each
    read back at once (the stages are in registers): `carried_rk4` on the arrays."""
    prob, fns, W = ctx
    yn[0], yn[1], yn[2], yn[3], yn[4], yn[5] = carried_rk4((prob, fns, W, yt, K[1]), t,
                                                           (y[0], y[1], y[2], y[3], y[4], y[5]), h,
                                                           (K[0, 3], K[0, 4], K[0, 5]))


@functools.lru_cache(maxsize=None)
def stepper(body, method, D):
    """What `take_step` takes a step of ``method`` with, for the model (``body``) and states of ``D`` numbers.

    DOP853: the one DOP853 loop's stages for the model's right-hand side
    (`rotframe.numerics.dop853_loop.dop853_stages`); RK4: the one RK4 step
    (`rotframe.numerics.rk4`; a particle's, `particle_rk4`, where the state is its 6 numbers); a
    splitting: None (the model's own step). ``D`` is a constant of their code, so LLVM unrolls the
    loops over the state. Made once a process for each.
    """
    system = particle_system if body is None else body_system
    kind = f"engine_{'particle' if body is None else 'body'}{D}"
    if method == DOP853:
        return dop853_stages(kind, system, D)
    if method == RK4:
        return particle_rk4 if body is None and D == 6 else rk4_step(kind, system, D)
    return None


@jit_inline
def _dop853_take(step, body, t, y, h, K, yt, yn, ctx):
    """DOP853's step of `take_step`: the one DOP853 loop's (`rotframe.numerics.dop853_loop.dop853_step`)."""
    dop853_step(step, ctx, t, y, h, K, yn, yt)


@jit_inline
def _rk4_take(step, body, t, y, h, K, yt, yn, ctx):
    """RK4's step of `take_step`: the one RK4 step (`rotframe.numerics.rk4`)."""
    step(ctx, t, y, h, K, yt, yn)


# the splitting's order that a copy of `_own_take` binds (`rotframe.numerics.compiled.bound`); 0 in the template
METHOD = 0


def _own_take(step, body, t, y, h, K, yt, yn, ctx):
    """A splitting's step of `take_step`, the template: the model's own (`rotframe.problem.models.own_step`) of order
    ``METHOD``."""
    own_step(body, METHOD, t, y, h, yn, ctx[0], ctx[1], ctx[2])


@functools.lru_cache(maxsize=None)
def take_step(method):
    """``take(step, body, t, y, h, K, yt, yn, ctx)``: one step of ``method`` of length ``h`` from (t, y), with
    K[0] = f(t, y): ``yn``.

    ``step`` is the variant's `stepper`: DOP853's step is the one DOP853 loop's
    (`rotframe.numerics.dop853_loop.dop853_step` with the system's stages), RK4's the one RK4
    step (`rotframe.numerics.rk4`); a splitting is the model's own (`rotframe.problem.models.own_step`).
    ``ctx`` is the system's: ``(prob, fns, W)``, and more after them in the trajectory tier's
    (`rotframe.problem.by_address`). Chosen here, in Python, for the method: numba would inline every method's
    step into each caller before it pruned the others (the event locator's trials call it at several sites:
    an events variant's first compile took some 8 s for it).
    """
    if method == DOP853:
        return _dop853_take
    if method == RK4:
        return _rk4_take
    return jit_inline(bound(_own_take, f"own_take_{method}", METHOD=method))
