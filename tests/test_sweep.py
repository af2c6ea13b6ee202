"""`rotframe sweep`: grids and Monte Carlo, the ensemble path, Dask workers, resuming, bad input."""

import json
import logging
import math
import os
import subprocess
import sys
import time

import numpy as np
import pytest

pq = pytest.importorskip("pyarrow.parquet")

from rotframe.app import cli

from rotframe.app import runner

from rotframe.app import sweep  # noqa: E402
from rotframe.errors import IntegrationError, ScenarioError  # noqa: E402
from workers import busy_worker_killer  # noqa: E402

REPO_SCENARIOS = __import__("pathlib").Path(__file__).resolve().parents[1] / "scenarios"

PROJECTILE_MC = ["--samples", "120", "--vary", "speed=normal(1600,5)", "--vary", "azimuth=normal(232,0.05)"]


def rotframe(*args, cwd, timeout=120):
    return subprocess.run([sys.executable, "-m", "rotframe", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout)


def sweep_json(capsys, *args):
    code = cli.main(["sweep", *args, "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    return json.loads(captured.out)


def rrd_entities(path):
    """{entity: (temporal rows, timelines)} of a recording."""
    from rerun.chunk import RrdReader

    out = {}
    for chunk in RrdReader(str(path)).stream():
        rows, names = out.get(chunk.entity_path, (0, set()))
        out[chunk.entity_path] = (rows + (0 if chunk.is_static else chunk.num_rows),
                                  names | set(chunk.timeline_names))
    return out


@pytest.fixture(scope="module")
def cluster():
    """A LocalCluster of two single-threaded worker processes (restarted by their nannies when killed)."""
    distributed = pytest.importorskip("distributed")
    local = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                     silence_logs=logging.CRITICAL)
    client = distributed.Client(local)
    yield client
    client.close()
    local.close()


# ---------------------------------------------------------------------------
# physics through the sweep
# ---------------------------------------------------------------------------


def test_foucault_latitude_sweep_matches_omega_sin_latitude(tmp_path, monkeypatch, capsys):
    from rotframe import earth

    monkeypatch.chdir(tmp_path)
    out = sweep_json(capsys, "foucault", "--set", "duration=3600", "--set", "small_angle=true", "--method", "exact",
                     "--grid", "latitude=-90:90:37")
    assert out["rows"] == 37 and out["failed"] == 0 and out["path"] == "runs"
    table = pq.read_table(out["out"]).to_pydict()
    assert table["row"] == list(range(37))
    lat = np.array(table["latitude"])
    assert np.allclose(lat, np.linspace(-90, 90, 37), rtol=0, atol=1e-12)
    expected = np.degrees(earth.OMEGA_EARTH * np.sin(np.radians(lat))) * 3600
    rate = np.array(table["precession_rate_deg_per_hour"])
    scale = np.degrees(earth.OMEGA_EARTH) * 3600
    assert np.all(np.abs(rate - expected) <= 1e-5 * np.maximum(np.abs(expected), scale * 1e-3))
    assert np.allclose(table["theory_precession_rate_deg_per_hour"], expected, rtol=1e-9, atol=1e-12)
    assert set(table["error"]) == {""}
    assert "sweeps/foucault-precession_rate_deg_per_hour.png" in out["plots"]
    assert all((tmp_path / p).stat().st_size > 1000 for p in out["plots"])
    rows, timelines = rrd_entities(tmp_path / out["recording"])["/world/ensemble"]
    assert 2 <= rows <= sweep.MAX_TRACK_SAMPLES and "sim_time" in timelines
    assert not (tmp_path / "sweeps" / "foucault.parquet.parts").exists()


def test_tower_drop_monte_carlo_is_one_ensemble_call(tmp_path, monkeypatch, capsys):
    from rotframe.problem import particles as engine
    monkeypatch.chdir(tmp_path)
    sizes = []
    real = engine.simulate_particles

    def counting(**kwargs):
        sizes.append(len(np.atleast_2d(kwargs["r0"])))
        return real(**kwargs)

    monkeypatch.setattr(engine, "simulate_particles", counting)
    t0 = time.perf_counter()
    out = sweep_json(capsys, "tower-drop", "--samples", "100000", "--vary", "height=normal(158.5,1)", "--seed", "7")
    elapsed = time.perf_counter() - t0
    assert out["path"] == "ensemble" and out["rows"] == 100000 and out["failed"] == 0 and out["batches"] == 1
    # the Monte Carlo in vectorised calls of the engine, one per fixed chunk of rows (and fall-time class),
    # each particle once (and the recorded ones again, for their paths)
    assert 100000 <= sum(sizes) <= 100000 + sweep.MAX_TRACKS and max(sizes) <= sweep.batch.ENSEMBLE_CHUNK
    assert elapsed < 45, elapsed
    table = pq.read_table(out["out"]).to_pydict()
    heights = np.array(table["height"])
    assert np.array_equal(heights, np.random.default_rng(7).normal(158.5, 1, 100000))
    monkeypatch.setattr(engine, "simulate_particles", real)
    for i in (0, 31415, 99999):
        single, _ = runner.run("tower-drop", {"height": heights[i]})
        for key, value in single["metrics"].items():
            assert table[key][i] == pytest.approx(value, rel=1e-12, abs=1e-18)


def test_ensemble_groups_match_single_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    spec = sweep.parse_spec("tower-drop", grid=["height=20:300:4", "latitude=-60:60:3"])
    res = sweep.run_sweep(spec, plots=False, recording=False)
    assert res.path == "ensemble" and res.rows == 12
    table = res.table.to_pydict()
    for i in range(12):
        single, _ = runner.run("tower-drop", {"height": table["height"][i], "latitude": table["latitude"][i]})
        for key, value in single["metrics"].items():
            assert table[key][i] == pytest.approx(value, rel=1e-12, abs=1e-18)


def test_a_failed_run_is_a_row_not_the_end(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    real = runner.run

    def flaky(name, sets, **kwargs):
        if sets.get("latitude") == 30.0:
            raise IntegrationError("non-finite state of particle 0 after t = 1 s", t_reached=1.0)
        return real(name, sets, **kwargs)

    monkeypatch.setattr(runner, "run", flaky)
    spec = sweep.parse_spec("projectile", grid=["latitude=0:60:3"])
    res = sweep.run_sweep(spec, plots=False, recording=False)
    table = res.table.to_pydict()
    assert res.rows == 3 and res.failed == 1
    assert table["error"][1].startswith("IntegrationError: non-finite state")
    assert math.isnan(table["range_m"][1]) and table["error"][0] == table["error"][2] == ""
    # Monte Carlo draws outside a parameter's range fail their own rows only
    spec = sweep.parse_spec("tower-drop", samples=200, vary=["height=normal(2,2)"], seed=1)
    res = sweep.run_sweep(spec, out="neg.parquet", plots=False, recording=False)
    table = res.table.to_pydict()
    bad = [e for h, e in zip(table["height"], table["error"]) if h <= 0]
    assert bad and all("out of range" in e for e in bad) and res.failed == len(bad)
    assert all(np.isfinite(f) for h, f in zip(table["height"], table["fall_time_s"]) if h > 0)


def test_dzhanibekov_flip_interval_on_a_log_grid(tmp_path, monkeypatch):
    from rotframe.app import scenario
    if "dzhanibekov" not in scenario.names():
        pytest.skip("no dzhanibekov scenario yet")
    monkeypatch.chdir(tmp_path)
    spec = sweep.parse_spec("dzhanibekov", sets={"omega": "0,1,0", "duration": "300"},
                            log_grid=["omega[0]=1e-7:1e-2:6"])
    res = sweep.run_sweep(spec, recording=False)
    table = res.table.to_pydict()
    assert np.allclose(table["omega[0]"], np.geomspace(1e-7, 1e-2, 6))
    interval = np.array(table["flip_interval_s"])
    assert np.allclose(interval, table["theory_flip_interval_s"], rtol=1e-3)
    assert np.all(np.diff(interval) < 0)  # flips come sooner the larger the perturbation
    assert any(p.endswith("dzhanibekov-flip_interval_s.png") for p in res.plots)


# ---------------------------------------------------------------------------
# execution: Dask, lost workers, resuming
# ---------------------------------------------------------------------------


def test_local_cluster_gives_the_in_process_table(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    here = sweep_json(capsys, "projectile", *PROJECTILE_MC, "--out", "here.parquet")
    there = sweep_json(capsys, "projectile", *PROJECTILE_MC, "--out", "there.parquet", "--workers", "2")
    assert here["rows"] == there["rows"] == 120 and there["failed"] == 0
    a, b = pq.read_table("here.parquet"), pq.read_table("there.parquet")
    assert a.column_names == b.column_names and a.equals(b)


def test_a_lost_worker_costs_no_rows(cluster, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    client = cluster
    pids = client.run(os.getpid)
    spec = sweep.parse_spec("foucault", sets={"duration": "300"}, grid=["latitude=-80:80:24"])
    kill_a_busy_worker = busy_worker_killer(client, pids)
    killed = kill_a_busy_worker.killed

    res = sweep.run_sweep(spec, "dask.parquet", client=client, batch_rows=2, on_batch=kill_a_busy_worker,
                          plots=False, recording=False)
    ref = sweep.run_sweep(spec, "here.parquet", batch_rows=2, plots=False, recording=False)
    assert killed and res.rows == 24 and res.failed == 0
    assert res.table.equals(ref.table)
    assert killed[0] not in client.scheduler_info()["workers"]  # it really died (its nanny started a new one)


def test_interrupted_sweep_resumes_to_the_same_table(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    spec = sweep.parse_spec("projectile", samples=60, vary=["speed=normal(1600,5)"], seed=3)
    full = sweep.run_sweep(spec, "full.parquet", batch_rows=10, plots=False, recording=False)

    def interrupt(done, total):
        if done >= 30:
            raise KeyboardInterrupt

    with pytest.raises(sweep.SweepInterrupted) as info:
        sweep.run_sweep(spec, "cut.parquet", batch_rows=10, on_batch=interrupt)
    assert (info.value.saved, info.value.total) == (30, 60)
    parts = sorted((tmp_path / "cut.parquet.parts").glob("part-*.parquet"))
    assert len(parts) == 3 and not (tmp_path / "cut.parquet").exists()
    parts[1].unlink()  # a lost part is computed again
    resumed = sweep.run_sweep(spec, "cut.parquet", resume=True, batch_rows=10)
    assert resumed.computed == 40 and resumed.rows == 60
    assert resumed.table.equals(full.table)
    assert not (tmp_path / "cut.parquet.parts").exists()
    assert resumed.recording and (tmp_path / resumed.recording).is_file()
    again = sweep.run_sweep(spec, "cut.parquet", resume=True, plots=False, recording=False)
    assert again.computed == 0 and again.table.equals(full.table)
    other = sweep.parse_spec("projectile", samples=60, vary=["speed=normal(1600,5)"], seed=4)
    with pytest.raises(ScenarioError, match="different sweep"):
        sweep.run_sweep(other, "cut.parquet", resume=True)


def test_ctrl_c_inside_a_run_stops_the_sweep(tmp_path, monkeypatch):
    from rotframe.particles.integrators import RunInterrupted

    monkeypatch.chdir(tmp_path)
    real = runner.run

    def interrupted_at_45(name, sets, **kwargs):
        if sets.get("latitude") == 45.0:
            raise RunInterrupted(None)
        return real(name, sets, **kwargs)

    monkeypatch.setattr(runner, "run", interrupted_at_45)
    spec = sweep.parse_spec("projectile", grid=["latitude=0:60:5"])
    with pytest.raises(sweep.SweepInterrupted) as info:
        sweep.run_sweep(spec, batch_rows=1)
    assert info.value.saved == 3  # latitudes 0, 15 and 30; the interrupted row is not written as a failure
    monkeypatch.setattr(runner, "run", real)
    res = sweep.run_sweep(spec, resume=True, batch_rows=1, plots=False, recording=False)
    assert res.computed == 2 and res.failed == 0


def test_monte_carlo_rows_depend_only_on_the_seed():
    spec = sweep.parse_spec("projectile", samples=5, vary=["speed=uniform(1500,1700)", "azimuth=normal(232,1)"],
                            seed=11)
    rng = np.random.default_rng(11)
    expected = np.stack([rng.uniform(1500, 1700, 5), rng.normal(232, 1, 5)], axis=1)
    assert np.array_equal(sweep.sweep_points(spec), expected)
    grid = sweep.parse_spec("projectile", grid=["speed=1000:2000:3"], log_grid=["drag=1e-6:1e-4:2"])
    assert sweep.sweep_points(grid).tolist() == [[1000, 1e-6], [1000, 1e-4], [1500, 1e-6], [1500, 1e-4],
                                                 [2000, 1e-6], [2000, 1e-4]]


# ---------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------


BAD = [
    (["foucault", "--grid", "latitude=0:10:0"], "N = 0 must be >= 1"),
    (["foucault", "--grid", "latitud=0:10:5"], "did you mean 'latitude'"),
    (["projectile", *PROJECTILE_MC[:2], "--vary", "speed=gauss(1600,5)"], "unknown distribution 'gauss'"),
    (["foucault", "--log-grid", "latitude=-10:10:5"], "must both be > 0"),
    (["foucault", "--grid", "latitude=-100:90:5"], "out of range"),
    (["foucault", "--grid", "small_angle=0:1:2"], "not a numeric parameter"),
    (["projectile", "--samples", "0", "--vary", "speed=normal(1600,5)"], "must be >= 1"),
]


@pytest.mark.parametrize("args,fragment", BAD)
def test_bad_sweeps_exit_2_with_one_line(tmp_path, args, fragment):
    res = rotframe("sweep", *args, cwd=tmp_path)
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and fragment in lines[0], res.stderr
    assert "Traceback" not in res.stderr and not (tmp_path / "sweeps").exists()


# ---------------------------------------------------------------------------
# the Python API and the resume fingerprint
# ---------------------------------------------------------------------------


def test_python_sweep_is_the_command_lines_sweep(tmp_path, monkeypatch):
    pd = pytest.importorskip("pandas")
    import rotframe
    import rotframe.app.sweep as module  # the package still imports as before

    monkeypatch.chdir(tmp_path)
    assert callable(rotframe.sweep) and module.run_sweep is sweep.run_sweep
    df = rotframe.sweep("tower-drop", grid={"height": [20.0, 158.5], "latitude": [-30.0, 50.9]}, drag=0)
    spec = sweep.parse_spec("tower-drop", sets={"drag": 0}, grid=["height=20:158.5:2", "latitude=-30:50.9:2"])
    ref = sweep.run_sweep(spec, "ref.parquet", plots=False, recording=False).table.to_pandas()
    assert isinstance(df, pd.DataFrame) and list(df.columns) == list(ref.columns)
    pd.testing.assert_frame_equal(df, ref)
    # points from a quasi-random design: one row each, in order; Monte Carlo as on the command line
    qmc = pytest.importorskip("scipy.stats.qmc")
    design = qmc.scale(qmc.LatinHypercube(d=2, seed=3).random(5), [10, -60], [300, 60])
    df = rotframe.sweep("tower-drop", points=pd.DataFrame({"height": design[:, 0], "latitude": design[:, 1]}))
    assert np.array_equal(df["height"], design[:, 0]) and np.array_equal(df["latitude"], design[:, 1])
    for i in (0, 4):
        single = rotframe.run("tower-drop", height=design[i, 0], latitude=design[i, 1])
        assert df["east_deflection_m"][i] == pytest.approx(single.metrics["east_deflection_m"], rel=1e-12)
    mc = rotframe.sweep("projectile", vary={"speed": "normal(1600,5)"}, samples=3, seed=2, out="mc.parquet")
    assert np.array_equal(mc["speed"], np.random.default_rng(2).normal(1600, 5, 3))
    assert pq.read_table("mc.parquet").num_rows == 3
    assert not list(tmp_path.glob("sweeps"))  # out=None writes nothing


@pytest.mark.parametrize("kwargs,fragment", [
    ({"grid": {"hieght": [1, 2]}}, "did you mean 'height'"),
    ({"grid": {"height": [1, 2]}, "points": {"latitude": [1, 2]}}, "not grid and points"),
    ({"points": {"height": [1, 2], "latitude": [3]}}, "equal length"),
    ({"points": {"height": [1, float("nan")]}}, "non-finite"),
    ({"vary": {"height": "normal(100,1)"}}, "--vary needs --samples"),
    ({"grid": {"height": [-1, 2]}}, "height"),
])
def test_python_sweep_refuses_bad_input_in_one_line(tmp_path, monkeypatch, kwargs, fragment):
    import rotframe

    monkeypatch.chdir(tmp_path)
    with pytest.raises(ScenarioError) as info:
        rotframe.sweep("tower-drop", **kwargs)
    assert fragment in str(info.value) and "\n" not in str(info.value)


def test_resume_refuses_a_changed_scenario_file(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "my-gun.toml"
    text = (REPO_SCENARIOS / "projectile.toml").read_text(encoding="utf-8")
    path.write_text(text, encoding="utf-8")
    spec = sweep.parse_spec(str(path), samples=6, vary=["speed=normal(1600,5)"], seed=1)

    def stop(done, total):
        raise KeyboardInterrupt

    with pytest.raises(sweep.SweepInterrupted):
        sweep.run_sweep(spec, "gun.parquet", batch_rows=2, on_batch=stop)
    path.write_text(text + "\n# changed after the first batch\n", encoding="utf-8")
    with pytest.raises(ScenarioError, match="scenario file.* changed"):
        sweep.run_sweep(spec, "gun.parquet", resume=True, batch_rows=2)
    path.write_text(text, encoding="utf-8")  # the same text again: the resume goes on
    res = sweep.run_sweep(spec, "gun.parquet", resume=True, batch_rows=2, plots=False, recording=False)
    assert res.computed == 4 and res.rows == 6


def test_a_dask_objects_error_at_exit_is_kept_quiet_and_others_are_not(monkeypatch):
    """A Dask future cut by a signal while it was made raises in its ``__del__`` at exit; a sweep that made a client
    prints no traceback for it (`execute._quiet_dask_unraisable`), and still passes on any other object's."""
    import types

    from distributed.client import Future

    from rotframe.app.sweep import execute

    seen = []
    monkeypatch.setattr(sys, "unraisablehook", lambda unraisable: seen.append(unraisable.object))
    execute._quiet_dask_unraisable()
    execute._quiet_dask_unraisable()  # once a process: the second call adds nothing
    error = AttributeError("'Future' object has no attribute '_cleared'")

    def unraisable(obj):
        return types.SimpleNamespace(exc_type=AttributeError, exc_value=error, exc_traceback=None, err_msg=None,
                                     object=obj)

    sys.unraisablehook(unraisable(Future.__del__))
    assert seen == []
    sys.unraisablehook(unraisable(test_a_dask_objects_error_at_exit_is_kept_quiet_and_others_are_not))
    assert seen == [test_a_dask_objects_error_at_exit_is_kept_quiet_and_others_are_not]
