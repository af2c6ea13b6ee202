"""Angles as people write them: astropy's reading is the reference, plus hemisphere letters.

The reference is astropy's own parser (``Angle(text, unit=deg)``), never
rotframe's; hand-written cases fix the meaning of the forms the issue names.
"""

from __future__ import annotations

import math

import astropy.units as u
import pytest
from astropy.coordinates import Angle
from hypothesis import given, settings
from hypothesis import strategies as st

from rotframe import earth
from rotframe.errors import ScenarioError
from rotframe.app import scenario
ASTROPY_FORMS = ["48d50m46s", "48d50m46.5s", "48 50 46", "48:50:46", "48°50′46″", "48.846 deg", "0.8 rad",
                 "100 arcmin", "-33.9", "-33d54m", "12h30m", "1d", "46s", "+45d", "48d50m46s N", "48d50m46s S",
                 "48°50′46″ N", "48 50 46 S"]


@pytest.mark.parametrize("text", ASTROPY_FORMS)
def test_every_astropy_form_means_what_astropy_says(text):
    expected = Angle(text, unit=u.deg).deg
    assert math.degrees(earth.parse_angle(text)) == pytest.approx(expected, rel=1e-15, abs=1e-15)


@pytest.mark.parametrize("text, deg", [
    ("48d50m46s", 48 + 50 / 60 + 46 / 3600),  # the trailing s is seconds, not south
    ("33.9 S", -33.9), ("45 N", 45.0), ("45N", 45.0), ("33.9S", -33.9),
    ("48d50m46s N", 48 + 50 / 60 + 46 / 3600), ("48d50m46s S", -(48 + 50 / 60 + 46 / 3600)),
    ("48°50′46″ N", 48 + 50 / 60 + 46 / 3600), ("3e1 deg", 30.0), ("0.5 rad S", -math.degrees(0.5)),
])
def test_latitudes_by_hand(text, deg):
    assert math.degrees(earth.parse_latitude(text)) == pytest.approx(deg, rel=1e-14)


@pytest.mark.parametrize("text, deg", [("70.6 W", -70.6), ("2d21m E", 2.35), ("70.6W", -70.6), ("-70.6", -70.6)])
def test_longitudes_by_hand(text, deg):
    assert math.degrees(earth.parse_longitude(text)) == pytest.approx(deg, rel=1e-14)


@pytest.mark.parametrize("text, deg", [("30 W", -30.0), ("30 E", 30.0), ("232d30m15s", 232 + 30 / 60 + 15 / 3600)])
def test_azimuths_by_hand(text, deg):
    assert math.degrees(earth.parse_azimuth(text)) == pytest.approx(deg, rel=1e-14)


@pytest.mark.parametrize("parse, text", [
    (earth.parse_latitude, "-45d S"), (earth.parse_latitude, "-45 N"), (earth.parse_latitude, "45 E"),
    (earth.parse_latitude, "45 W"), (earth.parse_longitude, "45 N"), (earth.parse_longitude, "-2 E"),
    (earth.parse_azimuth, "30 S"), (earth.parse_angle, "-45 N"), (earth.parse_latitude, "95 N"),
    (earth.parse_latitude, "45 kg"), (earth.parse_latitude, "north"),
])
def test_contradictions_and_wrong_letters_are_refused(parse, text):
    with pytest.raises(ScenarioError) as exc:
        parse(text, "thekey")
    assert "thekey" in str(exc.value) and text in str(exc.value)


_dms = st.tuples(st.integers(0, 89), st.integers(0, 59), st.integers(0, 59), st.integers(0, 999),
                 st.sampled_from("NS"), st.sampled_from(["{d}d{m}m{s}.{f:03d}s {h}", "{d}d{m}m{s}.{f:03d}s{h}",
                                                         "{d}°{m}′{s}.{f:03d}″ {h}", "{d} {m} {s}.{f:03d} {h}",
                                                         "{d}:{m}:{s}.{f:03d} {h}"]))


@settings(max_examples=200, deadline=None)
@given(_dms)
def test_round_trip_dms_with_hemisphere(parts):
    d, m, s, f, h, form = parts
    text = form.format(d=d, m=m, s=s, f=f, h=h)
    value = (d + m / 60 + (s + f / 1000) / 3600) * (-1 if h == "S" else 1)
    got = math.degrees(earth.parse_latitude(text))
    assert got == pytest.approx(value, abs=1e-12)
    assert got == pytest.approx(Angle(text, unit=u.deg).deg, abs=1e-12)  # and astropy agrees


@settings(max_examples=100, deadline=None)
@given(st.floats(0.0, 179.999, allow_nan=False), st.sampled_from("EW"))
def test_round_trip_plain_number_with_letter(x, h):
    text = f"{x!r} {h}"
    assert math.degrees(earth.parse_longitude(text)) == pytest.approx(-x if h == "W" else x, abs=1e-12)


@pytest.mark.parametrize("value, deg", [("48d50m46s", 48 + 50 / 60 + 46 / 3600), ("33.9 S", -33.9), ("45 N", 45.0),
                                        ("48°50′46″ N", 48 + 50 / 60 + 46 / 3600)])
def test_scenario_set_latitude(value, deg):
    values = scenario.load("tower-drop").with_values({"latitude": value})
    assert values["latitude"] == pytest.approx(deg, rel=1e-14)


@pytest.mark.parametrize("key, value", [("latitude", "-45d S"), ("latitude", "45 E"), ("azimuth", "30 N"),
                                        ("elevation", "45 N")])
def test_cli_refuses_contradictions_with_exit_2(key, value, capsys):
    from rotframe.app.cli import main

    name = "tower-drop" if key == "latitude" else "projectile"
    assert main(["run", name, "--set", f"{key}={value}", "--no-record", "--json"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and key in err and value in err and "Traceback" not in err
