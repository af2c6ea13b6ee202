"""DOP853 specialised to the steady models: three compiled functions instead of fourteen.

The general driver `rotframe.particles.drivers.run_dop853` handles every
term, rotation schedule and event, and a first run compiles it with its force,
step, schedule and event helpers in 3 to 4 s (numba's typing and lowering of
about fourteen functions). Most scenes that run DOP853 need much less:

- a **steady** rotation rate (``w`` constant, so no schedule and no Euler term);
- **uniform** gravity (a constant vector, or none);
- any of **Coriolis**, **centrifugal** and a **pendulum** string;
- no drag, no spring, no events.

For such a model `run_dop853_steady` is the same algorithm with the force
written in place: the same stages, error norm, step control, sample steps and
failure checks, in the same floating-point order, so that its results are
bitwise those of the general driver (``tests/test_dop853_steady.py`` checks
this on random models). It is three compiled functions instead of about
fourteen, and a first ``rotframe run foucault`` compiles for about 2.5 s instead of 3.3 to 4 s
on the 2-core machine (numba's own start, about 0.5 s, included).

`steady_parameters` packs the model for it; `is_steady_model` says
whether a model qualifies.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from rotframe.numerics.compiled import jit_internal, jit_kernel
from rotframe.numerics.dop853 import coefficients
from rotframe.numerics.step_control import first_step, first_step_trial, next_step, step_collapsed

__all__ = ["is_steady_model", "steady_parameters", "steady_tableau", "run_dop853_steady", "STEADY_TERMS"]

# The step-size control and the starting step are the shared ones (rotframe.numerics.step_control). The force
# (rotframe.particles.forces.state_acceleration, its string constraint included), the error norm
# (rotframe.numerics.dop853.dop853_error_norm) and the sample steps of the general
# driver (rotframe.particles.drivers.run_dop853) are written in place below, in the same order, rather than
# shared: calling the general force compiles the packed model and its helpers (what this driver exists to
# avoid), and sharing the others by numba's IR inlining (numerics.compiled.inlined) made a first run's
# compile 5 to 8 % more work, measured. tests/test_dop853_steady.py keeps the copies bitwise the same.

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
    """The DOP853 tableau as one (16, 13) array: rows 0-11 ``A``, 12 ``B``, 13 ``C``, 14 ``E3``, 15 ``E5``.

    The same floats as `rotframe.numerics.dop853.coefficients` (made once; read-only).
    """
    A, B, C, E3, E5 = coefficients()
    tab = np.zeros((16, 13))
    tab[:12, :12] = A
    tab[12, :12] = B
    tab[13, :12] = C
    tab[14] = E3
    tab[15] = E5
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
def _step(y, h, q, tab, K, y_new, tmp):
    """One DOP853 step of length h from y; ``K[0]`` holds f(y) on entry, ``K`` (13, 6) all stages on return."""
    for s in range(1, 13):
        last = s == 12
        for j in range(6):
            acc = 0.0
            if last:
                for p in range(12):
                    acc += tab[12, p] * K[p, j]
                y_new[j] = y[j] + h * acc
                tmp[j] = y_new[j]
            else:
                for p in range(s):
                    acc += tab[s, p] * K[p, j]
                tmp[j] = y[j] + h * acc
        K[s, 3], K[s, 4], K[s, 5] = _acceleration(tmp[0], tmp[1], tmp[2], tmp[3], tmp[4], tmp[5], q)
        K[s, 0] = tmp[3]
        K[s, 1] = tmp[4]
        K[s, 2] = tmp[5]


@jit_kernel
def run_dop853_steady(r, v, t0, sample_times, q, rtol, atol, span, tab, work, out_r, out_v, h_state):
    """Adaptive DOP853 for an ensemble under a steady model (see the module docstring).

    Parameters and results as `rotframe.particles.drivers.run_dop853`, with
    ``q`` from `steady_parameters`, ``tab`` from `steady_tableau` and
    ``work`` (32, 6) scratch from the caller. There are no events, so every
    particle stays alive. Returns ``(n_done, bad, nfev, steps)`` (cost of particle 0).
    """
    n = r.shape[0]
    n_out = sample_times.shape[0]
    K = work[0:13]
    Kt = work[13:26]
    y = work[26]
    y_new = work[27]
    yt = work[28]
    tmp = work[29]
    f0 = work[30]
    atol_vec = work[31]
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
                _step(y, h, q, tab, K, y_new, tmp)
                nf += 12
                # Hairer's error norm, as rotframe.numerics.dop853.dop853_error_norm (one atol for all six)
                e5 = 0.0
                e3 = 0.0
                for j in range(6):
                    a = y[j] if y[j] >= 0.0 else -y[j]
                    b = y_new[j] if y_new[j] >= 0.0 else -y_new[j]
                    sc = atol + rtol * (a if a >= b else b)
                    s5 = 0.0
                    s3 = 0.0
                    for i in range(13):
                        s5 += tab[15, i] * K[i, j]
                        s3 += tab[14, i] * K[i, j]
                    r5 = s5 / sc
                    r3 = s3 / sc
                    e5 += r5 * r5
                    e3 += r3 * r3
                if e5 == 0.0 and e3 == 0.0:
                    err = 0.0
                else:
                    err = (h if h >= 0.0 else -h) * e5 / math.sqrt((e5 + 0.01 * e3) * 6)
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
            while k_out < n_out and sample_times[k_out] <= t_new:
                ts = sample_times[k_out]
                if ts == t_new:
                    for i in range(3):
                        out_r[k_out, p, i] = y_new[i]
                        out_v[k_out, p, i] = y_new[3 + i]
                else:
                    for j in range(6):
                        Kt[0, j] = f0[j]
                    _step(y, ts - t, q, tab, Kt, yt, tmp)
                    nf += 12
                    for i in range(3):
                        out_r[k_out, p, i] = yt[i]
                        out_v[k_out, p, i] = yt[3 + i]
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
