"""The rotating-Earth scenarios against closed forms and independent solve_ivp references."""

import math
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rotframe.app import runner
OMEGA = 2 * math.pi * 1.00273781191135448 / 86400.0  # Earth Rotation Angle rate, written out here


def run(name, method=None, **sets):
    summary, result = runner.run(name, {k: str(v) for k, v in sets.items()}, method=method)
    return summary


def normal_gravity(lat):
    s2 = math.sin(lat) ** 2
    return 9.7803253359 * (1 + 0.00193185265241 * s2) / math.sqrt(1 - 0.00669437999013 * s2)


# --- tower drop -------------------------------------------------------------


def test_reich_default_reproduces_the_historical_figure():
    s = run("tower-drop")
    assert s["method"] == "exact"
    assert 0.0274 < s["metrics"]["east_deflection_m"] < 0.0278  # Reich computed 27.6 mm (measured 28.4)
    assert s["metrics"]["north_deflection_m"] < 0  # equatorward, second order


@pytest.mark.parametrize("lat", [50.883, -33.0, 0.0])
def test_eastward_deflection_is_one_third_omega_g_t3_cos_lat(lat):
    s = run("tower-drop", latitude=lat, height=300)
    g = normal_gravity(math.radians(lat))
    t = math.sqrt(2 * 300 / g)
    first_order = OMEGA * g * t**3 * math.cos(math.radians(lat)) / 3
    # first order in Omega: the relative error is of order Omega t
    assert s["metrics"]["east_deflection_m"] == pytest.approx(first_order, rel=10 * OMEGA * t)


@pytest.mark.parametrize("method", ["exact", "splitting4", "dop853"])
def test_drop_matches_solve_ivp_of_the_rotating_frame_equations(method):
    lat = math.radians(50 + 53 / 60)  # the default, "50d53m"
    g = normal_gravity(lat)
    w = OMEGA * np.array([0.0, math.cos(lat), math.sin(lat)])

    def rhs(t, y):
        return np.concatenate([y[3:], [0, 0, -g] - 2 * np.cross(w, y[3:])])

    def ground(t, y):
        return y[2]

    ground.terminal = True
    ref = solve_ivp(rhs, (0, 20), [0, 0, 158.5, 0, 0, 0], method="DOP853", rtol=1e-13, atol=1e-15, events=ground)
    s = run("tower-drop", method=method)
    assert s["metrics"]["fall_time_s"] == pytest.approx(ref.t_events[0][0], rel=1e-10)
    assert s["metrics"]["east_deflection_m"] == pytest.approx(ref.y_events[0][0][0], rel=1e-8)
    assert s["metrics"]["north_deflection_m"] == pytest.approx(ref.y_events[0][0][1], rel=1e-5)


# --- Foucault -----------------------------------------------------------------


def test_pantheon_default_rate_period_and_duration():
    s = run("foucault")
    assert s["params"]["duration"] >= 3600
    assert s["diagnostics"]["simulated_hours"] >= 1.0
    assert "1 h" in " ".join(s["notes"])
    assert s["metrics"]["precession_rate_deg_per_hour"] == pytest.approx(11.33, abs=0.02)
    assert s["metrics"]["period_s"] == pytest.approx(16.42, abs=0.01)
    # default dop853 at rtol 1e-10 does not keep the string length by construction: its drift is bounded
    # by the tolerance times the length (6.7e-9 m); the splitting keeps it to round-off
    assert s["diagnostics"]["constraint_drift_m"] < 1e-10 * 67.0
    s = run("foucault", method="splitting", duration=600)
    assert s["diagnostics"]["constraint_drift_m"] < 1e-12


@pytest.mark.parametrize("lat", [48.846, -30.0, 0.0, 90.0, -90.0])
def test_small_angle_plane_turns_at_omega_sin_latitude(lat):
    s = run("foucault", latitude=lat, small_angle="true", duration=7200)
    expected = math.degrees(OMEGA * math.sin(math.radians(lat))) * 3600
    assert s["metrics"]["precession_rate_deg_per_hour"] == pytest.approx(expected, rel=1e-6, abs=1e-9)


@pytest.mark.parametrize("lat", [48.846, -48.846])
def test_full_pendulum_rate_includes_airy_precession(lat):
    # Released from rest in the rotating frame, the swing is an ellipse with minor axis
    # b = a Omega sin(lat) / w0, whose Airy precession (3/8) w0 a b / L^2 runs against the
    # Foucault turn: rate = Omega sin(lat) (1 - 3/8 (a/L)^2). Clockwise in the north.
    L, a = 67.0, 3.0
    s = run("foucault", latitude=lat, amplitude=a, length=L)
    foucault = math.degrees(OMEGA * math.sin(math.radians(lat))) * 3600
    expected = foucault * (1 - 3 / 8 * (a / L) ** 2)
    assert s["metrics"]["precession_rate_deg_per_hour"] == pytest.approx(expected, rel=3e-5)
    assert math.copysign(1, s["metrics"]["precession_rate_deg_per_hour"]) == math.copysign(1, lat)


def test_equator_pendulum_does_not_turn():
    s = run("foucault", latitude=0)
    assert abs(s["metrics"]["precession_rate_deg_per_hour"]) < 1e-6


def test_full_pendulum_agrees_with_solve_ivp_over_ten_periods():
    lat = math.radians(48.846)
    g = normal_gravity(lat)
    L, a = 67.0, 3.0
    w = OMEGA * np.array([0.0, math.cos(lat), math.sin(lat)])
    pivot = np.array([0, 0, L])

    def rhs(t, y):  # Lagrange multiplier form of the spherical pendulum, written independently
        r, v = y[:3], y[3:]
        n = (r - pivot) / L
        f = np.array([0, 0, -g]) - 2 * np.cross(w, v)
        tension = -(f @ n) - (v @ v) / L
        return np.concatenate([v, f + tension * n])

    y0 = [a, 0, L - math.sqrt(L * L - a * a), 0, 0, 0]
    ref = solve_ivp(rhs, (0, 164.0), y0, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    summary, result = runner.run("foucault", {"duration": "164", "step": "1e-3"}, method="splitting4")
    traj = result.trajectory
    assert np.max(np.abs(traj.r[-1, 0] - ref[:3])) < 1e-7


# --- inertial oscillation --------------------------------------------------------


@pytest.mark.parametrize("lat,sense", [(45.0, "clockwise"), (-45.0, "counter-clockwise"), (90.0, "clockwise")])
def test_inertial_period_and_radius(lat, sense):
    s = run("inertial-oscillation", latitude=lat, speed=0.7)
    f = 2 * OMEGA * abs(math.sin(math.radians(lat)))
    assert s["metrics"]["period_s"] == pytest.approx(2 * math.pi / f, rel=1e-9)
    assert s["metrics"]["radius_m"] == pytest.approx(0.7 / f, rel=1e-9)
    assert s["diagnostics"]["sense"] == sense


def test_inertial_oscillation_on_the_equator_goes_straight():
    s = run("inertial-oscillation", latitude=0)
    assert math.isinf(s["metrics"]["period_s"])


# --- projectile -------------------------------------------------------------------


@pytest.mark.parametrize("lat", [49.6, -49.6])
def test_projectile_deflects_right_in_the_north_left_in_the_south(lat):
    s = run("projectile", latitude=lat, azimuth=0, speed=800, elevation=45)
    assert math.copysign(1, s["metrics"]["lateral_deflection_m"]) == math.copysign(1, lat)


@pytest.mark.parametrize("method", [None, "dop853"])
def test_projectile_matches_solve_ivp_flat_vacuum(method):
    lat, az, el, V = math.radians(49.6), math.radians(232.0), math.radians(50.0), 1600.0
    g = normal_gravity(lat)
    w = OMEGA * np.array([0.0, math.cos(lat), math.sin(lat)])
    aim = np.array([math.sin(az), math.cos(az), 0.0])
    right = np.array([math.cos(az), -math.sin(az), 0.0])

    def rhs(t, y):
        return np.concatenate([y[3:], [0, 0, -g] - 2 * np.cross(w, y[3:])])

    def ground(t, y):
        return y[2] if t > 1 else 1.0

    ground.terminal = True
    v0 = V * (math.cos(el) * aim + [0, 0, math.sin(el)])
    ref = solve_ivp(rhs, (0, 400), [0, 0, 0, *v0], method="DOP853", rtol=1e-13, atol=1e-12, events=ground)
    hit = ref.y_events[0][0][:3]
    s = run("projectile", method=method)
    assert s["method"] == (method or "exact")  # the default terms are linear: the exact flow
    assert s["metrics"]["flight_time_s"] == pytest.approx(ref.t_events[0][0], rel=1e-9)
    assert s["metrics"]["range_m"] == pytest.approx(hit @ aim, rel=1e-9)
    assert s["metrics"]["lateral_deflection_m"] == pytest.approx(hit @ right, rel=1e-7)


def test_curvature_matters_for_the_paris_gun_and_not_for_the_tower():
    gun = runner.run("projectile", {})[0]
    curved = runner.run("projectile", {}, terms=["central-gravity", "coriolis", "curvature"])[0]
    assert (gun["method"], curved["method"]) == ("exact", "dop853")  # no exact flow once gravity turns
    assert curved["metrics"]["range_m"] > gun["metrics"]["range_m"] * 1.01  # the ground falls away


# --- bad input, through the command line ---------------------------------------------


@pytest.mark.parametrize("args", [
    ["tower-drop", "--set", "latitude=91"],
    ["tower-drop", "--set", "latitude=-90.5"],
    ["tower-drop", "--set", "height=-3"],
    ["foucault", "--set", "length=-67"],
    ["foucault", "--set", "length=3 kg"],
    ["foucault", "--set", "amplitude=70"],
    ["projectile", "--set", "elevation=0"],
])
def test_impossible_earth_inputs_exit_2(tmp_path, args):
    res = subprocess.run([sys.executable, "-m", "rotframe", "run", *args, "--no-record"], cwd=tmp_path,
                         capture_output=True, text=True)
    assert res.returncode == 2, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1


def test_latitude_strings_parse():
    s = run("tower-drop", latitude="48d50m46s N")
    assert s["params"]["latitude"] == pytest.approx(48 + 50 / 60 + 46 / 3600)
    s = run("tower-drop", latitude="33d52m S")
    assert s["params"]["latitude"] == pytest.approx(-(33 + 52 / 60))


def test_audit_shows_what_each_optional_term_changes(tmp_path):
    import json

    def audit(name):
        res = subprocess.run([sys.executable, "-m", "rotframe", "run", name, "--audit", "--json", "--no-record"],
                             cwd=tmp_path, capture_output=True, text=True)
        assert res.returncode == 0, res.stderr
        return json.loads(res.stdout)["audit"]["terms"]

    tower = audit("tower-drop")
    assert tower["centrifugal"]["switched"] == "on"
    assert tower["centrifugal"]["peak_acceleration_m_s2"] < 1e-5
    assert abs(tower["centrifugal"]["metrics"]["east_deflection_m"]["relative"]) < 1e-6
    gun = audit("projectile")
    assert abs(gun["curvature"]["metrics"]["range_m"]["relative"]) > 1e-2
    assert gun["central-gravity"]["peak_acceleration_m_s2"] > 0.1
