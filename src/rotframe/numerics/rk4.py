"""The classical Runge-Kutta step (RK4), written once and compiled for each system's right-hand side.

A system is ``rhs(ctx, t, z, K, s)``, a compiled function that writes ``f(t, z)`` into row ``s`` of
``K`` (the protocol of `rotframe.numerics.dop853_loop`). `rk4_step` compiles, for a system,

    step(ctx, t, y, h, K, yt, yn)

one step from ``(t, y)`` with ``K[0] = f(t, y)`` given: the stages ``K[1] = f(t + h/2, y + h/2 K[0])``,
``K[2] = f(t + h/2, y + h/2 K[1])``, ``K[3] = f(t + h, y + h K[2])`` (``yt`` their state), then
``yn = y + h (K[0] + 2 K[1] + 2 K[2] + K[3]) / 6`` (Kutta 1901; Hairer, Norsett & Wanner, *Solving
Ordinary Differential Equations I*, 2nd ed., II.1). The systems: the
body of your own problems and a particle of theirs that carries the frame's attitude
(`rotframe.problem.engine`, on the CPU and the GPU), and the rigid body's fixed-step RK4
(`rotframe.rigid.kernels.rk4_run`).

The right-hand side is a global name of a copy of the template (`rotframe.numerics.compiled.bound`):
numba calls it directly, the GPU's compiler rebinds it to its own version
(`rotframe.particles.gpu.device_function`), and each system's step is cached under its own name.

A particle, ``x'' = a(t, x, x')``, has the same step written on its six numbers
(`rk4_particle_step`), with every stage in registers: the position's stages are the velocity's,
so the step needs only the acceleration, ``ACCEL(ctx, t, state) -> (ax, ay, az)`` on a 6-tuple
state. The scenes' particles (`rotframe.particles.kernels.rk4_step`, with the rates of a
precomputed plan, in registers for their ensembles on the CPU and the GPU) and the particles of
your own problems (`rotframe.problem.steps`) take it. The arithmetic is Kutta's, grouped as the
scenes' kernels always grouped it (``x + (h/6) (...)``), so their numbers are unchanged.
"""

from __future__ import annotations

from rotframe.numerics.compiled import bound, jit_llvm_inline

__all__ = ["rk4_step", "rk4_particle_step"]

#: the system's right-hand side and the length of its state, bound per system (`rk4_step`); None and 0 in the
#: template, which is never compiled
RHS = None
DIM = 0
#: a particle's acceleration, bound per system (`rk4_particle_step`); None in the template, which is never compiled
ACCEL = None


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


def _particle_step(mid, end, t, state, h, a1):
    """The template of `rk4_particle_step`."""
    x, y, z, vx, vy, vz = state
    a1x, a1y, a1z = a1
    hh = 0.5 * h
    h6 = h / 6.0
    v2x = vx + hh * a1x
    v2y = vy + hh * a1y
    v2z = vz + hh * a1z
    a2x, a2y, a2z = ACCEL(mid, t + hh, (x + hh * vx, y + hh * vy, z + hh * vz, v2x, v2y, v2z))
    v3x = vx + hh * a2x
    v3y = vy + hh * a2y
    v3z = vz + hh * a2z
    a3x, a3y, a3z = ACCEL(mid, t + hh, (x + hh * v2x, y + hh * v2y, z + hh * v2z, v3x, v3y, v3z))
    v4x = vx + h * a3x
    v4y = vy + h * a3y
    v4z = vz + h * a3z
    a4x, a4y, a4z = ACCEL(end, t + h, (x + h * v3x, y + h * v3y, z + h * v3z, v4x, v4y, v4z))
    return (x + h6 * (vx + 2.0 * v2x + 2.0 * v3x + v4x),
            y + h6 * (vy + 2.0 * v2y + 2.0 * v3y + v4y),
            z + h6 * (vz + 2.0 * v2z + 2.0 * v3z + v4z),
            vx + h6 * (a1x + 2.0 * a2x + 2.0 * a3x + a4x),
            vy + h6 * (a1y + 2.0 * a2y + 2.0 * a3y + a4y),
            vz + h6 * (a1z + 2.0 * a2z + 2.0 * a3z + a4z))


def rk4_particle_step(name, accel, compile):
    """The RK4 step of a particle whose acceleration is ``accel`` (module docstring), compiled by ``compile``.

    ``step(mid, end, t, state, h, a1) -> state``: from ``state = (x, y, z, vx, vy, vz)`` at ``t``
    with ``a1`` its acceleration, one step of length ``h``, the stages in registers.
    ``accel(ctx, t, state) -> (ax, ay, az)`` is called with ``ctx = mid`` at ``t + h/2`` and with
    ``ctx = end`` at ``t + h``: a scene passes the rates of its plan there; the engine passes
    its problem both times. ``compile`` is the caller's inlining (numba's, into each caller's
    loop), so the step's arithmetic is in each caller's loop.

    On the Foucault model the engine's particle took 1.21 to 1.29 times the scene's time with its
    stages in arrays (`rk4_step`) and 1.11 to 1.13 with them in registers, each stage's state
    written to an array for the user's force (`tools/foucault_on_engine.py`, prepared runs; one
    pinned core, best of 9, 2026-11-29).
    """
    return compile(bound(_particle_step, f"rk4_particle_step_{name}", ACCEL=accel))
