"""Runs far shorter than their scene's time scales: a clean exit, and no rate fitted from round-off.

A line fitted in the units of a 1e-169 s run (``np.polyfit``) failed inside LAPACK
(an internal error, exit 1); `rotframe.numerics.linefit.line_fit` fits on [0, 1]
instead. What such a run cannot resolve is null with a note.
"""

import json
import math

import numpy as np
import pytest

from cli_calls import assert_clean, call
from rotframe.numerics.linefit import line_fit

DURATION_SCENES = ["foucault", "free-top", "inertial-oscillation", "turntable", "dzhanibekov", "heavy-top",
                   "tumbling-ball"]


@pytest.mark.parametrize("scale", [1e-300, 1e-169, 1.0, 1e150])
def test_line_fit_finds_the_slope_at_every_time_scale(scale):
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0.0, 1.0, 50)) * scale
    y = 0.7 - 2.5 * (t / scale)  # slope -2.5 / scale in the units of t
    slope, resid, error = line_fit(t, y)
    # np.polyfit in the units [0, 1] is the independent reference for the fit itself
    ref = np.polyfit(t / scale, y, 1)[0] / scale
    assert math.isclose(slope, ref, rel_tol=1e-12)
    assert math.isclose(slope * scale, -2.5, rel_tol=1e-12)
    assert np.max(np.abs(resid)) < 1e-14 and error * scale < 1e-14


def test_line_fit_standard_error_is_the_textbook_one():
    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 10.0, 200)
    y = 1.0 + 0.3 * t + rng.normal(0.0, 0.1, t.size)
    slope, resid, error = line_fit(t, y)
    n = t.size
    textbook = math.sqrt(np.sum(resid**2) / (n - 2) / np.sum((t - t.mean()) ** 2))
    assert math.isclose(error, textbook, rel_tol=1e-10)
    assert abs(slope - 0.3) < 5 * error


@pytest.mark.parametrize("name", DURATION_SCENES)
@pytest.mark.parametrize("duration", ["1e-300", "1.2351025734603783e-169", "1e-9"])
def test_a_vanishing_duration_exits_cleanly(capsys, name, duration):
    code, out, err = call(capsys, "run", name, "--set", f"duration={duration}", "--no-record", "--json")
    assert_clean(code, out, err)


def test_free_top_space_rate_over_a_nanosecond_is_null_with_a_note(capsys):
    # e3 turns 7e-14 rad about L in 1e-9 s: round-off of the angles (1e-16 rad) is a 1e-3 part of it,
    # far over the exact flow's 1e-9 tolerance, so the rate is not a number the run can give
    code, out, err = call(capsys, "run", "free-top", "--set", "duration=1e-9", "--no-record", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["metrics"]["space_precession_rate_rad_s"] is None
    assert any("space_precession_rate_rad_s not measured" in n for n in summary["notes"])
    # the body precession angle starts at 0, where round-off is tiny: its fit resolves the closed form
    assert math.isclose(summary["metrics"]["body_precession_period_s"],
                        summary["theory"]["body_precession_period_s"], rel_tol=1e-9)


@pytest.mark.parametrize("speed", ["1e-160", "1e-300"])
def test_a_shot_whose_apex_is_subnormal_measures_nothing_at_its_landing(capsys, speed):
    # heights below 1e-290 m keep a few digits or none: speed 1e-160 m/s gave the flight time 0.5 % off,
    # 1e-170 m/s a factor 667, unflagged; the closed form's flight time (2 v sin(el) / g) is still shown
    code, out, err = call(capsys, "run", "projectile", "--set", f"speed={speed}", "--no-record", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert all(summary["metrics"][k] is None for k in ("range_m", "lateral_deflection_m", "flight_time_s"))
    assert any("apex" in n and "normal range" in n for n in summary["notes"])
    el = math.radians(summary["params"]["elevation"])
    assert math.isclose(summary["theory"]["flight_time_s"], 2 * float(speed) * math.sin(el) / 9.80665, rel_tol=1e-2)


def test_a_metric_its_own_tolerance_cannot_resolve_is_null_with_a_note(capsys):
    # a shot at 1e-12 m/s: the lateral deflection is 1e-42 m in theory, the run resolves it to 1e-34 m
    # (round-off of positions of 1e-25 m); it gave -1.2e-41 m, the wrong sign, inside that tolerance
    code, out, err = call(capsys, "run", "projectile", "--set", "speed=1e-12", "--no-record", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["metrics"]["lateral_deflection_m"] is None
    assert any(n.startswith("lateral_deflection_m not measured") for n in summary["notes"])
    assert summary["metrics"]["range_m"] is not None  # resolved: kept


def test_unresolved_metrics_keeps_error_metrics_and_resolved_ones():
    from rotframe.app.runner import unresolved_metrics

    analysis = {"metrics": {"err_m": 1e-16, "big": 2.0, "tiny": 3e-9, "bare": 5.0},
                "theory": {"err_m": 0.0, "big": 2.0, "tiny": 1e-9, "bare": 5.0},
                "tolerance": {"err_m": 1e-8, "big": 1e-8, "tiny": 1e-8}}
    out = unresolved_metrics(analysis)
    assert out["metrics"]["err_m"] == 1e-16 and out["metrics"]["big"] == 2.0 and out["metrics"]["bare"] == 5.0
    assert math.isnan(out["metrics"]["tiny"]) and len(out["notes"]) == 1
    assert analysis["metrics"]["tiny"] == 3e-9  # the scene's own analysis is not changed


def test_norm3_neither_overflows_nor_underflows():
    from rotframe.numerics.vectors import norm3

    x = np.array([[3e200, 4e200, 0.0], [3e-200, 0.0, 4e-200], [1.0, 2.0, 2.0]])
    assert np.allclose(norm3(x) / np.array([5e200, 5e-200, 3.0]), 1.0, rtol=1e-15, atol=0)


@pytest.mark.parametrize("setting", ["speed=1.234207595334801e+170", "duration=1.1509925876644392e+85"])
def test_a_turntable_at_huge_scales_is_not_called_diverged(capsys, setting):
    # |r - oracle| by np.linalg.norm squared 1e170 m into inf: a "diverged: inf m" exit 3 for a finite run
    code, out, err = call(capsys, "run", "turntable", "--set", setting, "--no-record", "--json")
    assert code == 0, err


@pytest.mark.parametrize("setting", ["omega3=1e300", "omega_perp=1e300"])
def test_a_free_top_whose_momentum_overflows_is_refused_in_one_line(capsys, setting):
    # L = I omega overflowed before the check that refuses it (an internal error where warnings are errors)
    code, out, err = call(capsys, "run", "free-top", "--set", setting, "--no-record", "--json")
    assert code == 2 and "overflows a float64" in err, err


@pytest.mark.parametrize("setting, code", [("mass=1e300", 3), ("length=1e300", 3), ("psidot0=1e150", 0),
                                           ("wobble=-1e150", 0)])
def test_a_heavy_top_at_huge_scales_exits_cleanly(capsys, setting, code):
    # the first step's failure carried the kernel's raw arrays where a trajectory was expected, and a
    # fixed-step error bound (w h)^p overflowed a Python float: both were internal errors (exit 1)
    got, out, err = call(capsys, "run", "heavy-top", "--set", setting, "--no-record", "--json")
    assert_clean(got, out, err)
    assert got == code, err
