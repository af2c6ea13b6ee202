"""Tests of rotframe.earth against independent references (written again here)."""

import math
import socket
import subprocess
import sys

import astropy.units as u
import numpy as np
import pytest
from astropy.coordinates import Angle, EarthLocation, Latitude
from astropy.utils import data as astropy_data
from astropy.utils import iers

from rotframe import earth
from rotframe.earth import (
    G0,
    GM_EARTH,
    OMEGA_EARTH,
    R_EARTH,
    SITES,
    Site,
    ecef_to_enu,
    ecef_to_enu_matrix,
    effective_gravity_enu,
    enu_to_ecef,
    geocentric_latitude,
    gravity_altitude,
    gravity_central,
    gravity_uniform,
    normal_gravity,
    omega_enu,
    parse_angle,
    parse_latitude,
    parse_length,
    parse_longitude,
    plumb_tilt,
)
from rotframe.errors import ScenarioError

DEG = math.pi / 180.0


# ------------------------------------------------------------------ constants


def test_omega_earth_is_the_earth_rotation_angle_rate():
    # IERS Conventions 2010 eq. 5.15: dERA/dt = 2 pi x 1.00273781191135448 per UT1 day.
    expected = 2.0 * math.pi * 1.00273781191135448 / 86400.0
    assert OMEGA_EARTH == pytest.approx(expected, rel=1e-13)
    # The value quoted in IERS/IAU documents, 7.292115146706979e-5 rad/s ...
    assert OMEGA_EARTH == pytest.approx(7.292115146706979e-5, rel=1e-13)
    # ... which rounds to the published value 7.292115147e-5 (docs/physics/earth.md) (10 significant digits).
    assert OMEGA_EARTH == pytest.approx(7.292115147e-5, rel=1e-10)
    # Not one turn per sidereal day against the equinox, nor one turn per solar day.
    assert abs(OMEGA_EARTH - 2 * math.pi / 86164.0905) > 5e-13
    assert OMEGA_EARTH / (2 * math.pi / 86400.0) == pytest.approx(1.0027378, rel=1e-7)


def test_omega_earth_is_the_same_float_as_astropys_unit_arithmetic():
    # rotframe computes it without astropy (so that importing it is cheap); astropy's own
    # arithmetic, 2 pi rad x ratio / 86400 s in rad/s, must give the very same float
    ratio = earth.ERA_RATE_RATIO
    assert OMEGA_EARTH == (2.0 * np.pi * u.rad * ratio / (86400.0 * u.s)).to_value(u.rad / u.s)


def test_constants_are_si_floats():
    for c in (OMEGA_EARTH, R_EARTH, GM_EARTH, G0):
        assert type(c) is float
    assert R_EARTH == 6378100.0  # IAU 2015 nominal equatorial radius
    assert GM_EARTH == 3.986004e14
    assert G0 == 9.80665


# ------------------------------------------------------------------ parsing


@pytest.mark.parametrize(
    "value, degrees",
    [
        ("48d50m46s N", 48 + 50 / 60 + 46 / 3600),
        ("50d53m", 50 + 53 / 60),
        (48.846, 48.846),
        (48, 48.0),
        ("-33.9 deg", -33.9),
        ("-33.9", -33.9),
        ("33.9 S", -33.9),
        ("48.846 deg", 48.846),
        (48.846 * u.deg, 48.846),
        (Angle("48d50m46s"), 48 + 50 / 60 + 46 / 3600),
        (Latitude(-12.5 * u.deg), -12.5),
        (0.5 * u.rad, 0.5 / DEG),
        ("90", 90.0),
        (-90.0, -90.0),
    ],
)
def test_parse_latitude(value, degrees):
    got = parse_latitude(value)
    assert type(got) is float
    assert got == pytest.approx(degrees * DEG, rel=1e-14, abs=1e-16)


@pytest.mark.parametrize("value", [90.5, "91d", "-90.001 deg", 100 * u.deg, "2 rad"])
def test_parse_latitude_refuses_beyond_90(value):
    with pytest.raises(ScenarioError) as info:
        parse_latitude(value)
    msg = str(info.value)
    assert repr(value) in msg or str(value) in msg
    assert "90" in msg and "latitude" in msg


@pytest.mark.parametrize("value", ["abc", "2 E", 3 * u.m, True, float("nan"), [1, 2], None])
def test_parse_latitude_refuses_garbage(value):
    with pytest.raises(ScenarioError):
        parse_latitude(value)


def test_scenario_error_is_value_error():
    with pytest.raises(ValueError):
        parse_latitude(95)


def test_parse_angle_and_longitude():
    assert parse_angle(30) == pytest.approx(math.pi / 6)
    assert parse_angle("1.5 rad", "azimuth") == pytest.approx(1.5)
    assert parse_angle(200.0) == pytest.approx(200 * DEG)  # not wrapped
    assert parse_longitude("2d20m46s E") == pytest.approx((2 + 20 / 60 + 46 / 3600) * DEG)
    assert parse_longitude("2.346 W") == pytest.approx(-2.346 * DEG)
    assert parse_longitude(350) == pytest.approx(-10 * DEG)
    with pytest.raises(ScenarioError, match="azimuth"):
        parse_angle("12 kg", "azimuth")
    with pytest.raises(ScenarioError):
        parse_longitude("12 N")


def test_parse_length():
    assert parse_length(158.5) == 158.5
    assert parse_length("158.5") == 158.5
    assert parse_length("520 ft") == pytest.approx(520 * 0.3048, rel=1e-15)
    assert parse_length("1.2 km") == pytest.approx(1200.0)
    assert parse_length(3 * u.km) == pytest.approx(3000.0)
    for bad in ("3 s", 3 * u.kg, "abc", "nan", True):
        with pytest.raises(ScenarioError, match="height"):
            parse_length(bad, "height")
    with pytest.raises(ScenarioError):
        parse_length(-1.0, "length", positive=True)
    # imperial units were enabled only for the call
    with pytest.raises(ValueError):
        u.Quantity("520 ft")


def test_sites():
    p = SITES["pantheon-paris"]
    assert p.latitude == pytest.approx(48.846 * DEG) and p.longitude == pytest.approx(2.346 * DEG)
    assert SITES["freiberg"].latitude == pytest.approx(parse_latitude("50d53m"), abs=1e-5)
    assert SITES["paris-gun"].latitude_deg == pytest.approx(49.6)
    assert SITES["north-pole"].latitude == math.pi / 2
    assert SITES["south-pole"].latitude == -math.pi / 2
    assert SITES["equator"].latitude == 0.0
    assert Site.from_any("Pantheon Paris") is p
    s = Site.from_any("48d50m46s N", "2d20m46s E", "10 ft")
    assert s.latitude == pytest.approx(48.846111 * DEG, rel=1e-7)
    assert s.height == pytest.approx(3.048)
    assert Site.from_any(s) is s
    with pytest.raises(ScenarioError):
        Site.from_any(91)
    with pytest.raises(ScenarioError):
        Site(2.0)  # radians beyond pi/2
    with pytest.raises(AttributeError):
        p.latitude = 0.0  # frozen


# ------------------------------------------------------------------ rotation and gravity


@pytest.mark.parametrize("lat_deg", [0.0, 90.0, -90.0, 48.846, -33.9])
def test_omega_enu(lat_deg):
    w = omega_enu(lat_deg * DEG)
    assert w.shape == (3,)
    assert np.linalg.norm(w) == pytest.approx(OMEGA_EARTH, rel=1e-15)
    lat = lat_deg * DEG
    # Independent: Earth's axis (0, 0, Omega) in ECEF, rotated into ENU by the basis
    # vectors written here (site at longitude 0).
    east = np.array([0.0, 1.0, 0.0])
    north = np.array([-math.sin(lat), 0.0, math.cos(lat)])
    up = np.array([math.cos(lat), 0.0, math.sin(lat)])
    w_ecef = np.array([0.0, 0.0, OMEGA_EARTH])
    expected = np.array([east @ w_ecef, north @ w_ecef, up @ w_ecef])
    np.testing.assert_allclose(w, expected, rtol=0, atol=1e-20)


def test_omega_enu_special_values_and_broadcast():
    np.testing.assert_allclose(omega_enu(0.0), [0, OMEGA_EARTH, 0], atol=1e-25)
    np.testing.assert_allclose(omega_enu(math.pi / 2), [0, 0, OMEGA_EARTH], atol=1e-20)
    np.testing.assert_allclose(omega_enu(-math.pi / 2), [0, 0, -OMEGA_EARTH], atol=1e-20)
    ws = omega_enu(np.linspace(-1.5, 1.5, 7).reshape(7, 1))
    assert ws.shape == (7, 1, 3)
    np.testing.assert_allclose(omega_enu(48.846 * u.deg), omega_enu(48.846 * DEG), rtol=1e-15)


def test_somigliana():
    # Published WGS84 normal gravity at the equator and the poles (NIMA TR8350.2 table 3.4).
    assert normal_gravity(0.0) == pytest.approx(9.7803253359, abs=1e-10)
    assert normal_gravity(math.pi / 2) == pytest.approx(9.8321849379, abs=1e-9)
    assert normal_gravity(-math.pi / 2) == pytest.approx(9.8321849379, abs=1e-9)
    g = normal_gravity(np.linspace(0, math.pi / 2, 50))
    assert np.all(np.diff(g) > 0)
    np.testing.assert_allclose(
        effective_gravity_enu(0.3, "wgs84"), [0, 0, -normal_gravity(0.3)], rtol=1e-15
    )
    np.testing.assert_allclose(effective_gravity_enu(0.3, "standard"), [0, 0, -9.80665])
    with pytest.raises(ScenarioError, match="spherical"):
        effective_gravity_enu(0.3, "flat")


def _g_eff_ecef_direct(lat, lon):
    """Gravitation plus centrifugal at the surface of the sphere, in ECEF (test reference)."""
    R = np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])
    R = R_EARTH * R
    w = np.array([0.0, 0.0, OMEGA_EARTH])
    g_grav = -GM_EARTH * R / np.linalg.norm(R) ** 3
    return R, g_grav - np.cross(w, np.cross(w, R))


def _enu_basis_from_geometry(R):
    """ENU basis from the radial vector and Earth's axis (test reference)."""
    up = R / np.linalg.norm(R)
    east = np.cross([0.0, 0.0, 1.0], up)
    east /= np.linalg.norm(east)
    north = np.cross(up, east)
    return east, north, up


@pytest.mark.parametrize("lat_deg, lon_deg", [(0.0, 0.0), (20.0, 100.0), (45.0, -30.0),
                                              (48.846, 2.346), (-33.9, 151.2), (80.0, 10.0)])
def test_effective_gravity_matches_direct_ecef_computation(lat_deg, lon_deg):
    lat, lon = lat_deg * DEG, lon_deg * DEG
    R, g_ecef = _g_eff_ecef_direct(lat, lon)
    e, n, up = _enu_basis_from_geometry(R)
    expected = np.array([g_ecef @ e, g_ecef @ n, g_ecef @ up])
    got = effective_gravity_enu(lat)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-13)
    # tilt: angle between -g_eff and the radial up, towards the pole in the north
    tilt = math.acos(-(g_ecef @ up) / np.linalg.norm(g_ecef))
    assert plumb_tilt(lat) == pytest.approx(math.copysign(tilt, lat_deg), abs=1e-12)
    # the module's rotation matrix gives the same vector from the ECEF computation
    np.testing.assert_allclose(ecef_to_enu_matrix(lat, lon) @ g_ecef, got, atol=1e-13)


def test_plumb_tilt_maximum_near_45_degrees():
    lats = np.linspace(-90, 90, 3601) * DEG
    tilt = plumb_tilt(lats)
    i = int(np.argmax(tilt))
    assert abs(lats[i] / DEG - 45.0) < 0.5
    assert 0.097 < tilt[i] / DEG < 0.101  # about 0.1 deg
    assert plumb_tilt(0.0) == 0.0 and abs(plumb_tilt(math.pi / 2)) < 1e-18
    np.testing.assert_allclose(tilt, -tilt[::-1], atol=1e-18)
    # magnitude on the equator: GM/R^2 - Omega^2 R
    g_eq = effective_gravity_enu(0.0)
    assert -g_eq[2] == pytest.approx(GM_EARTH / R_EARTH**2 - OMEGA_EARTH**2 * R_EARTH, rel=1e-15)


def test_geocentric_latitude_against_astropy_wgs84():
    for lat_deg in (0.0, 10.0, 45.0, 48.846, -60.0, 89.0, 90.0):
        loc = EarthLocation.from_geodetic(0 * u.deg, lat_deg * u.deg, 0 * u.m, "WGS84")
        x, y, z = (c.to_value(u.m) for c in (loc.x, loc.y, loc.z))
        assert geocentric_latitude(lat_deg * DEG) == pytest.approx(
            math.atan2(z, math.hypot(x, y)), abs=1e-12
        )
    assert (45 * DEG - geocentric_latitude(45 * DEG)) / DEG == pytest.approx(0.1924, abs=1e-3)


# ------------------------------------------------------------------ ENU <-> ECEF


def test_ecef_to_enu_matrix_orthonormal_and_up_radial():
    rng = np.random.default_rng(1)
    lat = rng.uniform(-math.pi / 2, math.pi / 2, 200)
    lon = rng.uniform(-math.pi, math.pi, 200)
    m = ecef_to_enu_matrix(lat, lon)
    assert m.shape == (200, 3, 3)
    np.testing.assert_allclose(m @ np.swapaxes(m, -1, -2), np.broadcast_to(np.eye(3), m.shape),
                               atol=1e-15)
    np.testing.assert_allclose(np.linalg.det(m), 1.0, atol=1e-15)
    for k in range(0, 200, 37):
        R = np.array([math.cos(lat[k]) * math.cos(lon[k]), math.cos(lat[k]) * math.sin(lon[k]),
                      math.sin(lat[k])])
        e, n, up = _enu_basis_from_geometry(R)
        np.testing.assert_allclose(m[k], np.stack([e, n, up]), atol=1e-14)
    # at the poles the frame is still a rotation and up is the axis
    mp = ecef_to_enu_matrix(math.pi / 2, 0.3)
    np.testing.assert_allclose(mp @ mp.T, np.eye(3), atol=1e-15)
    np.testing.assert_allclose(mp[2], [0, 0, 1], atol=1e-15)


def test_enu_ecef_round_trip_and_up_is_radial():
    site = Site.from_any("48d50m46s N", "2d20m46s E", 35.0)
    rng = np.random.default_rng(2)
    enu = rng.normal(scale=1000.0, size=(4, 5, 3))
    ecef = enu_to_ecef(site, enu)
    assert ecef.shape == (4, 5, 3)
    np.testing.assert_allclose(ecef_to_enu(site, ecef), enu, atol=2e-9)
    # the origin is on the sphere of radius R + h; going up moves radially outwards
    o = enu_to_ecef(site, [0.0, 0.0, 0.0])
    assert np.linalg.norm(o) == pytest.approx(R_EARTH + 35.0, rel=1e-15)
    top = enu_to_ecef(site, [0.0, 0.0, 1000.0])
    assert np.linalg.norm(top) == pytest.approx(R_EARTH + 1035.0, rel=1e-15)
    np.testing.assert_allclose((top - o) / 1000.0, o / np.linalg.norm(o), atol=1e-12)
    # free vectors: rotation only, lengths kept
    v = rng.normal(size=(10, 3))
    ve = enu_to_ecef(site, v, vector=True)
    np.testing.assert_allclose(np.linalg.norm(ve, axis=-1), np.linalg.norm(v, axis=-1))
    np.testing.assert_allclose(ecef_to_enu(site, ve, vector=True), v, atol=1e-14)
    # Earth's axis in ENU is omega_enu
    np.testing.assert_allclose(
        ecef_to_enu(site, [0, 0, OMEGA_EARTH], vector=True), omega_enu(site.latitude),
        atol=1e-20,
    )


def test_enu_up_is_the_ellipsoid_normal_for_geodetic_latitude():
    # astropy (offline) gives the ECEF position of a geodetic point; the ellipsoid normal
    # (gradient of x^2/a^2 + y^2/a^2 + z^2/b^2) must be the module's "up" at geodetic lat.
    lat, lon = 48.846, 2.346
    loc = EarthLocation.from_geodetic(lon * u.deg, lat * u.deg, 0 * u.m, "WGS84")
    p = np.array([c.to_value(u.m) for c in (loc.x, loc.y, loc.z)])
    a = 6378137.0
    b = a * math.sqrt(1 - 0.00669437999013)
    nrm = np.array([p[0] / a**2, p[1] / a**2, p[2] / b**2])
    nrm /= np.linalg.norm(nrm)
    np.testing.assert_allclose(ecef_to_enu_matrix(lat * DEG, lon * DEG)[2], nrm, atol=1e-12)


# ------------------------------------------------------------------ gravity models


def test_gravity_models():
    rng = np.random.default_rng(3)
    r = rng.normal(scale=[1e5, 1e5, 2e4], size=(50, 3))
    np.testing.assert_allclose(gravity_uniform(9.81), [0, 0, -9.81])
    gvec = effective_gravity_enu(0.7)
    np.testing.assert_allclose(gravity_uniform(gvec, r), np.broadcast_to(gvec, r.shape))
    ga = gravity_altitude(r, 9.8, R_EARTH)
    np.testing.assert_allclose(ga[:, :2], 0.0)
    np.testing.assert_allclose(ga[:, 2], -9.8 * (R_EARTH / (R_EARTH + r[:, 2])) ** 2)
    # central field: compare with the ECEF computation at a site, mapped back to ENU
    site = SITES["paris-gun"]
    gc = gravity_central(r)
    for k in range(0, 50, 7):
        x = enu_to_ecef(site, r[k])
        g_ecef = -GM_EARTH * x / np.linalg.norm(x) ** 3
        np.testing.assert_allclose(gc[k], ecef_to_enu(site, g_ecef, vector=True),
                                   rtol=1e-9, atol=1e-12)
    # at the origin: GM/R^2 straight down, and it agrees with gravity_altitude on the z axis
    np.testing.assert_allclose(gravity_central([0, 0, 0]), [0, 0, -GM_EARTH / R_EARTH**2])
    z = np.array([[0.0, 0.0, 1e4]])
    np.testing.assert_allclose(gravity_central(z), gravity_altitude(z, GM_EARTH / R_EARTH**2),
                               rtol=1e-14)


# ------------------------------------------------------------------ astropy offline


def _public_calls():
    parse_latitude("48d50m46s N")
    parse_latitude(48.846 * u.deg)
    parse_longitude("2d20m46s E")
    parse_angle("30 deg")
    parse_length("520 ft")
    s = Site.from_any("50d53m", 13.34, "10 m")
    Site.from_any("freiberg")
    omega_enu(s.latitude)
    normal_gravity(s.latitude)
    effective_gravity_enu(s.latitude)
    effective_gravity_enu(s.latitude, "wgs84")
    plumb_tilt(s.latitude)
    geocentric_latitude(s.latitude)
    enu_to_ecef(s, [1.0, 2.0, 3.0])
    ecef_to_enu(s, [R_EARTH, 0.0, 0.0])
    gravity_central([0.0, 0.0, 10.0])


def test_public_functions_work_offline(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("rotframe.earth tried to open a network connection")

    monkeypatch.setattr(socket.socket, "connect", refuse)
    monkeypatch.setattr(socket, "create_connection", refuse)
    before = (iers.conf.auto_download, astropy_data.conf.allow_internet)
    with astropy_data.conf.set_temp("allow_internet", False):
        _public_calls()
    assert (iers.conf.auto_download, astropy_data.conf.allow_internet) == before
    _public_calls()
    assert (iers.conf.auto_download, astropy_data.conf.allow_internet) == before


def test_import_leaves_astropy_configuration_alone():
    code = (
        "from astropy.utils import iers, data\n"
        "for a, b in ((True, True), (False, True), (True, False)):\n"
        "    iers.conf.auto_download = a; data.conf.allow_internet = b\n"
        "    if a and b:\n"
        "        import rotframe.earth as e\n"
        "    e.parse_latitude('48d50m46s N'); e.parse_length('520 ft')\n"
        "    assert (iers.conf.auto_download, data.conf.allow_internet) == (a, b), (a, b)\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"


def test_offline_context_restores_values():
    before = (iers.conf.auto_download, astropy_data.conf.allow_internet)
    with earth.astropy_offline():
        assert iers.conf.auto_download is False
        assert astropy_data.conf.allow_internet is False
        with earth.astropy_offline():
            pass
        assert astropy_data.conf.allow_internet is False
    assert (iers.conf.auto_download, astropy_data.conf.allow_internet) == before
