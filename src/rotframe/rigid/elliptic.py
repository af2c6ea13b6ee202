"""Jacobi elliptic functions and Carlson's symmetric integrals, one source for the rigid layer.

* [`jacobi_reduced`][rotframe.rigid.elliptic.jacobi_reduced] (with [`sncndn_landen`][rotframe.rigid.elliptic.sncndn_landen], [`complete_pair`][rotframe.rigid.elliptic.complete_pair]):
  ``sn, cn, dn(u | m)`` with ``m1 = 1 - m`` supplied exactly, by reduction modulo
  ``4K`` (A&S 16.8) and descending Landen transformations (A&S 16.12-16.13); keeps
  relative accuracy near the separatrix ``m -> 1``, where ``scipy.special.ellipj``
  does not (scipy issue 8480). [`jacobi_reduced_into`][rotframe.rigid.elliptic.jacobi_reduced_into] fills given arrays and
  [`jacobi_reduced_arrays`][rotframe.rigid.elliptic.jacobi_reduced_arrays] is its numpy-allocating front for Python callers (a first
  run then compiles no array allocation).
* [`carlson_rf`][rotframe.rigid.elliptic.carlson_rf], [`carlson_rj`][rotframe.rigid.elliptic.carlson_rj], [`carlson_rc`][rotframe.rigid.elliptic.carlson_rc]: Carlson's duplication
  algorithm (Carlson 1995, Numer. Algorithms 10, 13; DLMF 19.16), compiled.
* [`ellipk_agm`][rotframe.rigid.elliptic.ellipk_agm]: the complete ``K(m)`` from ``m1`` by the arithmetic-geometric mean (A&S 17.6).
* [`incomplete_pi`][rotframe.rigid.elliptic.incomplete_pi] (compiled, scalars) and [`incomplete_pi_arrays`][rotframe.rigid.elliptic.incomplete_pi_arrays] (scipy's
  ``elliprf``/``elliprj``, arrays): the incomplete integral of the third kind
  ``Pi(nu; am | m) = s R_F(c^2, d^2, 1) + nu/3 s^3 R_J(c^2, d^2, 1, 1 - nu s^2)``
  from ``s = sin am``, ``c = |cos am|``, ``d = dn`` (A&S 17.2; DLMF 19.25.14).

All functions are pure, float64, no I/O. The formulas are written out in
``docs/physics/rigid-bodies.md``.
"""

from __future__ import annotations

from rotframe.numerics.compiled import jit_kernel

import math

import numpy as np
from numba import njit
from scipy import special

__all__ = [
    "jacobi_reduced",
    "jacobi_reduced_into",
    "jacobi_reduced_arrays",
    "sncndn_landen",
    "complete_pair",
    "carlson_rf",
    "carlson_rj",
    "carlson_rc",
    "ellipk_agm",
    "incomplete_pi",
    "incomplete_pi_arrays",
]

_jit = jit_kernel
# duplication stops when every relative deviation is below this: the truncated series then errs
# by about ERRTOL^6 / 4 ~ 1e-19 relative (Carlson 1995, eq. 2.2)
_ERRTOL = 0.0008


@njit(cache=True)
def sncndn_landen(u, m, m1, ks, kps):
    """sn, cn, dn(u | m) by descending Landen transformations (A&S 16.12-16.13).

    Moduli are carried in pairs without cancellation, ``k_{n+1} = k_n^2 / (1 + k'_n)^2``
    and ``k'_{n+1} = 2 sqrt(k'_n) / (1 + k'_n)``, starting from ``k = sqrt(m)``,
    ``k' = sqrt(m1)`` (``m1 = 1 - m`` supplied exactly), until ``k^2 < 1e-18``,
    where ``sn = sin v - k^2/4 (v - sin v cos v) cos v`` (16.13). Going back up,
    ``sn_n = (1 + k) sn / (1 + k sn^2)``, ``cn_n = cn dn / (1 + k sn^2)`` and
    ``dn = sqrt(cn^2 + k'^2 sn^2)`` are ratios and sums of positive terms, and at
    each level the larger of ``sn, cn`` is recomputed from the smaller, so both
    keep their relative accuracy for ``u`` in ``[0, K/2]`` (unlike the AGM's
    arcsine recursion, whose argument nears 1 when ``m -> 1``). ``ks``, ``kps``: scratch
    arrays of 48 for the moduli, from the caller (which allocates them once for many calls).
    """
    k, kp = math.sqrt(m), math.sqrt(m1)
    v = u
    n = 0
    while k * k >= 1e-18 and n < 48:
        k, kp = k * k / ((1.0 + kp) * (1.0 + kp)), 2.0 * math.sqrt(kp) / (1.0 + kp)
        ks[n], kps[n] = k, kp
        v /= 1.0 + k
        n += 1
    mu = k * k
    s0, c0 = math.sin(v), math.cos(v)
    corr = 0.25 * mu * (v - s0 * c0)
    s, c = complete_pair(s0 - corr * c0, c0 + corr * s0)
    for i in range(n - 1, -1, -1):
        k, kp = ks[i], kps[i]
        d = math.sqrt(c * c + kp * kp * s * s)
        den = 1.0 + k * s * s
        s, c = complete_pair((1.0 + k) * s / den, c * d / den)
    return s, c, math.sqrt(c * c + m1 * s * s)


@njit(cache=True)
def complete_pair(s, c):
    """Recompute the larger of ``sn, cn >= 0`` from the smaller, ``sn^2 + cn^2 = 1``.

    ``sqrt((1 - x)(1 + x))`` of the smaller one is accurate to an ulp, whereas a
    value near 1 carried through the recurrence keeps only absolute accuracy
    (``1 - cn`` would lose its digits at small ``u``).
    """
    if s < c:
        return s, math.sqrt((1.0 - s) * (1.0 + s))
    return math.sqrt((1.0 - c) * (1.0 + c)), c


@njit(cache=True)
def jacobi_reduced(u, m, m1, K):
    """Reduce ``u`` and evaluate sn, cn, dn on ``[0, K]``.

    Returns ``sn_w, cn_w, dn_w`` at ``w in [0, K]``, the sign ``sgn`` of the
    reduced argument, whether ``w = 2K - |ur|`` (``refl``) and the period count
    ``j`` (``u = ur + 4K j``): the arrays [`jacobi_reduced_into`][rotframe.rigid.elliptic.jacobi_reduced_into] fills.
    """
    n = u.size
    sn_w, cn_w, dn_w = np.empty(n), np.empty(n), np.empty(n)
    sgn, refl, jj = np.empty(n), np.empty(n, dtype=np.bool_), np.empty(n)
    jacobi_reduced_into(u, m, m1, K, sn_w, cn_w, dn_w, sgn, refl, jj, np.empty(48), np.empty(48))
    return sn_w, cn_w, dn_w, sgn, refl, jj


def jacobi_reduced_arrays(u, m, m1, K):
    """[`jacobi_reduced`][rotframe.rigid.elliptic.jacobi_reduced] from Python: the arrays allocated by numpy, so that a first run
    compiles only [`jacobi_reduced_into`][rotframe.rigid.elliptic.jacobi_reduced_into] and [`sncndn_landen`][rotframe.rigid.elliptic.sncndn_landen] (no allocation)."""
    n = u.size
    sn_w, cn_w, dn_w = np.empty(n), np.empty(n), np.empty(n)
    sgn, refl, jj = np.empty(n), np.empty(n, dtype=np.bool_), np.empty(n)
    jacobi_reduced_into(np.ascontiguousarray(u, dtype=np.float64), float(m), float(m1), float(K), sn_w, cn_w,
                        dn_w, sgn, refl, jj, np.empty(48), np.empty(48))
    return sn_w, cn_w, dn_w, sgn, refl, jj


@njit(cache=True)
def jacobi_reduced_into(u, m, m1, K, sn_w, cn_w, dn_w, sgn, refl, jj, ks, kps):
    """[`jacobi_reduced`][rotframe.rigid.elliptic.jacobi_reduced] into given arrays (``ks``, ``kps``: scratch of 48 for [`sncndn_landen`][rotframe.rigid.elliptic.sncndn_landen]).

    On ``[K/2, K]`` the quarter-period shift
    ``sn(K - v) = cn v / dn v``, ``cn(K - v) = k' sn v / dn v``,
    ``dn(K - v) = k' / dn v`` (A&S 16.8.2) keeps relative accuracy near ``K``.
    """
    n = u.size
    kp = math.sqrt(m1)
    period = 4.0 * K
    for i in range(n):
        ur = np.fmod(u[i], period)  # exact remainder, then into [-2K, 2K]
        if ur > 2.0 * K:
            ur -= period
        elif ur < -2.0 * K:
            ur += period
        j = (u[i] - ur) / period  # a whole number up to rounding: round half to even, as np.round, whose
        if abs(j) < 4503599627370496.0:  # compiled version costs a first run 0.3 s; from 2^52 on (and
            j = float(round(j))  # inf, nan) j is its own rounding
        sgn[i] = 1.0 if ur >= 0.0 else -1.0
        v = abs(ur)
        refl[i] = v > K
        w = 2.0 * K - v if refl[i] else v
        if w <= 0.5 * K:
            s, c, d = sncndn_landen(w, m, m1, ks, kps)
        else:
            s1, c1, d1 = sncndn_landen(K - w, m, m1, ks, kps)
            s, c, d = c1 / d1, kp * s1 / d1, kp / d1
        sn_w[i], cn_w[i], dn_w[i], jj[i] = s, c, d, j


@_jit
def carlson_rf(x, y, z):
    """Carlson's R_F(x, y, z), x, y, z >= 0, at most one zero (DLMF 19.16.1)."""
    for _ in range(100):
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * (sy + sz) + sy * sz
        x, y, z = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)
        ave = (x + y + z) / 3.0
        dx, dy, dz = (ave - x) / ave, (ave - y) / ave, (ave - z) / ave
        if max(abs(dx), abs(dy), abs(dz)) <= _ERRTOL:
            break
    e2 = dx * dy - dz * dz
    e3 = dx * dy * dz
    return (1.0 + (e2 / 24.0 - 0.1 - 3.0 / 44.0 * e3) * e2 + e3 / 14.0) / math.sqrt(ave)


@_jit
def carlson_rc(x, y):
    """Carlson's R_C(x, y), x >= 0, y > 0 (DLMF 19.2.17)."""
    w = 1.0
    for _ in range(100):
        lam = 2.0 * math.sqrt(x) * math.sqrt(y) + y
        x, y = 0.25 * (x + lam), 0.25 * (y + lam)
        ave = (x + y + y) / 3.0
        s = (y - ave) / ave
        if abs(s) <= _ERRTOL:
            break
    return w * (1.0 + s * s * (0.3 + s * (1.0 / 7.0 + s * (0.375 + s * 9.0 / 22.0)))) / math.sqrt(ave)


@_jit
def carlson_rj(x, y, z, p):
    """Carlson's R_J(x, y, z, p), x, y, z >= 0 (at most one zero), p > 0 (DLMF 19.16.2)."""
    c1, c2, c3, c4 = 3.0 / 14.0, 1.0 / 3.0, 3.0 / 22.0, 3.0 / 26.0
    c5, c6, c7, c8 = 0.75 * c3, 1.5 * c4, 0.5 * c2, c3 + c3
    total = 0.0
    fac = 1.0
    for _ in range(100):
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * (sy + sz) + sy * sz
        alpha = (p * (sx + sy + sz) + sx * sy * sz) ** 2
        beta = p * (p + lam) ** 2
        total += fac * carlson_rc(alpha, beta)
        fac *= 0.25
        x, y, z, p = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam), 0.25 * (p + lam)
        ave = 0.2 * (x + y + z + p + p)
        dx, dy, dz, dp = (ave - x) / ave, (ave - y) / ave, (ave - z) / ave, (ave - p) / ave
        if max(abs(dx), abs(dy), abs(dz), abs(dp)) <= _ERRTOL:
            break
    ea = dx * (dy + dz) + dy * dz
    eb = dx * dy * dz
    ec = dp * dp
    ed = ea - 3.0 * ec
    ee = eb + 2.0 * dp * (ea - ec)
    return 3.0 * total + fac * (1.0 + ed * (-c1 + c5 * ed - c6 * ee) + eb * (c7 + dp * (-c8 + dp * c4))
                                + dp * ea * (c2 - dp * c3) - c2 * dp * ec) / (ave * math.sqrt(ave))


@_jit
def ellipk_agm(m1):
    """Complete K(m) from the complementary parameter m1 = 1 - m > 0: pi / (2 AGM(1, sqrt(m1)))."""
    a, b = 1.0, math.sqrt(m1)
    for _ in range(64):
        if abs(a - b) <= 1e-16 * a:
            break
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (a + b)


@_jit
def incomplete_pi(s, c, d, nu):
    """Incomplete Pi(nu; am | m) from s = sin am, c = |cos am|, d = dn (A&S 17.2; DLMF 19.25.14)."""
    s2 = s * s
    return s * carlson_rf(c * c, d * d, 1.0) + nu / 3.0 * s * s2 * carlson_rj(c * c, d * d, 1.0, 1.0 - nu * s2)


def incomplete_pi_arrays(s, c, d, nu):
    """Incomplete ``Pi(nu; am | m)`` from ``s = sin am``, ``c = |cos am|``, ``d = dn``."""
    s2 = s * s
    return s * special.elliprf(c * c, d * d, 1.0) + nu / 3.0 * s * s2 * special.elliprj(
        c * c, d * d, 1.0, 1.0 - nu * s2
    )
