"""Recordings a student can read: read back with RrdReader, entity paths and what they hold.

DESIGN's layout (timeline ``sim_time``, ``world/<name>``, ``diagnostics/<quantity>``,
``scenario``) plus what issue 15 adds: z-up view coordinates, trails that grow with
time, theory beside the measured series, the heavy top's L per sample.
"""

from __future__ import annotations

import numpy as np
import pytest

import rotframe


def _read(path):
    """{entity: {"static": bool, "rows": int, "columns": {name: pyarrow column, ...}}}."""
    from rerun.chunk import RrdReader

    out = {}
    for chunk in RrdReader(str(path)).stream():
        rb = chunk.to_record_batch()
        info = out.setdefault(chunk.entity_path, {"static": True, "rows": 0, "columns": {}})
        if not chunk.is_static:
            info["static"] = False
            info["rows"] += chunk.num_rows
        for name in rb.schema.names:
            info["columns"].setdefault(name, []).append(rb.column(name))
    return out


SCENES = {
    "turntable": ({"duration": 2}, ["/world/puck", "/world/puck/trail", "/world/frame", "/world/inertial_axes",
                                     "/diagnostics/position_error_m"]),
    "tower-drop": ({}, ["/world/body", "/world/body/trail", "/world/frame", "/world/frame/omega",
                        "/diagnostics/east_deflection_mm", "/diagnostics/east_deflection_mm/theory"]),
    "foucault": ({"duration": 120}, ["/world/bob", "/world/bob/trail", "/world/swing_plane", "/world/frame/omega",
                                     "/diagnostics/swing_angle_deg", "/diagnostics/swing_angle_deg/theory"]),
    "inertial-oscillation": ({}, ["/world/puck", "/world/puck/trail", "/world/frame",
                                  "/diagnostics/velocity_direction_deg/theory"]),
    "projectile": ({}, ["/world/shell", "/world/shell/trail", "/world/frame"]),
    "free-top": ({}, ["/world/body", "/world/angular_momentum", "/diagnostics/omega_body/1"]),
    "dzhanibekov": ({"duration": 40}, ["/world/body", "/world/angular_momentum", "/diagnostics/energy_rel_error"]),
    "heavy-top": ({"duration": 1}, ["/world/body", "/world/angular_momentum", "/world/tip_path",
                                    "/diagnostics/theta_deg", "/diagnostics/theta_deg/theory_min",
                                    "/diagnostics/theta_deg/theory_max", "/diagnostics/energy_rel_error"]),
}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_layout(name, tmp_path):
    params, expected = SCENES[name]
    path = rotframe.run(name, **params).record(tmp_path / f"{name}.rrd")
    found = _read(path)
    missing = [e for e in expected + ["/scenario", "/world"] if e not in found]
    assert not missing, f"{name}: missing {missing}; have {sorted(found)}"
    assert any("ViewCoordinates" in c for c in found["/world"]["columns"])  # z up for the viewer
    for entity, info in found.items():
        if not info["static"]:
            assert "sim_time" in info["columns"], entity
    for trail in (e for e in expected if e.endswith("/trail") or e.endswith("tip_path")):
        assert not found[trail]["static"] and found[trail]["rows"] > 1, f"{trail} should grow with time"


def test_trail_grows():
    """Each frame of the trail ends at the point of that time and holds no later point."""
    import pyarrow as pa  # noqa: F401  (rerun's columns are pyarrow arrays)

    r = rotframe.run("tower-drop")
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as d:
        found = _read(r.record(Path(d) / "t.rrd"))
    strips = [s for col in found["/world/body/trail"]["columns"]["LineStrips3D:strips"] for s in col.to_pylist()]
    lengths = [len(s[0]) for s in strips if s]
    assert lengths == sorted(lengths) and lengths[0] < lengths[-1]


def test_heavy_top_L_turns_and_keeps_its_vertical_part(tmp_path):
    """L in space per sample: vertical part constant (the gravity torque is horizontal), horizontal part turns.

    Logged as float32 arrows scaled to a fixed length: the vertical component is
    compared to 1e-5 relative (float32 round-off is 6e-8); the horizontal part must
    turn by more than 10 degrees in 1 s of the default top (precession ~ 1 rad/s).
    """
    r = rotframe.run("heavy-top", duration=1)
    found = _read(r.record(tmp_path / "h.rrd"))
    info = found["/world/angular_momentum"]
    assert not info["static"] and info["rows"] > 100
    vectors = np.array([v[0] for col in info["columns"]["Arrows3D:vectors"] for v in col.to_pylist() if v])
    assert np.ptp(vectors[:, 2]) <= 1e-5 * np.linalg.norm(vectors[0])
    heading = np.unwrap(np.arctan2(vectors[:, 1], vectors[:, 0]))
    assert np.ptp(heading) > np.radians(10)


def test_text_summary_of_a_recording(tmp_path):
    from rotframe.app.recording_summary import describe

    path = rotframe.run("tower-drop").record(tmp_path / "t.rrd")
    text = describe(path)
    assert "/world/body" in text and "Points3D" in text and "east_deflection_m" in text


def _blueprint(path):
    """{(entity, column): values} of the recording's blueprint store."""
    from rerun.chunk import RrdReader

    reader = RrdReader(str(path))
    out = {}
    for chunk in reader.stream(store=reader.blueprints()[0]):
        rb = chunk.to_record_batch()
        for name in rb.schema.names:
            out[(str(chunk.entity_path).rsplit("/", 1)[-1], name)] = rb.column(name).to_pylist()
    return out


@pytest.mark.parametrize("name, params, within_s", [("foucault", {}, 60.0), ("free-top", {}, 60.0),
                                                    ("tower-drop", {}, 60.0)])
def test_playback_shows_the_run_in_under_a_minute(name, params, within_s, tmp_path):
    r = rotframe.run(name, **params)
    bp = _blueprint(r.record(tmp_path / f"{name}.rrd"))
    speed = bp[("time_panel", "TimePanelBlueprint:playback_speed")][0][0]
    duration = float(r.trajectory.times[-1])
    assert speed >= 1.0 and duration / speed <= within_s, (duration, speed)


def test_foucault_eye_looks_down_on_the_swing(tmp_path):
    r = rotframe.run("foucault", duration=600)
    bp = _blueprint(r.record(tmp_path / "f.rrd"))
    eye = np.array(bp[("EyeControls3D", "EyeControls3D:position")][0][0])
    target = np.array(bp[("EyeControls3D", "EyeControls3D:look_target")][0][0])
    down = target - eye
    amplitude = r.params["amplitude"]
    assert down[2] < 0 and abs(down[2]) > 2 * np.hypot(down[0], down[1])  # from above, steeper than 60 deg
    assert np.linalg.norm(down) < 0.2 * r.params["length"]  # near the swing, not framing the 67 m string
    assert np.linalg.norm(down) > amplitude


def test_error_series_are_also_logged_as_log10_of_their_largest_size_so_far(tmp_path):
    r = rotframe.run("dzhanibekov", duration=40)
    found = _read(r.record(tmp_path / "d.rrd"))
    raw = np.concatenate([np.asarray(c.to_pylist(), dtype=object) for c in
                          found["/diagnostics/energy_rel_error"]["columns"]["Scalars:scalars"]])
    logs = np.concatenate([np.asarray(c.to_pylist(), dtype=object) for c in
                           found["/diagnostics/log10_energy_rel_error"]["columns"]["Scalars:scalars"]])
    raw = np.array([v[0] for v in raw], dtype=float)
    logs = np.array([v[0] for v in logs], dtype=float)
    envelope = np.maximum.accumulate(np.abs(raw))  # the largest error so far: a drift reads, no comb of zeros
    nonzero = envelope != 0
    assert np.allclose(logs[nonzero], np.log10(envelope[nonzero]))
    assert np.all(logs[~nonzero] == -18.0)
    assert np.all(np.diff(logs) >= 0)
    assert np.max(logs) < -12  # round-off of the exact solution: visible on a log axis, not 0.000 000 000 4


def _views(container):
    """The views of a blueprint's container, depth first."""
    import rerun.blueprint as rrb

    if isinstance(container, rrb.Container):
        for item in container.contents:
            yield from _views(item)
    else:
        yield container


@pytest.mark.parametrize("name", sorted(SCENES) + ["cr3bp", "tumbling-ball"])
def test_every_time_series_opens_on_the_whole_run(name, tmp_path, monkeypatch):
    """rerun's default shows a window around the time cursor (a minute of Foucault's hour): every time-series
    view of every scene's blueprint shows all its data, its time axis from 0 to the run's last time."""
    from rotframe.app import record

    sent = []
    original = record.Recording.blueprint

    def spy(self, *args, **kwargs):
        original(self, *args, **kwargs)
        sent.append(self)

    monkeypatch.setattr(record.Recording, "blueprint", spy)
    params = SCENES.get(name, ({},))[0]
    path = rotframe.run(name, **params).record(tmp_path / f"{name}.rrd")
    (rec,) = sent
    logged = [c for info in _read(path).values() for c in info["columns"].get("sim_time", [])]
    end_ns = max(max(int(t.value) for t in column) for column in logged)  # the last time in the file
    series = [v for v in _views(rec.sent_blueprint.root_container) if type(v).__name__ == "TimeSeriesView"]
    assert series, name
    for view in series:
        ranges = view.properties["VisibleTimeRanges"].ranges.as_arrow_array().to_pylist()
        assert ranges == [{"timeline": record.TIMELINE, "range": {"start": None, "end": None}}], (name, ranges)
        axis = view.properties["TimeAxis"].view_range.as_arrow_array().to_pylist()
        assert axis[0]["start"] == 0 and abs(axis[0]["end"] - end_ns) <= 1, (name, axis)
