"""Benchmarks that are not ladders: ensemble throughput, sweep rows per second, start-up and recording time."""

from __future__ import annotations

import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from rotframe.app.bench.measure import timed

__all__ = ["ensemble_rows", "sweep_rows", "startup_rows", "record_rows"]


def ensemble_rows(quick):
    """Particle-steps per second of the tower-drop ensemble path on one core and on all, beside hand-written loops.

    rotframe: :func:`rotframe.particles.ensemble.integrate_ensemble` (gravity + Coriolis,
    exact-rotation splitting, the ground event watched every step) with
    ``threads=1`` and with every core. Ceiling: the same splitting written out
    by hand (no event), serial and with ``prange``. ``parallel_efficiency`` is
    the N-core rate over ``cores x`` the single-core rate; the goal is 0.7.
    """
    import numba

    from rotframe.app.bench import ceiling
    from rotframe.particles.ensemble import integrate_ensemble, resolve_threads
    from rotframe.particles.integrators import Event
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    n, steps = (20000, 50) if quick else (100000, 200)
    cores = resolve_threads(None)
    w = np.array([0.0, 4.6e-5, 5.7e-5])
    g = np.array([0.0, 0.0, -9.81])
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=g)
    rng = np.random.default_rng(1)
    r0 = rng.normal(size=(n, 3)) + [0, 0, 1000]
    v0 = rng.normal(size=(n, 3))
    h = 1e-3
    ground = Event("ground", "r", 2, 0.0, -1, True)

    def ours(threads):
        return integrate_ensemble(model, r0, v0, steps * h, ground, method="rotation-splitting", run={"step": h, "samples": 1},
                                  threads=threads)

    c, s = math.cos(-2 * np.linalg.norm(w) * h), math.sin(-2 * np.linalg.norm(w) * h)
    axis = w / np.linalg.norm(w)
    ceiling.serial(r0[:2].copy(), v0[:2].copy(), g, axis, c, s, h, 2)
    ceiling.parallel(r0[:2].copy(), v0[:2].copy(), g, axis, c, s, h, 2)

    def hand(fn):
        def go():
            r, v = r0.copy(), v0.copy()
            fn(r, v, g, axis, c, s, h, steps)
            return r
        return go

    ours(1)
    a = ours(1)
    b = ours(None)
    identical = bool(np.array_equal(a.state, b.state) and np.array_equal(a.t_event, b.t_event, equal_nan=True))
    rows = []
    budget = 1.0 if quick else 3.0
    saved = numba.get_num_threads()
    try:
        numba.set_num_threads(cores)
        for name, fn in [("rotframe ensemble, 1 thread", lambda: ours(1)),
                         (f"rotframe ensemble, {cores} threads", lambda: ours(None)),
                         ("hand-written loop, 1 core", hand(ceiling.serial)),
                         (f"hand-written prange loop, {cores} cores (ceiling)", hand(ceiling.parallel))]:
            wall, _ = timed(fn, budget=budget, max_repeats=3 if quick else 5)
            rows.append({"scenario": "ensemble", "method": name, "setting": f"{n} particles x {steps} steps",
                         "wall_s": wall, "error": math.nan, "error_kind": "throughput", "nfev": n * steps,
                         "particle_steps_per_s": n * steps / wall, "threads": 1 if ", 1 " in name else cores})
    finally:
        numba.set_num_threads(saved)
    single, multi = rows[0]["particle_steps_per_s"], rows[1]["particle_steps_per_s"]
    rows[1]["parallel_efficiency"] = multi / (cores * single)
    rows[1]["goal_ratio"] = multi / (0.7 * cores * single)
    rows[1]["bitwise_identical_to_1_thread"] = identical
    rows[3]["parallel_efficiency"] = rows[3]["particle_steps_per_s"] / (cores * rows[2]["particle_steps_per_s"])
    rows[1]["of_ceiling"] = multi / rows[3]["particle_steps_per_s"]
    return rows


def sweep_rows(quick):
    """Rows per second of a Foucault sweep (one run per row) on a Dask ``LocalCluster`` of 1, 2 and all workers."""
    import shutil

    from rotframe.particles.ensemble import resolve_threads
    from rotframe.app.sweep import parse_spec, run_sweep

    cores = resolve_threads(None)
    n = 8 if quick else 32
    spec = parse_spec("foucault", sets={"duration": 60.0}, grid=[f"latitude=5:85:{n}"])
    rows = []
    for workers in sorted({1, 2, cores}):
        d = tempfile.mkdtemp()
        try:
            t0 = time.perf_counter()
            res = run_sweep(spec, os.path.join(d, "s.parquet"), workers=workers, plots=False, recording=False)
            wall = time.perf_counter() - t0
        finally:
            shutil.rmtree(d, ignore_errors=True)
        rows.append({"scenario": "sweep", "method": f"LocalCluster, {workers} worker(s)",
                     "setting": f"foucault 60 s x {n} latitudes", "wall_s": wall, "error": math.nan,
                     "error_kind": "throughput (cluster start included)", "nfev": 0, "rows": res.rows,
                     "rows_per_s": res.rows / wall, "workers": workers})
    return rows


def startup_rows(scenario="foucault"):
    """Wall time of ``rotframe run SCENARIO --no-record`` in a new process: warm cache, then empty cache.

    ``import_s`` is the time of ``import rotframe.app.cli`` plus numpy/scipy in a new process, to
    tell the compile time (``wall_s - import_s``) apart.
    """
    rows = []
    cmd = [sys.executable, "-m", "rotframe", "run", scenario, "--no-record", "--json"]
    imp = [sys.executable, "-c", "import rotframe.app.cli, numpy, scipy, numba"]
    t0 = time.perf_counter()
    subprocess.run(imp, capture_output=True, check=True)
    import_s = time.perf_counter() - t0
    subprocess.run(cmd, capture_output=True, check=True)  # fills the cache
    walls = []
    for _ in range(3):
        t0 = time.perf_counter()
        subprocess.run(cmd, capture_output=True, check=True)
        walls.append(time.perf_counter() - t0)
    rows.append({"scenario": "startup", "method": f"rotframe run {scenario} --no-record", "setting": "warm compile cache",
                 "wall_s": statistics.median(walls), "error": math.nan, "error_kind": "start-up", "nfev": 0,
                 "import_s": import_s})
    with tempfile.TemporaryDirectory() as empty:
        t0 = time.perf_counter()
        subprocess.run(cmd, env=dict(os.environ, NUMBA_CACHE_DIR=empty), capture_output=True, check=True)
        rows.append({"scenario": "startup", "method": f"rotframe run {scenario} --no-record",
                     "setting": "first-ever run (empty compile cache)", "wall_s": time.perf_counter() - t0,
                     "error": math.nan, "error_kind": "start-up", "nfev": 0, "import_s": import_s})
    return rows


def record_rows(n=10**6):
    """Time to record ``n`` samples of a particle (Points3D + trail + a scalar series)."""
    from rotframe.app.record import Recording

    times = np.linspace(0, 100, n)
    pos = np.stack([np.cos(times), np.sin(times), times * 0.01], axis=1)
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        rec = Recording(os.path.join(d, "bench.rrd"), "bench")
        rec.points("world/p", times, pos)
        rec.scalars("diagnostics/x", times, pos[:, 0])
        rec.finish()
        wall = time.perf_counter() - t0
    return [{"scenario": "record", "method": "Recording.points + scalars", "setting": f"{n} samples",
             "wall_s": wall, "error": math.nan, "error_kind": "recording", "nfev": 0}]
