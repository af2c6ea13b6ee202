"""The command line as a user meets it: exit codes, one-line errors, JSON, recordings."""

import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def rotframe(*args, cwd, timeout=300):
    return subprocess.run([sys.executable, "-m", "rotframe", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout)


def read_rrd(path):
    """{entity: (n_temporal_rows, timeline names, columns)} from a recording, via RrdReader.

    Static chunks add their columns but no rows.
    """
    from rerun.chunk import RrdReader

    out = {}
    for chunk in RrdReader(str(path)).stream():
        rows, names, cols = out.get(chunk.entity_path, (0, set(), set()))
        rb = chunk.to_record_batch()
        rows += 0 if chunk.is_static else chunk.num_rows
        out[chunk.entity_path] = (rows, names | set(chunk.timeline_names), cols | set(rb.schema.names))
    return out


def test_run_turntable_writes_a_readable_recording(tmp_path):
    res = rotframe("run", "turntable", "--set", "samples=500", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    path = tmp_path / "recordings" / "turntable.rrd"
    assert path.is_file()
    assert not list((tmp_path / "recordings").glob("*.tmp"))
    entities = read_rrd(path)
    rows, timelines, cols = entities["/world/puck"]
    assert rows == 501 and "sim_time" in timelines and "Points3D:positions" in cols
    assert "/world/puck/trail" in entities
    assert "/diagnostics/position_error_m" in entities
    assert "/scenario" in entities


def test_run_json_is_one_object_with_timing(tmp_path):
    res = rotframe("run", "turntable", "--json", "--no-record", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    summary = json.loads(res.stdout)
    assert summary["scenario"] == "turntable"
    assert set(summary["timing"]) >= {"simulate_s", "record_s", "total_s"}
    assert summary["metrics"]["position_error_m"] < 1e-6  # within a micrometre of the oracle
    assert summary["recording"] is None
    assert set(summary["params"]) >= {"omega0", "alpha", "speed", "duration"}


BAD = [
    (["run", "nosuch"], "unknown scenario"),
    (["run", "turntabel"], "did you mean 'turntable'"),
    (["run", "../turntable"], "not a scenario name"),
    (["run", "turntable", "--set", "omga0=1"], "did you mean 'omega0'"),
    (["run", "turntable", "--set", "speed=3 s"], "wrong dimension"),
    (["run", "turntable", "--set", "speed=nan"], "finite"),
    (["run", "turntable", "--set", "duration=-1"], "out of range"),
    (["run", "turntable", "--set", "speed"], "KEY=VALUE"),
    (["run", "turntable", "--method", "euler"], "allowed"),
    (["run", "missing.toml"], "does not exist"),
    (["view", "nope.rrd"], "no recording"),
]


@pytest.mark.parametrize("args,fragment", BAD)
def test_bad_input_exits_2_with_one_line(tmp_path, args, fragment):
    res = rotframe(*args, cwd=tmp_path)
    assert res.returncode == 2, (res.stdout, res.stderr)
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert fragment in lines[0]
    assert "Traceback" not in res.stderr


def test_bad_scenario_file_names_file_and_key(tmp_path):
    src = (REPO / "scenarios" / "turntable.toml").read_text()
    bad = tmp_path / "mine.toml"
    bad.write_text(src.replace("[parameters.omega0]", "[parameters.omega0]\ndefualt_unit = 1"))
    res = rotframe("run", str(bad), cwd=tmp_path)
    assert res.returncode == 2
    assert "mine.toml" in res.stderr and "defualt_unit" in res.stderr


def test_scenario_file_from_anywhere_runs(tmp_path):
    src = (REPO / "scenarios" / "turntable.toml").read_text().replace("default = 4.0", "default = 1.0")
    mine = tmp_path / "elsewhere" / "spin.toml"
    mine.parent.mkdir()
    mine.write_text(src)
    res = rotframe("run", str(mine), "--json", "--no-record", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["params"]["duration"] == 1.0


def test_list_and_help_do_not_import_heavy_modules(tmp_path):
    code = ("import sys; from rotframe.app.cli import main; main(['list']);"
            "heavy = [m for m in ('rerun', 'astropy', 'numba') if m in sys.modules]; print('HEAVY', heavy)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert "HEAVY []" in res.stdout, res.stdout + res.stderr
    assert "turntable" in res.stdout


def test_sigterm_leaves_a_readable_partial_recording(tmp_path):
    # an earlier complete recording must survive untouched
    rec_dir = tmp_path / "recordings"
    rec_dir.mkdir()
    (rec_dir / "turntable.rrd").write_bytes(b"earlier")
    # compile the kernels first, so that the signal arrives while the run integrates
    assert rotframe("run", "turntable", "--set", "duration=0.1", "--method", "splitting", "--no-record",
                    cwd=tmp_path).returncode == 0
    from signs import start, wait_for

    # the sign: the engine's second call of its loop (the first may run in the plain tier), so the run is integrating
    proc, sign = start(tmp_path, "rotframe.problem.particles", "advance_blocks", 2, "run", "turntable",
                       "--set", "duration=400", "--set", "step=1e-6", "--method", "splitting")
    wait_for(sign, proc)
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 143, err
    assert (rec_dir / "turntable.rrd").read_bytes() == b"earlier"
    partial = rec_dir / "turntable.partial.rrd"
    assert partial.is_file()
    assert "partial" in err and "simulated time" in err
    rows, _, _ = read_rrd(partial)["/world/puck"]
    assert rows >= 1


def test_quantity_strings_convert(tmp_path):
    res = rotframe("run", "tower-drop", "--set", "height=520 ft", "--set", "latitude=50d53m", "--json", "--no-record",
                   cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    params = json.loads(res.stdout)["params"]
    assert params["height"] == pytest.approx(520 * 0.3048)
    assert params["latitude"] == pytest.approx(50 + 53 / 60)


def test_exact_refused_on_curvature_names_curvature(tmp_path):
    # 'curvature' makes the model nonlinear (the ground is a sphere): the one-line error must say so,
    # not blame a varying omega (the projectile's omega is constant)
    toml = (REPO / "scenarios" / "projectile.toml").read_text()
    toml = toml.replace('model = ["gravity", "coriolis"]', 'model = ["gravity", "coriolis", "curvature"]')
    assert "curvature\"]" in toml
    path = tmp_path / "curved.toml"
    path.write_text(toml)
    res = rotframe("run", str(path), "--method", "exact", "--no-record", cwd=tmp_path)
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert "curvature" in lines[0] and "exact" in lines[0]
    assert "omega varies" not in lines[0]


def test_show_says_which_method_runs_by_default(tmp_path):
    # projectile.toml names no method: the scene picks exact (linear model) or dop853, and show says so
    res = rotframe("show", "projectile", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    line = next(x for x in res.stdout.splitlines() if x.startswith("default method:"))
    assert "exact" in line and "dop853" in line
    # heavy-top.toml names its method: the run line carries it and no default line is added
    res = rotframe("show", "heavy-top", cwd=tmp_path)
    assert "method = top-splitting8" in res.stdout and "default method:" not in res.stdout
