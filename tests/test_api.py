"""The Python API (rotframe.run and Result): the documented contract, metrics recomputed from the arrays.

Each metric check recomputes the metric from ``Result.trajectory`` by a route
that shares no code with the scene's analysis, so a wrong array (frame, units,
shape, sample held at an event) or a wrong metric fails.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import rotframe
from rotframe.errors import RotframeError, ScenarioError


def test_import_is_cheap():
    """`import rotframe` and its version import none of astropy, numba, rerun, scipy (a fresh process)."""
    code = ("import sys, rotframe; rotframe.__version__; rotframe.__all__; "
            "print(','.join(m for m in ('astropy', 'numba', 'rerun', 'scipy') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_lazy_names_resolve():
    for name in rotframe.__all__:
        assert getattr(rotframe, name) is not None
    assert rotframe.frames.euler_to_dcm is not None
    with pytest.raises(AttributeError):
        rotframe.no_such_thing


def test_scenarios_and_load():
    names = rotframe.scenarios()
    for required in ("turntable", "tower-drop", "foucault", "inertial-oscillation", "projectile", "free-top",
                     "dzhanibekov", "heavy-top"):
        assert required in names
    scn = rotframe.load("foucault")
    p = scn.parameters["length"]
    assert (p.name, p.unit, p.default) == ("length", "m", 67.0)
    assert p.bounds == (0, None) and p.exclusive_min and p.doc


def test_acceptance_command():
    """The issue's acceptance line, in a fresh process."""
    code = "import rotframe; r = rotframe.run('tower-drop', height='520 ft'); print(r.metrics)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "east_deflection_m" in out.stdout


def test_tower_drop_deflection_from_the_arrays():
    """East deflection at the landing, recomputed from r and v samples (a Taylor step to z = 0).

    From the last sample above ground, (r, v) and the acceleration estimated by a
    finite difference of v give the landing time from z = 0 and x there; the
    neglected term (1/6) x''' tau^3, with x''' ~ 2 Omega g cos(lat) ~ 1e-3 m/s^3 and
    tau below one sample interval (9.5 ms), is below 2e-10 m: the tolerance is 1e-9 m
    on a 27.6 mm deflection.
    """
    r = rotframe.run("tower-drop", height="520 ft", latitude="50d53m")
    tr = r.trajectory
    assert tr.kind == "particles" and tr.r.shape == tr.v.shape == (len(tr.times), 1, 3)
    z = tr.r[:, 0, 2]
    k = int(np.nonzero(z > 1e-9)[0][-1])  # last sample in the air (later samples hold the landing state)
    a = (tr.v[k, 0] - tr.v[k - 1, 0]) / (tr.times[k] - tr.times[k - 1])
    # z_k + vz tau + az tau^2 / 2 = 0, the root in (0, dt]
    tau = (-tr.v[k, 0, 2] - math.sqrt(tr.v[k, 0, 2] ** 2 - 2 * a[2] * z[k])) / a[2]
    x_land = tr.r[k, 0, 0] + tr.v[k, 0, 0] * tau + 0.5 * a[0] * tau ** 2
    assert abs(x_land - r.metrics["east_deflection_m"]) < 1e-9
    assert abs(tr.times[k] + tau - r.metrics["fall_time_s"]) < 1e-9
    assert r.params["height"] == pytest.approx(158.496)  # 520 ft exactly
    assert r.units["east_deflection_m"] == "m" and r.units["height"] == "m"


def test_foucault_rate_from_the_turning_points():
    """Precession from the direction of r at the turning points (largest horizontal distance), fitted.

    The scene measures the rate from the principal axis of v v^T + w0^2 x x^T; here the
    swing direction is read off the position at each local maximum of |r_h| instead.
    The swing is an ellipse of axis ratio Omega sin(lat) / w0 ~ 1.4e-4, so the direction
    of r near its maximum is the major axis within ~1.4e-4 rad, and the sample nearest the
    maximum (32 samples a period) is within pi/32 of it in phase, where the direction
    differs from the major axis by at most that ratio again. Over 0.5 h (0.1 rad of turn,
    ~110 turning points) a least-squares slope is then good to ~1e-4 relative; the test
    allows 2e-3 relative.
    """
    r = rotframe.run("foucault", duration=1800)
    tr = r.trajectory
    x, y = tr.r[:, 0, 0], tr.r[:, 0, 1]
    rho = np.hypot(x, y)
    k = np.nonzero((rho[1:-1] > rho[:-2]) & (rho[1:-1] >= rho[2:]))[0] + 1
    angle = np.unwrap(2 * np.arctan2(y[k], x[k])) / 2  # a direction, defined modulo pi
    slope = np.polyfit(tr.times[k], angle, 1)[0]  # rad/s, anticlockwise positive
    rate = -math.degrees(slope) * 3600  # clockwise positive, deg/h
    measured = r.metrics["precession_rate_deg_per_hour"]
    assert rate == pytest.approx(measured, rel=2e-3)
    assert measured > 0  # clockwise in the north


def test_heavy_top_turning_angles_from_quaternions():
    """theta min/max from q via scipy's Rotation (not rotframe.rigid.dynamics), within the sampling error.

    theta(t) is sampled 2000 times a second against a nutation period of 0.22 s; near an
    extremum theta differs from its extreme value by (1/2) theta'' dt^2 <~ 1e-5 deg, so
    1e-4 deg covers it.
    """
    from scipy.spatial.transform import Rotation

    r = rotframe.run("heavy-top", duration=1.0)
    tr = r.trajectory
    assert tr.kind == "body" and tr.L.shape == (len(tr.times), 3) and tr.q.shape == (len(tr.times), 4)
    e3 = Rotation.from_quat(tr.q).apply([0.0, 0.0, 1.0])  # body axis 3 in space
    theta = np.degrees(np.arccos(np.clip(e3[:, 2], -1, 1)))
    assert theta.min() == pytest.approx(r.metrics["theta_min_deg"], abs=1e-4)
    assert theta.max() == pytest.approx(r.metrics["theta_max_deg"], abs=1e-4)
    # L is in body axes: p_psi = L3 is conserved by the gravity torque (it has no 3-component)
    assert np.ptp(tr.L[:, 2]) <= 1e-12 * abs(tr.L[0, 2])


def test_values_as_numbers_quantities_and_strings_agree():
    u = pytest.importorskip("astropy.units")
    a = rotframe.run("foucault", length=30.0, latitude=45.0, duration=60)
    b = rotframe.run("foucault", length=30 * u.m, latitude=45 * u.deg, duration=1 * u.min)
    c = rotframe.run("foucault", length="3000 cm", latitude="45d", duration="1 min")
    assert a.params == b.params == c.params
    assert a.metrics["period_s"] == b.metrics["period_s"] == c.metrics["period_s"]
    d = rotframe.run("dzhanibekov", omega=np.array([0.0, 1.0, 1e-3]) * u.rad / u.s, duration=30)
    assert d.params["omega"] == [0.0, 1.0, 1e-3]


@pytest.mark.parametrize("kwargs, words", [
    ({"lenght": 3}, ["lenght", "did you mean 'length'"]),
    ({"length": "3 s"}, ["length", "wrong dimension"]),
    ({"length": -1}, ["length", "out of range"]),
    ({"samples": 2.5}, ["samples", "whole number"]),
])
def test_bad_values_name_the_key_not_the_cli(kwargs, words):
    with pytest.raises(ScenarioError) as info:
        rotframe.run("foucault", **kwargs)
    message = str(info.value)
    assert all(w in message for w in words), message
    assert "--set" not in message and "--method" not in message
    assert isinstance(info.value, (RotframeError, ValueError))


def test_quantity_of_wrong_dimension():
    u = pytest.importorskip("astropy.units")
    with pytest.raises(ScenarioError, match="latitude"):
        rotframe.run("foucault", latitude=3 * u.m)
    with pytest.raises(ScenarioError, match="method='rk5'"):
        rotframe.run("foucault", "rk5")


def test_to_json_has_every_key_of_the_cli_json(tmp_path, capsys):
    from rotframe.app import cli
    assert cli.main(["run", "tower-drop", "--json", "--no-record"]) == 0
    cli_json = json.loads(capsys.readouterr().out)
    r = rotframe.run("tower-drop")
    api_json = json.loads(r.to_json())
    assert set(cli_json) <= set(api_json)
    for key in ("metrics", "theory", "diagnostics", "params", "units", "timing"):
        assert set(cli_json[key]) <= set(api_json[key]), key
    assert api_json["metrics"] == pytest.approx(cli_json["metrics"], rel=1e-12)
    assert isinstance(api_json["warnings"], list)
    assert cli_json["units"]["east_deflection_m"] == "m"


def test_record_writes_the_cli_recording(tmp_path):
    from rotframe.app import cli
    from rotframe.app.recording_summary import entities

    r = rotframe.run("heavy-top", duration=0.5)
    path = r.record(tmp_path / "api.rrd")
    assert path.is_file() and r.recording == str(path) and r.to_dict()["recording"] == str(path)
    assert cli.main(["run", "heavy-top", "--set", "duration=0.5", "--out", str(tmp_path / "cli.rrd")]) == 0
    api, cli_rec = entities(path), entities(tmp_path / "cli.rrd")
    assert set(api) == set(cli_rec)
    assert {e: v["rows"] for e, v in api.items()} == {e: v["rows"] for e, v in cli_rec.items()}


def test_export_formats_round_trip(tmp_path):
    r = rotframe.run("tower-drop")
    npz = np.load(r.export(tmp_path / "t.npz"))
    assert np.array_equal(npz["r"], r.trajectory.r) and json.loads(str(npz["units"]))["r"] == "m"
    table = np.genfromtxt(tmp_path / "t.csv" if r.export(tmp_path / "t.csv") else None, delimiter=",",
                          names=True)
    assert np.array_equal(table["x_m"], r.trajectory.r[:, 0, 0])  # %.17g round-trips float64
    pq = pytest.importorskip("pyarrow.parquet")
    t = pq.read_table(r.export(tmp_path / "t.parquet"))
    assert np.array_equal(t.column("time_s").to_numpy(), r.trajectory.times)
    with pytest.raises(ScenarioError, match="must end in"):
        r.export(tmp_path / "t.txt")


def test_to_dataframe():
    pytest.importorskip("pandas")
    r = rotframe.run("dzhanibekov", duration=10)
    df = r.to_dataframe()
    assert list(df.columns[:4]) == ["time_s", "L1_kg_m2_s", "L2_kg_m2_s", "L3_kg_m2_s"] and len(df) == len(r.trajectory.times)


def test_progress_callback_and_bar(capsys):
    seen = []
    rotframe.run("heavy-top", duration=0.5, progress=seen.append)
    assert seen and seen[-1] == pytest.approx(1.0) and all(0 <= f <= 1 for f in seen)
    rotframe.run("heavy-top", duration=0.5, progress=True)
    assert "100.0%" in capsys.readouterr().err


def test_show_outside_a_notebook_says_how_to_open(tmp_path, capsys):
    r = rotframe.run("tower-drop")
    path = r.show(tmp_path / "s.rrd")
    assert path.is_file() and "rotframe view" in capsys.readouterr().err


def test_png(tmp_path):
    r = rotframe.run("foucault", duration=60)
    r.plot(tmp_path / "f.png")
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_version_and_help_for_every_option(capsys):
    import argparse
    import collections

    from rotframe.app import cli
    with pytest.raises(SystemExit) as info:
        cli.main(["--version"])
    assert info.value.code == 0 and capsys.readouterr().out.strip() == f"rotframe {rotframe.__version__}"
    parser = cli.build_parser(collections.defaultdict(lambda: None))
    missing = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                missing += [f"{name} {a.dest}" for a in sub._actions
                            if not isinstance(a, argparse._HelpAction) and not a.help]
    assert not missing, missing


def test_cli_export_and_png(tmp_path, capsys):
    from rotframe.app import cli
    assert cli.main(["run", "heavy-top", "--set", "duration=0.2", "--no-record", "--json",
                     "--export", str(tmp_path / "h.npz"), "--png", str(tmp_path / "h.png")]) == 0
    summary = json.loads(capsys.readouterr().out)  # stdout is still one JSON object
    data = np.load(tmp_path / "h.npz")
    assert data["L"].shape == (len(data["times"]), 3) and data["q"].shape == (len(data["times"]), 4)
    assert summary["export"] == str(tmp_path / "h.npz") and (tmp_path / "h.png").stat().st_size > 0
    assert cli.main(["run", "heavy-top", "--export", str(tmp_path / "h.txt")]) == 2
    assert "--export" in capsys.readouterr().err


def test_view_without_a_display(tmp_path, monkeypatch, capsys):
    from rotframe.app import cli
    path = rotframe.run("tower-drop").record(tmp_path / "t.rrd")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    assert cli.main(["view", str(path)]) == 0
    captured = capsys.readouterr()
    assert len(captured.err.strip().splitlines()) == 1 and "--web" in captured.err
    assert "/world/body" in captured.out


def test_ensemble_sweep_rows_carry_the_theory_of_single_runs(tmp_path, monkeypatch):
    """A tower-drop sweep runs as one ensemble; its rows have the theory columns a single run has."""
    from rotframe.app import sweep
    monkeypatch.chdir(tmp_path)
    spec = sweep.parse_spec("tower-drop", grid=["height=20:300:3", "latitude=-60:60:2"])
    res = sweep.run_sweep(spec, plots=False, recording=False)
    assert res.path == "ensemble"
    table = res.table.to_pydict()
    for i in range(res.rows):
        single = rotframe.run("tower-drop", height=table["height"][i], latitude=table["latitude"][i])
        for key, value in single.theory.items():
            assert table["theory_" + key][i] == pytest.approx(value, rel=1e-14), key


def test_csv_export_reads_back_with_pandas(tmp_path):
    """The CSV's first line is a plain header: pandas.read_csv with no options gets the columns and values."""
    pd = pytest.importorskip("pandas")
    r = rotframe.run("tower-drop")
    path = r.export(tmp_path / "t.csv")
    assert not path.read_text().startswith("#")
    df = pd.read_csv(path)
    cols = r.trajectory.columns()
    assert list(df.columns) == list(cols)
    for name, values in cols.items():
        assert np.array_equal(df[name].to_numpy(), np.asarray(values)), name  # %.17g round-trips float64
    body = rotframe.run("dzhanibekov", duration=5).export(tmp_path / "b.csv")
    assert list(pd.read_csv(body).columns) == ["time_s", "L1_kg_m2_s", "L2_kg_m2_s", "L3_kg_m2_s", "qx", "qy", "qz", "qw"]
