"""DOP853 on the steady models: the one DOP853 loop with a small force, for a smaller first compile.

The general driver `rotframe.particles.drivers.run_dop853` handles every term, rotation
schedule and event, and a first run compiles the packed model, its every term and the event
code with it. Most scenes that run DOP853 need much less:

- a **steady** rotation rate (``w`` constant, so no schedule and no Euler term);
- **uniform** gravity (a constant vector, or none);
- any of **Coriolis**, **centrifugal** and a **pendulum** string;
- no drag, no spring, no events.

For such a model `run_dop853_steady` runs the same loop (`rotframe.particles.dop853_ensemble.run_particles`
on `rotframe.numerics.dop853_loop`) with a force of its own (`_acceleration`: the terms of
`rotframe.particles.accelerations` on a vector of 13 numbers), in the floating-point order of
the general force, so that its results are bitwise those of the general driver
(``tests/test_dop853_steady.py`` checks this on random models).

`steady_parameters` packs the model for it; `is_steady_model` says
whether a model qualifies.
"""

from __future__ import annotations

import numpy as np

from rotframe.numerics.compiled import jit_internal, jit_kernel, jit_llvm_inline
from rotframe.numerics.dop853_loop import dop853_stages, dop853_trajectory
from rotframe.particles.accelerations import centrifugal_about_axis, coriolis_about_axis, string_tension
from rotframe.particles.dop853_ensemble import run_particles, store_sample

__all__ = ["is_steady_model", "steady_parameters", "run_dop853_steady", "STEADY_TERMS"]

# The force sums the terms of rotframe.particles.accelerations (each term's arithmetic, written once) over
# the steady vector, in the order of rotframe.particles.forces.state_acceleration, rather than calling that
# general force: it would compile the packed model and its helpers (what this driver exists to avoid).
# tests/test_dop853_steady.py keeps the two bitwise the same.

#: The terms that the steady driver evaluates (a model with any other term runs the general driver).
STEADY_TERMS = frozenset({"gravity", "coriolis", "centrifugal", "pendulum"})

# layout of the parameter vector of the steady driver
_G, _W, _PIVOT, _L, _CORIOLIS, _CENTRIFUGAL, _W_MAG = 0, 3, 6, 9, 10, 11, 12
_N = 13


def is_steady_model(model, events=(), packed=None):
    """Whether ``model`` (and a run with ``events``) can run `run_dop853_steady`.

    True for a constant rotation rate, uniform gravity (or none) and no term
    outside `STEADY_TERMS`, without events. ``packed`` is ``model.pack()``
    where the caller has it.
    """
    from rotframe.particles.packed import I_GMODE

    if events or not model.omega.is_constant or not set(model.terms) <= STEADY_TERMS:
        return False
    P = model.pack() if packed is None else packed
    return P[I_GMODE] in (0.0, -1.0)


def steady_parameters(model, packed=None):
    """The parameter vector (13,) of `run_dop853_steady` for a model that qualifies.

    The values are those of ``model.pack()`` (the same floats, so the same results;
    ``packed`` where the caller has it): uniform gravity (zero when off), the unit
    axis, the pivot and string length, the Coriolis and centrifugal switches and the
    rate ``w`` (rad/s).
    """
    from rotframe.particles import packed as k

    P = model.pack() if packed is None else packed
    q = np.zeros(_N)
    if P[k.I_GMODE] == 0.0:
        q[_G:_G + 3] = P[k.I_G:k.I_G + 3]
    q[_W:_W + 3] = P[k.I_AXIS:k.I_AXIS + 3]
    q[_PIVOT:_PIVOT + 3] = P[k.I_PIVOT:k.I_PIVOT + 3]
    q[_L] = P[k.I_PLEN]
    q[_CORIOLIS] = P[k.I_CORIOLIS]
    q[_CENTRIFUGAL] = P[k.I_CENTRIFUGAL]
    q[_W_MAG] = model.omega.values[0]
    return q


@jit_internal
def _acceleration(x, y, z, vx, vy, vz, q):
    """The steady model's acceleration, in the order of `rotframe.particles.forces.state_acceleration`."""
    ax = q[_G]
    ay = q[_G + 1]
    az = q[_G + 2]
    ux = q[_W]
    uy = q[_W + 1]
    uz = q[_W + 2]
    w = q[_W_MAG]
    if q[_CENTRIFUGAL] != 0.0:
        cx, cy, cz = centrifugal_about_axis(x, y, z, ux, uy, uz, w)
        ax += cx
        ay += cy
        az += cz
    if q[_CORIOLIS] != 0.0:
        cx, cy, cz = coriolis_about_axis(vx, vy, vz, ux, uy, uz, w)
        ax -= cx
        ay -= cy
        az -= cz
    L = q[_L]
    if L > 0.0:
        ax, ay, az = string_tension(ax, ay, az, x, y, z, vx, vy, vz, q[_PIVOT], q[_PIVOT + 1], q[_PIVOT + 2], L)
    return ax, ay, az


@jit_llvm_inline
def _steady_rhs(q, t, z, K, s):
    """``K[s] = f(z)`` of the steady model ``q`` (`steady_parameters`): velocity, then `_acceleration`."""
    K[s, 3], K[s, 4], K[s, 5] = _acceleration(z[0], z[1], z[2], z[3], z[4], z[5], q)
    K[s, 0] = z[3]
    K[s, 1] = z[4]
    K[s, 2] = z[5]


_steady_trajectory = dop853_trajectory("steady", dop853_stages("steady", _steady_rhs, 6), store_sample, 6)


@jit_kernel
def run_dop853_steady(r, v, t0, sample_times, q, rtol, atol, span, work, out_r, out_v, h_state):
    """Adaptive DOP853 for an ensemble under a steady model (see the module docstring).

    Parameters and results as `rotframe.particles.drivers.run_dop853`, with ``q`` from
    `steady_parameters`. There are no events, so every particle stays alive. Returns
    ``(n_done, bad, nfev, steps)`` (cost of particle 0).
    """
    return run_particles(_steady_rhs, _steady_trajectory, None, q, r, v, None, t0, sample_times, rtol, atol, span,
                         out_r, out_v, h_state, work, None)
