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
