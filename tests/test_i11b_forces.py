"""Every force term of the particle model against scipy's solve_ivp with a right-hand side written here.

Each case switches on one term (plus what it needs to act) with parameters chosen
so that the term changes the final state by far more than the tolerance: a small
planet (R = 2 km) so that altitude and central gravity differ from uniform
gravity, a thin atmosphere (H = 300 m) over a 1 km climb, a fast frame
(|w| ~ 0.5 rad/s) on a generic axis. The reference is scipy's DOP853 at
rtol = atol = 1e-13 on the hand-written RHS (its own error, estimated by
rerunning at 1e-11, is below 1e-9 relative on these 4-second runs); rotframe
runs dop853 at rtol 1e-12. Tolerance 1e-7 relative to the state scale.
A planted sign error or dropped factor in any term changes the result by
1e-3 or more (checked by hand: see the report of issue 11).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rotframe.app import runner
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel

AXIS = np.array([0.3, -0.5, 0.81])
AXIS = AXIS / np.linalg.norm(AXIS)
R_SMALL = 2000.0
G0 = 9.0


def _omega(t, w0, alpha):
    return (w0 + alpha * t) * AXIS, alpha * AXIS


def _rhs_factory(terms, p):
    def rhs(t, y):
        r, v = y[:3], y[3:]
        w, wd = _omega(t, p.get("w0", 0.0), p.get("alpha", 0.0))
        a = np.zeros(3)
        if "gravity" in terms:
            a += p["g"]
        if "altitude-gravity" in terms:
            a += np.array([0.0, 0.0, -G0 * (R_SMALL / (R_SMALL + r[2])) ** 2])
        if "central-gravity" in terms:
            d = r - np.array([0.0, 0.0, -R_SMALL])
            a += -G0 * R_SMALL**2 * d / np.linalg.norm(d) ** 3
        if "spring" in terms:
            a += -p["spring"] * np.array([r[0], r[1], 0.0])
        if "coriolis" in terms:
            a += -2.0 * np.cross(w, v)
        if "centrifugal" in terms:
            a += -np.cross(w, np.cross(w, r))
        if "euler" in terms:
            a += -np.cross(wd, r)
        rho = math.exp(-r[2] / p["H"]) if p.get("H", 0.0) > 0 else 1.0
        if "linear-drag" in terms:
            a += -p["k1"] * rho * v
        if "quadratic-drag" in terms:
            a += -p["k2"] * rho * np.linalg.norm(v) * v
        if "pendulum" in terms:
            # textbook index-1 form of the string: remove the applied acceleration along the string
            # and add the centripetal |v|^2 / L towards the pivot (v is tangent on the sphere)
            n = (r - p["pivot"]) / p["L"]
            a = a - (a @ n) * n - (v @ v) / p["L"] * n
        return np.concatenate([v, a])
    return rhs


CASES = {
    "uniform+coriolis": (("gravity", "coriolis"), {"g": np.array([0.1, -0.2, -9.8]), "w0": 0.5}),
    "altitude-gravity": (("altitude-gravity",), {}),
    "central-gravity": (("central-gravity",), {}),
    "centrifugal": (("coriolis", "centrifugal"), {"w0": 0.5}),
    "euler": (("coriolis", "centrifugal", "euler"), {"w0": 0.3, "alpha": 0.1}),
    "linear-drag+density": (("gravity", "linear-drag"), {"g": np.array([0, 0, -9.8]), "k1": 0.05, "H": 300.0}),
    "quadratic-drag+density": (("gravity", "quadratic-drag"), {"g": np.array([0, 0, -9.8]), "k2": 4e-4, "H": 300.0}),
    "quadratic-drag-uniform-air": (("gravity", "quadratic-drag"), {"g": np.array([0, 0, -9.8]), "k2": 4e-4}),
    "spring": (("spring", "coriolis"), {"spring": 2.0, "w0": 0.4}),
    "pendulum": (("gravity", "coriolis", "pendulum"),
                 {"g": np.array([0, 0, -9.8]), "w0": 0.3, "L": 5.0, "pivot": np.array([1.0, 2.0, 8.0]),
                  "r0": np.array([1.0, 2.0, 8.0]) + 5.0 * np.array([0.6, 0.0, -0.8]),
                  "v0": np.array([1.6, 2.5, 1.2])}),  # v0 . (0.6, 0, -0.8) = 0: tangent to the sphere
}


def _model(terms, p):
    w0, alpha = p.get("w0", 0.0), p.get("alpha", 0.0)
    if alpha:
        omega = OmegaSchedule(AXIS, np.array([0.0, 100.0]), np.array([w0, w0 + 100.0 * alpha]))
    else:
        omega = OmegaSchedule.constant(w0 * AXIS)
    return ParticleModel(terms, omega=omega, g=p.get("g", np.zeros(3)), g0=G0, radius=R_SMALL,
                         pendulum_length=p.get("L", 0.0), pivot=p.get("pivot", np.zeros(3)),
                         gm=G0 * R_SMALL**2, k_linear=p.get("k1", 0.0), k_quadratic=p.get("k2", 0.0),
                         scale_height=p.get("H", 0.0), spring=p.get("spring", 0.0))


R0 = np.array([30.0, -20.0, 10.0])
V0 = np.array([40.0, 25.0, 300.0])  # climbs ~1 km: altitude, density and central gravity all vary


@pytest.mark.parametrize("case", sorted(CASES))
@pytest.mark.parametrize("method", ["dop853", "splitting4"])
def test_force_term_matches_hand_written_rhs(case, method):
    terms, p = CASES[case]
    T = 4.0
    r0, v0 = p.get("r0", R0), p.get("v0", V0)
    ref = solve_ivp(_rhs_factory(terms, p), (0.0, T), np.concatenate([r0, v0]), method="DOP853",
                    rtol=1e-13, atol=1e-13, t_eval=[T]).y[:, -1]
    kw = {"rtol": 1e-12} if method == "dop853" else {"step": 2e-4}
    traj = integrate_particles(_model(terms, p), r0, v0, T, method=method, samples=4, **kw)
    got = np.concatenate([traj.r[-1, 0], traj.v[-1, 0]])
    scale = np.max(np.abs(ref))
    # splitting4 at h = 2e-4: global error ~ (h w)^4 T * scale ~ 1e-12 relative; dop853 at 1e-12: ~1e-10
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-7 * scale)


DISTINCTIVE = {  # case -> (terms, parameters) without the term under test, or with it replaced
    "uniform+coriolis": (("gravity",), None),
    "altitude-gravity": (("gravity",), {"g": np.array([0.0, 0.0, -G0])}),
    "central-gravity": (("gravity",), {"g": np.array([0.0, 0.0, -G0])}),
    "centrifugal": (("coriolis",), None),
    "euler": (("coriolis", "centrifugal"), None),
    "linear-drag+density": (None, {"H": 0.0}),
    "quadratic-drag+density": (None, {"H": 0.0}),
    "quadratic-drag-uniform-air": (("gravity",), None),
    "spring": (("coriolis",), None),
    "pendulum": (("gravity", "pendulum"), None),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_each_term_matters_in_its_case(case):
    """The term under test moves the final state by > 1e-3 of its scale, 1e4 times the tolerance above."""
    terms, p = CASES[case]
    other_terms, changes = DISTINCTIVE[case]
    y0 = np.concatenate([p.get("r0", R0), p.get("v0", V0)])
    full = solve_ivp(_rhs_factory(terms, p), (0, 4.0), y0, rtol=1e-10, atol=1e-10).y[:, -1]
    without = solve_ivp(_rhs_factory(other_terms or terms, dict(p, **(changes or {}))), (0, 4.0), y0,
                        rtol=1e-10, atol=1e-10).y[:, -1]
    assert np.max(np.abs(full - without)) > 1e-3 * np.max(np.abs(full))


def _great_circle_range(r_end, azimuth_deg, R):
    """Distance along the sphere |r - c| = R from the gun at the origin to the point under r_end, along the aim."""
    c = np.array([0.0, 0.0, -R])
    u = (r_end - c) / np.linalg.norm(r_end - c)
    az = math.radians(azimuth_deg)
    aim = np.array([math.sin(az), math.cos(az), 0.0])
    right = np.array([math.cos(az), -math.sin(az), 0.0])
    u_plane = u - (u @ right) * right  # the projection onto the plane of the aim
    return R * math.atan2(u_plane @ aim, u_plane @ np.array([0.0, 0.0, 1.0]))


def test_projectile_curved_range_is_measured_along_the_ground():
    """With curvature, range_m is the great-circle distance to the impact point (not its tangent-plane x)."""
    summary, result = runner.run("projectile", {"speed": 1600.0, "elevation": 45.0},
                                 terms=["gravity", "coriolis", "curvature", "central-gravity"])
    traj = result.trajectory
    r_end = traj.event_states["ground"][0][0][:3]
    R = result.extras["model"].radius
    expected = _great_circle_range(r_end, 232.0, R)
    # tangent-plane range differs by ~ range^3 / (6 R^2) ~ 70 m here; the great circle agrees to round-off
    assert summary["metrics"]["range_m"] == pytest.approx(expected, rel=1e-9)
    az = math.radians(232.0)
    flat = r_end @ np.array([math.sin(az), math.cos(az), 0.0])
    assert abs(flat - expected) > 10.0


def _first_order_lateral(v, el, az, lat, g, Omega):
    """r1(T) . right with r1 = -W x v0 t^2 - (1/3) W x g t^3 (first order in W), T = 2 v sin(el) / g."""
    W = Omega * np.array([0.0, math.cos(lat), math.sin(lat)])
    v0 = v * np.array([math.cos(el) * math.sin(az), math.cos(el) * math.cos(az), math.sin(el)])
    gv = np.array([0.0, 0.0, -g])
    T = 2 * v * math.sin(el) / g
    r1 = -np.cross(W, v0) * T**2 - np.cross(W, gv) * T**3 / 3.0
    return r1 @ np.array([math.cos(az), -math.sin(az), 0.0])


@pytest.mark.parametrize("sets", [{}, {"latitude": -33.9, "azimuth": 10.0, "elevation": 70.0},
                                  {"latitude": 20.0, "azimuth": 95.0, "elevation": 15.0, "speed": 300.0}])
def test_projectile_theory_is_the_first_order_flat_vacuum_deflection(sets):
    """The scene's theory column equals a first-order formula written here (catches swapped arguments)."""
    summary, result = runner.run("projectile", sets)
    p = summary["params"]
    g = result.extras["g"]
    Omega = float(np.linalg.norm(result.extras["model"].omega.vector()))
    expected = _first_order_lateral(p["speed"], math.radians(p["elevation"]), math.radians(p["azimuth"]),
                                    math.radians(p["latitude"]), g, Omega)
    theory = summary["theory"]["lateral_deflection_m"]
    theory = theory["value"] if isinstance(theory, dict) else theory
    assert theory == pytest.approx(expected, rel=1e-9)
    flat_range = p["speed"] ** 2 * math.sin(2 * math.radians(p["elevation"])) / g
    rng = summary["theory"]["range_m"]
    rng = rng["value"] if isinstance(rng, dict) else rng
    assert rng == pytest.approx(flat_range, rel=1e-12)
