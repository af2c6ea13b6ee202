"""The exact motion of the torque-free rigid body (Jacobi elliptic functions, Carlson's integrals).

Conventions (the whole rigid layer uses them)
---------------------------------------------
* Plain float64 arrays, SI units (kg m^2, kg m^2/s, rad, s); no I/O.
* Body axes are principal axes; ``inertia = (I1, I2, I3)`` are the principal
  moments along body axes 1, 2, 3 (any order of size). A zero moment (thin rod)
  is allowed when the angular momentum along that axis is zero, and its angular
  velocity component is then taken as zero.
* Orientation is a unit quaternion, SCALAR-LAST ``(x, y, z, w)`` as in scipy,
  representing the ACTIVE rotation body -> space: ``space_vec = R(q) @ body_vec``
  with ``R(q) = scipy.spatial.transform.Rotation.from_quat(q).as_matrix()``.
  Composition is Hamilton's product, ``R(a * b) = R(a) @ R(b)``.
* The dynamic variable is the angular momentum in body axes ``L_body``; the
  body angular velocity is ``omega_body = L_body / I``. Euler's equations read
  ``dL/dt = L x omega + N_body`` and the attitude ``dq/dt = q * (omega, 0) / 2``.

[`free_body_exact`][rotframe.rigid.free_body.free_body_exact] keeps ``L`` to about ``1e-14 |L|`` over many flips, also
beside the separatrix, and the attitude to about ``1e-12`` rad. It runs the
closed form compiled ([`rotframe.rigid.exact_flow.flow_into`][rotframe.rigid.exact_flow.flow_into], a few
microseconds a call) where it applies, else [`free_body_closed_form`][rotframe.rigid.free_body.free_body_closed_form], the
same formulas with numpy and scipy on arrays.

References
----------
.. [1] Landau & Lifshitz, Mechanics, par. 37.
.. [2] Celledoni, Fasso, Safstrom & Zanna, The exact computation of the free
   rigid body motion and its use in splitting methods, SIAM J. Sci. Comput. 30
   (2008) 2084-2112.
.. [3] Abramowitz & Stegun, Handbook of Mathematical Functions, ch. 16-17
   (16.8 quarter-period shifts, 16.12-16.13 descending Landen transformation,
   17.2 elliptic integrals); Carlson, Numer. Math. 33 (1979) (``R_F``, ``R_J``).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numpy.typing import ArrayLike
from scipy import special
from scipy.spatial.transform import Rotation

from rotframe.numerics.rotation import quat_about_axis, quat_mul_arrays, rotate_about
from rotframe.rigid.checks import (
    InvalidStateError,
    check_axis_momentum,
    check_inertia,
    check_quaternion,
    symmetry_axis,
)
from rotframe.rigid.elliptic import incomplete_pi_arrays, jacobi_reduced_arrays
from rotframe.validation import check_vector3, guard_public

__all__ = ["free_body_exact", "free_body_closed_form", "elliptic_period"]


def free_body_exact(
    inertia: ArrayLike,
    L0_body: ArrayLike,
    q0: ArrayLike,
    times: ArrayLike,
) -> tuple[np.ndarray, np.ndarray]:
    """Exact motion of the torque-free rigid body (the closed form, compiled once a process needs it twice).

    The asymmetric body with valid input runs the compiled closed form
    ([`rotframe.rigid.exact_flow.flow_into`][rotframe.rigid.exact_flow.flow_into]: about 6 us a call for a few time
    points, against 0.3 to 0.5 ms for the numpy path). It is compiled once per machine and kept in
    numba's disk cache: a call finds it ready when it is loaded or cached
    ([`rotframe.rigid.exact_flow.flow_ready`][rotframe.rigid.exact_flow.flow_ready]); otherwise the first call of a process
    takes the numpy path (a single call does not pay a compile of some 8 s), and the second call
    compiles it and caches it, so every later call, in this process or any other, is compiled.
    The scenes and ``rotframe.simulate_body`` call `free_body_closed_form` itself: a few calls of
    many samples each, and numbers that do not depend on what the disk cache holds (the two
    paths agree to round-off, not to the bit). Every other case (two equal moments, the
    separatrix, rotation about the middle axis, ``L = 0``, a zero moment) and the refusal of invalid input are
    [`free_body_closed_form`][rotframe.rigid.free_body.free_body_closed_form]'s, whose docstring states the formulas, parameters and
    results. The two agree to round-off (``tests/test_rigid_exact.py``).
    """
    from rotframe.rigid import exact_flow

    _CALLS[0] += 1
    if _CALLS[0] > 1 or exact_flow.flow_ready():  # needed twice, or compiled already: the compiled flow
        fast = exact_flow.flow_into(inertia, L0_body, q0, times)
        if fast is not None:
            return fast
    return free_body_closed_form(inertia, L0_body, q0, times)


#: Calls of `free_body_exact` in this process: the second compiles the flow (or loads it from the disk cache).
_CALLS = [0]


def free_body_closed_form(
    inertia: ArrayLike,
    L0_body: ArrayLike,
    q0: ArrayLike,
    times: ArrayLike,
) -> tuple[np.ndarray, np.ndarray]:
    """Exact motion of the torque-free rigid body, evaluated with numpy and scipy on arrays.

    Angular momentum (Landau & Lifshitz par. 37, in the notation of
    docs/physics/rigid-bodies.md): in a frame of principal axes ordered so that ``L`` circulates
    about axis 3 (moments ascending when ``M^2 > 2 E I2``, descending otherwise,
    which is the "swap 1 and 3" of the textbook),
    ``L = (J1 a1 cn u, +-J2 a2 sn u, J3 a3 dn u)`` with ``u = u0 + lambda t``,
    ``lambda = sqrt((J3 - J2)(M^2 - 2E J1) / (J1 J2 J3))`` and parameter
    ``m = (J2 - J1)(2E J3 - M^2) / ((J3 - J2)(M^2 - 2E J1))``. Every difference
    of invariants is evaluated as a sum of same-sign terms, e.g.
    ``2E J3 - M^2 = (J3 - J1) L1^2/J1 + (J3 - J2) L2^2/J2``, and ``1 - m`` from
    its reduced numerator ``(J3 - J1)(M^2 - 2E J2)`` with
    ``M^2 - 2E J2 = (J3 - J2) L3^2/J3 - (J2 - J1) L1^2/J1``, so no digit is lost
    near the separatrix. ``K = ellipkm1(1 - m)``; ``sn, cn, dn`` come from
    descending Landen transformations written in the complementary parameter
    after reduction modulo ``4K`` to ``[0, K/2]`` (A&S 16.8, 16.12), avoiding
    ``scipy.special.ellipj`` near ``m = 1`` (scipy issue 8480). ``u0`` is the
    incomplete integral ``F(am u0 | m)`` from Carlson's ``R_F``.

    Attitude (Celledoni et al. 2008): ``L`` is fixed in space. With ``n = L/|L|``
    in body axes at polar angle ``theta`` and azimuth ``phi`` from axis 3,
    ``R(t) = S0 Rz(psi(t)) Ry(-theta(t)) Rz(-phi(t)) P`` where ``P`` maps body to
    the ordered frame and ``S0`` is fixed by ``R(0) = R(q0)``. The angle about
    ``L`` obeys ``psi' = |L| (L1^2/J1 + L2^2/J2) / (L1^2 + L2^2)``
    ``= |L|/J3 [1 + (J3 - J1)/J1 / (1 - nu sn^2 u)]`` with
    ``nu = -J3 (J2 - J1) / (J1 (J3 - J2))``, whose integral is closed form:
    ``psi = |L|/J3 [t + (J3 - J1)/(J1 lambda) (Pi(nu; am u | m) - Pi(nu; am u0 | m))]``,
    the incomplete elliptic integral of the third kind evaluated with Carlson's
    ``R_F`` and ``R_J`` from ``sn, cn, dn`` (A&S 17.2.17; Carlson 1979), which
    keeps its accuracy where ``am u`` nears ``pi/2`` at ``m -> 1``.

    Symmetric body (two equal moments ``Ip``, symmetry axis ``s``) and sphere:
    ``H = |L|^2/(2 Ip) + (1/Is - 1/Ip) Ls^2/2``, two commuting exact rotations:
    ``L(t) = Rot_s(k t) L0`` with ``k = omega_s (Is - Ip)/Ip`` and
    ``R(t) = R0 Rot(n0, |L| t/Ip) Rot_s(-k t)``. Exactly on the separatrix
    ``sn = tanh``, ``cn = dn = sech``; rotation about the middle axis is steady.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments (kg m^2) along body axes 1, 2, 3.
    L0_body : array_like, shape (3,)
        Angular momentum (kg m^2/s) at ``t = 0``, body axes.
    q0 : array_like, shape (4,)
        Orientation at ``t = 0``, scalar-last ``(x, y, z, w)``, body -> space
        (normalised here).
    times : array_like, shape (n,)
        Times (s) relative to the initial state; any order, negative allowed.

    Returns
    -------
    L_body : ndarray, shape (n, 3)
        Angular momentum (kg m^2/s) in body axes at ``times``.
    q : ndarray, shape (n, 4)
        Orientation quaternions, scalar-last, body -> space; continuous in ``t``
        (no sign jumps) and equal to ``q0`` at ``t = 0``.
    """
    inertia, inv_i = check_inertia(inertia)
    L0 = check_vector3(L0_body, "L0_body", InvalidStateError)
    check_axis_momentum(inertia, L0)
    q0 = check_quaternion(q0)
    t = np.atleast_1d(np.asarray(times, dtype=np.float64))
    if t.ndim != 1 or not np.all(np.isfinite(t)):
        raise InvalidStateError("times must be a 1-D array of finite numbers (s)")

    norm_L = math.hypot(*L0)
    if norm_L == 0.0:
        return np.tile(L0, (t.size, 1)), np.tile(q0, (t.size, 1))
    sym = symmetry_axis(inertia)
    if sym is not None:
        return _free_symmetric(inv_i, sym, L0, q0, t)
    frame = _elliptic_frame(inertia, L0)
    if frame is None:  # steady rotation about the middle axis
        middle = int(np.argsort(inertia)[1])
        angle = norm_L * inv_i[middle] * t
        q = quat_mul_arrays(q0, quat_about_axis(L0 / norm_L, angle))
        return np.tile(L0, (t.size, 1)), q
    return _free_asymmetric(frame, L0, q0, t)


def elliptic_period(inertia: ArrayLike, L0_body: ArrayLike) -> float:
    """Period (s) of the body angular velocity ``omega(t)`` of the free body.

    Asymmetric body: ``4 K(m) / lambda`` (Landau & Lifshitz par. 37; ``sn`` and
    ``cn`` have period ``4K``); symmetric body: ``2 pi / |k|`` with
    ``k = omega_s (Is - Ip) / Ip``. For steady rotation about the smallest or
    largest axis this is the period of small wobbles about it. ``inf`` for the
    sphere, ``k = 0``, exact separatrix motion, steady rotation about the middle
    axis and zero momentum.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments (kg m^2).
    L0_body : array_like, shape (3,)
        Angular momentum (kg m^2/s), body axes.

    Returns
    -------
    float
        Period (s).
    """
    inertia, inv_i = check_inertia(inertia)
    L0 = check_vector3(L0_body, "L0_body", InvalidStateError)
    check_axis_momentum(inertia, L0)
    if not np.any(L0):
        return math.inf
    sym = symmetry_axis(inertia)
    if sym is not None:
        k = L0[sym] * inv_i[3]  # 1/I_s - 1/I_p without cancellation (checks.check_inertia)
        return math.inf if k == 0.0 else 2.0 * math.pi / abs(k)
    frame = _elliptic_frame(inertia, L0)
    if frame is None or frame["m1"] == 0.0:
        return math.inf
    return 4.0 * frame["K"] / frame["lam"]


def _free_symmetric(inv_i, s, L0, q0, t):
    """Exact free symmetric body: two commuting exact rotations (see free_body_exact)."""
    norm_L = math.hypot(*L0)
    inv_p = inv_i[(s + 1) % 3]
    gamma = L0[s] * inv_i[3]  # body rate of the second flow, = -k; 1/I_s - 1/I_p without cancellation
    e_s = np.eye(3)[s]
    q = quat_mul_arrays(quat_mul_arrays(q0, quat_about_axis(L0 / norm_L, norm_L * inv_p * t)), quat_about_axis(e_s, gamma * t))
    L = rotate_about(e_s, -gamma * t, L0)
    return L, q


def _elliptic_frame(moments, L0):
    """Ordered frame and elliptic constants of the asymmetric free body.

    Returns None for steady rotation about the middle axis. Otherwise a dict with
    ``P`` (proper signed permutation: ordered = P @ body), ``J`` (ordered
    moments), ``sigma`` (+1 ascending, -1 descending), ``amp`` (amplitudes of
    ``L`` along the ordered axes), ``lam``, ``m``, ``m1``, ``K``, ``nu``, ``Pic``
    (complete ``Pi(nu | m)``), ``ratio`` (``amp[1] / amp[0]``), ``L`` (ordered
    ``L0``). ``m1 == 0`` flags motion exactly on the separatrix.
    """
    order = np.argsort(moments, kind="stable")
    P = np.eye(3)[order]
    if np.linalg.det(P) < 0.0:
        P[1] = -P[1]
    J = moments[order]
    norm_L, J_max = math.hypot(*L0), J[2]
    n = P @ L0 / norm_L  # scale-free: unit momentum, moments / J_max
    # M^2 - 2 E J2 from same-sign terms (docs/physics/rigid-bodies.md: reduced numerator of 1 - m),
    # its sign taken with (L1, L3) scaled to order one so that nothing underflows
    s = max(abs(n[0]), abs(n[2]))
    if s == 0.0:
        return None  # steady rotation about the middle axis
    D_s = (J[2] - J[1]) / J[2] * (n[2] / s) ** 2 - (J[1] - J[0]) / J[0] * (n[0] / s) ** 2
    if D_s < 0.0:  # L circulates about the smallest axis: swap 1 and 3 (a proper rotation)
        P = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]]) @ P
        J = J[::-1].copy()
    if (P @ L0)[2] < 0.0:  # rotate by pi about axis 1 so that L3 > 0
        P = np.diag([1.0, -1.0, -1.0]) @ P
    if D_s == 0.0 and (P @ L0)[0] < 0.0:  # separatrix: rotate by pi about axis 3 so that L1 > 0
        P = np.diag([-1.0, -1.0, 1.0]) @ P
    L = P @ L0
    n = L / norm_L
    J1, J2, J3 = J / J_max
    A = (J3 - J1) * n[0] ** 2 / J1 + (J3 - J2) * n[1] ** 2 / J2  # (2E J3 - M^2) / |L|^2
    B = (J2 - J1) * n[1] ** 2 / J2 + (J3 - J1) * n[2] ** 2 / J3  # (M^2 - 2E J1) / |L|^2
    amp = norm_L * np.sqrt([J1 * A / (J3 - J1), J2 * A / (J3 - J2), J3 * B / (J3 - J1)])
    lam = norm_L / J_max * math.sqrt((J3 - J2) * B / (J1 * J2 * J3))
    m = (J2 - J1) * A / ((J3 - J2) * B)
    m1 = (J3 - J1) * D_s * s * s / ((J3 - J2) * B)  # D_s s^2 = (M^2 - 2E J2) / |L|^2
    if D_s != 0.0:  # keep k'^2 = m1 a normal number: states nearer the saddle than
        m1 = max(m1, 1e-300)  # 1e-150 of |L| move as if they were 1e-150 from it
    nu = -J3 * (J2 - J1) / (J1 * (J3 - J2))
    if m1 > 0.0:
        K = float(special.ellipkm1(m1))
        Pic = float(incomplete_pi_arrays(1.0, 0.0, math.sqrt(m1), nu))
    else:
        K = Pic = math.inf
    return {
        "P": P, "J": J, "sigma": 1.0 if J3 > J1 else -1.0, "amp": amp, "lam": lam, "m": m,
        "m1": m1, "K": K, "nu": nu, "Pic": Pic, "L": L,
        "ratio": math.sqrt(J2 * (J3 - J1) / (J1 * (J3 - J2))),
    }


def _free_asymmetric(fr, L0, q0, t):
    """Exact free asymmetric body in the ordered frame ``fr`` (see free_body_exact)."""
    J, amp, sigma, lam = fr["J"], fr["amp"], fr["sigma"], fr["lam"]
    Lc = fr["L"]
    # u0 from the initial state: sn u0 ~ sigma L2 / ratio, cn u0 ~ L1 (amp[0] may be 0)
    s0, c0 = sigma * Lc[1] / fr["ratio"], Lc[0]
    if fr["m1"] == 0.0:
        u0 = math.asinh(s0 / c0)
    else:
        hyp = math.hypot(s0, c0)
        s0, c0 = (s0 / hyp, c0 / hyp) if hyp > 0.0 else (0.0, 1.0)
        G = abs(s0) * float(special.elliprf(c0 * c0, c0 * c0 + fr["m1"] * s0 * s0, 1.0))
        u0 = math.copysign(G if c0 >= 0.0 else 2.0 * fr["K"] - G, s0)
    u = np.concatenate(([u0], u0 + lam * t))
    sn, cn, dn, am, Pi = _jacobi_with_pi(u, fr)
    L_ord = np.stack([amp[0] * cn, sigma * amp[1] * sn, amp[2] * dn], axis=-1)
    norm_L = math.hypot(*Lc)
    psi = norm_L / J[2] * (t + (J[2] - J[0]) / (J[0] * lam) * (Pi[1:] - Pi[0]))
    theta = np.arctan2(np.hypot(L_ord[:, 0], L_ord[:, 1]), L_ord[:, 2])
    # azimuth of (L1, L2), continuous in u: sigma am(u) plus a bounded correction
    az = np.arctan2(sigma * fr["ratio"] * sn, cn)
    phi = sigma * am + _wrap(az - sigma * am)
    ez, ey = np.eye(3)[2], np.eye(3)[1]
    qP = _permutation_quat(fr["P"].tobytes())
    qP_inv = qP * np.array([-1.0, -1.0, -1.0, 1.0])
    S0 = quat_mul_arrays(quat_mul_arrays(quat_mul_arrays(q0, qP_inv), quat_about_axis(ez, phi[0])), quat_about_axis(ey, theta[0]))
    q = quat_mul_arrays(quat_mul_arrays(quat_mul_arrays(quat_mul_arrays(S0, quat_about_axis(ez, psi)), quat_about_axis(ey, -theta[1:])),
                    quat_about_axis(ez, -phi[1:])), qP)
    L = L_ord[1:] @ fr["P"]  # ordered -> body: P^T @ L
    return L, q


@functools.lru_cache(maxsize=64)
def _permutation_quat(P_bytes):
    """Quaternion (scalar-last) of a proper signed permutation matrix given as its float64 bytes.

    There are 24 such matrices; scipy's ``from_matrix`` costs more than the rest of a short call, so
    each is converted once (the same function on the same matrix: the same numbers), read-only.
    """
    q = Rotation.from_matrix(np.frombuffer(P_bytes, dtype=np.float64).reshape(3, 3)).as_quat()
    q.flags.writeable = False
    return q


def _jacobi_with_pi(u, fr):
    """sn, cn, dn, continuous am and Pi(nu; am u | m) at ``u`` (arrays).

    Reduction (A&S 16.8): ``u = ur + 4K j`` with ``|ur| <= 2K``; ``sn`` odd, ``cn``,
    ``dn`` even; ``v -> 2K - v`` flips the sign of ``cn``; ``Pi`` is odd in
    ``am``, ``Pi(pi - a) = 2 Pic - Pi(a)`` and ``Pi(a + 2 pi j) = Pi(a) + 4 j Pic``.
    ``Pi`` on ``[0, K]`` from Carlson (A&S 17.2; DLMF 19.25.14):
    ``Pi = s R_F(c^2, d^2, 1) + nu/3 s^3 R_J(c^2, d^2, 1, 1 - nu s^2)``.
    """
    nu = fr["nu"]
    if fr["m1"] == 0.0:
        # separatrix: sn = tanh, cn = dn = sech, am = gd(u); with sin(am) = tanh u,
        # Pi(nu; am | 1) = int ds / ((1 - s^2)(1 - nu s^2))
        #               = (u + sqrt(-nu) atan(sqrt(-nu) tanh u)) / (1 - nu)   (nu < 0)
        sn = np.tanh(u)
        e = np.exp(-np.abs(u))
        cn = 2.0 * e / (1.0 + e * e)
        root = math.sqrt(-nu)
        Pi = (u + root * np.arctan(root * sn)) / (1.0 - nu)
        return sn, cn, cn.copy(), np.arctan2(sn, cn), Pi
    K, Pic = fr["K"], fr["Pic"]
    sn_w, cn_w, dn_w, sgn, refl, j = jacobi_reduced_arrays(u, fr["m"], fr["m1"], K)
    G = incomplete_pi_arrays(sn_w, cn_w, dn_w, nu)
    sn = sgn * sn_w
    cn = np.where(refl, -cn_w, cn_w)
    am_w = np.arctan2(sn_w, cn_w)
    am = sgn * np.where(refl, math.pi - am_w, am_w) + 2.0 * math.pi * j
    Pi = sgn * np.where(refl, 2.0 * Pic - G, G) + 4.0 * Pic * j
    return sn, cn, dn_w, am, Pi


def _wrap(x):
    """Angle wrapped to [-pi, pi)."""
    return (x + math.pi) % (2.0 * math.pi) - math.pi


# text, complex and object input to the public functions: a InvalidStateError, not a numpy TypeError
guard_public(globals(), __all__, InvalidStateError)
