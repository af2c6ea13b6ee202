"""Every script in examples/ runs (with short settings) and says what it should.

The scripts run in this process through runpy (the slow imports are paid once);
the user-scene plugin also runs through the command line in a fresh process, as
a user would start it.
"""

from __future__ import annotations

import os
import runpy
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

#: script -> (arguments for a short run, text its output must contain)
RUNS = {
    "foucault_my_latitude.py": (["--latitude", "33d52m S", "--duration", "10 min"], "anticlockwise"),
    "tower_drop_my_tower.py": (["--height", "828 m", "--latitude", "25d11m N"], "mm east"),
    "dzhanibekov_my_body.py": (["--duration", "5"], "flip every"),
    "aerospace_ypr.py": ([], "body rates"),
    "sweep_latitude.py": (["--points", "3", "--duration", "300"], "3 runs"),
    "spin_gravity.py": (["--height", "6 ft"], "spinward_offset_m"),
    "own_force_lorentz.py": (["--omega", "2"], "gyration radius"),
    "own_frame_station.py": (["--duration", "5"], "error against the inertial line"),
    "own_torque_damping.py": ([], "exact 3 exp"),
}


def test_every_example_is_listed():
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == sorted(RUNS)


@pytest.mark.parametrize("script", sorted(RUNS))
def test_example_runs(script, monkeypatch, capsys, tmp_path):
    args, expected = RUNS[script]
    if script == "sweep_latitude.py":
        args = args + ["--out", str(tmp_path / "sweep.png")]
    monkeypatch.setattr(sys, "argv", [script, *args])
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(EXAMPLES / script), run_name="__main__")
    out = capsys.readouterr().out
    assert expected in out, out
    if script == "sweep_latitude.py":
        assert (tmp_path / "sweep.png").stat().st_size > 0


def test_user_scene_from_the_command_line(tmp_path):
    """ROTFRAME_PLUGINS makes `rotframe run` see a scene registered by user code, by name and by file."""
    env = dict(os.environ, ROTFRAME_PLUGINS=str(EXAMPLES / "spin_gravity.py"))
    env["PYTHONPATH"] = os.pathsep.join([str(EXAMPLES.parent / "src"), env.get("PYTHONPATH", "")])
    out = subprocess.run([sys.executable, "-m", "rotframe", "run", "spin-gravity", "--set", "height=10",
                          "--json", "--out", str(tmp_path / "s.rrd")], capture_output=True, text=True, env=env,
                         cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    import json

    summary = json.loads(out.stdout)
    assert summary["scenario"] == "spin-gravity" and summary["units"]["spinward_offset_m"] == "m"
    assert (tmp_path / "s.rrd").is_file()
    bad = subprocess.run([sys.executable, "-m", "rotframe", "run", str(EXAMPLES / "spin-gravity.toml")],
                         capture_output=True, text=True, env=dict(env, ROTFRAME_PLUGINS=""), cwd=tmp_path)
    assert bad.returncode == 2 and "register_scene" in bad.stderr and "Traceback" not in bad.stderr
