"""The classical Runge-Kutta step (RK4), written once and compiled for each system's right-hand side.

A system is ``rhs(ctx, t, z, K, s)``, a compiled function that writes ``f(t, z)`` into row ``s`` of
``K`` (the protocol of `rotframe.numerics.dop853_loop`). `rk4_step` compiles, for a system,

    step(ctx, t, y, h, K, yt, yn)

one step from ``(t, y)`` with ``K[0] = f(t, y)`` given: the stages ``K[1] = f(t + h/2, y + h/2 K[0])``,
``K[2] = f(t + h/2, y + h/2 K[1])``, ``K[3] = f(t + h, y + h K[2])`` (``yt`` their state), then
``yn = y + h (K[0] + 2 K[1] + 2 K[2] + K[3]) / 6`` (Kutta 1901; Hairer, Norsett & Wanner, *Solving
Ordinary Differential Equations I*, 2nd ed., II.1). The systems: the
particle and the body of your own problems (`rotframe.problem.engine`, on the CPU and the GPU) and
the rigid body's fixed-step RK4 (`rotframe.rigid.kernels.rk4_run`).

The right-hand side is a global name of a copy of the template (`rotframe.numerics.compiled.bound`):
numba calls it directly, the GPU's compiler rebinds it to its own version
(`rotframe.particles.gpu.device_function`), and each system's step is cached under its own name.

The scenes' particles keep a step of their own on 6-tuples (`rotframe.particles.kernels.rk4_step`,
the same arithmetic with the rates of a precomputed plan), which their ensembles run in registers
on the CPU and the GPU.
"""

from __future__ import annotations

from rotframe.numerics.compiled import bound, jit_llvm_inline

__all__ = ["rk4_step"]

#: the system's right-hand side and the length of its state, bound per system (`rk4_step`); None and 0 in the
#: template, which is never compiled
RHS = None
DIM = 0


def _step(ctx, t, y, h, K, yt, yn):
    """The template of `rk4_step`."""
    D = DIM
    for s in range(1, 4):  # one call site of the right-hand side
        c = 0.5 if s < 3 else 1.0
        for j in range(D):
            yt[j] = y[j] + c * h * K[s - 1, j]
        RHS(ctx, t + c * h, yt, K, s)
    for j in range(D):
        yn[j] = y[j] + h * (K[0, j] + 2.0 * K[1, j] + 2.0 * K[2, j] + K[3, j]) / 6.0


def rk4_step(name, rhs, D):
    """The RK4 step of the system ``rhs`` of states of ``D`` numbers (module docstring), compiled for it (cached as
    ``rk4_step_<name>``).

    ``D`` is a constant of the step's code: read from the state's shape as it ran, it kept LLVM from
    unrolling the loops over the state. A stand-alone RK4 loop on the Foucault model's arrays took
    10.7 ms with the length read, 6.6 ms with it constant and 6.1 ms on a 6-tuple; the engine's
    inlined loop on that model went from 11.5 to 12.6 ms a run to 9.9 to 11.8 (one pinned core,
    2026-11-29).

    Compiled once and inlined by LLVM into each caller (`rotframe.numerics.compiled.jit_llvm_inline`): called,
    the step passed the system's data (the engine's problem tuple, some fifty numbers) through the call at every
    step; inlined, the engine's RK4 on the Foucault model took 10.5 to 11.0 ms against 13.7 (one pinned core,
    2026-11-29). The same arithmetic, so the same numbers.
    """
    return jit_llvm_inline(bound(_step, f"rk4_step_{name}", RHS=rhs, DIM=int(D)))
