"""Closed forms used as references for rotating-frame dynamics.

Pure numpy/scipy: plain floats in SI units and radians, no units objects, no I/O.
scipy is imported inside the functions that use it (``expm``, ``brentq``),
so importing this module costs numpy alone: a scene that never finds a root does not
load `scipy.optimize`.
Local frame on the Earth: ENU, x east, y north, z up; Earth's angular velocity there is
``Omega (0, cos lat, sin lat)``. Pass ``g`` as the magnitude of the effective gravity
(centrifugal term inside it) unless a function says otherwise. ``rotation_rate`` is the
scalar rotation rate Omega in rad/s (``rotframe.earth.OMEGA_EARTH`` for the Earth); a
rotation *vector* is named ``omega_vec``, as ``omega`` is a vector elsewhere in rotframe.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from rotframe.errors import ScenarioError
from rotframe.numerics.hat import skew
from rotframe.validation import check_vector3

__all__ = [
    "DropResult",
    "InertialOscillation",
    "ProjectileFlat",
    "drop_east_deflection_first_order",
    "drop_north_deflection_second_order",
    "drop_north_deflection_centrifugal_second_order",
    "linear_rotating_propagator",
    "coriolis_uniform_gravity",
    "drop_exact_linear",
    "foucault_precession_rate",
    "pendulum_period",
    "airy_precession",
    "inertial_oscillation",
    "projectile_flat_vacuum",
    "projectile_lateral_deflection_first_order",
    "turntable_inertial_line",
]


class DropResult(NamedTuple):
    """Landing of a dropped body: fall time (s), east and north deflection (m)."""

    fall_time: float
    east: float
    north: float


class InertialOscillation(NamedTuple):
    """Inertial circle: period (s) and radius (m); ``inf`` on the equator."""

    period: float
    radius: float


class ProjectileFlat(NamedTuple):
    """Flat-Earth vacuum trajectory: range (m) and flight time (s)."""

    range: float
    flight_time: float


# --------------------------------------------------------------------------------------
# Falling bodies
# --------------------------------------------------------------------------------------


def drop_east_deflection_first_order(height, latitude, g, rotation_rate):
    """Eastward deflection of a body dropped from rest, to first order in Omega, m.

    ``d = (1/3) Omega g t^3 cos(lat)``, ``t = sqrt(2 h / g)``.

    Derivation: in ENU with ``a = g_vec - 2 omega x v``, the zeroth-order velocity is
    ``(0, 0, -g t)``; ``-2 omega x v0 = (2 Omega g t cos(lat), 0, 0)``; integrating twice
    gives ``x = Omega g t^3 cos(lat) / 3``. The first-order change of the fall time does
    not enter (x is already first order). Reich (1831): h = 158.5 m, lat = 50d53m,
    g = 9.81 m/s^2 gives 27.6 mm.

    Parameters
    ----------
    height : float or array_like
        Drop height, m.
    latitude : float or array_like
        Latitude, rad.
    g : float
        Effective gravity, m/s^2.
    rotation_rate : float
        Rotation rate Omega (a scalar, rad/s; ``rotframe.earth.OMEGA_EARTH`` for the Earth).

    Returns
    -------
    float or ndarray
        East deflection, m (positive east).
    """
    t = np.sqrt(2.0 * np.asarray(height, dtype=float) / g)
    d = rotation_rate * g * t**3 * np.cos(latitude) / 3.0
    return float(d) if np.ndim(d) == 0 else d


def drop_north_deflection_second_order(height, latitude, g, rotation_rate):
    """Northward deflection of a body dropped from rest, to second order in Omega, m.

    ``d_north = -(1/6) Omega^2 g t^4 sin(lat) cos(lat)``, ``t = sqrt(2 h / g)``:
    equatorward (south in the north). Coriolis only, uniform effective gravity
    (the centrifugal term is inside ``g``).

    Derivation: the first-order east velocity ``v_x = Omega g t^2 cos(lat)`` gives
    ``(-2 omega x v)_y = -2 Omega sin(lat) v_x``; integrating twice gives the formula.
    The changes of the fall time are of second order and multiply a zero north velocity.

    Parameters and units as in `drop_east_deflection_first_order`.
    """
    t = np.sqrt(2.0 * np.asarray(height, dtype=float) / g)
    d = -(rotation_rate**2) * g * t**4 * np.sin(latitude) * np.cos(latitude) / 6.0
    return float(d) if np.ndim(d) == 0 else d


def drop_north_deflection_centrifugal_second_order(height, latitude, g, rotation_rate):
    """Northward deflection from the variation of the centrifugal force along the fall, m.

    With effective gravity ``g`` measured at the foot, the explicit centrifugal term
    adds only its change with height: at r = (0, 0, z) in ENU,
    ``-w x (w x r) = Omega^2 z (0, -sin(lat) cos(lat), cos^2(lat))``. Along the
    zeroth-order fall ``z = h - g t^2 / 2``, ``y'' = -Omega^2 sin cos (h - g t^2 / 2)``,
    so ``y = -Omega^2 sin cos (h t^2 / 2 - g t^4 / 24)``; at ``h = g T^2 / 2``:

    ``d_north = -(5/24) Omega^2 g T^4 sin(lat) cos(lat)``,

    5/4 of the Coriolis part (`drop_north_deflection_second_order`), in the
    same (equatorward) sense. Second order in Omega; the neglected terms are of
    relative order Omega T. Parameters as in `drop_east_deflection_first_order`.
    """
    t = np.sqrt(2.0 * np.asarray(height, dtype=float) / g)
    d = -5.0 * (rotation_rate**2) * g * t**4 * np.sin(latitude) * np.cos(latitude) / 24.0
    return float(d) if np.ndim(d) == 0 else d


def linear_rotating_propagator(
    omega_vec,
    g_vec,
    t,
    r0,
    v0,
    centrifugal=False,
    spring=None,
    linear_drag=0.0,
):
    """Exact solution of the linear rotating-frame equations with constant coefficients.

    Solves, in the rotating frame,

    ``r'' = g - 2 w x v  [- w x (w x r)]  [- K r]  [- k v]``

    with constant angular velocity ``w``, uniform ``g``, optional explicit centrifugal term
    (do not add it when ``g`` is an effective gravity), optional linear restoring force
    ``K r`` (per unit mass) and optional linear drag ``k v``. With the augmented state
    ``s = (r, v, 1)`` (7 components) the system is ``s' = M s``,

    ::

        M = [[ 0,           I,            0 ],
             [ -W^2 - K,   -2 W - k I,    g ],
             [ 0,           0,            0 ]]

    (``W`` the skew matrix of ``w``, ``W v = w x v``; ``W^2 r = w x (w x r)``), and
    ``s(t) = expm(M t) s(0)`` exactly, evaluated with `scipy.linalg.expm`
    (Pade approximation with scaling and squaring, accurate to round-off for these sizes)
    separately for each time, so errors do not accumulate along the time grid.

    Parameters
    ----------
    omega_vec : array_like, shape (3,)
        Angular velocity of the frame, rad/s (e.g. ``Omega (0, cos lat, sin lat)`` in ENU).
    g_vec : array_like, shape (3,)
        Uniform acceleration, m/s^2 (e.g. ``(0, 0, -g)``).
    t : float or array_like
        Times, s (any shape; any sign).
    r0, v0 : array_like, shape (3,)
        Position (m) and rotating-frame velocity (m/s) at t = 0.
    centrifugal : bool
        Include ``-w x (w x r)``.
    spring : None, float, array_like of shape (3,) or (3, 3)
        Restoring term ``-K r``, 1/s^2: a scalar (isotropic), the diagonal of K (put 0 for
        free components, e.g. ``(w0^2, w0^2, 0)`` for a small-angle pendulum acting on the
        horizontal components only), or a full matrix.
    linear_drag : float
        Drag coefficient ``k``, 1/s (acceleration ``-k v``).

    Returns
    -------
    r, v : ndarray, shape t.shape + (3,)
        Position (m) and rotating-frame velocity (m/s) at the times ``t``.
    """
    w = check_vector3(omega_vec, "omega_vec", finite=False)
    g = check_vector3(g_vec, "g_vec", finite=False)
    s0 = np.concatenate([check_vector3(r0, "r0", finite=False), check_vector3(v0, "v0", finite=False), [1.0]])
    W = skew(w)
    a_r = np.zeros((3, 3))
    if centrifugal:
        a_r -= W @ W
    if spring is not None:
        a_r -= _spring_matrix(spring)
    m = np.zeros((7, 7))
    m[0:3, 3:6] = np.eye(3)
    m[3:6, 0:3] = a_r
    m[3:6, 3:6] = -2.0 * W - float(linear_drag) * np.eye(3)
    m[3:6, 6] = g
    from scipy.linalg import expm

    t = np.asarray(t, dtype=float)
    flat = t.reshape(-1)
    s = expm(m[None, :, :] * flat[:, None, None]) @ s0
    s = s.reshape(t.shape + (7,))
    return s[..., 0:3], s[..., 3:6]


def _sinc_like(theta):
    """a = sin(x)/x, b = (1 - cos x)/x^2, c = (x - sin x)/x^3 at x = theta, without cancellation.

    ``b`` as 2 sin^2(x/2)/x^2; ``c`` by its series sum_k (-1)^k x^(2k) / (2k + 3)! for |x| < 1
    (ten terms: the next is below 1e-24), directly above.
    """
    x = float(theta)
    if x == 0.0:
        return 1.0, 0.5, 1.0 / 6.0
    a = math.sin(x) / x
    b = 2.0 * (math.sin(0.5 * x) / x) ** 2
    if abs(x) < 1.0:
        c, term = 0.0, 1.0 / 6.0
        for k in range(10):
            c += term
            term *= -x * x / ((2 * k + 4) * (2 * k + 5))
    else:
        c = (x - math.sin(x)) / x**3
    return a, b, c


def coriolis_uniform_gravity(omega_vec, g_vec, r0, v0, t):
    """Closed-form motion under uniform gravity and the Coriolis term alone, for any rotation rate.

    Solves ``r'' = g - 2 w x v`` (constant ``w``, uniform ``g``; no centrifugal term:
    ``g`` is the effective gravity). Along ``n = w / |w|`` the motion is uniformly
    accelerated; across it the velocity turns about ``-n`` at 2|w| around the drift
    ``-(n x g) / (2 |w|)``. With ``x = 2 |w| t``, ``v0p = v0 - (v0 . n) n``, ``gp = g - (g . n) n``
    and the cancellation-free functions a = sin x / x, b = (1 - cos x) / x^2,
    c = (x - sin x) / x^3 (so that the limit |w| -> 0 is regular):

    ``r(t) = r0 + ((v0 . n) t + (g . n) t^2 / 2) n + v0p t a - 2 (w x v0) t^2 b + gp t^2 b - 2 (w x g) t^3 c``

    ``v(t) = ((v0 . n) + (g . n) t) n + v0p cos x - 2 (w x v0) t a + gp t a - 2 (w x g) t^2 b``

    For small |w| t, ``-2 (w x g) t^3 c -> -(w x g) t^3 / 3``, the classic eastward deflection
    (`drop_east_deflection_first_order`). An independent oracle for the exact linear
    flow (no matrix exponential); docs/physics/earth.md.

    Parameters
    ----------
    omega_vec, g_vec, r0, v0 : array_like, shape (3,)
        Angular velocity (rad/s), gravity (m/s^2), initial position (m) and rotating-frame velocity (m/s).
    t : float
        Time (s).

    Returns
    -------
    r, v : ndarray, shape (3,)
    """
    w = check_vector3(omega_vec, "omega_vec")
    g = check_vector3(g_vec, "g_vec")
    r0 = check_vector3(r0, "r0")
    v0 = check_vector3(v0, "v0")
    t = float(t)
    rate = float(np.linalg.norm(w))
    n = w / rate if rate > 0 else np.array([0.0, 0.0, 1.0])
    a, b, c = _sinc_like(2.0 * rate * t)
    v0_par, g_par = float(v0 @ n), float(g @ n)
    v0p, gp = v0 - v0_par * n, g - g_par * n
    wv, wg = np.cross(w, v0), np.cross(w, g)
    r = (r0 + (v0_par * t + 0.5 * g_par * t * t) * n + v0p * t * a - 2.0 * wv * t * t * b + gp * t * t * b
         - 2.0 * wg * t**3 * c)
    v = (v0_par + g_par * t) * n + v0p * math.cos(2.0 * rate * t) - 2.0 * wv * t * a + gp * t * a - 2.0 * wg * t * t * b
    return r, v


def drop_exact_linear(height, latitude, g, rotation_rate) -> DropResult:
    """Fall time and landing deflection of a body dropped from rest, exact linear solution.

    Solves ``r'' = (0, 0, -g) - 2 omega x v`` in ENU with ``omega = Omega (0, cos lat,
    sin lat)``, ``r(0) = (0, 0, h)``, ``v(0) = 0`` by `linear_rotating_propagator`
    (uniform effective gravity, so no explicit centrifugal term), and finds the landing
    time as the root of ``z(t) = 0`` with `scipy.optimize.brentq`, bracketed around
    the vacuum fall time ``sqrt(2 h / g)``. All orders in Omega are included; compare
    `drop_east_deflection_first_order` (agreement to relative order (Omega t)^2)
    and `drop_north_deflection_second_order`.

    Parameters
    ----------
    height : float
        Drop height, m (> 0).
    latitude : float
        Latitude, rad.
    g : float
        Effective gravity, m/s^2 (> 0).
    rotation_rate : float
        Rotation rate Omega (a scalar, rad/s; ``rotframe.earth.OMEGA_EARTH`` for the Earth).

    Returns
    -------
    DropResult
        ``(fall_time [s], east [m], north [m])`` at landing (z = 0).
    """
    height, g = float(height), float(g)
    if not (height > 0.0 and g > 0.0):
        raise ScenarioError(f"drop needs height > 0 and g > 0; got height={height}, g={g}")
    w = rotation_rate * np.array([0.0, math.cos(latitude), math.sin(latitude)])
    gv = np.array([0.0, 0.0, -g])
    r0 = np.array([0.0, 0.0, height])
    v0 = np.zeros(3)

    def z(tt):
        return linear_rotating_propagator(w, gv, tt, r0, v0)[0][2]

    t0 = math.sqrt(2.0 * height / g)
    lo, hi = 0.5 * t0, 2.0 * t0
    for _ in range(60):
        if z(hi) < 0.0:
            break
        lo, hi = hi, 2.0 * hi
    else:  # pragma: no cover - only for absurd rotation_rate
        raise ScenarioError(f"no landing found for height={height}, rotation_rate={rotation_rate}")
    from scipy.optimize import brentq

    tf = brentq(z, lo, hi, xtol=1e-15 * t0, rtol=4.0 * np.finfo(float).eps)
    r, _ = linear_rotating_propagator(w, gv, tf, r0, v0)
    return DropResult(float(tf), float(r[0]), float(r[1]))


# --------------------------------------------------------------------------------------
# Pendulums and inertial circles
# --------------------------------------------------------------------------------------


def foucault_precession_rate(latitude, rotation_rate):
    """Rate at which the swing plane of a Foucault pendulum turns, rad/s.

    ``rate = Omega sin(lat)``: positive means clockwise seen from above, so it is positive
    in the north and negative (counter-clockwise) in the south. Pantheon (48.846 deg N):
    11.3 deg per hour. Small-amplitude limit; add `airy_precession` for a finite
    elliptical swing.
    """
    r = rotation_rate * np.sin(latitude)
    return float(r) if np.ndim(r) == 0 else r


def pendulum_period(length, g, amplitude=0.0):
    """Exact period of a plane pendulum of finite amplitude, s.

    ``T = 4 sqrt(L / g) K(k^2)``, ``k = sin(theta0 / 2)``, ``theta0 = arcsin(a / L)``,
    with ``K(m)`` the complete elliptic integral of the first kind in the parameter
    ``m = k^2`` (by the arithmetic-geometric mean). For ``a -> 0``, ``T -> 2 pi sqrt(L / g)``
    (L = 67 m: 16.4 s).

    Parameters
    ----------
    length : float or array_like
        Pendulum length L, m.
    g : float or array_like
        Gravity, m/s^2.
    amplitude : float or array_like
        Horizontal displacement of the bob at the turning point, m (0 <= a <= L).

    Returns
    -------
    float or ndarray
        Period, s.
    """
    length = np.asarray(length, dtype=float)
    a = np.abs(np.asarray(amplitude, dtype=float))
    if np.any(a > length):
        raise ScenarioError(
            f"pendulum amplitude {amplitude} m exceeds the length {length} m; "
            "allowed 0 <= amplitude <= length"
        )
    theta0 = np.arcsin(a / length)
    # K(k^2) from the complementary parameter 1 - k^2 = cos^2(theta0 / 2) >= 1/2, without cancellation
    t = 4.0 * np.sqrt(length / g) * _ellipk_complement(np.cos(0.5 * theta0) ** 2)
    return float(t) if np.ndim(t) == 0 else t


def _ellipk_complement(m1):
    """Complete elliptic integral ``K(m)`` of the parameter ``m = 1 - m1``, for ``m1`` in (0, 1].

    ``K = pi / (2 AGM(1, sqrt(m1)))`` (Abramowitz & Stegun 17.6.1), elementwise; the
    arithmetic-geometric mean converges quadratically, to round-off in at most six
    steps for ``m1 >= 1/2``. (No scipy.special: a run that needs only this pays no import.)
    """
    a = np.ones_like(np.asarray(m1, dtype=float))
    b = np.sqrt(m1)
    for _ in range(64):
        if np.all(np.abs(a - b) <= 1e-16 * a):
            break
        a, b = 0.5 * (a + b), np.sqrt(a * b)
    return np.pi / (a + b)


def airy_precession(length, g, a, b):
    """Airy precession of a spherical pendulum swinging on a small ellipse, rad/s.

    ``rate = (3/8) w0 a b / L^2``, ``w0 = sqrt(g / L)``, for an ellipse of semi-axes
    ``a`` and ``b`` (m, small against L). The axes of the ellipse turn in the same sense
    as the bob goes round it: give ``b`` the sign of that sense (positive for
    counter-clockwise motion seen from above, which then gives a counter-clockwise,
    positive rate; note that `foucault_precession_rate` counts clockwise as positive).
    Leading order in a/L and b/L.
    """
    w0 = np.sqrt(np.asarray(g, dtype=float) / length)
    r = 0.375 * w0 * a * b / np.asarray(length, dtype=float) ** 2
    return float(r) if np.ndim(r) == 0 else r


def inertial_oscillation(latitude, speed, rotation_rate) -> InertialOscillation:
    """Period and radius of an inertial oscillation on the f-plane.

    Horizontal motion under the Coriolis force alone, ``f = 2 Omega sin(lat)``: the body
    runs round a circle clockwise in the north (counter-clockwise in the south) with
    period ``2 pi / |f|`` (s) and radius ``|v| / |f|`` (m). On the equator f = 0 and both
    are ``math.inf`` (no warning, no exception).

    Parameters
    ----------
    latitude : float or array_like
        Latitude, rad.
    speed : float or array_like
        Horizontal speed, m/s.
    rotation_rate : float
        Rotation rate Omega (a scalar, rad/s; ``rotframe.earth.OMEGA_EARTH`` for the Earth).

    Returns
    -------
    InertialOscillation
        ``(period [s], radius [m])``; floats for scalar input, arrays otherwise.
    """
    f = np.abs(2.0 * rotation_rate * np.sin(np.asarray(latitude, dtype=float)))
    v = np.abs(np.asarray(speed, dtype=float))
    f, v = np.broadcast_arrays(f, v)
    zero = f == 0.0
    safe = np.where(zero, 1.0, f)
    period = np.where(zero, math.inf, 2.0 * math.pi / safe)
    radius = np.where(zero, np.where(v == 0.0, 0.0, math.inf), v / safe)
    if period.ndim == 0:
        return InertialOscillation(float(period), float(radius))
    return InertialOscillation(period, radius)


# --------------------------------------------------------------------------------------
# Projectiles
# --------------------------------------------------------------------------------------


def projectile_flat_vacuum(speed, elevation, g) -> ProjectileFlat:
    """Range and flight time of a projectile on a flat, non-rotating Earth in vacuum.

    ``range = v^2 sin(2 e) / g``, ``flight_time = 2 v sin(e) / g``, launched from and
    landing on the ground (z = 0).

    Parameters
    ----------
    speed : float
        Muzzle speed v, m/s.
    elevation : float
        Elevation e above the horizontal, rad.
    g : float
        Gravity, m/s^2.

    Returns
    -------
    ProjectileFlat
        ``(range [m], flight_time [s])``.
    """
    rng = speed**2 * np.sin(2.0 * elevation) / g
    tf = 2.0 * speed * np.sin(elevation) / g
    if np.ndim(rng) == 0:
        return ProjectileFlat(float(rng), float(tf))
    return ProjectileFlat(rng, tf)


def projectile_lateral_deflection_first_order(speed, elevation, azimuth, latitude, g, rotation_rate):
    """Coriolis deflection of a projectile across its line of fire, first order in Omega, m.

    Flat Earth, vacuum, uniform effective gravity ``g`` (centrifugal inside it), launched
    from and landing on the ground z = 0. Positive = to the right of the aim.

    Derivation (ENU; azimuth ``alpha`` from north, clockwise): aim ``a = (sin alpha,
    cos alpha, 0)``, right of the aim ``rhat = (cos alpha, -sin alpha, 0)``,
    ``omega = Omega (0, cos lat, sin lat)``, ``u = v cos e``, ``w = v sin e``.
    Zeroth order: ``r0(t) = u t a + (w t - g t^2 / 2) zhat``. First order:
    ``r1'' = -2 omega x r0'``; as omega is constant and ``r0(0) = 0``,
    ``r1' = -2 omega x r0`` and ``r1 = -2 omega x P``, ``P = int_0^t r0 =
    (u t^2 / 2) a + (w t^2 / 2 - g t^3 / 6) zhat`` (a polynomial in t, exact).
    With ``a x rhat = -zhat``, ``zhat x rhat = a``:
    ``r1 . rhat = -2 omega . (P x rhat)
    = Omega u t^2 sin(lat) - Omega cos(lat) cos(alpha) (w t^2 - g t^3 / 3)``.
    At the vacuum landing time ``T = 2 w / g``, ``w T^2 - g T^3 / 3 = w T^2 / 3``:

    ``d = Omega T^2 (u sin(lat) - (w / 3) cos(lat) cos(alpha))``.

    The first-order shift of the landing time does not enter, because the zeroth-order
    velocity has no lateral component. The first term (vertical Omega on the horizontal
    velocity) deflects to the right in the north and left in the south; the second
    (horizontal Omega on the vertical velocity) pushes west on the way up and east on the
    way down, net west, i.e. to the left of a northward shot. Neglected terms are of
    relative order Omega T.

    Parameters
    ----------
    speed : float
        Muzzle speed, m/s.
    elevation : float
        Elevation above the horizontal, rad.
    azimuth : float
        Direction of fire, rad, from north towards east.
    latitude : float
        Latitude, rad.
    g : float
        Effective gravity, m/s^2.
    rotation_rate : float
        Rotation rate Omega (a scalar, rad/s; ``rotframe.earth.OMEGA_EARTH`` for the Earth).

    Returns
    -------
    float or ndarray
        Lateral deflection at landing, m (positive to the right of the aim).
    """
    u_h = speed * np.cos(elevation)
    w_v = speed * np.sin(elevation)
    tf = 2.0 * w_v / g
    d = rotation_rate * tf**2 * (
        u_h * np.sin(latitude) - (w_v / 3.0) * np.cos(latitude) * np.cos(azimuth)
    )
    return float(d) if np.ndim(d) == 0 else d


# --------------------------------------------------------------------------------------
# Turntable
# --------------------------------------------------------------------------------------


def turntable_inertial_line(r0, v0_inertial, theta_of_t, t):
    """A straight inertial line seen from a frame turning about z.

    The frame turns about the z axis by ``theta(t) = int_0^t |omega| dt`` (counter-clockwise
    seen from +z; any spin-up law) and coincides with the inertial frame when theta = 0.
    A free particle moves on ``r_in(t) = r0 + v_in t`` in inertial space; its
    rotating-frame components are

    ``r_rot(t) = R_z(-theta(t)) (r0 + v_in t)``

    (``R_z(phi)`` the active counter-clockwise rotation), an exact solution of
    ``a_rot = -2 w x v - w x (w x r) - w' x r`` with ``w = theta'(t) zhat``: it exercises
    Coriolis, centrifugal and Euler terms at once. The matching rotating-frame initial
    velocity is ``v_rot(0) = v_in - w(0) x r0`` (when theta(0) = 0).

    Parameters
    ----------
    r0 : array_like, shape (3,)
        Inertial position at t = 0, m.
    v0_inertial : array_like, shape (3,)
        Inertial velocity, m/s.
    theta_of_t : array_like, shape (N,)
        Rotation angle of the frame at the times ``t``, rad.
    t : array_like, shape (N,)
        Times, s.

    Returns
    -------
    ndarray, shape (N, 3)
        Rotating-frame positions, m.
    """
    r0 = check_vector3(r0, "r0", finite=False)
    v = check_vector3(v0_inertial, "v0_inertial", finite=False)
    theta = np.asarray(theta_of_t, dtype=float)
    t = np.asarray(t, dtype=float)
    theta, t = np.broadcast_arrays(theta, t)
    p = r0 + t[..., None] * v
    c, s = np.cos(theta), np.sin(theta)
    out = np.empty(p.shape)
    out[..., 0] = c * p[..., 0] + s * p[..., 1]
    out[..., 1] = -s * p[..., 0] + c * p[..., 1]
    out[..., 2] = p[..., 2]
    return out


# --------------------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------------------


def _spring_matrix(spring):
    k = np.asarray(spring, dtype=float)
    if k.ndim == 0:
        return float(k) * np.eye(3)
    if k.shape == (3,):
        return np.diag(k)
    if k.shape == (3, 3):
        return k
    raise ValueError(f"spring must be a scalar, shape (3,) or (3, 3); got shape {k.shape}")
