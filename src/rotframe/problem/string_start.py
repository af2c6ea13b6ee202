"""The check that a pendulum's particles start on its string's sphere, compiled.

`rotframe.simulate` checks its start states once; a prepared run
(`rotframe.problem.prepared.PreparedProblem`) checks them at every run, so the check is on its
path. In numpy's array calls on a few numbers (the distance from the pivot, the speed along the
string) it took 8 of a prepared run's 48 us, where the scene's `rotframe.particles.prepared.PreparedRun`
takes 13 us in all (the Foucault model over 1 s; one pinned core, best of 2000, 2026-11-29).
Compiled, it is one call of about a microsecond. It compiles in 0.25 s, once (cached on disk),
for a problem with a string alone: the other check every run makes (finite numbers) stays in
numpy, whose calls cost less than a first compile (a particle's default tolerances are made by
the engine's loop itself, `rotframe.numerics.step_control.own_tolerances`).
"""

from __future__ import annotations

import math

from rotframe.numerics.compiled import jit_kernel

__all__ = ["string_defect", "OFF_SPHERE", "ALONG_STRING", "SPHERE_TOLERANCE"]

#: what `string_defect` found: a particle off the string's sphere, one moving along the string
OFF_SPHERE, ALONG_STRING = 1, 2
#: the relative tolerance of a start on the string's sphere: its distance from the pivot within this of the length,
#: its speed along the string within this of its speed
SPHERE_TOLERANCE = 1e-9


@jit_kernel
def string_defect(r, v, px, py, pz, length):
    """The first start state off the string, as ``(kind, particle, value)``; ``(0, -1, 0.0)`` where none is.

    ``r``, ``v`` (N, 3) the start states, finite; the string of ``length`` (m) about the pivot
    ``(px, py, pz)``. The kinds, each checked over all particles before the next:

    - `OFF_SPHERE`: the particle's distance ``d`` from the pivot is off the length by more than
      `SPHERE_TOLERANCE` times it (value ``d``, m);
    - `ALONG_STRING`: its speed along the string, ``|v . n|`` with ``n = (r - pivot) / length``,
      exceeds `SPHERE_TOLERANCE` times its speed (value that speed, m/s).
    """
    N = r.shape[0]
    for i in range(N):
        dx = r[i, 0] - px
        dy = r[i, 1] - py
        dz = r[i, 2] - pz
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        if abs(d - length) > SPHERE_TOLERANCE * length:
            return OFF_SPHERE, i, d
    for i in range(N):
        vx = v[i, 0]
        vy = v[i, 1]
        vz = v[i, 2]
        radial = abs(vx * ((r[i, 0] - px) / length) + vy * ((r[i, 1] - py) / length) + vz * ((r[i, 2] - pz) / length))
        if radial > SPHERE_TOLERANCE * max(math.sqrt(vx * vx + vy * vy + vz * vz), 1e-300):
            return ALONG_STRING, i, radial
    return 0, -1, 0.0
