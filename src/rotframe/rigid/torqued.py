"""Free and torqued rigid body by Lie-Poisson splitting, and the plain right-hand side with RK4.

* [`lie_poisson`][rotframe.rigid.torqued.lie_poisson]: symmetric splitting into exact rotations about body axes
  (McLachlan 1993; Dullweber, Leimkuhler & McLachlan 1997), order 2, 4, 6 or 8:
  ``|L|`` kept to round-off, energy error bounded without trend; a constant torque
  in body or space axes.
* [`torqued_splitting`][rotframe.rigid.torqued.torqued_splitting]: a torque that depends on time and state, Strang
  splitting around the same exact free flow.
* [`rigid_rhs`][rotframe.rigid.torqued.rigid_rhs] (for ``solve_ivp``) and [`rigid_rk4`][rotframe.rigid.torqued.rigid_rk4]: classical RK4, for
  comparison. It does not keep ``|L|``, the energy or ``|q|``: all drift like ``h^4 t``.

Conventions as in [`rotframe.rigid.free_body`][rotframe.rigid.free_body].

References
----------
.. [5] Yoshida, Construction of higher order symplectic integrators, Phys.
   Lett. A 150 (1990) 262.
.. [6] McLachlan, Explicit Lie-Poisson integration and the Euler equations,
   Phys. Rev. Lett. 71 (1993) 3043; Dullweber, Leimkuhler & McLachlan,
   J. Chem. Phys. 107 (1997) 5840.
.. [7] Kahan & Li, Composition constants for raising the orders of
   unconventional schemes for ordinary differential equations, Math. Comp. 66
   (1997) 1089.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from numpy.typing import ArrayLike

from rotframe.rigid.checks import (
    InvalidStateError,
    check_axis_momentum,
    check_inertia,
    check_quaternion,
    check_steps,
    check_torque,
    symmetry_axis,
)
from rotframe.rigid.drivers import allocate_samples, composition_weights, finish_samples, run_splitting
from rotframe.rigid.kernels import euler_rhs, free_step, rk4_run
from rotframe.rigid.observables import body_to_space
from rotframe.validation import check_vector3, guard_public

__all__ = ["lie_poisson", "torqued_splitting", "rigid_rhs", "rigid_rk4"]


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
    the free step (Strang). Orders 4, 6 and 8 compose the order-2 step
    (Yoshida's triple jump [5] for 4, Kahan & Li's 9 and 17 stages [7] for 6
    and 8). ``|L|`` is kept to round-off (without torque); the energy error
    is ``O(h^order)`` and bounded, without trend.

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
    order : {2, 4, 6, 8}
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
    inertia, inv_i = check_inertia(inertia)
    L0 = check_vector3(L0_body, "L0_body", InvalidStateError)
    check_axis_momentum(inertia, L0)
    torque_body, torque_space = check_torque(inertia, torque, torque_frame)
    sym = symmetry_axis(inertia)
    return run_splitting(inv_i, -1 if sym is None else sym, 0.0, torque_body, torque_space,
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
    [`lie_poisson`][rotframe.rigid.torqued.lie_poisson]), kick(tau/2), with the orientation frozen during the
    kicks; a kick evaluates the torque at its midpoint in L (explicit midpoint
    rule), so a torque that depends on L (damping, say) keeps the step second
    order. Orders 4, 6 and 8 as in [`lie_poisson`][rotframe.rigid.torqued.lie_poisson]. The loop runs in Python and
    calls the compiled free flow (about a microsecond a step): for constant
    torques use [`lie_poisson`][rotframe.rigid.torqued.lie_poisson], which is compiled throughout.

    Parameters
    ----------
    inertia, L0_body, q0, h, n_steps, order, sample_every
        As in [`lie_poisson`][rotframe.rigid.torqued.lie_poisson].
    torque : callable
        ``torque(t, L_body, q)``: time (s), angular momentum (body axes,
        kg m^2/s), orientation (scalar-last, body -> space) -> torque (N m).
    torque_frame : {"body", "space"}
        Axes of the returned torque.

    Returns
    -------
    L_body, q, times
        As in [`lie_poisson`][rotframe.rigid.torqued.lie_poisson].
    """
    inertia, inv_i = check_inertia(inertia)
    L = check_vector3(L0_body, "L0_body", InvalidStateError).copy()
    check_axis_momentum(inertia, L)
    q = check_quaternion(q0).copy()
    if torque_frame not in ("body", "space"):
        raise InvalidStateError(f"torque_frame = {torque_frame!r}; allowed: 'body' or 'space'")
    if not callable(torque):
        raise InvalidStateError("torque must be a callable torque(t, L_body, q) -> (3,)")
    h, n_steps, sample_every = check_steps(h, n_steps, sample_every)
    weights = composition_weights(order)
    sym = symmetry_axis(inertia)
    sym = -1 if sym is None else sym
    out_L, out_q, times = allocate_samples(h, n_steps, sample_every)
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
            free_step(L, q, tau, inv_i, sym)
            L += half * body_torque(t + 0.75 * tau, L + 0.5 * half * body_torque(t + half, L, q), q)
            t += tau
        q /= np.linalg.norm(q)
        if step % sample_every == 0 or step == n_steps:
            out_L[kept], out_q[kept] = L, q
            kept += 1
            if not (np.all(np.isfinite(L)) and np.all(np.isfinite(q))):
                break
    return finish_samples(out_L, out_q, times, kept, "torqued_splitting")


def _conjugate(q):
    return np.array([-q[0], -q[1], -q[2], q[3]])


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
    inertia, inv_i = check_inertia(inertia)
    torque_body, torque_space = check_torque(inertia, torque, torque_frame)
    return euler_rhs(np.asarray(y, dtype=np.float64), inv_i, float(mgl), torque_body, torque_space)


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
    """Classical fixed-step RK4 on [`rigid_rhs`][rotframe.rigid.torqued.rigid_rhs] (compiled), for comparison.

    RK4 keeps none of the invariants: ``|L|``, the energy and ``|q|`` drift like
    ``h^4 t``; ``q`` is not renormalised (only the rotation matrix used for the
    torque normalises it).

    Parameters
    ----------
    inertia, L0_body, q0, h, n_steps, sample_every
        As in [`lie_poisson`][rotframe.rigid.torqued.lie_poisson].
    mgl, torque, torque_frame
        As in [`rigid_rhs`][rotframe.rigid.torqued.rigid_rhs].

    Returns
    -------
    L_body : ndarray, shape (k, 3)
    q : ndarray, shape (k, 4)
    times : ndarray, shape (k,)
        As in [`lie_poisson`][rotframe.rigid.torqued.lie_poisson].
    """
    inertia, inv_i = check_inertia(inertia)
    L0 = check_vector3(L0_body, "L0_body", InvalidStateError)
    check_axis_momentum(inertia, L0)
    q0 = check_quaternion(q0)
    torque_body, torque_space = check_torque(inertia, torque, torque_frame)
    h, n_steps, sample_every = check_steps(h, n_steps, sample_every)
    out_L, out_q, times = allocate_samples(h, n_steps, sample_every)
    kept = rk4_run(inv_i, float(mgl), torque_body, torque_space, L0, q0, h, n_steps,
                    sample_every, out_L, out_q)
    return finish_samples(out_L, out_q, times, kept, "rigid_rk4")




# text, complex and object input to the public functions: a InvalidStateError, not a numpy TypeError
guard_public(globals(), __all__, InvalidStateError)
