"""Metrics never come from aliased samples or from round-off (issue 11, part 1 and 4).

Every reference here is independent of the code under test: closed forms written
out in the test, or scipy's solve_ivp (DOP853) with tolerances far below the
comparison's. A metric that the run cannot resolve must be null (NaN / JSON null)
with a note that says why.
"""

import json
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


def null(x):
    """JSON null: None, NaN, or an infinite value (which the JSON output writes as null)."""
    return x is None or (isinstance(x, float) and not math.isfinite(x))


def notes(s):
    return " ".join(s.get("notes", []))


# --- free symmetric top ------------------------------------------------------------


def test_small_top_with_earth_duration_is_null_with_a_note_not_an_alias():
    # the case: before, 884522 s against the true 1.2566 s
    s = run("free-top", i1=2, i3=3, omega3=10, omega_perp=0.1)
    assert null(s["metrics"]["body_precession_period_s"])
    assert null(s["metrics"]["space_precession_rate_rad_s"])
    assert "duration <=" in notes(s) and "periods" in notes(s)
    assert s["warnings"] == []


def test_small_top_with_a_fitting_duration_matches_the_closed_form():
    # body frame: (w1, w2) turns at k = w3 (I3 - I1) / I1; in space the axis circles L at |L| / I1.
    # Exact flow, so the measured rates agree to round-off (1e-10 leaves room for the fit).
    s = run("free-top", i1=2, i3=3, omega3=10, omega_perp=0.1, duration=100)
    k = 10 * (3 - 2) / 2
    assert s["metrics"]["body_precession_period_s"] == pytest.approx(2 * math.pi / k, rel=1e-10)
    L = math.hypot(2 * 0.1, 3 * 10)
    assert s["metrics"]["space_precession_rate_rad_s"] == pytest.approx(L / 2, rel=1e-10)
    assert s["warnings"] == []


@pytest.mark.parametrize("method", ["lie-poisson4", "rk4"])
def test_small_top_other_methods_agree_with_the_closed_form(method):
    s = run("free-top", method=method, i1=2, i3=3, omega3=10, omega_perp=0.1, duration=20)
    assert s["metrics"]["body_precession_period_s"] == pytest.approx(2 * math.pi / 5, rel=1e-6)


def test_free_top_spinning_about_an_equatorial_axis_has_no_body_precession():
    # omega3 = 0: omega = (w_perp, 0, 0) is a principal axis, fixed in the body; the symmetry axis
    # is perpendicular to L and circles it at |L| / I1 = w_perp.
    s = run("free-top", omega3=0)
    assert null(s["metrics"]["body_precession_period_s"])
    assert "equatorial" in notes(s)
    assert s["metrics"]["space_precession_rate_rad_s"] == pytest.approx(7.292115e-11, rel=1e-9)


def test_free_top_spinning_about_its_symmetry_axis_precesses_nowhere():
    s = run("free-top", omega_perp=0)
    assert null(s["metrics"]["body_precession_period_s"])
    assert null(s["metrics"]["space_precession_rate_rad_s"])
    assert "omega_perp = 0" in notes(s)


def test_spherical_top_has_no_body_precession():
    s = run("free-top", i1=1, i3=1, omega3=1, omega_perp=0.1, duration=100)
    assert null(s["metrics"]["body_precession_period_s"])
    assert "i1 = i3" in notes(s)


@pytest.mark.parametrize("omega3", [OMEGA, -OMEGA])
def test_euler_period_in_sidereal_days_is_positive_whatever_the_sense_of_spin(omega3):
    # Euler's period, for a body spinning at the Earth's sidereal rate, is A / (C - A) sidereal days
    # (2 pi / OMEGA each) for either sense of the spin. OMEGA (not 7.292115e-5, 2e-9 off) so that
    # the identity holds to round-off: the sidereal day is the Earth's whatever the body.
    A, C = 8.0101e37, 8.03641e37
    s = run("free-top", omega3=omega3)
    assert s["diagnostics"]["body_precession_period_sidereal_days"] == pytest.approx(A / (C - A), rel=1e-9)
    assert s["metrics"]["body_precession_period_s"] > 0
    assert "with the spin" in s["diagnostics"]["body_precession_sense"]


def test_prolate_top_precesses_against_its_spin():
    s = run("free-top", i1=3, i3=2, omega3=10, omega_perp=0.1, duration=50)
    assert "against the spin" in s["diagnostics"]["body_precession_sense"]
    assert s["metrics"]["body_precession_period_s"] == pytest.approx(2 * math.pi * 3 / (10 * 1), rel=1e-10)


def test_omega3_zero_runs_without_traceback_from_the_command_line():
    out = subprocess.run([sys.executable, "-m", "rotframe", "run", "free-top", "--set", "omega3=0", "--no-record",
                          "--json"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    s = json.loads(out.stdout)
    assert s["metrics"]["body_precession_period_s"] is None
    assert s["warnings"] == []


# --- inertial oscillation ------------------------------------------------------------


def test_years_of_inertial_oscillation_give_the_true_period_and_sense():
    # before: 10 yr gave 384641 s and counter-clockwise (aliased: 2000 samples for 5180 turns); 2 yr
    # (1036 turns) aliased the same way. Truth: 2 pi / (2 Omega sin 45), clockwise.
    s = run("inertial-oscillation", duration="2 yr")
    period = 2 * math.pi / (2 * OMEGA * math.sin(math.radians(45)))
    assert s["metrics"]["period_s"] == pytest.approx(period, rel=1e-9)
    assert s["metrics"]["radius_m"] == pytest.approx(0.5 / (2 * OMEGA * math.sin(math.radians(45))), rel=1e-9)
    assert s["diagnostics"]["sense"] == "clockwise"
    assert s["warnings"] == []


def test_too_long_inertial_run_is_null_with_a_note():
    s = run("inertial-oscillation", duration="1000 yr")
    assert null(s["metrics"]["period_s"]) and null(s["metrics"]["radius_m"])
    assert "duration <=" in notes(s)


def test_inertial_oscillation_at_rest_or_on_the_equator():
    s = run("inertial-oscillation", speed=0)
    assert null(s["metrics"]["period_s"]) and "rest" in notes(s)
    s = run("inertial-oscillation", latitude=0)
    assert math.isinf(s["metrics"]["period_s"]) and "equator" in notes(s)  # infinite: JSON null


def test_inertial_oscillation_near_the_equator_measures_a_period_longer_than_the_run():
    # the velocity turns by 4e-11 rad in two days: far above round-off, so the rate is measurable
    lat = 1e-10
    s = run("inertial-oscillation", latitude=lat)
    f = 2 * OMEGA * math.sin(math.radians(lat))
    assert s["metrics"]["period_s"] == pytest.approx(2 * math.pi / f, rel=1e-4)
    assert s["metrics"]["radius_m"] == pytest.approx(0.5 / f, rel=1e-4)


# --- Dzhanibekov -----------------------------------------------------------------------


def _euler_flip_interval(inertia, w0, n_flips=6):
    """Mean interval between sign changes of w2 from Euler's equations by solve_ivp (rtol 1e-12)."""
    I = np.asarray(inertia, float)

    def rhs(t, w):
        return [(I[1] - I[2]) * w[1] * w[2] / I[0], (I[2] - I[0]) * w[2] * w[0] / I[1],
                (I[0] - I[1]) * w[0] * w[1] / I[2]]

    def crossing(t, w):
        return w[1]

    sol = solve_ivp(rhs, (0, 400), w0, method="DOP853", rtol=1e-12, atol=1e-14, events=crossing)
    t = sol.t_events[0][:n_flips]
    return (t[-1] - t[0]) / (len(t) - 1)


def test_long_dzhanibekov_run_gives_the_true_flip_interval():
    # before: 34.65 s against 19.55 s (4000 samples over 1e5 s); the reference is solve_ivp
    # with rtol 1e-12, whose event times are good to ~1e-9 s: 1e-6 relative is its margin
    ref = _euler_flip_interval([1, 2, 3], [0.01, 1.0, 0.01])
    s = run("dzhanibekov", duration=1e5)
    assert ref == pytest.approx(19.55, abs=0.01)
    assert s["metrics"]["flip_interval_s"] == pytest.approx(ref, rel=1e-6)
    assert s["warnings"] == []


def test_too_long_dzhanibekov_run_is_null_with_a_note():
    s = run("dzhanibekov", duration=1e7)
    assert null(s["metrics"]["flip_interval_s"])
    assert "duration <=" in notes(s)


# --- heavy top ---------------------------------------------------------------------------


def test_heavy_top_without_gravity_does_not_nod():
    # g = 0 with L along the symmetry axis: the axis is fixed in space, theta stays at theta0;
    # before, a "nutation period" of milliseconds came from 1e-12 degree round-off wiggles
    s = run("heavy-top", g=0)
    assert null(s["metrics"]["nutation_period_s"])
    assert "no nutation" in notes(s)
    assert s["metrics"]["theta_max_deg"] == pytest.approx(20, abs=1e-9)
    assert s["warnings"] == []


def test_sleeping_top_has_no_nutation_period():
    s = run("heavy-top", theta0=0)
    assert null(s["metrics"]["nutation_period_s"])


def test_torque_free_top_nods_with_the_closed_form_period():
    # g = 0 and a precession rate: L is not along the axis, which circles the fixed L at |L| / I1,
    # so theta (from the vertical) oscillates with period 2 pi I1 / |L|. ZXZ rates at phi = psi = 0:
    # w_body = (0, phidot sin theta, phidot cos theta + psidot). Maxima on samples: dt / (n - 1) ~ 1e-5.
    i1, i3, th, pd, sd = 1.9e-4, 2.5e-5, math.radians(20), 5.0, 300.0
    L = math.hypot(i1 * pd * math.sin(th), i3 * (pd * math.cos(th) + sd))
    s = run("heavy-top", g=0, phidot0=pd)
    assert s["metrics"]["nutation_period_s"] == pytest.approx(2 * math.pi * i1 / L, rel=1e-3)
    assert s["warnings"] == []


def test_long_heavy_top_run_is_null_with_a_note():
    s = run("heavy-top", duration=2e4, step=0.01)
    assert all(null(s["metrics"][k]) for k in ("theta_min_deg", "theta_max_deg", "nutation_period_s"))
    assert "duration <=" in notes(s)


# --- tower drop: underflow and denormal inputs ---------------------------------------------


def test_subnormal_height_is_refused_with_exit_2_and_one_line():
    out = subprocess.run([sys.executable, "-m", "rotframe", "run", "tower-drop", "--set", "height=1e-320",
                          "--no-record"], capture_output=True, text=True)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "height" in lines[0] and "1e-320" in lines[0]


@pytest.mark.parametrize("h", [1e-30, 1e-12, 1e-3])
def test_tiny_drops_fall_in_sqrt_2h_over_g(h):
    # before: the fixed 1 s margin in the duration left a 1e-3 s bracket that 100 bisections
    # could not shrink to the true fall time. Corrections to sqrt(2h/g) are (Omega t)^2.
    g = 9.7803253359 * (1 + 0.00193185265241 * math.sin(math.radians(50 + 53 / 60)) ** 2) / math.sqrt(
        1 - 0.00669437999013 * math.sin(math.radians(50 + 53 / 60)) ** 2)
    for method in ("exact", "dop853", "rk4"):
        s = run("tower-drop", method=method, height=h)
        assert s["metrics"]["fall_time_s"] == pytest.approx(math.sqrt(2 * h / g), rel=1e-9), method


def test_deflections_below_the_float_range_are_null():
    s = run("tower-drop", height=1e-300)
    assert null(s["metrics"]["east_deflection_m"]) and "normal range" in notes(s)
    assert s["metrics"]["fall_time_s"] > 0


# --- Foucault --------------------------------------------------------------------------------


def test_short_foucault_run_does_not_report_a_rate():
    s = run("foucault", duration=5)
    assert null(s["metrics"]["precession_rate_deg_per_hour"])
    assert "hours_per_turn" not in s["diagnostics"]


def test_small_angle_uses_the_exact_propagator_as_documented():
    s = run("foucault", small_angle="true")
    assert s["method"] == "exact"
    s = run("foucault")
    assert s["method"] == "dop853"  # the full pendulum's default (cheapest for its accuracy in the bench)


# --- every null has a note --------------------------------------------------------------------


@pytest.mark.parametrize("name,sets", [
    ("free-top", {"i1": 2, "i3": 3, "omega3": 10, "omega_perp": 0.1}),
    ("free-top", {"omega3": 0}), ("free-top", {"omega_perp": 0}),
    ("inertial-oscillation", {"duration": "1000 yr"}), ("inertial-oscillation", {"latitude": 0}),
    ("dzhanibekov", {"duration": 5}), ("heavy-top", {"g": 0}), ("heavy-top", {"theta0": 0}),
    ("tower-drop", {"height": 1e-300}), ("foucault", {"duration": 5}),
])
def test_every_null_metric_comes_with_a_note(name, sets):
    s = run(name, **sets)
    assert any(null(v) for v in s["metrics"].values())
    assert s.get("notes")


# --- extreme but allowed inputs ----------------------------------------------------------------


def test_inertial_circle_of_a_nearly_still_puck_keeps_its_radius():
    # speed 1e-300: the positions (~1e-296 m) square to zero in float64 unless the fit is scaled
    s = run("inertial-oscillation", speed=1e-300)
    assert s["metrics"]["radius_m"] == pytest.approx(1e-300 / (2 * OMEGA * math.sin(math.radians(45))), rel=1e-9)


def test_full_pendulum_swing_at_round_off_of_the_string_is_null_with_a_note():
    s = run("foucault", amplitude=1e-200)
    assert null(s["metrics"]["precession_rate_deg_per_hour"]) and "small_angle" in notes(s)
    assert s["warnings"] == []


def test_heavy_top_run_shorter_than_a_nutation_does_not_report_turning_points():
    s = run("heavy-top", duration=1e-3)
    assert null(s["metrics"]["theta_max_deg"]) and "shorter than one nutation period" in notes(s)
    assert s["warnings"] == []
