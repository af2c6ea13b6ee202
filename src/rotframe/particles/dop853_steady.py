"""DOP853 specialised to the steady models: a few small compiled functions instead of about fourteen.

The general driver `rotframe.particles.drivers.run_dop853` handles every
term, rotation schedule and event, and a first run compiles it with its force,
step, schedule and event helpers in 3 to 4 s (numba's typing and lowering of
about fourteen functions). Most scenes that run DOP853 need much less:

- a **steady** rotation rate (``w`` constant, so no schedule and no Euler term);
- **uniform** gravity (a constant vector, or none);
- any of **Coriolis**, **centrifugal** and a **pendulum** string;
- no drag, no spring, no events.

For such a model `run_dop853_steady` is the same algorithm with the force
written in place: the same stages, error norm, step control and starting step
(`rotframe.numerics.step_control`), dense output (`rotframe.numerics.dop853_dense`)
and failure checks, in the same floating-point order, so that its results are
bitwise those of the general driver (``tests/test_dop853_steady.py`` checks
this on random models). Its kernel, the force, one stage loop and the shared
pieces compile in about 2.5 s on a first ``rotframe run foucault`` on the 2-core
machine (numba's own start, about 0.5 s, included), where the general driver
takes 3.3 to 4 s.

`steady_parameters` packs the model for it; `is_steady_model` says
whether a model qualifies.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from rotframe.numerics.compiled import jit_internal, jit_kernel
from rotframe.numerics.dop853 import coefficients, dop853_error_norm
from rotframe.numerics.dop853_dense import dense_coefficients, dense_value, extended_tableau
from rotframe.numerics.step_control import first_step, first_step_trial, next_step, step_collapsed

__all__ = ["is_steady_model", "steady_parameters", "steady_tableau", "run_dop853_steady", "STEADY_TERMS"]

# The error norm, the step-size control, the starting step and the dense output are the shared ones
# (rotframe.numerics). The force (rotframe.particles.forces.state_acceleration, its string constraint
# included) is written in place below, in the same order, rather than shared: calling the general force
# compiles the packed model and its helpers (what this driver exists to avoid). tests/test_dop853_steady.py
# keeps the two bitwise the same.

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


@functools.cache
def steady_tableau():
    """The DOP853 tableau with its dense output as one (22, 16) array.

    Rows 0-15 ``A`` of `rotframe.numerics.dop853_dense.extended_tableau` (row 12 the order-8
    weights ``B``, rows 13-15 the dense output's stages), 16 ``E3``, 17 ``E5``, 18-21 the dense
    output's weights ``D``: the same floats (made once; read-only). The model is steady, so the
    nodes ``C`` are not needed.
    """
    A, _, D = extended_tableau()
    _, _, _, E3, E5 = coefficients()
    tab = np.zeros((22, 16))
    tab[:16] = A
    tab[16, :13] = E3
    tab[17, :13] = E5
    tab[18:22] = D
    tab.flags.writeable = False
    return tab


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
        d = ux * x + uy * y + uz * z
        w2 = w * w
        ax += w2 * (x - d * ux)
        ay += w2 * (y - d * uy)
        az += w2 * (z - d * uz)
    if q[_CORIOLIS] != 0.0:
        w2 = 2.0 * w
        cx = ux * w2
        cy = uy * w2
        cz = uz * w2
        ax -= cy * vz - cz * vy
        ay -= cz * vx - cx * vz
        az -= cx * vy - cy * vx
    L = q[_L]
    if L > 0.0:
        nx = (x - q[_PIVOT]) / L
        ny = (y - q[_PIVOT + 1]) / L
        nz = (z - q[_PIVOT + 2]) / L
        an = ax * nx + ay * ny + az * nz
        vn = vx * nx + vy * ny + vz * nz
        v2t = vx * vx + vy * vy + vz * vz - vn * vn
        c = an + v2t / L
        ax -= c * nx
        ay -= c * ny
        az -= c * nz
    return ax, ay, az


@jit_internal
def _stages(first, last, y, h, q, tab, K, z):
    """Stages ``first .. last - 1``: ``z = y + h sum_p tab[s, p] K[p]``, ``K[s] = f(z)`` (the model is steady)."""
    for s in range(first, last):
        for j in range(6):
            acc = 0.0
            for p in range(s):
                acc += tab[s, p] * K[p, j]
            z[j] = y[j] + h * acc
        K[s, 3], K[s, 4], K[s, 5] = _acceleration(z[0], z[1], z[2], z[3], z[4], z[5], q)
        K[s, 0] = z[3]
        K[s, 1] = z[4]
        K[s, 2] = z[5]


@jit_kernel
def run_dop853_steady(r, v, t0, sample_times, q, rtol, atol, span, tab, work, out_r, out_v, h_state):
    """Adaptive DOP853 for an ensemble under a steady model (see the module docstring).

    Parameters and results as `rotframe.particles.drivers.run_dop853`, with
    ``q`` from `steady_parameters`, ``tab`` from `steady_tableau` and
    ``work`` (28, 6) scratch from the caller. There are no events, so every
    particle stays alive. Returns ``(n_done, bad, nfev, steps)`` (cost of particle 0).
    """
    n = r.shape[0]
    n_out = sample_times.shape[0]
    K = work[0:16]
    y = work[16]
    y_new = work[17]
    tmp = work[18]
    f0 = work[19]
    atol_vec = work[20]
    F = work[21:28]  # the interpolant's coefficients of the current step
    E3 = tab[16, :13]
    E5 = tab[17, :13]
    for j in range(6):
        atol_vec[j] = atol
    nfev0 = 0
    steps0 = 0
    n_done = n_out
    bad = -1
    t_end = sample_times[n_out - 1]
    for p in range(n):
        for i in range(3):
            y[i] = r[p, i]
            y[3 + i] = v[p, i]
        t = t0
        h = h_state[p]
        ax, ay, az = _acceleration(y[0], y[1], y[2], y[3], y[4], y[5], q)
        f0[0], f0[1], f0[2], f0[3], f0[4], f0[5] = y[3], y[4], y[5], ax, ay, az
        nf = 1
        if h <= 0.0:  # Hairer's starting step (numerics.step_control), one more evaluation at its trial step
            h0 = first_step_trial(y, f0, rtol, atol_vec, span)
            for j in range(6):
                tmp[j] = y[j] + h0 * f0[j]
            ax, ay, az = _acceleration(tmp[0], tmp[1], tmp[2], tmp[3], tmp[4], tmp[5], q)
            K[1, 0], K[1, 1], K[1, 2], K[1, 3], K[1, 4], K[1, 5] = tmp[3], tmp[4], tmp[5], ax, ay, az
            h = first_step(y, f0, K[1], h0, rtol, atol_vec, span)
            nf += 1
        rejected = False
        k_out = 0
        while k_out < n_out and sample_times[k_out] <= t:
            for i in range(3):
                out_r[k_out, p, i] = y[i]
                out_v[k_out, p, i] = y[3 + i]
            k_out += 1
        failed = False
        while t < t_end:
            accepted = False
            at_end = False
            truncated = False
            h_used = h
            while not accepted:
                h_ctrl = h
                truncated = t + h > t_end
                if truncated:
                    h = t_end - t
                if step_collapsed(h, t):
                    if step_collapsed(t_end - t, t):
                        at_end = True  # within a few ulp of the end (see run_dop853)
                        h = h_ctrl
                    else:
                        failed = True
                    break
                for j in range(6):
                    K[0, j] = f0[j]
                # the step: stages 1-11, then row 12 (the order-8 weights) into y_new and f(y_new); int(): one
                # compiled _stages for every range (a literal would compile one for each)
                _stages(int(1), int(12), y, h, q, tab, K, tmp)
                _stages(int(12), int(13), y, h, q, tab, K, y_new)
                nf += 12
                err = dop853_error_norm(K, h, y, y_new, rtol, atol_vec, E3, E5)
                accepted, h_next = next_step(h, h_ctrl, err, rejected)  # Hairer's control (numerics.step_control)
                rejected = not accepted
                h_used = h
                h = h_next
            if failed:
                break
            if at_end:
                t = t_end
                break
            t_new = t_end if truncated else t + h_used
            if p == 0:
                steps0 += 1
            dense = False
            while k_out < n_out and sample_times[k_out] <= t_new:
                ts = sample_times[k_out]
                if ts == t_new:
                    for i in range(3):
                        out_r[k_out, p, i] = y_new[i]
                        out_v[k_out, p, i] = y_new[3 + i]
                else:
                    if not dense:  # the dense output's stages and coefficients, once a step (as run_dop853)
                        _stages(int(13), int(16), y, h_used, q, tab, K, tmp)
                        dense_coefficients(y, y_new, K, h_used, tab[18:22], F)
                        nf += 3
                        dense = True
                    x = (ts - t) / h_used
                    for i in range(3):
                        out_r[k_out, p, i] = dense_value(F, y, x, i)
                        out_v[k_out, p, i] = dense_value(F, y, x, 3 + i)
                k_out += 1
            finite = True
            for j in range(6):
                y[j] = y_new[j]
                f0[j] = K[12, j]
                if not math.isfinite(y[j]):
                    finite = False
            t = t_new
            if not finite:
                failed = True
                break
        if failed:
            if bad < 0:
                bad = p
            if k_out < n_done:
                n_done = k_out
        while k_out < n_out:
            for i in range(3):
                out_r[k_out, p, i] = y[i]
                out_v[k_out, p, i] = y[3 + i]
            k_out += 1
        for i in range(3):
            r[p, i] = y[i]
            v[p, i] = y[3 + i]
        h_state[p] = h
        if p == 0:
            nfev0 = nf
    return n_done, bad, nfev0, steps0
