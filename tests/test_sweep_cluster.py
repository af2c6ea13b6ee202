"""Sweeps on a real Dask cluster: ``dask scheduler`` and two ``dask worker`` processes on localhost.

The cluster is started as subprocesses on free ports (readiness is polled from the
scheduler, never slept for) and stopped by the test's own process ids. The workers
get no ``ROTFRAME_PLUGINS``: the plugin scene of these tests reaches them only as the
source the sweep ships in its tasks. Every wait is bounded, so a hang fails a test
instead of stalling the suite. No timing is asserted.

Covered: the table is bitwise the same however the work is cut (batch size,
backend, threads, resume); a worker killed mid-sweep costs nothing; a row that kills
its workers is a failed row with the cause, never run in the client; the scheduler
killed mid-sweep ends the command with exit 1 and the resume hint, and ``--resume``
finishes the same table; SIGTERM and SIGINT during a Dask sweep give 143 and 130 and the hint.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")
pq = pytest.importorskip("pyarrow.parquet")

from rotframe.app import sweep  # noqa: E402
from workers import busy_worker_killer  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
# a task may see one worker die under it (a second death is KilledWorker), and a worker holds one task at a time,
# so that a row that kills its worker takes no other batch with it
ENV = dict(os.environ, PYTHONPATH=str(REPO / "src"), DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES="1",
           DASK_DISTRIBUTED__SCHEDULER__WORKER_SATURATION="1.0")
ENV.pop("ROTFRAME_PLUGINS", None)
ENV.pop("DASK_SCHEDULER_ADDRESS", None)

#: a plugin scene: the projectile, but a row at speed POISON kills its process, and every row naps NAP s
PLUGIN = '''
import os, signal, sys, time
import rotframe
from rotframe.scenes import projectile as _base

POISON = 1234.5
NAP = {nap}
METHODS = _base.METHODS


def simulate(values, terms, method, run, progress):
    if os.environ.get("ROTFRAME_TEST_CLIENT") == str(os.getpid()):
        raise RuntimeError("a row ran in the client")
    if values["speed"] == POISON:
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(NAP)
    return _base.simulate(values, terms, method, run, progress)


analyse, record = _base.analyse, _base.record
rotframe.register_scene("{scene}", sys.modules[__name__])
'''


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    """``dask scheduler`` and ``dask worker`` subprocesses (each worker with its nanny and one thread)."""

    def __init__(self, tmp, workers=2):
        self.port = free_port()
        self.address = f"tcp://127.0.0.1:{self.port}"
        self.log = open(tmp / f"dask-{self.port}.log", "w")
        self.procs = []
        self.scheduler = self._start([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                      "--port", str(self.port), "--no-dashboard"])
        for _ in range(workers):
            self._start([sys.executable, "-m", "distributed.cli.dask_worker", self.address, "--nthreads", "1",
                         "--no-dashboard", "--host", "127.0.0.1"])
        self.client = None
        deadline = time.monotonic() + 90
        while self.client is None:  # poll the scheduler until it answers
            if time.monotonic() > deadline or self.scheduler.poll() is not None:
                self.stop()
                pytest.fail(f"the Dask scheduler did not start; see {self.log.name}")
            try:
                self.client = distributed.Client(self.address, timeout="2s", set_as_default=False)
            except OSError:
                time.sleep(0.2)
        self.client.wait_for_workers(workers, timeout=90)

    def _start(self, argv):
        proc = subprocess.Popen(argv, env=ENV, stdout=self.log, stderr=subprocess.STDOUT)
        self.procs.append(proc)
        return proc

    def worker_pids(self):
        return self.client.run(os.getpid)

    def stop(self):
        if self.client is not None:
            try:
                self.client.close(timeout=5)
            except Exception:  # noqa: BLE001 -- the scheduler may be gone
                pass
        for proc in self.procs:
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)
        for proc in self.procs:
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(timeout=15)
        self.log.close()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = Cluster(tmp_path_factory.mktemp("dask"))
    yield c
    c.stop()


def plugin(tmp_path, scene="poison-projectile", nap=0.0):
    """A plugin module file and its scenario (projectile's, under the plugin's scene); (module path, toml path)."""
    source = (REPO / "scenarios" / "projectile.toml").read_text(encoding="utf-8")
    lines = [ln for ln in source.splitlines() if not ln.startswith(("scene =", "name ="))]
    toml = tmp_path / f"{scene}.toml"
    toml.write_text(f'name = "{scene}"\nscene = "{scene}"\n' + "\n".join(lines) + "\n", encoding="utf-8")
    module = tmp_path / f"{scene.replace('-', '_')}_plugin.py"
    module.write_text(PLUGIN.format(nap=nap, scene=scene), encoding="utf-8")
    return module, toml


def load_plugin(path):
    import importlib.util

    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def same(a, b):
    """Two sweep tables equal bitwise (NaN rows too, which Arrow's ``equals`` calls unequal)."""
    assert a.column_names == b.column_names
    for name in a.column_names:
        x, y = a.column(name).to_numpy(zero_copy_only=False), b.column(name).to_numpy(zero_copy_only=False)
        if x.dtype == np.float64:
            x, y = x.view(np.uint64), y.view(np.uint64)
        assert np.array_equal(x, y), name
    return True


# ---------------------------------------------------------------------------


def test_the_table_does_not_depend_on_how_the_work_is_cut(cluster, tmp_path, monkeypatch):
    """Tower-drop Monte Carlo over several ensemble chunks (with failed rows): in-process (every core, one thread,
    small batches),
    an interrupted and resumed run, a LocalCluster and the external scheduler give one table, bitwise."""
    from rotframe.particles.ensemble import threads_scope

    monkeypatch.chdir(tmp_path)
    n = 2 * sweep.batch.ENSEMBLE_CHUNK + 300
    spec = sweep.parse_spec("tower-drop", samples=n, vary=["height=uniform(-10,3000)"], seed=5)
    quiet = {"plots": False, "recording": False}
    ref = sweep.run_sweep(spec, "ref.parquet", **quiet).table
    errors = ref.column("error").to_pylist()
    assert ref.num_rows == n and 0 < sum(bool(e) for e in errors) < 100  # a few heights <= 0 are failed rows
    with threads_scope(1):
        small = sweep.run_sweep(spec, "small.parquet", batch_rows=sweep.batch.ENSEMBLE_CHUNK, **quiet).table
    assert same(small, ref)

    def stop(done, total):
        raise KeyboardInterrupt

    with pytest.raises(sweep.SweepInterrupted):
        sweep.run_sweep(spec, "cut.parquet", batch_rows=sweep.batch.ENSEMBLE_CHUNK, on_batch=stop, **quiet)
    resumed = sweep.run_sweep(spec, "cut.parquet", resume=True, **quiet)
    assert resumed.computed == n - sweep.batch.ENSEMBLE_CHUNK and same(resumed.table, ref)
    external = sweep.run_sweep(spec, "external.parquet", scheduler=cluster.address, **quiet)
    assert same(external.table, ref) and external.batches >= 2
    local = sweep.run_sweep(spec, "local.parquet", workers=2, **quiet)
    assert same(local.table, ref)
    # a scene run row by row (projectile): the external cluster gives the in-process table
    spec = sweep.parse_spec("projectile", samples=12, vary=["speed=normal(1600,5)"], seed=2)
    here = sweep.run_sweep(spec, "p-here.parquet", **quiet).table
    there = sweep.run_sweep(spec, "p-there.parquet", scheduler=cluster.address, batch_rows=3, **quiet).table
    assert same(there, here) and not any(here.column("error").to_pylist())


def test_a_worker_killed_mid_sweep_costs_no_rows(cluster, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    module, toml = plugin(tmp_path, scene="napping-projectile", nap=0.2)
    load_plugin(module)
    client = cluster.client
    pids = cluster.worker_pids()
    spec = sweep.parse_spec(str(toml), samples=16, vary=["speed=normal(1600,5)"], seed=4)
    kill_a_busy_worker = busy_worker_killer(client, pids)
    killed = kill_a_busy_worker.killed

    res = sweep.run_sweep(spec, "dask.parquet", client=client, batch_rows=2, on_batch=kill_a_busy_worker,
                          plots=False, recording=False)
    assert killed and res.rows == 16 and res.failed == 0, res.table.column("error").to_pylist()
    ref = sweep.run_sweep(spec, "here.parquet", batch_rows=5, plots=False, recording=False)
    assert same(res.table, ref.table)
    client.wait_for_workers(2, timeout=90)  # the nanny starts a new worker for the next test


def test_a_row_that_kills_its_workers_is_a_failed_row_never_run_here(cluster, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    module, toml = plugin(tmp_path)
    load_plugin(module)
    monkeypatch.setenv("ROTFRAME_TEST_CLIENT", str(os.getpid()))
    speeds = {"speed": np.array([1234.5, 1600.0, 1601.0, 1602.0, 1603.0, 1604.0])}
    spec = sweep.spec.python_spec(str(toml), points=speeds)
    res = sweep.run_sweep(spec, "poison.parquet", client=cluster.client, batch_rows=3, plots=False, recording=False)
    errors = res.table.column("error").to_pylist()
    assert res.failed == 1 and errors[0].startswith("KilledWorker"), errors
    assert not any(e for i, e in enumerate(errors) if i != 0)
    assert np.isnan(res.table.column("range_m").to_numpy()[0])
    cluster.client.wait_for_workers(2, timeout=90)


def test_a_scheduler_file_and_dask_scheduler_address_reach_the_cluster(cluster, tmp_path, monkeypatch):
    from rotframe.app import cli

    monkeypatch.chdir(tmp_path)
    module, toml = plugin(tmp_path, scene="remote-projectile")
    load_plugin(module)
    monkeypatch.setenv("ROTFRAME_TEST_CLIENT", str(os.getpid()))  # a row run here fails
    spec = sweep.spec.python_spec(str(toml), points={"speed": np.array([1600.0, 1601.0])})
    path = tmp_path / "scheduler.json"
    path.write_text(json.dumps({"address": cluster.address}), encoding="utf-8")
    res = sweep.run_sweep(spec, "file.parquet", scheduler_file=str(path), batch_rows=1, plots=False,
                          recording=False)
    assert res.failed == 0, res.table.column("error").to_pylist()
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", cluster.address)
    code = cli.main(["sweep", str(toml), "--samples", "4", "--vary", "speed=normal(1600,5)", "--out", "env.parquet",
                     "--json"])  # the first rows are timed on the cluster too, never here
    assert code == 0
    assert not any(pq.read_table(tmp_path / "env.parquet").column("error").to_pylist())


def test_a_batch_over_the_task_timeout_is_failed_rows_and_the_sweep_goes_on(cluster, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    module, toml = plugin(tmp_path, scene="sleepy-projectile", nap=2.0)
    load_plugin(module)
    spec = sweep.spec.python_spec(str(toml), points={"speed": np.array([1600.0, 1601.0])})
    res = sweep.run_sweep(spec, "slow.parquet", client=cluster.client, batch_rows=2, task_timeout=0.5, plots=False,
                          recording=False)
    errors = res.table.column("error").to_pylist()
    assert res.rows == 2 and res.failed == 2 and all(e.startswith("TimeoutError") for e in errors), errors


def wait_for_part(tmp_path, proc, name):
    deadline = time.monotonic() + 120
    while not list((tmp_path / f"{name}.parts").glob("part-*.parquet")):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "no batch finished"
        time.sleep(0.05)


@pytest.mark.parametrize("sig,code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)], ids=["SIGTERM", "SIGINT"])
def test_a_signal_during_a_dask_sweep_gives_its_code_and_the_hint(cluster, tmp_path, sig, code):
    module, toml = plugin(tmp_path, scene="slow-projectile", nap=0.3)
    env = dict(ENV, ROTFRAME_PLUGINS=str(module))
    # 120 rows of 0.3 s: the sweep is still running when the signal comes, even where a loaded machine delays this
    # process's view of the first part (with 40, CI once saw the sweep end, exit 0, before its signal landed)
    argv = [sys.executable, "-m", "rotframe", "sweep", str(toml), "--samples", "120", "--vary",
            "speed=normal(1600,5)", "--scheduler", cluster.address, "--out", "s.parquet"]
    proc = subprocess.Popen(argv, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wait_for_part(tmp_path, proc, "s.parquet")
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)  # a bound, so that a hang fails the test
    assert proc.returncode == code, err
    assert "--resume" in err and "Traceback" not in err
    cluster.client.wait_for_workers(2, timeout=90)


def test_the_scheduler_killed_mid_sweep_ends_with_the_hint_and_resume_finishes(tmp_path):
    own = Cluster(tmp_path, workers=1)
    try:
        module, toml = plugin(tmp_path, scene="slow-projectile", nap=0.3)
        env = dict(ENV, ROTFRAME_PLUGINS=str(module))
        argv = [sys.executable, "-m", "rotframe", "sweep", str(toml), "--samples", "24", "--vary",
                "speed=normal(1600,5)", "--out", "s.parquet", "--json"]
        proc = subprocess.Popen([*argv, "--scheduler", own.address], cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        wait_for_part(tmp_path, proc, "s.parquet")
        own.scheduler.send_signal(signal.SIGKILL)
        out, err = proc.communicate(timeout=90)  # a bound, so that a hang fails the test
    finally:
        own.stop()
    assert proc.returncode == 1, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "--resume" in lines[0] and "scheduler" in lines[0], err
    assert list((tmp_path / "s.parquet.parts").glob("part-*.parquet"))
    again = subprocess.run([*argv, "--resume"], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=240)
    assert again.returncode == 0, again.stderr
    assert json.loads(again.stdout)["rows"] == 24
    full = subprocess.run([*argv[:-3], "--out", "full.parquet", "--json"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=240)
    assert full.returncode == 0, full.stderr
    assert same(pq.read_table(tmp_path / "s.parquet"), pq.read_table(tmp_path / "full.parquet"))


def test_dask_s_late_cancel_callback_prints_nothing_after_an_interrupt(caplog):
    """A signal inside ``client.sync`` makes distributed schedule a ``cancel`` callback that
    can fail (a NameError in distributed 2026.8) after the sweep has reported; tornado logs
    it on ``tornado.application``, whose level distributed's config sets to ERROR itself."""
    import logging

    from rotframe.app.sweep import cluster as dask_path

    late = logging.getLogger("tornado.application")
    before = late.level
    try:
        with dask_path.quiet_dask_logs():
            late.error("Exception in callback (inside the sweep)")
        dask_path.silence_late_callbacks()
        late.error("Exception in callback (after the report)")
    finally:
        late.setLevel(before)
    assert not [r for r in caplog.records if r.name == "tornado.application"]
