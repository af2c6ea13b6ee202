"""Each scene's theory value against the test's own formula, and no warning from a correct default run.

A planted error in a scene's theory constant only made the run warn, and no test compared the
theory with an independent value (issue 33). Here every theory value a default run prints is
recomputed from the parameters it reports, by formulas and solvers written in this file (scipy's
solve_ivp and brentq, closed forms), never by the scene's code.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import rotframe

#: Earth's sidereal rate from the IERS ratio of the sidereal to the solar day (not rotframe's constant)
OMEGA_EARTH = 2 * math.pi * 1.00273781191135448 / 86400.0


@pytest.fixture(scope="module")
def runs():
    names = ("turntable", "inertial-oscillation", "free-top", "dzhanibekov", "cr3bp", "tumbling-ball")
    return {name: rotframe.run(name) for name in names}


@pytest.mark.parametrize("name", ["turntable", "inertial-oscillation", "free-top", "dzhanibekov", "cr3bp",
                                  "tumbling-ball"])
def test_a_correct_default_run_gives_no_warning(runs, name):
    assert runs[name].warnings == []


def test_turntable_turns(runs):
    p = runs["turntable"].params
    T = p["duration"]
    assert runs["turntable"].theory["turns"] == pytest.approx((p["omega0"] * T + 0.5 * p["alpha"] * T * T)
                                                              / (2 * math.pi), rel=1e-13)
    assert runs["turntable"].theory["position_error_m"] == 0.0


def test_inertial_oscillation_period_and_radius(runs):
    p = runs["inertial-oscillation"].params
    f = 2 * OMEGA_EARTH * math.sin(math.radians(p["latitude"]))
    theory = runs["inertial-oscillation"].theory
    assert theory["period_s"] == pytest.approx(2 * math.pi / f, rel=1e-9)
    assert theory["radius_m"] == pytest.approx(p["speed"] / f, rel=1e-9)


def test_free_top_precessions(runs):
    p = runs["free-top"].params
    body_rate = (p["i3"] - p["i1"]) / p["i1"] * p["omega3"]
    L = math.hypot(p["i1"] * p["omega_perp"], p["i3"] * p["omega3"])
    theory = runs["free-top"].theory
    assert theory["body_precession_period_s"] == pytest.approx(2 * math.pi / abs(body_rate), rel=1e-9)
    assert theory["space_precession_rate_rad_s"] == pytest.approx(L / p["i1"], rel=1e-9)


def test_dzhanibekov_flip_interval_against_solve_ivp(runs):
    p = runs["dzhanibekov"].params
    inertia = np.array([p["i1"], p["i2"], p["i3"]])

    def euler(t, L):
        w = L / inertia
        return np.cross(L, w)

    def flip(t, L):
        return L[1]

    sol = solve_ivp(euler, (0, p["duration"]), inertia * np.array(p["omega"]), method="DOP853", rtol=1e-12,
                    atol=1e-14, events=flip)
    crossings = sol.t_events[0]
    interval = (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    assert runs["dzhanibekov"].theory["flip_interval_s"] == pytest.approx(interval, rel=1e-8)


def test_cr3bp_collinear_points_by_the_tests_own_roots(runs):
    mu = runs["cr3bp"].params["mu"]

    def along_x(x):  # the effective acceleration on the x axis of the co-rotating frame (omega = 1)
        d1, d2 = x + mu, x - 1 + mu
        return x - (1 - mu) * d1 / abs(d1) ** 3 - mu * d2 / abs(d2) ** 3

    eps = 1e-6
    roots = (brentq(along_x, -mu + eps, 1 - mu - eps, xtol=1e-15), brentq(along_x, 1 - mu + eps, 3.0, xtol=1e-15),
             brentq(along_x, -3.0, -mu - eps, xtol=1e-15))
    theory = runs["cr3bp"].theory
    for key, x in zip(("L1_x", "L2_x", "L3_x"), roots):
        assert theory[key] == pytest.approx(x, abs=1e-12), key
    assert theory["left_L4"] == float(mu > (1 - math.sqrt(23 / 27)) / 2)  # Routh's criterion


def test_tumbling_ball_theory_is_the_straight_line(runs):
    assert runs["tumbling-ball"].theory["position_error_m"] == 0.0
