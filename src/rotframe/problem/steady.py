"""The engine's steady specialisations: DOP853 on a steady frame with uniform gravity, a string and one built-in
crossing, compiled once; RK4 and the rotation splitting on a steady frame with uniform gravity, air drag, a string,
the frame's terms and one built-in crossing, on the scenes' drivers, and on the GPU on the scenes' GPU kernel.

Most particle problems that run DOP853 in a rotating frame are *steady*: a constant rotation rate,
uniform gravity (or none), the pendulum's string (or none), and no other term. Foucault's pendulum is
one. For them the engine runs `rotframe.particles.dop853_steady`: the one DOP853 loop
(`rotframe.numerics.dop853_loop`) with that force written in place, compiled once for every such
problem and cached on disk, where the general loop (`rotframe.problem.engine`) compiles the problem's
functions and a loop that reads a frame table, stops, events and statuses. The choice is the engine's,
made from the terms (`steady_model`), as the exact flow of a linear problem is (`rotframe.problem.exact`):
a run names no variant.

It is the same computation: the same stages, error norm, step control and dense output, the
terms' arithmetic of `rotframe.particles.accelerations` in the order of the engine's right-hand side
(`rotframe.problem.models`), each particle's own tolerances by the same rule
(`rotframe.numerics.step_control.own_tolerances`), the same sample times. So its numbers are the
general loop's to the bit (``tests/test_steady_route.py`` checks random problems against
``inline=False``, which always runs the general loop). What it saves is compiling: its first compile
took 3.0 to 3.5 s on the 2-core reference machine (numba's start included; the general loop's
3.3 to 3.7 s, and the problem's glue beside it: ``python tools/first_compiles.py run foucault
--no-record``), and nothing of the problem's own is compiled, so a new steady problem only loads
the loop from numba's cache (0.24 s beyond imports, 2026-11-30). Like the exact flow, it takes a
force's ``linear`` form as what the force computes (the built-in terms set it).

A problem qualifies (`steady_model`) where:

- the method is ``dop853``, on the CPU, compiled (``jit=True``), ``inline`` not given (``inline=False``
  or ``True`` asks for the general loop, or its inlined form, by name);
- the frame turns at a constant rate (``omega`` a vector), its origin does not accelerate;
- the terms are at most one force with a constant linear form (``Force.linear`` with ``K = C = 0``:
  `rotframe.forces.gravity`) and at most one string (`rotframe.forces.pendulum`), in frame axes, their
  potentials numpy's where given (`rotframe.problem.terms.energy_by_numpy`);
- there is at most one event, a built-in crossing (`rotframe.events.crossing`) not zero at any particle's start,
  and the run is not a prepared problem's (`rotframe.problem.prepared`): the steady loop watches it after each
  accepted step and locates a crossing on its own DOP853 re-steps with rotframe's one locator, as the engine's
  loop does (`rotframe.particles.dop853_steady.steady_events_kernel`, since 2026-12-01: the tower drop's sweep
  ensembles run there);
- and, seen by the calls' driver's probe before the run, the work fits one call (some 2e5
  particle-steps, a tenth of a second): a call ends with a step cut to land on its last sample, which
  the engine's loop never cuts, so a longer run goes to the engine's loop
  (`rotframe.particles.chunked.RunNeedsCuts`, `rotframe.problem.particles`), as a failure does.

The fixed-step specialisation runs the scenes' fixed-step drivers (`rotframe.particles.drivers`, in the calls of
`rotframe.particles.chunked`), which keep a particle's six numbers in registers and test a built-in crossing in
place, where the engine's loop reaches its event function through the problem's glue. Each of their steps starts
on its sample interval's grid as the engine's does (`rotframe.numerics.step_control.grid_time`), and on the problems
below their arithmetic is the engine's, so they give its samples, event times and states, statuses and step
counts to the bit (``tests/test_steady_route.py``, random problems against ``inline=False``; 376 more, every one
the same, 2026-11-30), in the scenes' time: on the tower drop's ensemble (20,000 particles, the ground event, one
thread) ``simulate`` took 1.10 times the scenes' kernels' time under the splitting and 1.05 under RK4, its Python
around them included, where the engine's inlined loop took 1.66 and 1.12 (``python tools/ensembles_on_engine.py
20000 1``, 2026-11-30). A problem qualifies where:

- the method is ``rk4``, ``rotation-splitting`` or ``rotation-splitting4`` (`FIXED_STEADY`), on the CPU, compiled,
  ``inline`` not given;
- the frame turns at a constant rate, its origin does not accelerate, and the scenes' model keeps its omega to
  the bit (`omega_kept`: its axis and rate are the engine's, and their product is omega again; most vectors,
  the Earth's at a latitude among them);
- the terms are at most one force with a constant linear form, at most one air drag (`rotframe.forces.drag`, in
  any air: the drivers' drag is the engine's, its exact flow under the splitting, since 2026-11-30: 130 of the 400
  random problems below) and at most one string (`rotframe.forces.pendulum`: the drivers' splitting on the sphere
  turns the velocity by the engine's angle, -2 (w . n) h, on a steady frame, since 2026-11-30: 231 random pendulums
  on the drivers, every one the same). Any of the frame's terms may act: the drivers' RK4 sums the forces, then
  Coriolis, then the centrifugal term, as the engine's right-hand side does (`rotframe.particles.forces.
  state_acceleration`, since 2026-11-30: 400 more random problems, 109 of them RK4 with the centrifugal term,
  every one the same), and the splitting kicks with the centrifugal term as the engine does
  (`rotframe.particles.forces.position_acceleration`);
- there is at most one event, a built-in crossing (`rotframe.events.crossing`), not zero at any particle's start
  (the drivers take the sign after a zero start from derivatives, the engine from re-steps).

On the GPU (``device="gpu"``) the same fixed-step problems qualify where the run keeps its end alone (``samples=1``)
and its event, if any, is terminal, whatever the frame's omega (`omega_kept` asks for the bits the CPU's drivers
share with the engine's loop, which the GPU does not promise), and so does altitude gravity
(`rotframe.forces.altitude_gravity`, known by its ``Force.scene``) in place of uniform gravity: the scenes' GPU
kernel runs them (`rotframe.particles.gpu.GpuLaunch`,
one thread a particle, its six numbers in registers, no samples between: since 2026-12-02), where the engine's own
GPU loop (`rotframe.problem.gpu`) keeps a sample grid and reaches the terms through the problem's glue, at 0.08 to
0.16 of the kernel's speed when last measured on an H200 (2026-11-30). It takes the steps of the CPU's run of the
same problem (a step cut to divide the sample interval, counted from the start), so the samples, event times and
states agree with the engine's loop to round-off (a GPU may fuse a multiply and an add; on numba's simulator to the
bit, ``tests/test_simulate_gpu.py``), and the counts are the drivers'. The tower drop's sweeps on the GPU reach the
kernel this way (`rotframe.scenes.tower_drop._on_gpu`), as one run of the engine a group of drops.

A run that fails on the drivers (a state not finite, their guard on a speed that grows under no force) runs again
on the engine's loop, which names the cause (`rotframe.problem.tiers.SteadyLoopFailed`). The counts reported are
the engine's: each particle's steps to the end or to the step of its terminal event, the most any took; the
force evaluations, the drivers' own.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from rotframe.problem.terms import Force, StringConstraint, energy_by_numpy

__all__ = ["steady_model", "FIXED_STEADY", "SteadyProblem", "omega_kept"]

#: the fixed-step methods whose steps, samples and event times the scenes' fixed-step drivers
#: (`rotframe.particles.drivers`) take as the engine's loop takes them, to the bit, on a steady problem of
#: uniform gravity, drag, a string and the frame's terms (`steady_model`). ``rotation-splitting4`` joined on
#: 2026-11-30, when the engine's locator took the step's own length as its bracket (`rotframe.problem.fixed_step`),
#: as the drivers' does: its state at an event had differed in the last bits.
FIXED_STEADY = ("rk4", "rotation-splitting", "rotation-splitting4")


class SteadyProblem(NamedTuple):
    """A run that a steady loop runs (`steady_model`): the problem as the scenes'
    `rotframe.particles.model.ParticleModel`, the DOP853 steady loop's parameters ``q`` (None for a fixed-step
    method, which the scenes' drivers run) and the events as the drivers' rows
    (`rotframe.particles.trajectory.Event`)."""

    model: object
    q: object
    rows: tuple


def _constant_acceleration(f):
    """The constant acceleration ``b`` (3,) of a force whose linear form is ``a = b``; None for any other term."""
    if not isinstance(f, Force) or f.axes != "frame" or not f.linear:
        return None
    K, C, b = f.linear
    if np.any(np.asarray(K, dtype=float)) or np.any(np.asarray(C, dtype=float)):
        return None
    return np.array(b, dtype=float)


def _drag_flow(f):
    """``(k1, k2, H)`` of the built-in drag (`rotframe.forces.drag`: its exact flow's data) in frame axes; None for
    any other term."""
    flow = getattr(f, "flow", None) if isinstance(f, Force) and f.axes == "frame" else None
    return tuple(float(x) for x in flow[1:]) if flow and flow[0] == "drag" else None


def _event_rows(events, names, r, v):
    """The drivers' rows of the run's ``events`` (named ``names``), or None where the scenes' drivers would not
    locate them as the engine does: more than one event, one that is no built-in crossing
    (`rotframe.problem.exact.event_row`), or one that is zero at a particle's start, which the drivers' start rule
    (the sign from the derivatives) and the engine's (from re-steps) may read apart."""
    from rotframe.problem.exact import event_row

    if len(events) > 1:
        return None
    rows = tuple(event_row(g, name) for g, name in zip(events, names))
    for row in rows:
        if row is None or np.any((r if row.kind == "r" else v)[:, row.component] == row.value):
            return None
    return rows


def omega_kept(w):
    """Whether the scenes' model keeps the frame's ``w`` (3,) to the bit: its unit axis and rate
    (`rotframe.particles.model.OmegaSchedule.constant`, numpy's norm) are the engine's (the norm summed in order,
    `rotframe.problem.models.turn_axis`), and their product is ``w`` again (the drivers' Coriolis term reads it)."""
    import math

    from rotframe.particles.model import OmegaSchedule

    n = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    kept = OmegaSchedule.constant(w)
    axis, rate = kept.axis, float(kept.values[0])
    return n > 0.0 and rate == n and np.array_equal(axis, w / n) and np.array_equal(axis * rate, w)


def steady_model(method, on_gpu, jit, inline, frame, origin, terms, events, frame_terms, r=None, v=None,
                 event_names=(), fixed=True, samples=0):
    """The `SteadyProblem` of a run that a steady loop runs, or None where the run does not qualify (the module
    docstring): ``terms`` the run's forces and string as `set_up` reads them, ``frame_terms`` those of the frame's
    terms that act, ``r``, ``v`` (N, 3) the start states and ``event_names`` the events' names; ``fixed`` False
    takes DOP853's loop alone, and no events (a prepared problem's runs, `rotframe.problem.prepared`). Its ``q``
    is the DOP853 loop's parameters (`rotframe.particles.dop853_steady.steady_parameters`: the frame's omega as
    given, so the engine's arithmetic to the bit), ``model`` the same problem as the scenes'
    `rotframe.particles.model.ParticleModel`, which the calls' driver (`rotframe.particles.chunked`) reads for its
    work limits and the fixed-step drivers run. On the GPU (``on_gpu``) a fixed-step run whose ``samples`` is 1 and
    whose event, if any, is terminal qualifies too: the scenes' GPU kernel runs it (`rotframe.particles.gpu`, the
    module docstring)."""
    fixed_step = fixed and method in FIXED_STEADY
    on_gpu_kernel = on_gpu and fixed_step and samples == 1
    if ((method != "dop853" and not fixed_step) or (on_gpu and not on_gpu_kernel) or not jit or inline is not None
            or (events and not fixed) or frame.kind != "constant" or origin.kind != "zero"):
        return None
    omega = np.asarray(frame.data[0], dtype=float)
    if fixed_step and not on_gpu and np.any(omega) and not omega_kept(omega):  # the drivers take the engine's steps
        return None  # to the bit (docstring); the GPU's kernel, to round-off whatever the omega
    rows = _event_rows(events, event_names, r, v)
    if rows is None or (on_gpu and not all(row.terminal for row in rows)):  # the GPU's thread ends at its first event
        return None
    g = string = drag = altitude = None
    for f in terms:
        if isinstance(f, StringConstraint) and string is None:
            string = f
            continue
        flow = _drag_flow(f) if fixed_step and drag is None else None
        if flow is not None:  # the drivers' drag is the engine's
            drag = flow
            continue
        if on_gpu and g is None and altitude is None and isinstance(f, Force) and f.scene[:1] == ("altitude-gravity",):
            altitude = f.scene[1:]  # the GPU's kernel computes the scenes' term, the engine's to round-off
            continue
        b = _constant_acceleration(f) if g is None and altitude is None else None
        if b is None:
            return None
        g = b
    if not energy_by_numpy([f for f in terms if isinstance(f, Force) and f.potential is not None]):
        return None
    from rotframe.particles.dop853_steady import steady_parameters
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    names = (("gravity",) if g is not None else ()) + tuple(t for t in frame_terms if t != "euler")
    extra = {"g": g} if g is not None else {}
    if altitude is not None:
        names += ("altitude-gravity",)
        extra.update(g0=float(altitude[0]), radius=float(altitude[1]))
    pivot, length = np.zeros(3), 0.0
    if string is not None:
        names += ("pendulum",)
        pivot, length = np.array(string.pivot, dtype=float), float(string.length)
        extra.update(pendulum_length=length, pivot=pivot)
    if drag is not None:
        k1, k2, H = drag
        names += (("linear-drag",) if k1 > 0.0 else ()) + (("quadratic-drag",) if k2 > 0.0 else ())
        extra.update(k_linear=k1, k_quadratic=k2, scale_height=H)
    model = ParticleModel(names, omega=OmegaSchedule.constant(omega), **extra)
    if fixed_step:
        return SteadyProblem(model, None, rows)
    q = steady_parameters(np.zeros(3) if g is None else g, omega, pivot, length, "coriolis" in frame_terms,
                          "centrifugal" in frame_terms)
    return SteadyProblem(model, q, rows)
