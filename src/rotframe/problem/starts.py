"""A run's start states: checked, and made into the engine's arrays, each in one compiled call.

`rotframe.simulate` checks its start states once; a prepared run
(`rotframe.problem.prepared.PreparedProblem`) checks them at every run, so the checks and the
arrays they feed are on its path. Written with numpy's array calls, the checks (finite; on the
string's sphere; no velocity along the string) and the engine's arrays (the states, each
particle's absolute tolerances) took some twenty calls of about a microsecond each on a few
numbers: 17 us of a prepared run's 48 us, where the scene's `rotframe.particles.prepared.PreparedRun`
takes 13 us in all (the Foucault model over 1 s; one pinned core, best of 2000, 2026-11-29).
Compiled, each is one call of about a microsecond. The arithmetic is numpy's own, in the same
order (IEEE operations, each rounded once), so the decisions and the numbers are the same.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.numerics.compiled import jit_kernel

__all__ = ["start_defect", "start_arrays", "NOT_FINITE", "OFF_SPHERE", "ALONG_STRING", "SPHERE_TOLERANCE"]

#: what `start_defect` found: a number not finite, a particle off the string's sphere, one moving along the string
NOT_FINITE, OFF_SPHERE, ALONG_STRING = 1, 2, 3
#: the relative tolerance of a start on the string's sphere: its distance from the pivot within this of the length,
#: its speed along the string within this of its speed
SPHERE_TOLERANCE = 1e-9


@jit_kernel
def start_defect(r, v, px, py, pz, length):
    """The first start state a run refuses, as ``(kind, particle, value)``; ``(0, -1, 0.0)`` where none is.

    ``r``, ``v`` (N, 3) the start states; a string of ``length`` (m) about the pivot
    ``(px, py, pz)``, or ``length`` 0 for none. The kinds, checked in this order over all
    particles:

    - `NOT_FINITE`: a number of ``r`` or ``v`` is not finite (value 0);
    - `OFF_SPHERE`: the particle's distance ``d`` from the pivot is off the length by more than
      `SPHERE_TOLERANCE` times it (value ``d``, m);
    - `ALONG_STRING`: its speed along the string, ``|v . n|`` with ``n = (r - pivot) / length``,
      exceeds `SPHERE_TOLERANCE` times its speed (value that speed, m/s).
    """
    N = r.shape[0]
    for i in range(N):
        for j in range(3):
            if not (math.isfinite(r[i, j]) and math.isfinite(v[i, j])):
                return NOT_FINITE, i, 0.0
    if length == 0.0:
        return 0, -1, 0.0
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


@jit_kernel
def start_arrays(r, v, D, duration, rtol, given):
    """The engine's states ``y`` (N, D) and absolute tolerances ``atol`` (N, D) of a run from ``r``, ``v`` (N, 3).

    ``y`` holds ``r`` and ``v`` in its first six columns, zeros after (the frame's attitude is
    the caller's). ``atol`` is ``rtol`` in every column but the first six. Those are ``given``
    (6,) where it has six numbers (the caller's checked ``atol``); otherwise each particle's
    own scales, so that its steps, and its numbers, do not depend on the other particles of the
    ensemble: ``rtol`` times ``s_r = max(max|r|, max|v| T)`` for the position and
    ``s_v = max(max|v|, s_r / T)`` for the velocity (``T`` the duration), and ``1``, ``1 / T``
    for a particle at rest at the origin.
    """
    N = r.shape[0]
    y = np.zeros((N, D))
    atol = np.full((N, D), rtol)
    for i in range(N):
        ar = 0.0
        av = 0.0
        for j in range(3):
            y[i, j] = r[i, j]
            y[i, 3 + j] = v[i, j]
            ar = max(ar, abs(r[i, j]))
            av = max(av, abs(v[i, j]))
        if given.shape[0] == 6:
            for j in range(6):
                atol[i, j] = given[j]
            continue
        sr = max(ar, av * duration)
        sv = max(av, sr / duration)
        if sr == 0.0:
            sr = 1.0
            sv = 1.0 / duration
        for j in range(3):
            atol[i, j] = rtol * sr
            atol[i, 3 + j] = rtol * sv
    return y, atol
