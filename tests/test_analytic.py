"""Tests of rotframe.analytic against independent references.

Each reference integrates the equations of motion, written again here, with scipy's
solve_ivp (DOP853 at tight tolerance), or uses a closed form from a different derivation.
"""

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rotframe.analytic import (
    airy_precession,
    drop_east_deflection_first_order,
    drop_exact_linear,
    drop_north_deflection_second_order,
    foucault_precession_rate,
    inertial_oscillation,
    linear_rotating_propagator,
    pendulum_period,
    projectile_flat_vacuum,
    projectile_lateral_deflection_first_order,
    turntable_inertial_line,
)
from rotframe.earth import OMEGA_EARTH, parse_latitude
from rotframe.errors import ScenarioError

DEG = math.pi / 180.0
TIGHT = dict(method="DOP853", rtol=1e-13, atol=1e-14)


# ------------------------------------------------------------------ linear propagator


def _rhs_linear(omega, g, centrifugal, K, k):
    """r'' = g - 2 w x v - [w x (w x r)] - K r - k v, written out with np.cross."""

    def rhs(t, s):
        r, v = s[:3], s[3:]
        a = g - 2.0 * np.cross(omega, v) - K @ r - k * v
        if centrifugal:
            a = a - np.cross(omega, np.cross(omega, r))
        return np.concatenate([v, a])

    return rhs


CASES = [
    dict(),
    dict(centrifugal=True),
    dict(spring="diag"),
    dict(spring="matrix"),
    dict(spring="scalar"),
    dict(linear_drag=0.3),
    dict(centrifugal=True, spring="diag", linear_drag=0.1),
]


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("case", CASES, ids=lambda c: "-".join(f"{k}" for k in c) or "plain")
def test_propagator_matches_dop853(seed, case):
    rng = np.random.default_rng(seed)
    omega = rng.normal(size=3) * rng.uniform(0.2, 1.0)
    g = rng.normal(size=3) * 5.0
    r0, v0 = rng.normal(size=3) * 3.0, rng.normal(size=3) * 2.0
    spring = None
    K = np.zeros((3, 3))
    kind = case.get("spring")
    if kind == "diag":
        spring = np.array([rng.uniform(0.5, 2.0), rng.uniform(0.5, 2.0), 0.0])
        K = np.diag(spring)
    elif kind == "matrix":
        a = rng.normal(size=(3, 3))
        spring = K = a @ a.T + np.eye(3)
    elif kind == "scalar":
        spring = rng.uniform(0.5, 2.0)
        K = spring * np.eye(3)
    centrifugal = case.get("centrifugal", False)
    drag = case.get("linear_drag", 0.0)
    t = np.linspace(0.0, 6.0, 13)
    r, v = linear_rotating_propagator(omega, g, t, r0, v0, centrifugal=centrifugal,
                                      spring=spring, linear_drag=drag)
    assert r.shape == (13, 3) and v.shape == (13, 3)
    sol = solve_ivp(_rhs_linear(omega, g, centrifugal, K, drag), (0.0, 6.0),
                    np.concatenate([r0, v0]), t_eval=t, **TIGHT)
    assert sol.success
    scale = max(1.0, np.abs(sol.y).max())
    np.testing.assert_allclose(r, sol.y[:3].T, rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(v, sol.y[3:].T, rtol=0, atol=1e-10 * scale)


def test_propagator_without_rotation_is_a_parabola_and_shapes():
    g = np.array([0.3, -0.2, -9.81])
    r0, v0 = np.array([1.0, 2.0, 3.0]), np.array([-4.0, 5.0, 6.0])
    t = np.linspace(-2.0, 5.0, 8).reshape(2, 4)
    r, v = linear_rotating_propagator(np.zeros(3), g, t, r0, v0)
    assert r.shape == (2, 4, 3)
    np.testing.assert_allclose(r, r0 + v0 * t[..., None] + 0.5 * g * t[..., None] ** 2,
                               rtol=1e-14, atol=1e-12)
    np.testing.assert_allclose(v, v0 + g * t[..., None], rtol=1e-14, atol=1e-13)
    r1, v1 = linear_rotating_propagator([0, 0, 1.0], g, 0.5, r0, v0)
    assert r1.shape == (3,) and v1.shape == (3,)


# ------------------------------------------------------------------ drop


def _drop_reference(height, lat, g, omega):
    """Coriolis-only fall from rest, solve_ivp with a landing event (test reference)."""
    w = omega * np.array([0.0, math.cos(lat), math.sin(lat)])
    gv = np.array([0.0, 0.0, -g])

    def rhs(t, s):
        return np.concatenate([s[3:], gv - 2.0 * np.cross(w, s[3:])])

    def ground(t, s):
        return s[2]

    ground.terminal, ground.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 10 * math.sqrt(2 * height / g)), [0, 0, height, 0, 0, 0],
                    events=ground, **TIGHT)
    te = sol.t_events[0][0]
    ye = sol.y_events[0][0]
    return te, ye[0], ye[1]


def test_reich_freiberg_drop():
    lat = parse_latitude("50d53m")
    d1 = drop_east_deflection_first_order(158.5, lat, 9.81, OMEGA_EARTH)
    assert 0.0275 < d1 < 0.0277  # Reich computed 27.6 mm (28.4 mm measured)
    ex = drop_exact_linear(158.5, lat, 9.81, OMEGA_EARTH)
    assert 0.0275 < ex.east < 0.0277
    assert ex.north < 0  # equatorward
    assert ex.fall_time == pytest.approx(math.sqrt(2 * 158.5 / 9.81), rel=1e-6)


@pytest.mark.parametrize("omega", [OMEGA_EARTH, 1e-3, 1e-2])
@pytest.mark.parametrize("lat_deg", [0.0, 30.0, 50.883, -60.0])
def test_drop_exact_vs_first_order_and_reference(omega, lat_deg):
    h, g, lat = 158.5, 9.81, lat_deg * DEG
    t0 = math.sqrt(2 * h / g)
    ex = drop_exact_linear(h, lat, g, omega)
    d1 = drop_east_deflection_first_order(h, lat, g, omega)
    # exact linear vs first order: the next east term is third order in Omega
    wt = omega * t0
    assert abs(ex.east - d1) <= wt * abs(d1)
    assert abs(ex.east - d1) <= wt**2 * abs(d1)
    # north: second order in Omega, equatorward
    dn = drop_north_deflection_second_order(h, lat, g, omega)
    assert abs(ex.north - dn) <= wt * abs(dn) + 1e-15
    if lat_deg > 0:
        assert ex.north < 0
    elif lat_deg < 0:
        assert ex.north > 0
    # against solve_ivp with a landing event
    te, xe, ye = _drop_reference(h, lat, g, omega)
    assert ex.fall_time == pytest.approx(te, rel=1e-11)
    assert ex.east == pytest.approx(xe, rel=1e-8, abs=1e-13)
    assert ex.north == pytest.approx(ye, rel=1e-6, abs=1e-13)


# ------------------------------------------------------------------ pendulums


def test_pantheon_period_and_rate():
    assert pendulum_period(67.0, 9.81) == pytest.approx(16.42, abs=0.005)
    assert pendulum_period(67.0, 9.81) == pytest.approx(2 * math.pi * math.sqrt(67 / 9.81))
    rate = foucault_precession_rate(48.846 * DEG, OMEGA_EARTH)
    assert math.degrees(rate) * 3600 == pytest.approx(11.3, abs=0.05)  # deg per hour
    assert 2 * math.pi / rate / 3600 == pytest.approx(31.8, abs=0.05)  # hours per turn
    assert foucault_precession_rate(-30 * DEG, OMEGA_EARTH) < 0
    assert foucault_precession_rate(0.0, OMEGA_EARTH) == 0.0


@pytest.mark.parametrize("frac", [0.1, 0.5, 0.9, 1.0])
def test_pendulum_period_finite_amplitude(frac):
    L, g = 2.0, 9.81
    theta0 = math.asin(frac)

    def rhs(t, s):
        return [s[1], -(g / L) * math.sin(s[0])]

    def bottom(t, s):
        return s[0]

    bottom.terminal, bottom.direction = True, -1
    sol = solve_ivp(rhs, (0, 10.0), [theta0, 0.0], events=bottom, **TIGHT)
    quarter = sol.t_events[0][0]
    assert pendulum_period(L, g, frac * L) == pytest.approx(4 * quarter, rel=1e-10)


def test_pendulum_amplitude_beyond_length_refused():
    with pytest.raises(ScenarioError, match="amplitude"):
        pendulum_period(1.0, 9.81, 1.5)


def _plane_angle(x, y, vx, vy, w0sq):
    """Major axis of A_ij = v_i v_j + w0^2 x_i x_j, unwrapped modulo pi."""
    axx = vx * vx + w0sq * x * x
    ayy = vy * vy + w0sq * y * y
    axy = vx * vy + w0sq * x * y
    return 0.5 * np.unwrap(np.arctan2(2 * axy, axx - ayy))


@pytest.mark.parametrize("lat_deg", [48.846, -35.0])
def test_foucault_plane_turns_clockwise_in_the_north(lat_deg):
    # Small-angle pendulum with the vertical Coriolis component (exaggerated rotation):
    # x'' = -w0^2 x + 2 Wz y', y'' = -w0^2 y - 2 Wz x'. Released from rest.
    L, g = 67.0, 9.81
    w0 = math.sqrt(g / L)
    omega = 0.02 * w0
    lat = lat_deg * DEG
    wz = omega * math.sin(lat)

    def rhs(t, s):
        x, y, vx, vy = s
        return [vx, vy, -w0**2 * x + 2 * wz * vy, -w0**2 * y - 2 * wz * vx]

    t_end = 2 * math.pi / abs(wz) / 4  # a quarter turn of the plane
    t = np.linspace(0, t_end, 20001)
    sol = solve_ivp(rhs, (0, t_end), [1.0, 0, 0, 0], t_eval=t, **TIGHT)
    ang = _plane_angle(*sol.y, w0**2)
    slope = np.polyfit(t, ang, 1)[0]  # counter-clockwise positive
    rate = foucault_precession_rate(lat, omega)  # clockwise positive
    assert -slope == pytest.approx(rate, rel=2e-3)
    assert (rate > 0) == (lat_deg > 0)


def test_airy_precession_of_spherical_pendulum():
    # Spherical pendulum in Cartesian coordinates with the constraint force written out:
    # r'' = g + lam r, lam = -(|v|^2 + g.r) / L^2. Small ellipse a x b, counter-clockwise.
    L, g = 1.0, 9.81
    w0 = math.sqrt(g / L)
    a, b = 0.06 * L, 0.03 * L
    gv = np.array([0.0, 0.0, -g])

    def rhs(t, s):
        r, v = s[:3], s[3:]
        lam = -(v @ v + gv @ r) / L**2
        return np.concatenate([v, gv + lam * r])

    def apex(t, s):  # maximum of the horizontal radius
        return s[0] * s[3] + s[1] * s[4]

    apex.direction = -1
    s0 = [a, 0.0, -math.sqrt(L**2 - a**2), 0.0, w0 * b, 0.0]
    t_end = 60 * 2 * math.pi / w0
    sol = solve_ivp(rhs, (0, t_end), s0, events=apex, method="DOP853", rtol=1e-12,
                    atol=1e-13)
    te, ye = sol.t_events[0], sol.y_events[0]
    ang = 0.5 * np.unwrap(2 * np.arctan2(ye[:, 1], ye[:, 0]))  # apse line, modulo pi
    slope = np.polyfit(te, ang, 1)[0]
    expected = airy_precession(L, g, a, b)
    assert expected > 0 and slope > 0  # same sense as the motion
    assert slope == pytest.approx(expected, rel=0.03)
    assert airy_precession(L, g, a, -b) == pytest.approx(-expected)


# ------------------------------------------------------------------ inertial oscillation


@pytest.mark.parametrize("lat_deg", [45.0, -20.0, 89.0])
def test_inertial_oscillation_against_f_plane_integration(lat_deg):
    lat, speed = lat_deg * DEG, 0.3
    io = inertial_oscillation(lat, speed, OMEGA_EARTH)
    wz = OMEGA_EARTH * math.sin(lat)

    def rhs(t, s):  # horizontal part of -2 omega x v
        return [s[2], s[3], 2 * wz * s[3], -2 * wz * s[2]]

    t = np.linspace(0, io.period, 2001)
    sol = solve_ivp(rhs, (0, io.period), [0, 0, speed, 0], t_eval=t, **TIGHT)
    x, y = sol.y[0], sol.y[1]
    # back at the start after one period, and never before half of it
    assert math.hypot(x[-1], y[-1]) < 1e-8 * io.radius
    assert math.hypot(x[1000], y[1000]) == pytest.approx(2 * io.radius, rel=1e-9)
    centre = np.array([x[:-1].mean(), y[:-1].mean()])  # one full period, end excluded
    np.testing.assert_allclose(np.hypot(x - centre[0], y - centre[1]), io.radius, rtol=1e-8)
    # sense: clockwise in the north (angular momentum about the centre negative)
    lz = (x - centre[0]) * sol.y[3] - (y - centre[1]) * sol.y[2]
    assert np.all(np.sign(lz) == -np.sign(lat_deg))
    assert io.period == pytest.approx(2 * math.pi / (2 * OMEGA_EARTH * abs(math.sin(lat))))


def test_inertial_oscillation_on_the_equator_is_infinite_without_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        io = inertial_oscillation(0.0, 1.0, OMEGA_EARTH)
        assert io.period == math.inf and io.radius == math.inf
        io = inertial_oscillation(np.array([0.0, 0.5]), 2.0, OMEGA_EARTH)
        assert io.period[0] == math.inf and math.isfinite(io.period[1])


# ------------------------------------------------------------------ projectiles


def _projectile_reference(speed, elev, az, lat, g, omega):
    """Flat Earth, vacuum, Coriolis only; returns (range, flight time, lateral)."""
    w = omega * np.array([0.0, math.cos(lat), math.sin(lat)])
    gv = np.array([0.0, 0.0, -g])
    aim = np.array([math.sin(az), math.cos(az), 0.0])
    right = np.array([math.cos(az), -math.sin(az), 0.0])
    v0 = speed * (math.cos(elev) * aim + np.array([0, 0, math.sin(elev)]))

    def rhs(t, s):
        return np.concatenate([s[3:], gv - 2.0 * np.cross(w, s[3:])])

    def ground(t, s):
        return s[2]

    ground.terminal, ground.direction = True, -1
    t_guess = 2 * speed * math.sin(elev) / g
    sol = solve_ivp(rhs, (0, 3 * t_guess), np.concatenate([[0, 0, 0], v0]), events=ground,
                    **TIGHT)
    te, ye = sol.t_events[0][0], sol.y_events[0][0]
    return ye[:3] @ aim, te, ye[:3] @ right


def test_projectile_flat_vacuum():
    rng_, tf = projectile_flat_vacuum(300.0, 30 * DEG, 9.81)
    ref_range, ref_t, lateral = _projectile_reference(300.0, 30 * DEG, 0.7, 0.5, 9.81, 0.0)
    assert rng_ == pytest.approx(ref_range, rel=1e-10)
    assert tf == pytest.approx(ref_t, rel=1e-10)
    assert abs(lateral) < 1e-9


@pytest.mark.parametrize(
    "speed, elev_deg, az_deg, lat_deg",
    [
        (1640.0, 50.0, 235.0, 49.6),  # Paris Gun, towards Paris (vacuum)
        (800.0, 45.0, 0.0, 45.0),
        (800.0, 20.0, 90.0, 60.0),
        (500.0, 30.0, 180.0, -35.0),
        (500.0, 10.0, 300.0, -70.0),
        (900.0, 60.0, 20.0, 10.0),
    ],
)
def test_projectile_lateral_deflection_against_integration(speed, elev_deg, az_deg, lat_deg):
    g = 9.81
    args = (speed, elev_deg * DEG, az_deg * DEG, lat_deg * DEG, g, OMEGA_EARTH)
    d = projectile_lateral_deflection_first_order(*args)
    _, t_flight, lateral = _projectile_reference(*args)
    # Small parameter of the expansion: Coriolis over gravity, eps = Omega V / g
    # (= Omega T / (2 sin e)); e.g. the first-order change of the flight time for a
    # shot towards the east is of this order. Neglected terms: relative O(eps).
    eps = OMEGA_EARTH * speed / g
    assert OMEGA_EARTH * t_flight <= 2 * eps
    scale = OMEGA_EARTH * t_flight**2 * speed  # size of the first-order term
    assert abs(d - lateral) <= 2 * eps * scale
    assert abs(d - lateral) <= 0.02 * abs(lateral)


@pytest.mark.parametrize("az_deg", [0.0, 90.0, 180.0, 270.0, 45.0])
def test_projectile_deflects_right_in_the_north_left_in_the_south(az_deg):
    for lat_deg, sign in ((45.0, 1.0), (-45.0, -1.0)):
        args = (700.0, 25 * DEG, az_deg * DEG, lat_deg * DEG, 9.81, OMEGA_EARTH)
        d = projectile_lateral_deflection_first_order(*args)
        assert np.sign(d) == sign
        assert np.sign(_projectile_reference(*args)[2]) == sign


def test_vertical_shot_lands_west():
    # Fired straight up (u = 0), the known result is 4/3 Omega cos(lat) w^3 / g^2 west.
    w, g, lat = 100.0, 9.81, 40 * DEG
    d = projectile_lateral_deflection_first_order(w, math.pi / 2, 0.0, lat, g, OMEGA_EARTH)
    # aim north -> right is east, so a westward landing is negative
    assert d == pytest.approx(-4 / 3 * OMEGA_EARTH * math.cos(lat) * w**3 / g**2, rel=1e-12)


# ------------------------------------------------------------------ turntable


def test_turntable_inertial_line_solves_rotating_frame_equations():
    # Frame spinning up about z: w(t) = (w0 + alpha t) z. The rotating-frame equation
    # a = -2 w x v - w x (w x r) - w' x r is integrated independently.
    w0, alpha = 0.8, 0.15
    r0 = np.array([1.0, -0.5, 0.2])
    v_in = np.array([0.3, 0.7, -0.1])
    zhat = np.array([0.0, 0.0, 1.0])

    def rhs(t, s):
        r, v = s[:3], s[3:]
        w = (w0 + alpha * t) * zhat
        a = -2 * np.cross(w, v) - np.cross(w, np.cross(w, r)) - np.cross(alpha * zhat, r)
        return np.concatenate([v, a])

    t = np.linspace(0, 12.0, 61)
    v_rot0 = v_in - np.cross(w0 * zhat, r0)
    sol = solve_ivp(rhs, (0, 12.0), np.concatenate([r0, v_rot0]), t_eval=t, **TIGHT)
    theta = w0 * t + 0.5 * alpha * t**2
    r = turntable_inertial_line(r0, v_in, theta, t)
    assert r.shape == (61, 3)
    np.testing.assert_allclose(r, sol.y[:3].T, atol=1e-9)
    # theta = 0: the inertial line itself
    np.testing.assert_allclose(turntable_inertial_line(r0, v_in, np.zeros(3), [0, 1, 2]),
                               r0 + np.outer([0, 1, 2], v_in))


def test_scalar_rotation_rate_is_named_rotation_rate_and_positional_calls_still_work():
    """``omega`` is a vector elsewhere in rotframe: analytic's scalar rates are ``rotation_rate``."""
    import inspect

    import rotframe.analytic as an

    for name in ("drop_east_deflection_first_order", "drop_north_deflection_second_order",
                 "drop_north_deflection_centrifugal_second_order", "drop_exact_linear",
                 "foucault_precession_rate", "inertial_oscillation", "projectile_lateral_deflection_first_order"):
        params = inspect.signature(getattr(an, name)).parameters
        assert "rotation_rate" in params and "omega" not in params, name
    W = 7.292115e-5
    assert an.foucault_precession_rate(0.8, W) == an.foucault_precession_rate(0.8, rotation_rate=W)
    assert an.drop_east_deflection_first_order(100.0, 0.9, 9.81, W) == \
        an.drop_east_deflection_first_order(100.0, 0.9, 9.81, rotation_rate=W)
