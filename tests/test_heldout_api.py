"""The Python face as a newcomer meets it: what the guide's examples and the contract promise.

Each test here comes from typing an example of README.md / docs/ or checking an item of the
Python contract, and finding it failed (or checking a promise no other test checked).
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rotframe

ROOT = Path(__file__).resolve().parents[1]

#: Earth's sidereal rotation rate (IERS), rad/s: an oracle that does not come from rotframe.earth
OMEGA_EARTH = 7.2921150e-5


def _env(**extra):
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + env.get("PYTHONPATH", "")
    env.update(extra)
    return env


def test_the_guides_own_scenario_file_runs(tmp_path):
    """docs/guide/scenario-files.md: Foucault in Greenwich, 20 m of string, for 2 h.

    It ended in "non-finite state of particle 0 after t = 0 s": dop853 cut a step to land on a
    call's last sample, the sum t + (t_end - t) rounded an ulp short of t_end, and the next
    step (one ulp) was taken for a collapsed step size; the cut was also carried into the next
    call as the step size. The measured rate is checked against Omega sin(latitude) with the
    IERS rotation rate: Airy's finite-swing correction for a 3 m swing on 20 m of string is
    about 0.9 % of it here, so 2 % separates a right rate from a wrong one.
    """
    path = tmp_path / "my-pendulum.toml"
    path.write_text('name = "foucault-greenwich"\nscene = "foucault"\n\n[parameters.length]\ndefault = 20.0\n\n'
                    '[parameters.latitude]\ndefault = "51d28m N"\n', encoding="utf-8")
    for duration in ("1 h", "2 h"):
        r = rotframe.run(path, duration=duration)
        assert r.complete and not r.warnings
        assert r.params["length"] == 20.0 and r.params["latitude"] == pytest.approx(51 + 28 / 60)
        omega_sin = math.degrees(OMEGA_EARTH * math.sin(math.radians(51 + 28 / 60))) * 3600
        assert r.metrics["precession_rate_deg_per_hour"] == pytest.approx(omega_sin, rel=0.02)
        # the string is kept to round-off over 800 swings
        assert r.diagnostics["constraint_drift_m"] < 1e-8
        assert np.isfinite(r.trajectory.r).all()


def test_dop853_ends_each_call_on_its_last_sample():
    """The same model through integrate_particles: every sample finite, the string length kept.

    The pendulum's string is the sphere |r - pivot| = L; dop853 (rtol 1e-10) keeps it to about
    1e-10 L per hour, so 1e-7 m on 20 m catches any sample left unset or wrong.
    """
    from rotframe.scenes import foucault

    from rotframe.particles.integrators import integrate_particles

    for latitude in (51.4667, 51 + 28 / 60):
        model, r0, v0, g, _ = foucault.build({"latitude": latitude, "length": 20.0, "amplitude": 3.0,
                                              "small_angle": False, "g_model": "wgs84", "duration": 3600.0},
                                             ["gravity", "coriolis", "pendulum"])
        for duration in (3600.0, 7200.0):
            samples = int(32 * duration / (2 * math.pi * math.sqrt(20.0 / g)))
            traj = integrate_particles(model, r0, v0, duration, method="dop853", samples=samples)
            r = traj.r[:, 0]
            assert np.isfinite(r).all() and r.shape == (samples + 1, 3)
            assert np.abs(np.linalg.norm(r - [0.0, 0.0, 20.0], axis=1) - 20.0).max() < 1e-7


def test_metrics_print_as_plain_numbers():
    """print(r.metrics) shows 11.3..., not np.float64(11.3...); the doctest of run() relies on it."""
    r = rotframe.run("foucault", duration=600)
    for section in (r.metrics, r.theory, r.diagnostics):
        for key, value in section.items():
            assert value is None or type(value) in (float, int, bool, str, list), (key, type(value))
    assert "np." not in repr(r.metrics)
    assert (r.metrics["precession_rate_deg_per_hour"] > 0) is True


def test_free_body_quaternions_carry_the_body_momentum_to_a_fixed_space_vector():
    """L_space = R(q) L_body is constant for a free body: q is body -> space, scalar last.

    scipy's Rotation is the independent reference. The exact flow keeps L_space to round-off
    (1e-12 of |L| allows the ~1e3 compositions of 1e-16 errors); the inverse rotation would
    move it by O(|L|), so the check tells the two conventions apart.
    """
    from scipy.spatial.transform import Rotation

    for name in ("dzhanibekov", "free-top"):
        tr = rotframe.run(name).trajectory
        assert tr.kind == "body" and tr.L.shape == (len(tr.times), 3) and tr.q.shape == (len(tr.times), 4)
        assert tr.units["L"] == "kg m^2/s" and tr.units["times"] == "s"
        norm = np.linalg.norm(tr.L[0])
        L_space = Rotation.from_quat(tr.q).apply(tr.L)
        assert np.abs(L_space - L_space[0]).max() < 1e-12 * norm, name
        if name == "dzhanibekov":  # the flip turns the body: the wrong convention moves L_space
            wrong = Rotation.from_quat(tr.q).inv().apply(tr.L)
            assert np.abs(wrong - wrong[0]).max() > 0.1 * norm


@pytest.mark.parametrize("name", ["turntable", "tower-drop", "foucault", "inertial-oscillation", "projectile"])
def test_particle_arrays_have_the_contract_shapes(name):
    tr = rotframe.run(name).trajectory
    n = len(tr.times)
    assert tr.kind == "particles" and tr.r.shape == (n, 1, 3) and tr.v.shape == (n, 1, 3)
    assert tr.r.dtype == np.float64 and tr.units == {"times": "s", "r": "m", "v": "m/s"}
    assert tr.L is None and tr.q is None


def test_to_json_has_every_key_of_the_cli_json_for_every_scenario(capsys):
    from rotframe.app import cli
    for name in rotframe.scenarios():
        assert cli.main(["run", name, "--json", "--no-record"]) == 0
        cli_json = json.loads(capsys.readouterr().out)
        api_json = json.loads(rotframe.run(name).to_json())
        assert set(cli_json) <= set(api_json), name
        for key, value in cli_json.items():
            if isinstance(value, dict):
                assert set(value) <= set(api_json[key]), (name, key)
        assert api_json["metrics"] == pytest.approx(cli_json["metrics"], rel=1e-12, nan_ok=True), name


def test_list_and_scenarios_see_a_plugin_scene(tmp_path):
    """ROTFRAME_PLUGINS: `rotframe run` saw the user's scene, `rotframe list` did not."""
    env = _env(ROTFRAME_PLUGINS=str(ROOT / "examples" / "spin_gravity.py"))
    out = subprocess.run([sys.executable, "-m", "rotframe", "list"], capture_output=True, text=True, env=env,
                         cwd=tmp_path, check=True).stdout
    assert "spin-gravity" in out and "foucault" in out
    rows = json.loads(subprocess.run([sys.executable, "-m", "rotframe", "list", "--json"], capture_output=True,
                                     text=True, env=env, cwd=tmp_path, check=True).stdout)
    assert "spin-gravity" in [r["name"] for r in rows]
    code = "import rotframe; print(rotframe.scenarios())"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path,
                         check=True).stdout
    assert "spin-gravity" in out


def test_to_dataframe_rows_are_samples_times_particles():
    pd = pytest.importorskip("pandas")
    r = rotframe.run("tower-drop")
    df = r.to_dataframe()
    assert isinstance(df, pd.DataFrame)
    assert len(df) == r.trajectory.r.shape[0] * r.trajectory.r.shape[1]
    assert np.array_equal(df["x_m"].to_numpy(), r.trajectory.r[:, 0, 0])


def test_foucault_example_labels_its_theory_truly(capsys, monkeypatch):
    """examples/foucault_my_latitude.py printed the Airy-corrected theory as "Omega sin(lat)"."""
    import runpy

    monkeypatch.setattr(sys, "argv", ["foucault_my_latitude.py", "--duration", "10 min"])
    runpy.run_path(str(ROOT / "examples" / "foucault_my_latitude.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "Airy" in out and "clockwise" in out


def test_a_file_on_a_user_scene_declares_only_what_it_changes(tmp_path):
    """A file with scene = "spin-gravity" takes the other parameters (and height's unit) from the
    scenario file the scene was registered with; it was read with no unit ("20 ft": wrong dimension).

    The metrics are checked against the closed form of the straight inertial line (the ball keeps
    omega (R - h) and the floor turns under it), computed here from R, h and g_floor alone.
    """
    import runpy

    runpy.run_path(str(ROOT / "examples" / "spin_gravity.py"))  # registers the scene, as a user's import does
    path = tmp_path / "tall.toml"
    path.write_text('name = "tall-drop"\nscene = "spin-gravity"\n\n[parameters.height]\ndefault = "20 ft"\n',
                    encoding="utf-8")
    r = rotframe.run(path)
    R, h = 224.0, 20 * 0.3048
    assert r.params == {"radius": R, "g_floor": 9.81, "height": pytest.approx(h)}
    w = math.sqrt(9.81 / R)
    d = math.sqrt(R * R - (R - h) ** 2)
    t = d / (w * (R - h))
    # the fall time comes from linear interpolation between 2000 samples over 1.2 t: the error is
    # (1/8) |r''| dt^2 / |r'|, far below 1e-6 of t
    assert r.metrics["fall_time_s"] == pytest.approx(t, rel=1e-6)
    assert r.metrics["spinward_offset_m"] == pytest.approx(R * (math.atan2(d, R - h) - w * t), rel=1e-4)
    env = _env(ROTFRAME_PLUGINS=str(ROOT / "examples" / "spin_gravity.py"))
    out = subprocess.run([sys.executable, "-m", "rotframe", "run", str(path), "--json", "--no-record"],
                         capture_output=True, text=True, env=env, cwd=tmp_path, check=True).stdout
    assert json.loads(out)["params"]["height"] == pytest.approx(h)


def test_progress_bar_estimates_time_left_from_the_rate_after_its_first_report():
    """The first report came after the kernels loaded (0.8 s) at 0.1 %: "1544.8 s left" for a 1 s run."""
    import io

    from rotframe.app.progress import Progress

    stream = io.StringIO()
    bar = Progress("run", "%", delay=0.0, interval=0.0, stream=stream, tty_only=False)
    bar.start -= 10.0  # ten seconds of loading before the first report
    bar(0.001)
    assert "? left" in stream.getvalue()  # no rate yet
    bar.first = (bar.first[0] - 1.0, bar.first[1])  # then one second for 0.1 -> a rate of 10 % a second
    bar(0.101)
    left = stream.getvalue().rsplit("elapsed, ", 1)[1].split(" left")[0]
    assert left == "9 s" or left.startswith("9."), left