"""Rigid-body core: free body (exact), Lie-Poisson splitting, heavy symmetric top, RK4.

Conventions
-----------
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
* Space axes for the heavy top: ``z`` is up, gravity is ``-g z``; the centre of
  mass sits at ``length * e3`` on the body symmetry axis (``length`` from the
  fixed point), so the Euler angle ``theta`` is the angle between ``e3`` and ``z``.
* Euler angles appear only as inputs/outputs of the check formulas
  (:func:`symmetric_top_euler_energy`, :func:`heavy_top_turning_points`: ZXZ,
  Goldstein's phi, theta, psi); they are never integrated.

Methods and what they keep
--------------------------
* :func:`free_body_exact`: the exact flow (Jacobi elliptic functions and the
  elliptic integral of the third kind): ``L`` to about ``1e-14 |L|`` over many
  flips, also beside the separatrix, and the attitude to about ``1e-12`` rad.
* :func:`lie_poisson`: symmetric splitting into exact rotations about body axes
  (McLachlan 1993; Dullweber, Leimkuhler & McLachlan 1997), order 2, 4 or 6:
  ``|L|`` kept to round-off, energy error bounded without trend.
* :func:`heavy_top_splitting`: Strang splitting gravity kick / exact symmetric
  free flow, order 2, 4 or 6; keeps ``p_phi = L . z`` and ``p_psi = L3`` to
  round-off. Not stiff in the spin: spin and nutation are exact rotations, so
  no step-size limit comes from them (RK4 needs ``h < 2.8 / omega``). Accuracy
  is ``O(h^order)`` while ``h`` resolves the nutation period ``2 pi I1 / |L|``;
  with longer steps the error in ``theta`` is of order ``Omega_precession h``.
* :func:`rigid_rk4`: classical RK4 on :func:`rigid_rhs`, for comparison. It does
  not keep ``|L|``, the energy or ``|q|``: all drift like ``h^4 t``.

References
----------
.. [1] Landau & Lifshitz, Mechanics, par. 37.
.. [2] Celledoni, Fasso, Safstrom & Zanna, The exact computation of the free
   rigid body motion and its use in splitting methods, SIAM J. Sci. Comput. 30
   (2008) 2084-2112.
.. [3] Abramowitz & Stegun, Handbook of Mathematical Functions, ch. 16-17
   (16.8 quarter-period shifts, 16.12-16.13 descending Landen transformation,
   17.2 elliptic integrals); Carlson, Numer. Math. 33 (1979) (``R_F``, ``R_J``).
.. [4] Goldstein, Poole & Safko, Classical Mechanics, 3rd ed., 5.6-5.7.
.. [5] Yoshida, Construction of higher order symplectic integrators, Phys.
   Lett. A 150 (1990) 262.
.. [6] McLachlan, Explicit Lie-Poisson integration and the Euler equations,
   Phys. Rev. Lett. 71 (1993) 3043; Dullweber, Leimkuhler & McLachlan,
   J. Chem. Phys. 107 (1997) 5840.
"""

from __future__ import annotations

from typing import Callable

import math

import numpy as np
from numpy.typing import ArrayLike
from numba import njit
from scipy import special
from scipy.spatial.transform import Rotation

from rotframe.errors import IntegrationError, RotframeError
from rotframe.rigid.mass_properties import InvalidBodyError, check_mass, check_moments

__all__ = [
    "InvalidStateError",
    "free_body_exact",
    "lie_poisson",
    "torqued_splitting",
    "heavy_top_splitting",
    "rigid_rhs",
    "rigid_rk4",
    "energy",
    "omega_body",
    "body_to_space",
    "angular_momentum_space",
    "symmetric_top_euler_energy",
    "heavy_top_turning_points",
    "sleeping_top_threshold",
    "free_symmetric_precession",
    "elliptic_period",
]


class InvalidStateError(RotframeError, ValueError):
    """An initial state, step size or option that the rigid-body solvers cannot take."""


# ===========================================================================
# Exact free rigid body
# ===========================================================================


def free_body_exact(
    inertia: ArrayLike,
    L0_body: ArrayLike,
    q0: ArrayLike,
    times: ArrayLike,
) -> tuple[np.ndarray, np.ndarray]:
    """Exact motion of the torque-free rigid body.

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
    inertia, inv_i = _check_inertia(inertia)
    L0 = _check_vector(L0_body, "L0_body")
    _check_axis_momentum(inertia, L0)
    q0 = _check_quaternion(q0)
    t = np.atleast_1d(np.asarray(times, dtype=np.float64))
    if t.ndim != 1 or not np.all(np.isfinite(t)):
        raise InvalidStateError("times must be a 1-D array of finite numbers (s)")

    norm_L = math.hypot(*L0)
    if norm_L == 0.0:
        return np.tile(L0, (t.size, 1)), np.tile(q0, (t.size, 1))
    sym = _symmetry_axis(inertia)
    if sym is not None:
        return _free_symmetric(inv_i, sym, L0, q0, t)
    frame = _elliptic_frame(inertia, L0)
    if frame is None:  # steady rotation about the middle axis
        middle = int(np.argsort(inertia)[1])
        angle = norm_L * inv_i[middle] * t
        q = _qmul(q0, _qaxis(L0 / norm_L, angle))
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
    inertia, inv_i = _check_inertia(inertia)
    L0 = _check_vector(L0_body, "L0_body")
    _check_axis_momentum(inertia, L0)
    if not np.any(L0):
        return math.inf
    sym = _symmetry_axis(inertia)
    if sym is not None:
        k = L0[sym] * (inv_i[sym] - inv_i[(sym + 1) % 3])
        return math.inf if k == 0.0 else 2.0 * math.pi / abs(k)
    frame = _elliptic_frame(inertia, L0)
    if frame is None or frame["m1"] == 0.0:
        return math.inf
    return 4.0 * frame["K"] / frame["lam"]


# ===========================================================================
# Splitting integrators
# ===========================================================================


def lie_poisson(
    inertia: ArrayLike,
    L0_body: ArrayLike,
    q0: ArrayLike,
    h: float,
    n_steps: int,
    order: int = 2,
    torque: Callable | ArrayLike | None = None,
    torque_frame: str = "body",
    sample_every: int = 1,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Free (or constantly torqued) rigid body by Lie-Poisson splitting.

    ``H = sum L_i^2 / (2 I_i)``; the flow of each term is exact: ``L_body``
    turns about body axis ``i`` by ``-h L_i / I_i`` and the attitude by
    ``+h L_i / I_i`` (``q <- q * rot_i``). The order-2 step is the symmetric
    composition 1(h/2) 2(h/2) 3(h) 2(h/2) 1(h/2) (McLachlan 1993;
    Dullweber, Leimkuhler & McLachlan 1997). A body with two equal moments is
    split as ``|L|^2/(2 Ip) + (1/Is - 1/Ip) Ls^2/2``, two commuting exact
    rotations, so its free motion is exact at any step. A constant torque is a
    kick ``L_body += (h/2) N_body`` with the orientation frozen on both sides of
    the free step (Strang). Orders 4 and 6 compose the order-2 step by
    Yoshida's triple jump [5]. ``|L|`` is kept to round-off (without torque);
    the energy error is ``O(h^order)`` and bounded, without trend.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments (kg m^2) along body axes.
    L0_body : array_like, shape (3,)
        Initial angular momentum (kg m^2/s), body axes.
    q0 : array_like, shape (4,)
        Initial orientation, scalar-last, body -> space.
    h : float
        Step (s); negative runs backwards.
    n_steps : int
        Number of steps.
    order : {2, 4, 6}
        Order of the composition.
    torque : array_like, shape (3,), optional
        Constant torque (N m).
    torque_frame : {"body", "space"}
        Axes in which ``torque`` is constant.
    sample_every : int
        Keep every ``sample_every``-th step (and always the last).

    Returns
    -------
    L_body : ndarray, shape (k, 3)
        Angular momentum (kg m^2/s), body axes, at the kept steps (first row: t = 0).
    q : ndarray, shape (k, 4)
        Orientations, scalar-last, body -> space.
    times : ndarray, shape (k,)
        Times (s) of the kept steps.
    """
    inertia, inv_i = _check_inertia(inertia)
    L0 = _check_vector(L0_body, "L0_body")
    _check_axis_momentum(inertia, L0)
    torque_body, torque_space = _check_torque(inertia, torque, torque_frame)
    sym = _symmetry_axis(inertia)
    return _run_splitting(inv_i, -1 if sym is None else sym, 0.0, torque_body, torque_space,
                          L0, q0, h, n_steps, order, sample_every)


def torqued_splitting(
    inertia: ArrayLike,
    L0_body: ArrayLike,
    q0: ArrayLike,
    h: float,
    n_steps: int,
    torque: Callable | ArrayLike | None,
    torque_frame: str = "body",
    order: int = 2,
    sample_every: int = 1,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rigid body under a torque that depends on time and state, by Strang splitting.

    ``torque(t, L_body, q) -> (3,)`` (N m) in body or space axes. Each step of
    the symmetric composition is kick(tau/2), the exact free flow (as in
    :func:`lie_poisson`), kick(tau/2), with the orientation frozen during the
    kicks; a kick evaluates the torque at its midpoint in L (explicit midpoint
    rule), so a torque that depends on L (damping, say) keeps the step second
    order. Orders 4 and 6 by Yoshida's triple jump. The loop runs in Python and
    calls the compiled free flow (about a microsecond a step): for constant
    torques use :func:`lie_poisson`, which is compiled throughout.

    Parameters
    ----------
    inertia, L0_body, q0, h, n_steps, order, sample_every
        As in :func:`lie_poisson`.
    torque : callable
        ``torque(t, L_body, q)``: time (s), angular momentum (body axes,
        kg m^2/s), orientation (scalar-last, body -> space) -> torque (N m).
    torque_frame : {"body", "space"}
        Axes of the returned torque.

    Returns
    -------
    L_body, q, times
        As in :func:`lie_poisson`.
    """
    inertia, inv_i = _check_inertia(inertia)
    L = _check_vector(L0_body, "L0_body").copy()
    _check_axis_momentum(inertia, L)
    q = _check_quaternion(q0).copy()
    if torque_frame not in ("body", "space"):
        raise InvalidStateError(f"torque_frame = {torque_frame!r}; allowed: 'body' or 'space'")
    if not callable(torque):
        raise InvalidStateError("torque must be a callable torque(t, L_body, q) -> (3,)")
    h, n_steps, sample_every = _check_steps(h, n_steps, sample_every)
    weights = _composition_weights(order)
    sym = _symmetry_axis(inertia)
    sym = -1 if sym is None else sym
    out_L, out_q, times = _allocate(h, n_steps, sample_every)
    out_L[0], out_q[0] = L, q
    kept = 1

    def body_torque(t, L, q):
        tq = np.asarray(torque(t, L, q), dtype=np.float64)
        return tq if torque_frame == "body" else body_to_space(_conjugate(q), tq)

    t = 0.0
    for step in range(1, n_steps + 1):
        for w in weights:
            tau = w * h
            half = 0.5 * tau
            L += half * body_torque(t + 0.25 * tau, L + 0.5 * half * body_torque(t, L, q), q)
            _free_step(L, q, tau, inv_i, sym)
            L += half * body_torque(t + 0.75 * tau, L + 0.5 * half * body_torque(t + half, L, q), q)
            t += tau
        q /= np.linalg.norm(q)
        if step % sample_every == 0 or step == n_steps:
            out_L[kept], out_q[kept] = L, q
            kept += 1
            if not (np.all(np.isfinite(L)) and np.all(np.isfinite(q))):
                break
    return _finish(out_L, out_q, times, kept, "torqued_splitting")


def _conjugate(q):
    return np.array([-q[0], -q[1], -q[2], q[3]])


def heavy_top_splitting(
    i1: float,
    i3: float,
    mass: float,
    length: float,
    g: float,
    L0_body: ArrayLike,
    q0: ArrayLike,
    h: float,
    n_steps: int,
    order: int = 2,
    sample_every: int = 1,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Heavy symmetric top about a fixed point by Strang splitting.

    ``H = |L|^2/(2 I1) + (1/I3 - 1/I1) L3^2/2 + m g l (e3 . z)``. Kick
    (orientation frozen, exact flow of the potential):
    ``L_body += (h/2) l e3 x (-m g z_body)``, ``z_body = R(q)^T (0, 0, 1)``;
    then the exact free symmetric flow over ``h``; then the kick again
    (docs/physics/rigid-bodies.md). Orders 4 and 6 by Yoshida's triple jump. ``p_phi = L . z``
    and ``p_psi = L3`` are kept to round-off (the kick is horizontal and normal
    to ``e3``). Spin and nutation enter only through exact rotations, so no
    stability limit on ``h`` comes from the spin; the error is ``O(h^order)``
    while ``h`` resolves the nutation period ``2 pi I1 / |L|``, and of order
    ``Omega_precession * h`` in ``theta`` for longer steps.

    Parameters
    ----------
    i1, i3 : float
        Moments (kg m^2) about the fixed point: transverse (axes 1, 2) and
        about the symmetry axis 3.
    mass : float
        Mass (kg).
    length : float
        Distance (m) from the fixed point to the centre of mass along ``+e3``
        (negative: below the pivot).
    g : float
        Gravitational acceleration (m/s^2) along ``-z``.
    L0_body, q0, h, n_steps, order, sample_every
        As in :func:`lie_poisson`.

    Returns
    -------
    L_body : ndarray, shape (k, 3)
        Angular momentum about the fixed point (kg m^2/s), body axes.
    q : ndarray, shape (k, 4)
        Orientations, scalar-last, body -> space.
    times : ndarray, shape (k,)
        Times (s).
    """
    inertia, inv_i = _check_inertia((i1, i1, i3))
    mgl = _heavy_top_mgl(mass, length, g)
    L0 = _check_vector(L0_body, "L0_body")
    _check_axis_momentum(inertia, L0)
    zero = np.zeros(3)
    return _run_splitting(inv_i, 2, mgl, zero, zero, L0, q0, h, n_steps, order, sample_every)


# ===========================================================================
# Plain right-hand side and RK4
# ===========================================================================


def rigid_rhs(
    t: float,
    y: ArrayLike,
    inertia: ArrayLike,
    mgl: float = 0.0,
    torque: Callable | ArrayLike | None = None,
    torque_frame: str = "body",
) -> np.ndarray:
    """Right-hand side of the rigid body in quaternion form, for ``solve_ivp``.

    ``dL/dt = L x omega + N_body`` (Euler's equations in principal axes),
    ``dq/dt = q * (omega, 0) / 2`` (Hamilton product, scalar-last), with
    ``omega = L / I`` and ``N_body = N_const + mgl * (z_b[1], -z_b[0], 0)``
    (the gravity torque ``l e3 x (-m g z_body)`` of a top whose centre of mass is
    on body axis 3, ``z_body = R(q/|q|)^T (0, 0, 1)``).

    Parameters
    ----------
    t : float
        Time (s); unused (autonomous).
    y : array_like, shape (7,)
        ``(L_body (kg m^2/s), q (x, y, z, w))``.
    inertia : array_like, shape (3,)
        Principal moments (kg m^2).
    mgl : float
        ``m g l`` (N m) of the heavy top; 0 for none.
    torque : array_like, shape (3,), optional
        Constant torque (N m).
    torque_frame : {"body", "space"}
        Axes in which ``torque`` is constant.

    Returns
    -------
    ndarray, shape (7,)
        ``(dL_body/dt, dq/dt)``.
    """
    inertia, inv_i = _check_inertia(inertia)
    torque_body, torque_space = _check_torque(inertia, torque, torque_frame)
    return _rhs(np.asarray(y, dtype=np.float64), inv_i, float(mgl), torque_body, torque_space)


def rigid_rk4(
    inertia: ArrayLike,
    L0_body: ArrayLike,
    q0: ArrayLike,
    h: float,
    n_steps: int,
    mgl: float = 0.0,
    torque: Callable | ArrayLike | None = None,
    torque_frame: str = "body",
    sample_every: int = 1,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Classical fixed-step RK4 on :func:`rigid_rhs` (compiled), for comparison.

    RK4 keeps none of the invariants: ``|L|``, the energy and ``|q|`` drift like
    ``h^4 t``; ``q`` is not renormalised (only the rotation matrix used for the
    torque normalises it).

    Parameters
    ----------
    inertia, L0_body, q0, h, n_steps, sample_every
        As in :func:`lie_poisson`.
    mgl, torque, torque_frame
        As in :func:`rigid_rhs`.

    Returns
    -------
    L_body : ndarray, shape (k, 3)
    q : ndarray, shape (k, 4)
    times : ndarray, shape (k,)
        As in :func:`lie_poisson`.
    """
    inertia, inv_i = _check_inertia(inertia)
    L0 = _check_vector(L0_body, "L0_body")
    _check_axis_momentum(inertia, L0)
    q0 = _check_quaternion(q0)
    torque_body, torque_space = _check_torque(inertia, torque, torque_frame)
    h, n_steps, sample_every = _check_steps(h, n_steps, sample_every)
    out_L, out_q, times = _allocate(h, n_steps, sample_every)
    kept = _rk4_run(inv_i, float(mgl), torque_body, torque_space, L0, q0, h, n_steps,
                    sample_every, out_L, out_q)
    return _finish(out_L, out_q, times, kept, "rigid_rk4")


# ===========================================================================
# Helpers on states and checks against theory
# ===========================================================================


def energy(inertia: ArrayLike, L_body: ArrayLike) -> np.ndarray:
    """Kinetic energy ``sum L_i^2 / (2 I_i)`` (J) from body angular momentum.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments (kg m^2).
    L_body : array_like, shape (..., 3)
        Angular momentum (kg m^2/s), body axes.

    Returns
    -------
    ndarray, shape (...)
        Energy (J).
    """
    L = np.asarray(L_body, dtype=np.float64)
    return 0.5 * np.sum(L * omega_body(inertia, L), axis=-1)


def omega_body(inertia: ArrayLike, L: ArrayLike) -> np.ndarray:
    """Body angular velocity ``omega = L / I`` (rad/s).

    A zero moment gives a zero component (its ``L`` component must be zero).

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments (kg m^2).
    L : array_like, shape (..., 3)
        Angular momentum (kg m^2/s), body axes.

    Returns
    -------
    ndarray, shape (..., 3)
        Angular velocity (rad/s), body axes.
    """
    inertia, inv_i = _check_inertia(inertia)
    L = np.asarray(L, dtype=np.float64)
    _check_axis_momentum(inertia, L)
    return L * inv_i


def body_to_space(q: ArrayLike, vec: ArrayLike) -> np.ndarray:
    """Rotate body components to space components: ``R(q) @ vec``.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Orientations, scalar-last, body -> space (normalised here).
    vec : array_like, shape (..., 3)
        Vectors in body axes; broadcasts against ``q``.

    Returns
    -------
    ndarray, shape (..., 3)
        The vectors in space axes.
    """
    q = np.asarray(q, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    v = np.asarray(vec, dtype=np.float64)
    u, w = q[..., :3], q[..., 3:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def angular_momentum_space(q: ArrayLike, L_body: ArrayLike) -> np.ndarray:
    """Angular momentum in space axes, ``R(q) @ L_body`` (kg m^2/s).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Orientations, scalar-last, body -> space.
    L_body : array_like, shape (..., 3)
        Angular momentum, body axes.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    return body_to_space(q, L_body)


def symmetric_top_euler_energy(
    i1: float,
    i3: float,
    phi: ArrayLike,
    theta: ArrayLike,
    psi: ArrayLike,
    phidot: ArrayLike,
    thetadot: ArrayLike,
    psidot: ArrayLike,
) -> np.ndarray | float:
    """Kinetic energy (J) of a symmetric top from ZXZ Euler angles and rates.

    ``T = I1/2 (phidot^2 sin^2 theta + thetadot^2) + I3/2 (phidot cos theta + psidot)^2``
    (docs/physics/rigid-bodies.md; Goldstein 5.7). ``phi`` and ``psi`` do not enter.

    Parameters
    ----------
    i1, i3 : float or array_like
        Transverse and axial moments (kg m^2).
    phi, theta, psi : float or array_like
        ZXZ Euler angles (rad).
    phidot, thetadot, psidot : float or array_like
        Their rates (rad/s).

    Returns
    -------
    float or ndarray
        Kinetic energy (J).
    """
    del phi, psi
    s, c = np.sin(theta), np.cos(theta)
    return 0.5 * i1 * (phidot**2 * s**2 + thetadot**2) + 0.5 * i3 * (phidot * c + psidot) ** 2


def heavy_top_turning_points(
    i1: float,
    i3: float,
    mass: float,
    length: float,
    g: float,
    theta0: float,
    thetadot0: float,
    phidot0: float,
    psidot0: float,
) -> tuple[float, ...]:
    """Nutation limits and period of the heavy symmetric top (Goldstein 5.7).

    With ``u = cos theta``, ``udot^2 = f(u) = (1 - u^2)(alpha - beta u) - (b - a u)^2``,
    ``a = p_psi / I1``, ``b = p_phi / I1``, ``beta = 2 m g l / I1``,
    ``alpha = 2 E' / I1`` (``E'`` the energy without ``I3 w3^2 / 2``),
    ``p_psi = I3 w3``, ``p_phi = I1 phidot sin^2 theta + I3 w3 cos theta``. The
    motion stays between the two roots ``u1 <= u2`` of the cubic that bracket
    ``u0`` with ``f >= 0`` between them.

    Near the upright (or hanging) top ``u`` keeps too few digits of ``theta``, so
    the cubic is solved in ``v = 1 - s u`` (``s = sign(cos theta0)``), where
    ``1 - u^2 = v (2 - v)``, ``alpha - beta u = A0 + s beta v``,
    ``b - a u = B0 + s a v`` and ``A0 = thetadot^2 + phidot^2 sin^2 theta - s beta v0``,
    ``B0 = phidot sin^2 theta - s a v0`` come without cancellation from
    ``v0 = 2 sin^2(theta0 / 2)`` (or ``2 cos^2``). The nutation period
    ``T = 2 int dv / sqrt(f)``: writing ``f = (v - v1)(v2 - v) G(v)`` with ``G``
    linear and substituting ``v = v1 + (v2 - v1) sin^2 chi`` removes the endpoint
    singularities and gives ``T = 4 K(-s beta (v2 - v1) / G(v1)) / sqrt(G(v1))``.

    Parameters
    ----------
    i1, i3 : float
        Moments (kg m^2) about the fixed point, transverse and axial.
    mass, length, g : float
        Mass (kg), pivot-to-centre-of-mass distance (m), gravity (m/s^2).
    theta0, thetadot0, phidot0, psidot0 : float
        Initial ZXZ nutation angle (rad, in [0, pi]) and rates (rad/s).

    Returns
    -------
    theta_min, theta_max : float
        Extreme nutation angles (rad).
    period : float
        Nutation period (s); the small-oscillation limit when they coincide,
        ``inf`` when ``G(v1) <= 0`` (motion into an unstable equilibrium).
    """
    mgl = _heavy_top_mgl(mass, length, g)
    w3 = psidot0 + phidot0 * math.cos(theta0)
    sin0 = math.sin(theta0)
    s = 1.0 if math.cos(theta0) >= 0.0 else -1.0
    v0 = 2.0 * (math.sin(0.5 * theta0) if s > 0 else math.cos(0.5 * theta0)) ** 2
    a_s = s * i3 * w3 / i1  # s a
    beta_s = s * 2.0 * mgl / i1  # s beta
    A0 = thetadot0**2 + phidot0**2 * sin0**2 - beta_s * v0  # alpha - s beta
    B0 = phidot0 * sin0**2 - a_s * v0  # b - s a
    c2 = 2.0 * beta_s - A0 - a_s**2
    coeffs = np.array([-beta_s, c2, 2.0 * (A0 - a_s * B0), -(B0**2)])  # f(v)
    v1, v2 = _bracketing_roots(coeffs, v0)
    G1 = beta_s * (2.0 * v1 + v2) - c2  # G(v) = s beta (v1 + v2 + v) - c2
    if G1 <= 0.0:
        period = math.inf
    else:
        period = 4.0 * float(special.ellipk(-beta_s * (v2 - v1) / G1)) / math.sqrt(G1)
    th1, th2 = (2.0 * math.asin(math.sqrt(0.5 * v)) for v in (v1, v2))
    if s < 0:
        th1, th2 = math.pi - th2, math.pi - th1
    return th1, th2, period


def sleeping_top_threshold(i1: float, i3: float, mass: float, length: float, g: float) -> float:
    """Critical spin (rad/s) above which the upright heavy top is stable.

    ``omega3_c = sqrt(4 m g l I1) / I3`` (Goldstein 5.7: stable when
    ``I3^2 omega3^2 > 4 I1 m g l``).

    Parameters
    ----------
    i1, i3 : float
        Transverse and axial moments (kg m^2) about the fixed point.
    mass, length, g : float
        Mass (kg), pivot-to-centre-of-mass distance (m), gravity (m/s^2).

    Returns
    -------
    float
        Critical ``omega3`` (rad/s); 0 when ``m g l <= 0`` (hanging top).
    Examples
    --------
    >>> round(sleeping_top_threshold(1.9e-4, 2.5e-5, 0.1, 0.04, 9.81), 2)   # sqrt(4 I1 m g l) / I3, rad/s
    218.44
    """
    mgl = _heavy_top_mgl(mass, length, g)
    return math.sqrt(4.0 * max(mgl, 0.0) * i1) / i3


def free_symmetric_precession(i1: float, i3: float, omega3: float) -> float:
    """Body-frame precession rate of the free symmetric top (rad/s).

    ``k = omega3 (I3 - I1) / I1``: ``(omega1, omega2)`` turns about body axis 3 at
    ``k`` (positive: counter-clockwise seen from ``+e3``). The seed prints it
    with the sign of ``I1 - I3``; see docs/physics/seed-errata.md.

    Parameters
    ----------
    i1, i3 : float
        Transverse and axial moments (kg m^2).
    omega3 : float
        Spin about the symmetry axis (rad/s).

    Returns
    -------
    float
        ``k`` (rad/s).
    """
    return omega3 * (i3 - i1) / i1


# ===========================================================================
# Python helpers: checks
# ===========================================================================


def _check_inertia(inertia):
    """Principal moments as float64 (3,) and their inverses (0 for a zero moment)."""
    moments = np.array(check_moments(inertia), dtype=np.float64)
    moments = np.maximum(moments, 0.0)
    if np.count_nonzero(moments) < 2:
        raise InvalidBodyError(
            f"principal moments {moments.tolist()} kg m^2: a rotating body needs at least two "
            "non-zero moments (a point mass has no rotational dynamics)"
        )
    inv_i = np.zeros(3)
    np.divide(1.0, moments, out=inv_i, where=moments > 0.0)
    return moments, inv_i


def _check_axis_momentum(moments, L, name="L_body"):
    """Refuse angular momentum (or torque) about an axis of zero moment (infinite spin)."""
    for i in np.flatnonzero(moments == 0.0):
        if np.any(np.asarray(L)[..., i] != 0.0):
            raise InvalidStateError(
                f"body axis {i + 1} has zero moment of inertia (a thin rod), so {name}[{i}] "
                f"must be 0; got {np.asarray(L)[..., i].ravel()[:3].tolist()}"
            )


def _check_vector(v, name):
    """A finite 3-vector as float64."""
    a = np.asarray(v, dtype=np.float64)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise InvalidStateError(f"{name} = {np.asarray(v).tolist()} must be 3 finite numbers")
    return a


def _check_quaternion(q):
    """A finite non-zero quaternion (x, y, z, w), normalised."""
    a = np.asarray(q, dtype=np.float64)
    n = np.linalg.norm(a) if a.shape == (4,) and np.all(np.isfinite(a)) else 0.0
    if n == 0.0:
        raise InvalidStateError(
            f"q0 = {np.asarray(q).tolist()} must be 4 finite numbers (x, y, z, w), not all zero"
        )
    return a / n


def _check_torque(moments, torque, frame):
    """Constant torque split into (body, space) parts, one of them zero."""
    zero = np.zeros(3)
    if frame not in ("body", "space"):
        raise InvalidStateError(f"torque_frame = {frame!r}; allowed: 'body' or 'space'")
    if torque is None:
        return zero, zero
    n = _check_vector(torque, "torque")
    if frame == "body":
        _check_axis_momentum(moments, n, "torque")
        return n, zero
    if np.any(moments == 0.0) and np.any(n):
        raise InvalidStateError(
            "a body with a zero principal moment (thin rod) cannot take a space-fixed torque: "
            "its component along the rod would have no response"
        )
    return zero, n


def _check_steps(h, n_steps, sample_every):
    """Validated (h, n_steps, sample_every)."""
    h = float(h)
    if not math.isfinite(h) or h == 0.0:
        raise InvalidStateError(f"h = {h!r} s; allowed: a finite non-zero step")
    if int(n_steps) != n_steps or n_steps < 0:
        raise InvalidStateError(f"n_steps = {n_steps!r}; allowed: an integer >= 0")
    if int(sample_every) != sample_every or sample_every < 1:
        raise InvalidStateError(f"sample_every = {sample_every!r}; allowed: an integer >= 1")
    return h, int(n_steps), int(sample_every)


def _heavy_top_mgl(mass, length, g):
    """``m g l`` (N m) after checking its factors."""
    m = check_mass(mass)
    l, gg = float(length), float(g)
    if not (math.isfinite(l) and math.isfinite(gg)):
        raise InvalidBodyError(f"length = {length!r} m and g = {g!r} m/s^2 must be finite")
    return m * gg * l


def _symmetry_axis(moments):
    """Index of the unequal axis of a body with two equal moments (0 for a sphere), else None."""
    for s in range(3):
        if moments[(s + 1) % 3] == moments[(s + 2) % 3]:
            return s
    return None


# ===========================================================================
# Python helpers: exact free motion
# ===========================================================================


def _free_symmetric(inv_i, s, L0, q0, t):
    """Exact free symmetric body: two commuting exact rotations (see free_body_exact)."""
    norm_L = math.hypot(*L0)
    inv_p = inv_i[(s + 1) % 3]
    gamma = L0[s] * (inv_i[s] - inv_p)  # body rate of the second flow, = -k
    e_s = np.eye(3)[s]
    q = _qmul(_qmul(q0, _qaxis(L0 / norm_L, norm_L * inv_p * t)), _qaxis(e_s, gamma * t))
    L = _rotate_about(e_s, -gamma * t, L0)
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
        Pic = float(_carlson_pi(1.0, 0.0, math.sqrt(m1), nu))
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
    qP = Rotation.from_matrix(fr["P"]).as_quat()
    qP_inv = qP * np.array([-1.0, -1.0, -1.0, 1.0])
    S0 = _qmul(_qmul(_qmul(q0, qP_inv), _qaxis(ez, phi[0])), _qaxis(ey, theta[0]))
    q = _qmul(_qmul(_qmul(_qmul(S0, _qaxis(ez, psi)), _qaxis(ey, -theta[1:])),
                    _qaxis(ez, -phi[1:])), qP)
    L = L_ord[1:] @ fr["P"]  # ordered -> body: P^T @ L
    return L, q


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
    sn_w, cn_w, dn_w, sgn, refl, j = _jacobi_reduced(u, fr["m"], fr["m1"], K)
    G = _carlson_pi(sn_w, cn_w, dn_w, nu)
    sn = sgn * sn_w
    cn = np.where(refl, -cn_w, cn_w)
    am_w = np.arctan2(sn_w, cn_w)
    am = sgn * np.where(refl, math.pi - am_w, am_w) + 2.0 * math.pi * j
    Pi = sgn * np.where(refl, 2.0 * Pic - G, G) + 4.0 * Pic * j
    return sn, cn, dn_w, am, Pi


def _carlson_pi(s, c, d, nu):
    """Incomplete ``Pi(nu; am | m)`` from ``s = sin am``, ``c = |cos am|``, ``d = dn``."""
    s2 = s * s
    return s * special.elliprf(c * c, d * d, 1.0) + nu / 3.0 * s * s2 * special.elliprj(
        c * c, d * d, 1.0, 1.0 - nu * s2
    )


def _bracketing_roots(coeffs, v0):
    """Consecutive real roots ``v1 <= v2`` of the polynomial around ``v0`` with ``f >= 0`` between.

    Roots from the companion matrix (``numpy.roots``; a near-double pair may come
    out complex, its real part is kept), polished by Newton steps kept only while
    ``|f|`` decreases. Among the pairs of consecutive roots that bracket ``v0``
    (to a relative 1e-6, for a start at a turning point) the one with the largest
    ``f`` at its midpoint is the allowed region. Clipped to ``[0, 2]``.
    """
    dcoeffs = np.polyder(coeffs)
    # a leading coefficient whose term is below round-off on [0, 2] (a top of negligible weight) would put
    # the companion matrix at a scale that ruins the other roots: leave it to the Newton polish below
    lead = np.asarray(coeffs, dtype=float)
    while len(lead) > 2 and abs(lead[0]) * 2.0 ** (len(lead) - 1) <= 1e-17 * float(
            np.sum(np.abs(lead[1:]) * 2.0 ** np.arange(len(lead) - 2, -1, -1))):
        lead = lead[1:]
    roots = []
    for r in np.sort(np.roots(lead).real):
        for _ in range(4):
            d = np.polyval(dcoeffs, r)
            trial = r - np.polyval(coeffs, r) / d if d != 0.0 else r
            if not abs(np.polyval(coeffs, trial)) < abs(np.polyval(coeffs, r)):
                break
            r = trial
        roots.append(r)
    best = None
    slack = 1e-6 * abs(v0) + 1e-300
    for lo, hi in zip(roots[:-1], roots[1:]):
        if lo - slack <= v0 <= hi + slack:
            f_mid = np.polyval(coeffs, 0.5 * (lo + hi))
            if best is None or f_mid > best[0]:
                best = (f_mid, lo, hi)
    if best is None:  # no motion in theta (e.g. a top at rest without gravity)
        return v0, v0
    return float(np.clip(best[1], 0.0, 2.0)), float(np.clip(best[2], 0.0, 2.0))


def _wrap(x):
    """Angle wrapped to [-pi, pi)."""
    return (x + math.pi) % (2.0 * math.pi) - math.pi


def _qmul(a, b):
    """Hamilton product of scalar-last quaternions, broadcasting over leading axes."""
    av, aw = a[..., :3], a[..., 3:]
    bv, bw = b[..., :3], b[..., 3:]
    v = aw * bv + bw * av + np.cross(av, bv)
    w = aw * bw - np.sum(av * bv, axis=-1, keepdims=True)
    return np.concatenate([v, w], axis=-1)


def _qaxis(axis, angle):
    """Quaternions (..., 4) of rotations by ``angle`` (...) about unit ``axis`` (3,)."""
    half = 0.5 * np.asarray(angle, dtype=np.float64)[..., None]
    return np.concatenate([np.sin(half) * axis, np.cos(half)], axis=-1)


def _rotate_about(axis, angle, v):
    """Rotate ``v`` (3,) by ``angle`` (n,) about unit ``axis`` (Rodrigues): shape (n, 3)."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    return v * c + np.cross(axis, v) * s + axis * (axis @ v) * (1.0 - c)


# ===========================================================================
# Python helpers: drivers
# ===========================================================================


def _composition_weights(order):
    """Weights of the order-2 step in Yoshida's triple-jump composition [5]."""
    if order not in (2, 4, 6):
        raise InvalidStateError(f"order = {order!r}; allowed: 2, 4 or 6")
    w = np.array([1.0])
    for p in range(2, order, 2):  # raise the order from p to p + 2
        root = 2.0 ** (1.0 / (p + 1))
        g1 = 1.0 / (2.0 - root)
        w = np.concatenate([g1 * w, -root * g1 * w, g1 * w])
    return w


def _allocate(h, n_steps, sample_every):
    """Output arrays and sample times: steps 0, s, 2s, ... and always the last."""
    steps = np.arange(0, n_steps + 1, sample_every)
    if steps[-1] != n_steps:
        steps = np.append(steps, n_steps)
    return np.empty((steps.size, 3)), np.empty((steps.size, 4)), steps * h


def _finish(out_L, out_q, times, kept, name):
    """Return the samples, or raise IntegrationError keeping the finite ones."""
    if kept == times.size:
        return out_L, out_q, times
    t_reached = float(times[kept - 1])
    raise IntegrationError(
        f"{name}: state became non-finite after t = {t_reached:.6g} s (last finite sample); "
        "reduce the step",
        t_reached=t_reached, partial=(out_L[:kept], out_q[:kept], times[:kept]),
    )


def _run_splitting(inv_i, sym, mgl, torque_body, torque_space, L0, q0, h, n_steps, order,
                   sample_every):
    """Shared driver of lie_poisson and heavy_top_splitting."""
    q0 = _check_quaternion(q0)
    weights = _composition_weights(order)
    h, n_steps, sample_every = _check_steps(h, n_steps, sample_every)
    out_L, out_q, times = _allocate(h, n_steps, sample_every)
    kept = _split_run(inv_i, sym, mgl, torque_body, torque_space, L0, q0, h, n_steps, weights,
                      sample_every, out_L, out_q)
    return _finish(out_L, out_q, times, kept, "splitting")


# ===========================================================================
# Compiled kernels
# ===========================================================================


@njit(cache=True)
def _jacobi_reduced(u, m, m1, K):
    """Reduce ``u`` and evaluate sn, cn, dn on ``[0, K]``.

    Returns ``sn_w, cn_w, dn_w`` at ``w in [0, K]``, the sign ``sgn`` of the
    reduced argument, whether ``w = 2K - |ur|`` (``refl``) and the period count
    ``j`` (``u = ur + 4K j``). On ``[K/2, K]`` the quarter-period shift
    ``sn(K - v) = cn v / dn v``, ``cn(K - v) = k' sn v / dn v``,
    ``dn(K - v) = k' / dn v`` (A&S 16.8.2) keeps relative accuracy near ``K``.
    """
    n = u.size
    sn_w, cn_w, dn_w = np.empty(n), np.empty(n), np.empty(n)
    sgn, refl, jj = np.empty(n), np.empty(n, dtype=np.bool_), np.empty(n)
    kp = math.sqrt(m1)
    period = 4.0 * K
    for i in range(n):
        ur = np.fmod(u[i], period)  # exact remainder, then into [-2K, 2K]
        if ur > 2.0 * K:
            ur -= period
        elif ur < -2.0 * K:
            ur += period
        j = np.round((u[i] - ur) / period)
        sgn[i] = 1.0 if ur >= 0.0 else -1.0
        v = abs(ur)
        refl[i] = v > K
        w = 2.0 * K - v if refl[i] else v
        if w <= 0.5 * K:
            s, c, d = _sncndn_landen(w, m, m1)
        else:
            s1, c1, d1 = _sncndn_landen(K - w, m, m1)
            s, c, d = c1 / d1, kp * s1 / d1, kp / d1
        sn_w[i], cn_w[i], dn_w[i], jj[i] = s, c, d, j
    return sn_w, cn_w, dn_w, sgn, refl, jj


@njit(cache=True)
def _sncndn_landen(u, m, m1):
    """sn, cn, dn(u | m) by descending Landen transformations (A&S 16.12-16.13).

    Moduli are carried in pairs without cancellation, ``k_{n+1} = k_n^2 / (1 + k'_n)^2``
    and ``k'_{n+1} = 2 sqrt(k'_n) / (1 + k'_n)``, starting from ``k = sqrt(m)``,
    ``k' = sqrt(m1)`` (``m1 = 1 - m`` supplied exactly), until ``k^2 < 1e-18``,
    where ``sn = sin v - k^2/4 (v - sin v cos v) cos v`` (16.13). Going back up,
    ``sn_n = (1 + k) sn / (1 + k sn^2)``, ``cn_n = cn dn / (1 + k sn^2)`` and
    ``dn = sqrt(cn^2 + k'^2 sn^2)`` are ratios and sums of positive terms, and at
    each level the larger of ``sn, cn`` is recomputed from the smaller, so both
    keep their relative accuracy for ``u`` in ``[0, K/2]`` (unlike the AGM's
    arcsine recursion, whose argument nears 1 when ``m -> 1``).
    """
    ks = np.empty(48)
    kps = np.empty(48)
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
    s, c = _complete_pair(s0 - corr * c0, c0 + corr * s0)
    for i in range(n - 1, -1, -1):
        k, kp = ks[i], kps[i]
        d = math.sqrt(c * c + kp * kp * s * s)
        den = 1.0 + k * s * s
        s, c = _complete_pair((1.0 + k) * s / den, c * d / den)
    return s, c, math.sqrt(c * c + m1 * s * s)


@njit(cache=True)
def _complete_pair(s, c):
    """Recompute the larger of ``sn, cn >= 0`` from the smaller, ``sn^2 + cn^2 = 1``.

    ``sqrt((1 - x)(1 + x))`` of the smaller one is accurate to an ulp, whereas a
    value near 1 carried through the recurrence keeps only absolute accuracy
    (``1 - cn`` would lose its digits at small ``u``).
    """
    if s < c:
        return s, math.sqrt((1.0 - s) * (1.0 + s))
    return math.sqrt((1.0 - c) * (1.0 + c)), c


@njit(cache=True)
def _qmul_nb(a, b):
    """Hamilton product of scalar-last quaternions (4,)."""
    return np.array([
        a[3] * b[0] + b[3] * a[0] + a[1] * b[2] - a[2] * b[1],
        a[3] * b[1] + b[3] * a[1] + a[2] * b[0] - a[0] * b[2],
        a[3] * b[2] + b[3] * a[2] + a[0] * b[1] - a[1] * b[0],
        a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
    ])


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
    nj = c * Lj + s * Lk
    nk = -s * Lj + c * Lk
    after = nj * nj + nk * nk
    # first-order correction n (1 + (before - after) / (2 after)), applied as a small
    # increment: a factor near 1 would round with a bias (the doubles below 1 are
    # twice as dense as those above)
    corr = 0.5 * (before - after) / after if after > 0.0 else 0.0
    L[j] = nj + nj * corr
    L[k] = nk + nk * corr
    r = np.zeros(4)
    r[i] = math.sin(0.5 * angle)
    r[3] = math.cos(0.5 * angle)
    q[:] = _qmul_nb(q, r)


@njit(cache=True)
def _free_step(L, q, tau, inv_i, sym):
    """Free flow over ``tau``: exact for a symmetric body, else the 1,2,3,2,1 splitting."""
    if sym >= 0:
        inv_p = inv_i[(sym + 1) % 3]
        norm_L = math.sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2])
        if norm_L > 0.0:  # |L|^2 / (2 Ip): rotation about L, L_body unchanged
            half = 0.5 * tau * norm_L * inv_p
            r = np.empty(4)
            r[:3] = math.sin(half) * L / norm_L
            r[3] = math.cos(half)
            q[:] = _qmul_nb(q, r)
        _turn_about_axis(L, q, sym, tau * L[sym] * (inv_i[sym] - inv_p))
    else:
        _turn_about_axis(L, q, 0, 0.5 * tau * L[0] * inv_i[0])
        _turn_about_axis(L, q, 1, 0.5 * tau * L[1] * inv_i[1])
        _turn_about_axis(L, q, 2, tau * L[2] * inv_i[2])
        _turn_about_axis(L, q, 1, 0.5 * tau * L[1] * inv_i[1])
        _turn_about_axis(L, q, 0, 0.5 * tau * L[0] * inv_i[0])


@njit(cache=True)
def _torque_body(q, mgl, torque_body, torque_space):
    """Body torque: constant body part, ``R(q)^T`` times the space part, and gravity.

    Gravity: ``mgl (z_b[1], -z_b[0], 0) = l e3 x (-m g z_b)`` with
    ``z_b = R(q)^T (0, 0, 1)``, the third row of ``R(q)``.
    """
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    x, y, z, w = q[0] / n, q[1] / n, q[2] / n, q[3] / n
    # rows of R(q): R^T v = (col_0 . v, col_1 . v, col_2 . v)
    r00, r01, r02 = 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)
    r10, r11, r12 = 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)
    r20, r21, r22 = 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)
    ts = torque_space
    out = torque_body.copy()
    out[0] += r00 * ts[0] + r10 * ts[1] + r20 * ts[2] + mgl * r21
    out[1] += r01 * ts[0] + r11 * ts[1] + r21 * ts[2] - mgl * r20
    out[2] += r02 * ts[0] + r12 * ts[1] + r22 * ts[2]
    return out


@njit(cache=True)
def _split_run(inv_i, sym, mgl, torque_body, torque_space, L0, q0, h, n_steps, weights,
               sample_every, out_L, out_q):
    """Composition of Strang steps kick(tau/2) free(tau) kick(tau/2); returns samples kept."""
    L, q = L0.copy(), q0.copy()
    kick = mgl != 0.0 or np.any(torque_body != 0.0) or np.any(torque_space != 0.0)
    out_L[0], out_q[0] = L, q
    kept = 1
    for step in range(1, n_steps + 1):
        for w in weights:
            tau = w * h
            if kick:
                L += 0.5 * tau * _torque_body(q, mgl, torque_body, torque_space)
            _free_step(L, q, tau, inv_i, sym)
            if kick:
                L += 0.5 * tau * _torque_body(q, mgl, torque_body, torque_space)
        q /= math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
        if step % sample_every == 0 or step == n_steps:
            out_L[kept], out_q[kept] = L, q
            kept += 1
            if not (np.all(np.isfinite(L)) and np.all(np.isfinite(q))):
                return kept - 1
    return kept


@njit(cache=True)
def _rhs(y, inv_i, mgl, torque_body, torque_space):
    """Euler's equations plus quaternion kinematics (see rigid_rhs)."""
    L, q = y[:3], y[3:]
    om = L * inv_i
    dy = np.empty(7)
    dy[0] = L[1] * om[2] - L[2] * om[1]
    dy[1] = L[2] * om[0] - L[0] * om[2]
    dy[2] = L[0] * om[1] - L[1] * om[0]
    dy[:3] += _torque_body(q, mgl, torque_body, torque_space)
    wq = np.array([om[0], om[1], om[2], 0.0])
    dy[3:] = 0.5 * _qmul_nb(q, wq)
    return dy


@njit(cache=True)
def _rk4_run(inv_i, mgl, torque_body, torque_space, L0, q0, h, n_steps, sample_every, out_L,
             out_q):
    """Classical RK4 on _rhs; returns samples kept."""
    y = np.empty(7)
    y[:3], y[3:] = L0, q0
    out_L[0], out_q[0] = L0, q0
    kept = 1
    for step in range(1, n_steps + 1):
        k1 = _rhs(y, inv_i, mgl, torque_body, torque_space)
        k2 = _rhs(y + 0.5 * h * k1, inv_i, mgl, torque_body, torque_space)
        k3 = _rhs(y + 0.5 * h * k2, inv_i, mgl, torque_body, torque_space)
        k4 = _rhs(y + h * k3, inv_i, mgl, torque_body, torque_space)
        y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        if step % sample_every == 0 or step == n_steps:
            out_L[kept], out_q[kept] = y[:3], y[3:]
            kept += 1
            if not np.all(np.isfinite(y)):
                return kept - 1
    return kept


# text, complex and object input to the public functions: a InvalidStateError, not a numpy TypeError
from rotframe.validation import guard_public  # noqa: E402

guard_public(globals(), __all__, InvalidStateError)
