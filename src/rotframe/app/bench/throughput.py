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


__all__ = ["ensemble_rows", "same_work", "sweep_rows", "startup_rows", "record_rows"]


def ensemble_rows(quick):
    """Particle-steps per second of the tower-drop ensemble path on one core and on all, beside hand-written loops.

    rotframe: `rotframe.particles.ensemble.integrate_ensemble` (gravity + Coriolis,
    exact-rotation splitting, the ground event watched every step) with
    ``threads=1`` and with every core (or ``--threads N``). Ceiling: the same
    splitting written out by hand (`rotframe.app.bench.ceiling`, no event),
    serial and with ``prange`` on as many numba threads. ``parallel_efficiency``
    is the N-core rate over ``N x`` the single-core rate; ``goal_ratio`` that rate
    over ``0.7 x N x`` the single-core rate (1 or more meets the goal);
    ``scaling_vs_ceiling`` our efficiency over the ceiling's (what the machine
    allows: on a busy or shared machine neither scales).

    Same work: every particle starts 1000 m up and none lands within the run
    (checked: no event), so both take the same steps of the same particles; the
    final states of ours and of the serial hand-written loop are compared, and
    must agree to round-off (``same_work``, ``same_work_max_rel``).
    Times are the minimum over repeats (the fairest on a shared machine).
    """
    import numba

    from rotframe.app.bench import ceiling
    from rotframe.particles.ensemble import integrate_ensemble, resolve_threads
    from rotframe.particles.integrators import Event
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    n, steps = (20000, 50) if quick else (100000, 200)
    cores = resolve_threads(None)  # --threads N, else every core
    prange_threads = min(cores, numba.config.NUMBA_NUM_THREADS)
    w = np.array([0.0, 4.6e-5, 5.7e-5])
    g = np.array([0.0, 0.0, -9.81])
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=g)
    rng = np.random.default_rng(1)
    r0 = rng.normal(size=(n, 3)) + [0, 0, 1000]
    v0 = rng.normal(size=(n, 3))
    h = 1e-3
    ground = Event("ground", "r", 2, 0.0, -1, True)

    def ours(threads):
        return integrate_ensemble(model, r0, v0, steps * h, ground, method="rotation-splitting",
                                  run={"step": h, "samples": 1}, threads=threads)

    c, s = math.cos(-2 * np.linalg.norm(w) * h), math.sin(-2 * np.linalg.norm(w) * h)
    axis = w / np.linalg.norm(w)
    ceiling.serial(r0[:2].copy(), v0[:2].copy(), g, axis, c, s, h, 2)
    ceiling.parallel(r0[:2].copy(), v0[:2].copy(), g, axis, c, s, h, 2)

    def hand(fn):
        def go():
            r, v = r0.copy(), v0.copy()
            fn(r, v, g, axis, c, s, h, steps)
            return r, v
        return go

    ours(1)
    a = ours(1)
    b = ours(None)
    identical = bool(np.array_equal(a.state, b.state) and np.array_equal(a.t_event, b.t_event, equal_nan=True))
    same, same_rel, same_note = same_work(a, hand(ceiling.serial)(), n, steps, h)
    rows = []
    budget = 1.0 if quick else 3.0
    saved = numba.get_num_threads()
    try:
        numba.set_num_threads(prange_threads)
        for name, threads, fn in [("rotframe ensemble, 1 thread", 1, lambda: ours(1)),
                                  (f"rotframe ensemble, {cores} threads", cores, lambda: ours(None)),
                                  ("hand-written loop, 1 core", 1, hand(ceiling.serial)),
                                  (f"hand-written prange loop, {prange_threads} threads (ceiling)", prange_threads,
                                   hand(ceiling.parallel))]:
            wall = _best(fn, budget=budget, max_repeats=3 if quick else 5)
            rows.append({"scenario": "ensemble", "method": name, "setting": f"{n} particles x {steps} steps",
                         "wall_s": wall, "error": math.nan, "error_kind": "throughput (best of repeats)",
                         "nfev": n * steps, "particle_steps_per_s": n * steps / wall, "threads": threads})
    finally:
        numba.set_num_threads(saved)
    single, multi = rows[0]["particle_steps_per_s"], rows[1]["particle_steps_per_s"]
    rows[1]["parallel_efficiency"] = multi / (cores * single)
    rows[1]["goal_ratio"] = multi / (0.7 * cores * single)
    rows[1]["bitwise_identical_to_1_thread"] = identical
    rows[3]["parallel_efficiency"] = rows[3]["particle_steps_per_s"] / (prange_threads * rows[2]["particle_steps_per_s"])
    # the ceiling's own scaling is what this machine allows (a shared or busy machine scales less)
    rows[1]["scaling_vs_ceiling"] = rows[1]["parallel_efficiency"] / rows[3]["parallel_efficiency"]
    rows[1]["of_ceiling"] = multi / rows[3]["particle_steps_per_s"]
    rows[0]["of_ceiling"] = single / rows[2]["particle_steps_per_s"]
    for r in rows:
        r.update(same_work=same, same_work_max_rel=same_rel, same_work_note=same_note, cpu_count=os.cpu_count())
    return rows


def same_work(ours, hand, n, steps, h):
    """(same, max relative difference, note): do ours and the hand-written loop take the same steps of the same physics?

    Both must have integrated every particle for all ``steps`` (ours found no ground
    event) and reach the same final (r, v). Tolerance 1e-12 of the state's scale: the
    two differ only in the order of floating-point operations, so their difference is
    round-off, about ``steps x`` 1e-16 (2e-14 at 200 steps), while a missing Coriolis
    term or another splitting order differs by about 1e-7 of it or more here.
    """
    r, v = hand
    landed = int(np.sum(np.isfinite(ours.t_event)))
    ref = np.concatenate([r, v], axis=1)
    # round-off follows the size of the whole vector (a rotation mixes its components): scale by the largest |r|, |v|
    scale = np.repeat([max(np.linalg.norm(r, axis=1).max(), 1.0), max(np.linalg.norm(v, axis=1).max(), 1.0)], 3)
    rel = float(np.max(np.abs(ours.state - ref) / scale))
    same = bool(landed == 0 and rel <= 1e-12)
    note = (f"same {n} particles, {steps} steps of {h:g} s, gravity + Coriolis by Strang exact-rotation splitting in "
            f"both; final states agree to {rel:.1e} of their scale (round-off; allowed 1e-12); ours also watches the "
            f"ground event every step ({landed} landed)")
    if not same:
        note = "NOT the same work: " + note
    return same, rel, note


def _best(fn, budget, max_repeats):
    """The shortest wall time of ``fn()`` over repeats that fit in ``budget`` seconds (at least two)."""
    times = []
    while len(times) < 2 or (len(times) < max_repeats and sum(times) < budget):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def sweep_rows(quick):
    """Rows per second of a Foucault sweep (one run per row): in this process, and on a Dask ``LocalCluster``
    of 1, 2 and all workers.

    The cluster is started and every worker warmed up (the scene imported, its
    kernels loaded) before the clock, that time reported apart as ``cluster_start_s``,
    so ``rows_per_s`` is the sweep itself: batching, pickling, the runs, and writing
    the parts. ``scaling`` is the rate over the one-worker rate.
    Bounded: ``quick`` runs 16 rows of 120 s (about 0.1 s of work each) on 1 and 2 workers only.
    """
    import logging
    import shutil

    from rotframe.app.sweep import parse_spec, run_sweep

    cores = os.cpu_count() or 1
    n, duration = (16, 120.0) if quick else (48, 300.0)
    spec = parse_spec("foucault", sets={"duration": duration}, grid=[f"latitude=5:85:{n}"])
    setting = f"foucault {duration:g} s x {n} latitudes"
    counts = [1, 2] if quick else sorted({1, 2, cores})
    rows = []

    def one(client, spec=spec):
        d = tempfile.mkdtemp()
        try:
            t0 = time.perf_counter()
            res = run_sweep(spec, os.path.join(d, "s.parquet"), client=client, plots=False, recording=False)
            return res.rows, time.perf_counter() - t0
        finally:
            shutil.rmtree(d, ignore_errors=True)

    # this process: a two-row sweep first, so that the scene, its kernels and the table writer are loaded
    one(None, parse_spec("foucault", sets={"duration": 1.0}, grid=["latitude=5:85:2"]))
    done, wall = one(None)
    rows.append({"scenario": "sweep", "method": "in this process (no cluster)", "setting": setting, "wall_s": wall,
                 "error": math.nan, "error_kind": "throughput", "nfev": 0, "rows": done, "rows_per_s": done / wall,
                 "workers": 0})
    from distributed import Client, LocalCluster

    for workers in counts:
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                               silence_logs=logging.ERROR)
        client = Client(cluster)
        client.run(_warm)  # every worker imports the scene and loads its kernels before the clock
        start = time.perf_counter() - t0
        try:
            done, wall = one(client)
        finally:
            client.close()
            cluster.close()
        rows.append({"scenario": "sweep", "method": f"LocalCluster, {workers} worker(s)", "setting": setting,
                     "wall_s": wall, "error": math.nan, "error_kind": "throughput (cluster start and warm-up apart)", "nfev": 0,
                     "rows": done, "rows_per_s": done / wall, "workers": workers, "cluster_start_s": start})
    one_worker = rows[1]["rows_per_s"]
    for r in rows[1:]:
        r["scaling"] = r["rows_per_s"] / one_worker
        r["cpu_count"] = cores
    return rows


def _warm():
    """Import the Foucault scene and load its compiled kernels (a one-second run); on a worker or here."""
    from rotframe.app import runner

    runner.run("foucault", {"duration": 1.0})


#: Issue 13's goals for a first run: the first-ever run within 3 s beyond imports, a warm run within 1 s.
STARTUP_GOALS = {"cold": 3.0, "warm": 1.0}


def import_seconds(importtime_log):
    """Seconds a process spent importing, from its ``python -X importtime`` report (stderr).

    The sum of the cumulative times of the top-level imports: every module the process
    imported, at start or later (a scene imports astropy or numba when it runs), counted once.
    """
    total_us = 0
    for line in importtime_log.splitlines():
        if not line.startswith("import time:"):
            continue
        fields = line.split("|")
        if len(fields) != 3 or not fields[1].strip().isdigit():
            continue  # the header
        name = fields[2]
        if len(name) - len(name.lstrip(" ")) == 1:  # one space after the bar: a top-level import
            total_us += int(fields[1])
    return total_us / 1e6


def _timed_runs(cmd, repeats=1, env=None):
    """Median wall time and median import time (s) of ``repeats`` runs of ``cmd`` in new processes.

    ``cmd[0]`` is the interpreter; each run has ``-X importtime``, so that its own imports
    (`import_seconds`) are measured in the same process as its wall time.
    """
    walls, imports = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = subprocess.run([cmd[0], "-X", "importtime", *cmd[1:]], env=env, capture_output=True, text=True,
                             check=True)
        walls.append(time.perf_counter() - t0)
        imports.append(import_seconds(res.stderr))
    return statistics.median(walls), statistics.median(imports)


def startup_rows(scenarios=None):
    """``rotframe run NAME --no-record`` in new processes, for every scenario: warm cache, then empty.

    ``import_s`` is the time that run spent importing modules, measured in its own process
    (``python -X importtime``, `import_seconds`: numpy, scipy, numba, astropy, whatever
    that scene imports, when it imports them); ``beyond_imports_s = wall_s - import_s`` is what
    the goal of a first run counts (`STARTUP_GOALS`: cold 3 s beyond imports, warm 1 s in
    all). The warm time is the median of three runs after one that fills the cache; the cold
    one is a run with an empty numba cache (``NUMBA_CACHE_DIR`` set to a new folder), as in a
    fresh environment.
    """
    from rotframe.scenes import SCENES

    names = list(scenarios or [n for n in SCENES if isinstance(SCENES[n], str)])
    rows = []
    for name in names:
        cmd = [sys.executable, "-m", "rotframe", "run", name, "--no-record", "--json"]
        _timed_runs(cmd)  # fills the cache
        warm = _timed_runs(cmd, repeats=3)
        with tempfile.TemporaryDirectory() as empty:
            cold = _timed_runs(cmd, env=dict(os.environ, NUMBA_CACHE_DIR=empty))
        for setting, (wall, import_s), goal, cold_run in (
                ("warm compile cache", warm, STARTUP_GOALS["warm"], False),
                ("first-ever run (empty compile cache)", cold, STARTUP_GOALS["cold"], True)):
            counted = wall - import_s if cold_run else wall
            rows.append({"scenario": "startup", "method": f"rotframe run {name} --no-record", "setting": setting,
                         "run": name, "wall_s": wall, "error": math.nan, "error_kind": "start-up", "nfev": 0,
                         "import_s": import_s, "beyond_imports_s": wall - import_s, "goal_s": goal,
                         "goal_met": bool(counted <= goal)})
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
