"""The exact free asymmetric rigid body in one compiled call (the fast path of ``rigid.free_body_exact``).

[`rotframe.rigid.free_body.free_body_closed_form`][rotframe.rigid.free_body.free_body_closed_form] evaluates the closed-form motion (Jacobi
elliptic functions for the momentum, Carlson's integrals for the angle about
``L``; docs/physics.md, rigid bodies) with numpy and scipy on arrays: right for
many time points, but a few hundred microseconds of setup and small-array calls
for one. [`flow_into`][rotframe.rigid.exact_flow.flow_into] computes the same formulas, setup included, in
one numba function: the ordered frame, ``K(m)`` by the arithmetic-geometric
mean (A&S 17.6), ``R_F``, ``R_J``, ``R_C`` by Carlson's duplication algorithm
(Carlson 1995, Numer. Algorithms 10, 13) and ``sn, cn, dn`` by descending Landen
transformations, all from [`rotframe.rigid.elliptic`][rotframe.rigid.elliptic], and the attitude as the product
``q = S0 Rz(psi) Ry(-theta) Rz(-phi) P``. Symmetric bodies, the separatrix,
rotation about the middle axis and ``L = 0`` are left to ``free_body_closed_form``;
[`rotframe.rigid.free_body.free_body_exact`][rotframe.rigid.free_body.free_body_exact] (the public door) tries this
path first and falls back to it.
"""

from __future__ import annotations

from rotframe.numerics.compiled import jit_kernel

import math

import numpy as np

from rotframe.numerics.rotation import quat_mul
from rotframe.rigid.elliptic import carlson_rf, ellipk_agm, incomplete_pi, jacobi_reduced

__all__ = ["flow_into", "flow_ready"]

_jit = jit_kernel


@_jit
def _matrix_quat(P):
    """Unit quaternion (scalar-last) of a rotation matrix (Shepperd's method)."""
    tr = P[0, 0] + P[1, 1] + P[2, 2]
    if tr > 0.0:
        s = 2.0 * math.sqrt(tr + 1.0)
        return (P[2, 1] - P[1, 2]) / s, (P[0, 2] - P[2, 0]) / s, (P[1, 0] - P[0, 1]) / s, 0.25 * s
    if P[0, 0] > P[1, 1] and P[0, 0] > P[2, 2]:
        s = 2.0 * math.sqrt(1.0 + P[0, 0] - P[1, 1] - P[2, 2])
        return 0.25 * s, (P[0, 1] + P[1, 0]) / s, (P[0, 2] + P[2, 0]) / s, (P[2, 1] - P[1, 2]) / s
    if P[1, 1] > P[2, 2]:
        s = 2.0 * math.sqrt(1.0 + P[1, 1] - P[0, 0] - P[2, 2])
        return (P[0, 1] + P[1, 0]) / s, 0.25 * s, (P[1, 2] + P[2, 1]) / s, (P[0, 2] - P[2, 0]) / s
    s = 2.0 * math.sqrt(1.0 + P[2, 2] - P[0, 0] - P[1, 1])
    return (P[0, 2] + P[2, 0]) / s, (P[1, 2] + P[2, 1]) / s, 0.25 * s, (P[1, 0] - P[0, 1]) / s


@_jit
def _wrap(x):
    return (x + math.pi) % (2.0 * math.pi) - math.pi


@_jit
def _flow(moments, L0, q0, t, out_L, out_q):
    """The asymmetric free body at times t; returns False where the fast path does not apply.

    Input checks (else False, and the caller asks free_body_exact, which raises
    or handles the case): moments > 0 obeying the triangle inequality, finite
    L0 and t, a finite non-zero q0 (normalised here).
    """
    for i in range(3):
        if not (moments[i] > 0.0 and np.isfinite(moments[i]) and np.isfinite(L0[i])):
            return False
    if 2.0 * max(moments[0], moments[1], moments[2]) > moments[0] + moments[1] + moments[2]:
        return False
    for i in range(t.shape[0]):
        if not np.isfinite(t[i]):
            return False
    nq = math.sqrt(q0[0] ** 2 + q0[1] ** 2 + q0[2] ** 2 + q0[3] ** 2)
    if not (nq > 0.0 and np.isfinite(nq)):
        return False
    q0 = q0 / nq
    # ordered frame (free_body._elliptic_frame)
    order = np.argsort(moments, kind="mergesort")
    P = np.zeros((3, 3))
    for i in range(3):
        P[i, order[i]] = 1.0
    if np.linalg.det(P) < 0.0:
        P[1] = -P[1]
    J = np.empty(3)
    for i in range(3):
        J[i] = moments[order[i]]
    if J[0] == J[1] or J[1] == J[2]:
        return False
    norm_L = math.sqrt(L0[0] ** 2 + L0[1] ** 2 + L0[2] ** 2)
    if norm_L == 0.0:
        return False
    J_max = J[2]
    n = P @ L0 / norm_L
    s = max(abs(n[0]), abs(n[2]))
    if s == 0.0:
        return False
    D_s = (J[2] - J[1]) / J[2] * (n[2] / s) ** 2 - (J[1] - J[0]) / J[0] * (n[0] / s) ** 2
    if D_s == 0.0:
        return False  # the separatrix: free_body_exact's closed form in tanh and sech
    if D_s < 0.0:
        swap = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])
        P = swap @ P
        J = J[::-1].copy()
    if (P @ L0)[2] < 0.0:
        P[1] = -P[1]
        P[2] = -P[2]
    L = P @ L0
    n = L / norm_L
    J1, J2, J3 = J[0] / J_max, J[1] / J_max, J[2] / J_max
    A = (J3 - J1) * n[0] ** 2 / J1 + (J3 - J2) * n[1] ** 2 / J2
    B = (J2 - J1) * n[1] ** 2 / J2 + (J3 - J1) * n[2] ** 2 / J3
    amp0 = norm_L * math.sqrt(J1 * A / (J3 - J1))
    amp1 = norm_L * math.sqrt(J2 * A / (J3 - J2))
    amp2 = norm_L * math.sqrt(J3 * B / (J3 - J1))
    lam = norm_L / J_max * math.sqrt((J3 - J2) * B / (J1 * J2 * J3))
    m = (J2 - J1) * A / ((J3 - J2) * B)
    m1 = max((J3 - J1) * D_s * s * s / ((J3 - J2) * B), 1e-300)
    nu = -J3 * (J2 - J1) / (J1 * (J3 - J2))
    K = ellipk_agm(m1)
    Pic = incomplete_pi(1.0, 0.0, math.sqrt(m1), nu)
    sigma = 1.0 if J3 > J1 else -1.0
    ratio = math.sqrt(J2 * (J3 - J1) / (J1 * (J3 - J2)))
    # u0 from the initial state (free_body._free_asymmetric)
    s0, c0 = sigma * L[1] / ratio, L[0]
    hyp = math.hypot(s0, c0)
    if hyp > 0.0:
        s0, c0 = s0 / hyp, c0 / hyp
    else:
        s0, c0 = 0.0, 1.0
    G = abs(s0) * carlson_rf(c0 * c0, c0 * c0 + m1 * s0 * s0, 1.0)
    u0 = math.copysign(G if c0 >= 0.0 else 2.0 * K - G, s0)
    nt = t.shape[0]
    u = np.empty(nt + 1)
    u[0] = u0
    for i in range(nt):
        u[i + 1] = u0 + lam * t[i]
    sn_w, cn_w, dn_w, sgn, refl, jj = jacobi_reduced(u, m, m1, K)
    pq0, pq1, pq2, pq3 = _matrix_quat(P)
    S0 = (0.0, 0.0, 0.0, 1.0)
    Pi0 = 0.0
    for i in range(nt + 1):
        G = incomplete_pi(sn_w[i], cn_w[i], dn_w[i], nu)
        sn = sgn[i] * sn_w[i]
        cn = -cn_w[i] if refl[i] else cn_w[i]
        dn = dn_w[i]
        am_w = math.atan2(sn_w[i], cn_w[i])
        am = sgn[i] * (math.pi - am_w if refl[i] else am_w) + 2.0 * math.pi * jj[i]
        Pi = sgn[i] * (2.0 * Pic - G if refl[i] else G) + 4.0 * Pic * jj[i]
        l0, l1, l2 = amp0 * cn, sigma * amp1 * sn, amp2 * dn
        theta = math.atan2(math.hypot(l0, l1), l2)
        az = math.atan2(sigma * ratio * sn, cn)
        phi = sigma * am + _wrap(az - sigma * am)
        if i == 0:
            Pi0 = Pi
            # S0 = q0 P^-1 Rz(phi0) Ry(theta0)
            a = quat_mul(q0[0], q0[1], q0[2], q0[3], -pq0, -pq1, -pq2, pq3)
            a = quat_mul(a[0], a[1], a[2], a[3], 0.0, 0.0, math.sin(0.5 * phi), math.cos(0.5 * phi))
            S0 = quat_mul(a[0], a[1], a[2], a[3], 0.0, math.sin(0.5 * theta), 0.0, math.cos(0.5 * theta))
            continue
        k = i - 1
        psi = norm_L / J[2] * (t[k] + (J[2] - J[0]) / (J[0] * lam) * (Pi - Pi0))
        a = quat_mul(S0[0], S0[1], S0[2], S0[3], 0.0, 0.0, math.sin(0.5 * psi), math.cos(0.5 * psi))
        a = quat_mul(a[0], a[1], a[2], a[3], 0.0, -math.sin(0.5 * theta), 0.0, math.cos(0.5 * theta))
        a = quat_mul(a[0], a[1], a[2], a[3], 0.0, 0.0, -math.sin(0.5 * phi), math.cos(0.5 * phi))
        a = quat_mul(a[0], a[1], a[2], a[3], pq0, pq1, pq2, pq3)
        for j in range(4):
            out_q[k, j] = a[j]
        for j in range(3):  # ordered -> body: P^T L
            out_L[k, j] = P[0, j] * l0 + P[1, j] * l1 + P[2, j] * l2
    return True


def flow_ready() -> bool:
    """Whether the compiled flow runs without compiling: loaded in this process, or in numba's disk cache.

    Compiling it costs a first run seconds (about 8 s on a 2-core machine, the elliptic
    routines with it), more than the scenes' whole first run; so
    [`rotframe.rigid.free_body.free_body_exact`][rotframe.rigid.free_body.free_body_exact] takes this path only where it is ready
    (a call of [`flow_into`][rotframe.rigid.exact_flow.flow_into] compiles and caches it, as ``rotframe bench`` does).
    """
    if _flow.overloads:
        return True
    if not _ON_DISK:  # read numba's index once a process (empty when missing or stale)
        try:
            _ON_DISK.append(bool(_flow._cache._cache_file._load_index()))
        except Exception:  # noqa: BLE001 -- no cache, or another numba: treat as not ready
            _ON_DISK.append(False)
    return _ON_DISK[0]


_ON_DISK: list = []  # whether numba's disk cache holds the flow, read once


def flow_into(inertia, L0_body, q0, times):
    """The exact torque-free motion at ``times`` by the compiled closed form, or None where it does not apply.

    The fast path of [`rotframe.rigid.free_body.free_body_exact`][rotframe.rigid.free_body.free_body_exact] (which calls it
    first): the asymmetric body, valid input, ``times`` 1-D. None for two equal moments,
    the separatrix, rotation about the middle axis, ``L = 0``, a zero moment and invalid
    input, which ``free_body_exact`` evaluates (or refuses) itself.

    Returns
    -------
    (L_body (n, 3), q (n, 4)) or None
    """
    try:
        t = np.atleast_1d(np.asarray(times, dtype=np.float64))
        moments = np.asarray(inertia, dtype=np.float64)
        L0 = np.asarray(L0_body, dtype=np.float64)
        q = np.asarray(q0, dtype=np.float64)
    except (TypeError, ValueError):  # text, complex: free_body_exact's checks say what is wrong
        return None
    if t.ndim == 1 and moments.shape == (3,) and L0.shape == (3,) and q.shape == (4,):
        out_L = np.empty((t.size, 3))
        out_q = np.empty((t.size, 4))
        if _flow(moments, L0, q, t, out_L, out_q):
            return out_L, out_q
    return None
