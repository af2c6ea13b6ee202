"""Hand-written loops that set the ceiling for ensemble throughput (``rotframe bench ensemble``).

Gravity + constant Coriolis, every particle's state in registers, written out by
hand: once on one core (``serial``), once with ``prange`` over particles on all
(``parallel``). Two methods:

- the exact-rotation splitting (Strang: half drift, half kick, exact rotation
  of the velocity by ``-2 |w| h`` about ``w``, half kick, half drift);
- classical RK4 on ``a = g - 2 w x v``;
- adaptive DOP853 (`dop853_serial`, `dop853_parallel`) with Hairer's
  error control and step-size rule as rotframe's (so the same steps), from
  ``t = 0`` to ``T``, the stages in arrays of the particle's own.

Each with and without the ground event: after every step the event test
``z_old > 0 and z <= 0`` (a falling crossing of z = 0), stopping the particle
when it fires, as rotframe's ``Event("ground", "r", 2, 0.0, -1, True)``. The
bench starts every particle high enough that none lands, so the event code
runs its test every step and never its location: the same work as rotframe's.

Arguments: ``r, v`` (N, 3) updated in place, ``g`` (3,), ``w`` (3,) the rotation
vector, ``c, s`` cos and sin of the splitting's rotation angle, ``h``, ``steps``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from rotframe.numerics.step_control import first_step, first_step_trial, next_step

__all__ = ["serial", "parallel", "dop853_serial", "dop853_parallel", "rotation_cos_sin", "KINDS"]

_inl = njit(inline="always", error_model="numpy")


@_inl
def _splitting(x, y, z, vx, vy, vz, g, ax, ay, az, c, s, hh):
    x += hh * vx
    y += hh * vy
    z += hh * vz
    vx += hh * g[0]
    vy += hh * g[1]
    vz += hh * g[2]
    d = ax * vx + ay * vy + az * vz
    cx = ay * vz - az * vy
    cy = az * vx - ax * vz
    cz = ax * vy - ay * vx
    vx, vy, vz = (vx * c + cx * s + ax * d * (1 - c), vy * c + cy * s + ay * d * (1 - c),
                  vz * c + cz * s + az * d * (1 - c))
    vx += hh * g[0]
    vy += hh * g[1]
    vz += hh * g[2]
    x += hh * vx
    y += hh * vy
    z += hh * vz
    return x, y, z, vx, vy, vz


@_inl
def _acc(vx, vy, vz, g, wx, wy, wz):
    return (g[0] - 2.0 * (wy * vz - wz * vy), g[1] - 2.0 * (wz * vx - wx * vz), g[2] - 2.0 * (wx * vy - wy * vx))


@_inl
def _rk4(x, y, z, vx, vy, vz, g, wx, wy, wz, h):
    hh = 0.5 * h
    a1x, a1y, a1z = _acc(vx, vy, vz, g, wx, wy, wz)
    v2x, v2y, v2z = vx + hh * a1x, vy + hh * a1y, vz + hh * a1z
    a2x, a2y, a2z = _acc(v2x, v2y, v2z, g, wx, wy, wz)
    v3x, v3y, v3z = vx + hh * a2x, vy + hh * a2y, vz + hh * a2z
    a3x, a3y, a3z = _acc(v3x, v3y, v3z, g, wx, wy, wz)
    v4x, v4y, v4z = vx + h * a3x, vy + h * a3y, vz + h * a3z
    a4x, a4y, a4z = _acc(v4x, v4y, v4z, g, wx, wy, wz)
    h6 = h / 6.0
    return (x + h6 * (vx + 2.0 * v2x + 2.0 * v3x + v4x), y + h6 * (vy + 2.0 * v2y + 2.0 * v3y + v4y),
            z + h6 * (vz + 2.0 * v2z + 2.0 * v3z + v4z), vx + h6 * (a1x + 2.0 * a2x + 2.0 * a3x + a4x),
            vy + h6 * (a1y + 2.0 * a2y + 2.0 * a3y + a4y), vz + h6 * (a1z + 2.0 * a2z + 2.0 * a3z + a4z))


@_inl
def _particle(r, v, g, w, c, s, h, steps, p, rk4, ground):
    wn = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    ax, ay, az = w[0] / wn, w[1] / wn, w[2] / wn
    hh = 0.5 * h
    x, y, z = r[p, 0], r[p, 1], r[p, 2]
    vx, vy, vz = v[p, 0], v[p, 1], v[p, 2]
    for _ in range(steps):
        z_old = z
        if rk4:
            x, y, z, vx, vy, vz = _rk4(x, y, z, vx, vy, vz, g, w[0], w[1], w[2], h)
        else:
            x, y, z, vx, vy, vz = _splitting(x, y, z, vx, vy, vz, g, ax, ay, az, c, s, hh)
        if ground and z_old > 0.0 and z <= 0.0:
            break
    r[p, 0], r[p, 1], r[p, 2] = x, y, z
    v[p, 0], v[p, 1], v[p, 2] = vx, vy, vz


# one compiled loop per method and event flag, so that the flags are constants in each (as rotframe's
# drivers prune what a run does not use): the ceiling carries no branch that the work does not need
_VARIANTS = {}


def _variants():
    if _VARIANTS:
        return _VARIANTS

    @njit(cache=True, error_model="numpy")
    def serial_split(r, v, g, w, c, s, h, steps):
        for p in range(r.shape[0]):
            _particle(r, v, g, w, c, s, h, steps, p, False, False)

    @njit(cache=True, error_model="numpy")
    def serial_split_ground(r, v, g, w, c, s, h, steps):
        for p in range(r.shape[0]):
            _particle(r, v, g, w, c, s, h, steps, p, False, True)

    @njit(cache=True, error_model="numpy")
    def serial_rk4(r, v, g, w, c, s, h, steps):
        for p in range(r.shape[0]):
            _particle(r, v, g, w, c, s, h, steps, p, True, False)

    @njit(cache=True, error_model="numpy")
    def serial_rk4_ground(r, v, g, w, c, s, h, steps):
        for p in range(r.shape[0]):
            _particle(r, v, g, w, c, s, h, steps, p, True, True)

    @njit(cache=True, error_model="numpy", parallel=True)
    def parallel_split(r, v, g, w, c, s, h, steps):
        for p in prange(r.shape[0]):
            _particle(r, v, g, w, c, s, h, steps, p, False, False)

    @njit(cache=True, error_model="numpy", parallel=True)
    def parallel_split_ground(r, v, g, w, c, s, h, steps):
        for p in prange(r.shape[0]):
            _particle(r, v, g, w, c, s, h, steps, p, False, True)

    @njit(cache=True, error_model="numpy", parallel=True)
    def parallel_rk4(r, v, g, w, c, s, h, steps):
        for p in prange(r.shape[0]):
            _particle(r, v, g, w, c, s, h, steps, p, True, False)

    @njit(cache=True, error_model="numpy", parallel=True)
    def parallel_rk4_ground(r, v, g, w, c, s, h, steps):
        for p in prange(r.shape[0]):
            _particle(r, v, g, w, c, s, h, steps, p, True, True)

    _VARIANTS.update({(False, False, False): serial_split, (False, False, True): serial_split_ground,
                      (False, True, False): serial_rk4, (False, True, True): serial_rk4_ground,
                      (True, False, False): parallel_split, (True, False, True): parallel_split_ground,
                      (True, True, False): parallel_rk4, (True, True, True): parallel_rk4_ground})
    return _VARIANTS


def serial(r, v, g, w, c, s, h, steps, rk4, ground):
    """All particles on one core (RK4 or the splitting; watching the ground or not)."""
    _variants()[(False, bool(rk4), bool(ground))](r, v, g, w, c, s, h, steps)


def parallel(r, v, g, w, c, s, h, steps, rk4, ground):
    """Particles spread over numba's threads with ``prange``."""
    _variants()[(True, bool(rk4), bool(ground))](r, v, g, w, c, s, h, steps)


def rotation_cos_sin(w, h):
    """cos and sin of the splitting's Coriolis rotation angle ``-2 |w| h``."""
    angle = -2.0 * math.sqrt(sum(float(x) * float(x) for x in w)) * h
    return math.cos(angle), math.sin(angle)


#: (name, rotframe method, rk4 flag) of the hand-written methods
KINDS = (("rotation-splitting", "rotation-splitting", False), ("rk4", "rk4", True))


@_inl
def _dop_stage_f(y, g, w, K, s):
    ax, ay, az = _acc(y[3], y[4], y[5], g, w[0], w[1], w[2])
    K[s, 0], K[s, 1], K[s, 2], K[s, 3], K[s, 4], K[s, 5] = y[3], y[4], y[5], ax, ay, az


@_inl
def _dop_particle(r, v, p, g, w, tab, rtol, atol, T, ground):
    """One particle by DOP853 from 0 to T (or its ground crossing); its accepted steps.

    rotframe's step control and starting step (`rotframe.numerics.step_control`, a few scalar
    operations each), so that it takes the same steps as the drivers it bounds.
    """
    K = np.empty((13, 6))
    y = np.empty(6)
    y_new = np.empty(6)
    tmp = np.empty(6)
    atol_vec = np.full(6, atol)
    for i in range(3):
        y[i] = r[p, i]
        y[3 + i] = v[p, i]
    _dop_stage_f(y, g, w, K, 0)
    h0 = first_step_trial(y, K[0], rtol, atol_vec, T)
    for j in range(6):
        tmp[j] = y[j] + h0 * K[0, j]
    _dop_stage_f(tmp, g, w, K, 1)
    h = first_step(y, K[0], K[1], h0, rtol, atol_vec, T)
    t = 0.0
    steps = 0
    rejected = False
    while t < T:
        h_ctrl = h
        truncated = t + h > T
        if truncated:
            h = T - t
        for s in range(1, 13):
            for j in range(6):
                acc = 0.0
                if s == 12:
                    for q in range(12):
                        acc += tab[12, q] * K[q, j]
                    y_new[j] = y[j] + h * acc
                else:
                    for q in range(s):
                        acc += tab[s, q] * K[q, j]
                    tmp[j] = y[j] + h * acc
            _dop_stage_f(y_new if s == 12 else tmp, g, w, K, s)
        e5 = 0.0
        e3 = 0.0
        for j in range(6):
            sc = atol + rtol * max(abs(y[j]), abs(y_new[j]))
            s5 = 0.0
            s3 = 0.0
            for i in range(13):
                s5 += tab[15, i] * K[i, j]
                s3 += tab[14, i] * K[i, j]
            e5 += (s5 / sc) ** 2
            e3 += (s3 / sc) ** 2
        err = 0.0 if e5 == 0.0 and e3 == 0.0 else abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * 6)
        accepted, h_next = next_step(h, h_ctrl, err, rejected)
        rejected = not accepted
        if accepted:
            z_old = y[2]
            t = T if truncated else t + h
            steps += 1
            for j in range(6):
                y[j] = y_new[j]
                K[0, j] = K[12, j]
            if ground and z_old > 0.0 and y[2] <= 0.0:
                break
        h = h_next
    for i in range(3):
        r[p, i] = y[i]
        v[p, i] = y[3 + i]
    return steps


@njit(cache=True, error_model="numpy")
def dop853_serial(r, v, g, w, tab, rtol, atol, T, ground, steps):
    """All particles by DOP853 on one core; ``steps`` (N,) receives each one's accepted steps."""
    for p in range(r.shape[0]):
        steps[p] = _dop_particle(r, v, p, g, w, tab, rtol, atol, T, ground)


@njit(cache=True, error_model="numpy", parallel=True)
def dop853_parallel(r, v, g, w, tab, rtol, atol, T, ground, steps):
    """`dop853_serial` with ``prange`` over particles."""
    for p in prange(r.shape[0]):
        steps[p] = _dop_particle(r, v, p, g, w, tab, rtol, atol, T, ground)
