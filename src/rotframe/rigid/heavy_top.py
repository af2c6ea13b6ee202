"""The heavy symmetric top about a fixed point: splitting integrator and checks against theory.

Space axes: ``z`` is up, gravity is ``-g z``; the centre of mass sits at
``length * e3`` on the body symmetry axis (``length`` from the fixed point), so
the Euler angle ``theta`` is the angle between ``e3`` and ``z``. Euler angles
appear only as inputs/outputs of the check formulas
([`symmetric_top_euler_energy`][rotframe.rigid.heavy_top.symmetric_top_euler_energy], [`heavy_top_turning_points`][rotframe.rigid.heavy_top.heavy_top_turning_points]: ZXZ,
Goldstein's phi, theta, psi); they are never integrated.

[`heavy_top_splitting`][rotframe.rigid.heavy_top.heavy_top_splitting]: Strang splitting gravity kick / exact symmetric free
flow, order 2, 4, 6 or 8; keeps ``p_phi = L . z`` and ``p_psi = L3`` to round-off.
Not stiff in the spin: spin and nutation are exact rotations, so no step-size
limit comes from them (RK4 needs ``h < 2.8 / omega``). Accuracy is
``O(h^order)`` while ``h`` resolves the nutation period ``2 pi I1 / |L|``; with
longer steps the error in ``theta`` is of order ``Omega_precession h``.

References
----------
.. [4] Goldstein, Poole & Safko, Classical Mechanics, 3rd ed., 5.6-5.7.
.. [5] Yoshida, Construction of higher order symplectic integrators, Phys.
   Lett. A 150 (1990) 262.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike
from scipy import special

from rotframe.rigid.checks import (
    InvalidStateError,
    check_axis_momentum,
    check_inertia,
    heavy_top_mgl,
)
from rotframe.rigid.drivers import run_splitting
from rotframe.validation import check_vector3, guard_public

__all__ = [
    "heavy_top_splitting",
    "heavy_top_turning_points",
    "sleeping_top_threshold",
    "symmetric_top_euler_energy",
    "free_symmetric_precession",
]


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
    (docs/physics/rigid-bodies.md). Order 4 by Yoshida's triple jump, 6 and 8 by Kahan & Li's
    compositions (`rotframe.numerics.composition.composition_weights`). ``p_phi = L . z``
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
        As in `lie_poisson`.

    Returns
    -------
    L_body : ndarray, shape (k, 3)
        Angular momentum about the fixed point (kg m^2/s), body axes.
    q : ndarray, shape (k, 4)
        Orientations, scalar-last, body -> space.
    times : ndarray, shape (k,)
        Times (s).
    """
    inertia, inv_i = check_inertia((i1, i1, i3))
    mgl = heavy_top_mgl(mass, length, g)
    L0 = check_vector3(L0_body, "L0_body", InvalidStateError)
    check_axis_momentum(inertia, L0)
    zero = np.zeros(3)
    return run_splitting(inv_i, 2, mgl, zero, zero, L0, q0, h, n_steps, order, sample_every)


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
    mgl = heavy_top_mgl(mass, length, g)
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
    mgl = heavy_top_mgl(mass, length, g)
    return math.sqrt(4.0 * max(mgl, 0.0) * i1) / i3


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




# text, complex and object input to the public functions: a InvalidStateError, not a numpy TypeError
guard_public(globals(), __all__, InvalidStateError)
