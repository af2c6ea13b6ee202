"""Compiled steps of the rigid-body integrators (numba, ``cache=True``).

State: ``L`` (3,) angular momentum in principal body axes (kg m^2/s) and ``q``
(4,) the body -> space quaternion, scalar-last. ``inv_i`` holds ``1/I_i`` (0 for
a zero moment). A torque is a constant body part, a constant space part turned
into body axes by ``R(q)^T``, and the gravity torque ``mgl (z_b[1], -z_b[0], 0)``
of a heavy symmetric top (see [`rotframe.rigid.torqued.rigid_rhs`][rotframe.rigid.torqued.rigid_rhs]).

* `free_step`: the exact free flow of a symmetric body, or the 1,2,3,2,1
  Lie-Poisson splitting (McLachlan 1993).
* `split_run`: the Strang composition kick / free / kick over many steps.
* `euler_rhs`: Euler's equations plus quaternion kinematics.
* `euler_system`: the same as a system of the one DOP853 loop and the one RK4 step.
* `rk4_run`: classical RK4 (`rotframe.numerics.rk4`) on `euler_system`.
"""

from __future__ import annotations

from rotframe.numerics.compiled import jit_kernel, jit_llvm_inline

import math

import numpy as np
from numba import njit

from rotframe.numerics.rk4 import rk4_step
from rotframe.numerics.rotation import quat_mul, rodrigues_rotate

__all__ = ["free_step", "split_run", "body_torque", "euler_rates", "euler_rhs", "euler_system", "rk4_run"]

# error_model="numpy": a zero quaternion gives NaN, caught by the callers' finiteness checks
_jit_nan = jit_kernel


@njit(cache=True)
def _turn_about_axis(L, q, i, angle):
    """Exact rotation about body axis ``i``: ``L`` turns by ``-angle``, ``q <- q rot_i(angle)``.

    The rounded (cos, sin) pair has cos^2 + sin^2 = 1 + delta with a delta that
    is the same at every step when the angle is (a symmetric body at a fixed
    step), which would make |L| and the energy drift linearly in the number of
    steps. Rescaling the turned pair to its length before the turn (as a small
    increment, see below) leaves an error of random sign per step, so round-off grows like sqrt(N) (Brouwer's law).
    """
    j, k = (i + 1) % 3, (i + 2) % 3
    c, s = math.cos(angle), math.sin(angle)
    Lj, Lk = L[j], L[k]
    before = Lj * Lj + Lk * Lk
    # Rodrigues about the unit axis e_i by -angle: (nj, nk) = (c Lj + s Lk, -s Lj + c Lk)
    turned = rodrigues_rotate(L[0], L[1], L[2], 1.0 if i == 0 else 0.0, 1.0 if i == 1 else 0.0,
                              1.0 if i == 2 else 0.0, c, -s)
    nj, nk = turned[j], turned[k]
    after = nj * nj + nk * nk
    # first-order correction n (1 + (before - after) / (2 after)), applied as a small
    # increment: a factor near 1 would round with a bias (the doubles below 1 are
    # twice as dense as those above)
    corr = 0.5 * (before - after) / after if after > 0.0 else 0.0
    L[j] = nj + nj * corr
    L[k] = nk + nk * corr
    s_half = math.sin(0.5 * angle)  # the quaternion (s_half e_i, cos(angle / 2)) as scalars (no array)
    q[0], q[1], q[2], q[3] = quat_mul(q[0], q[1], q[2], q[3], s_half if i == 0 else 0.0,
                                      s_half if i == 1 else 0.0, s_half if i == 2 else 0.0,
                                      math.cos(0.5 * angle))


@njit(cache=True)
def free_step(L, q, tau, inv_i, sym):
    """Free flow over ``tau``: exact for a symmetric body, else the 1,2,3,2,1 splitting."""
    if sym >= 0:
        inv_p = inv_i[(sym + 1) % 3]
        norm_L = math.sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2])
        if norm_L > 0.0:  # |L|^2 / (2 Ip): rotation about L, L_body unchanged
            half = 0.5 * tau * norm_L * inv_p
            s_half = math.sin(half)  # the quaternion (sin(half) L / |L|, cos(half)) as scalars (no array)
            q[0], q[1], q[2], q[3] = quat_mul(q[0], q[1], q[2], q[3], s_half * L[0] / norm_L,
                                              s_half * L[1] / norm_L, s_half * L[2] / norm_L, math.cos(half))
        # 1/I_s - 1/I_p as (I_p - I_s) / (I_p I_s) (checks.check_inertia: the plain difference cancels)
        _turn_about_axis(L, q, sym, tau * L[sym] * (inv_i[3] if inv_i.shape[0] > 3 else inv_i[sym] - inv_p))
    else:
        # int(k), not the literal k: one compiled _turn_about_axis for every axis (a literal argument is a
        # type of its own, compiled apart)
        _turn_about_axis(L, q, int(0), 0.5 * tau * L[0] * inv_i[0])
        _turn_about_axis(L, q, int(1), 0.5 * tau * L[1] * inv_i[1])
        _turn_about_axis(L, q, int(2), tau * L[2] * inv_i[2])
        _turn_about_axis(L, q, int(1), 0.5 * tau * L[1] * inv_i[1])
        _turn_about_axis(L, q, int(0), 0.5 * tau * L[0] * inv_i[0])


@_jit_nan
def body_torque(x, y, z, w, mgl, nb0, nb1, nb2, ns0, ns1, ns2):
    """Body torque (3-tuple): constant body part ``nb``, ``R(q)^T ns`` and gravity.

    ``q = (x, y, z, w)`` is normalised here. Gravity: ``mgl (z_b[1], -z_b[0], 0)
    = l e3 x (-m g z_b)`` with ``z_b = R(q)^T (0, 0, 1)``, the third row of ``R(q)``
    (docs/physics/rigid-bodies.md). Without a space torque or gravity the rotation is skipped.
    """
    if mgl == 0.0 and ns0 == 0.0 and ns1 == 0.0 and ns2 == 0.0:
        return nb0, nb1, nb2
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    # rows of R(q): R^T v = (col_0 . v, col_1 . v, col_2 . v)
    r00, r01, r02 = 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)
    r10, r11, r12 = 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)
    r20, r21, r22 = 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)
    return (nb0 + (r00 * ns0 + r10 * ns1 + r20 * ns2 + mgl * r21),
            nb1 + (r01 * ns0 + r11 * ns1 + r21 * ns2 - mgl * r20),
            nb2 + (r02 * ns0 + r12 * ns1 + r22 * ns2))


@_jit_nan
def euler_rates(L0, L1, L2, x, y, z, w, i0, i1, i2, mgl, nb0, nb1, nb2, ns0, ns1, ns2):
    """Euler's equations and quaternion kinematics, the one right-hand side of the rigid layer.

    ``dL/dt = L x omega + N_body``, ``omega = L / I`` (``i0, i1, i2 = 1/I``, 0 for a
    zero moment), ``dq/dt = q * (omega, 0) / 2`` (Hamilton product, scalar-last,
    ``q`` not normalised), ``N_body`` from `body_torque`. Returns the 7-tuple
    ``(dL0, dL1, dL2, dx, dy, dz, dw)``. Used by `euler_rhs` (RK4,
    ``rigid_rhs``) and by the adaptive DOP853 of `rotframe.rigid.adaptive`.
    """
    o0, o1, o2 = L0 * i0, L1 * i1, L2 * i2
    t0, t1, t2 = body_torque(x, y, z, w, mgl, nb0, nb1, nb2, ns0, ns1, ns2)
    d0, d1, d2, d3 = quat_mul(x, y, z, w, o0, o1, o2, 0.0)
    return (L1 * o2 - L2 * o1 + t0, L2 * o0 - L0 * o2 + t1, L0 * o1 - L1 * o0 + t2,
            0.5 * d0, 0.5 * d1, 0.5 * d2, 0.5 * d3)


@njit(cache=True)
def _kick(L, q, c, mgl, torque_body, torque_space):
    """``L += c N_body(q)`` (``c`` = half the step) with `body_torque`, element by element.

    Scalars, not the array expression ``L += c * N``: the same operations, without
    numba's array machinery to compile on a first run.
    """
    tb, ts = torque_body, torque_space
    n0, n1, n2 = body_torque(q[0], q[1], q[2], q[3], mgl, tb[0], tb[1], tb[2], ts[0], ts[1], ts[2])
    L[0] += c * n0
    L[1] += c * n1
    L[2] += c * n2


@njit(cache=True)
def _store_row(out_L, out_q, k, L, q):
    """``out_L[k] = L``, ``out_q[k] = q`` element by element; whether all are finite.

    An array assigned to a row would compile numba's shape-mismatch message (2.6 s
    on a first run), and ``np.all(np.isfinite(...))`` numba's array ufunc machinery.
    """
    finite = True
    for i in range(3):
        out_L[k, i] = L[i]
        finite = finite and math.isfinite(L[i])
    for i in range(4):
        out_q[k, i] = q[i]
        finite = finite and math.isfinite(q[i])
    return finite


@njit(cache=True)
def split_run(inv_i, sym, mgl, torque_body, torque_space, L0, q0, h, n_steps, weights,
               sample_every, out_L, out_q):
    """Composition of Strang steps kick(tau/2) free(tau) kick(tau/2); returns samples kept."""
    L, q = L0.copy(), q0.copy()
    tb, ts = torque_body, torque_space  # scalar tests: np.any of an array comparison compiles 0.3 s more
    kick = (mgl != 0.0 or tb[0] != 0.0 or tb[1] != 0.0 or tb[2] != 0.0 or ts[0] != 0.0 or ts[1] != 0.0
            or ts[2] != 0.0)
    kept = int(0)  # int(), not a literal 0 or 1: one compiled _store_row for every row
    _store_row(out_L, out_q, kept, L, q)
    kept += 1
    for step in range(1, n_steps + 1):
        for w in weights:
            tau = w * h
            if kick:
                _kick(L, q, 0.5 * tau, mgl, torque_body, torque_space)
            free_step(L, q, tau, inv_i, sym)
            if kick:
                _kick(L, q, 0.5 * tau, mgl, torque_body, torque_space)
        norm_q = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
        for i in range(4):
            q[i] /= norm_q
        if step % sample_every == 0 or step == n_steps:
            if not _store_row(out_L, out_q, kept, L, q):
                return kept
            kept += 1
    return kept


@njit(cache=True)
def euler_rhs(y, inv_i, mgl, torque_body, torque_space):
    """`euler_rates` on the state ``y = (L_body, q)`` (7,); see ``rigid_rhs``."""
    tb, ts = torque_body, torque_space
    dy = np.empty(7)
    dy[0], dy[1], dy[2], dy[3], dy[4], dy[5], dy[6] = euler_rates(
        y[0], y[1], y[2], y[3], y[4], y[5], y[6], inv_i[0], inv_i[1], inv_i[2], mgl,
        tb[0], tb[1], tb[2], ts[0], ts[1], ts[2])
    return dy


@jit_llvm_inline
def euler_system(p, t, z, K, s):
    """``K[s] = f(z)``: `euler_rates` of ``z = (L_body, q)`` with ``p = (1/I1, 1/I2, 1/I3, mgl, Nb (3), Ns (3))``.

    The rigid body as a system of the one DOP853 loop and the one RK4 step (``rhs(ctx, t, z, K, s)``:
    `rotframe.numerics.dop853_loop`, `rotframe.numerics.rk4`; ``t`` unused, the torques are constant).
    """
    K[s, 0], K[s, 1], K[s, 2], K[s, 3], K[s, 4], K[s, 5], K[s, 6] = euler_rates(
        z[0], z[1], z[2], z[3], z[4], z[5], z[6], p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9])


#: the one RK4 step (`rotframe.numerics.rk4`) for the rigid body
_rk4_step = rk4_step("rigid", euler_system, 7)


@njit(cache=True)
def rk4_run(inv_i, mgl, torque_body, torque_space, L0, q0, h, n_steps, sample_every, out_L,
             out_q):
    """Classical RK4 (`rotframe.numerics.rk4`) on `euler_system`; returns samples kept."""
    p = np.empty(10)
    for i in range(3):
        p[i] = inv_i[i]
        p[4 + i] = torque_body[i]
        p[7 + i] = torque_space[i]
    p[3] = mgl
    y = np.empty(7)
    for i in range(3):
        y[i] = L0[i]
    for i in range(4):
        y[3 + i] = q0[i]
    K = np.empty((4, 7))
    yt = np.empty(7)
    yn = np.empty(7)
    kept = int(0)  # int(), not a literal 0 or 1: one compiled _store_row for every row
    _store_row(out_L, out_q, kept, L0, q0)
    kept += 1
    first = int(0)
    for step in range(1, n_steps + 1):
        euler_system(p, 0.0, y, K, first)
        _rk4_step(p, 0.0, y, h, K, yt, yn)
        for i in range(7):
            y[i] = yn[i]
        if step % sample_every == 0 or step == n_steps:
            if not _store_row(out_L, out_q, kept, y[:3], y[3:]):
                return kept
            kept += 1
    return kept
