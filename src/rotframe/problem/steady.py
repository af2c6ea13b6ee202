"""The engine's steady specialisation: DOP853 on a steady frame with uniform gravity and a string, compiled once.

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
- there are no events;
- and, seen by the calls' driver's probe before the run, the work fits one call (some 2e5
  particle-steps, a tenth of a second): a call ends with a step cut to land on its last sample, which
  the engine's loop never cuts, so a longer run goes to the engine's loop
  (`rotframe.particles.chunked.RunNeedsCuts`, `rotframe.problem.particles`), as a failure does.
"""

from __future__ import annotations

import numpy as np

from rotframe.problem.terms import Force, StringConstraint, energy_by_numpy

__all__ = ["steady_model"]


def _constant_acceleration(f):
    """The constant acceleration ``b`` (3,) of a force whose linear form is ``a = b``; None for any other term."""
    if not isinstance(f, Force) or f.axes != "frame" or not f.linear:
        return None
    K, C, b = f.linear
    if np.any(np.asarray(K, dtype=float)) or np.any(np.asarray(C, dtype=float)):
        return None
    return np.array(b, dtype=float)


def steady_model(method, on_gpu, jit, inline, frame, origin, terms, events, frame_terms):
    """``(model, q)`` of a run that the steady loop runs, or None where the run does not qualify (the module
    docstring): ``terms`` the run's forces and string as `set_up` reads them, ``frame_terms`` those of the frame's
    terms that act. ``q`` is the loop's parameters (`rotframe.particles.dop853_steady.steady_parameters`: the
    frame's omega as given, so the engine's arithmetic to the bit), ``model`` the same problem as the scenes'
    `rotframe.particles.model.ParticleModel`, which the calls' driver (`rotframe.particles.chunked`) reads for its
    work limits."""
    if (method != "dop853" or on_gpu or not jit or inline is not None or events or frame.kind != "constant"
            or origin.kind != "zero"):
        return None
    g = string = None
    for f in terms:
        if isinstance(f, StringConstraint) and string is None:
            string = f
            continue
        b = _constant_acceleration(f) if g is None else None
        if b is None:
            return None
        g = b
    if not energy_by_numpy([f for f in terms if isinstance(f, Force)]):
        return None
    from rotframe.particles.dop853_steady import steady_parameters
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    omega = np.asarray(frame.data[0], dtype=float)
    names = (("gravity",) if g is not None else ()) + tuple(t for t in frame_terms if t != "euler")
    extra = {"g": g} if g is not None else {}
    pivot, length = np.zeros(3), 0.0
    if string is not None:
        names += ("pendulum",)
        pivot, length = np.array(string.pivot, dtype=float), float(string.length)
        extra.update(pendulum_length=length, pivot=pivot)
    model = ParticleModel(names, omega=OmegaSchedule.constant(omega), **extra)
    q = steady_parameters(np.zeros(3) if g is None else g, omega, pivot, length, "coriolis" in frame_terms,
                          "centrifugal" in frame_terms)
    return model, q
