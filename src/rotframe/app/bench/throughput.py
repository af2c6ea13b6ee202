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


__all__ = ["ensemble_rows", "same_work", "same_state", "best_interleaved", "sweep_rows", "startup_rows", "record_rows"]


def ensemble_rows(quick):
    """Particle-steps per second of rotframe's many-particle paths beside hand-written ``prange`` loops.

    Cases: the exact-rotation splitting, RK4 and DOP853 on gravity + Coriolis, each
    without an event ([`rotframe.particles.integrators.integrate_particles`][rotframe.particles.integrators.integrate_particles] with
    (N, 3) states, the public many-particle call) and with the ground event
    ([`rotframe.particles.ensemble.integrate_ensemble`][rotframe.particles.ensemble.integrate_ensemble], the scenes' and sweeps'
    ensemble path). Each case has four rows: rotframe with ``threads=1`` and with every
    core (or ``--threads N``), the hand-written loop of the same steps
    (`rotframe.app.bench.ceiling`) on one core and with ``prange`` on as many
    numba threads (the ceiling); the fixed-step cases with the event have two more, the
    engine's door that the tower drop's sweeps run (``rotframe.simulate``'s core with the
    built-in ground crossing, on the steady specialisation: `rotframe.problem.steady`), at one
    thread and every core, with ``of_ceiling`` and ``of_integrate_ensemble``. ``of_ceiling``: rotframe's rate over the hand-written
    loop's at the same thread count (the goal is 0.7 or more). The all-core row of
    each case also has ``parallel_efficiency`` (N-core rate over ``N x`` one core),
    ``goal_ratio`` (that over 0.7), ``scaling_vs_ceiling`` (over the ceiling's own
    efficiency: a shared machine scales neither) and ``bitwise_identical_to_1_thread``.

    Same work: every particle starts high enough that none lands within the run
    (checked: no event found), so both take the same steps of the same particles; the
    final states of ours and of the hand-written loop must agree to round-off
    (``same_work``, ``same_work_max_rel``) and DOP853 must take the same number of
    steps (``same_steps``). Times are the minimum over rounds that run the four in
    turn (the fairest on a shared machine). The first four rows are the splitting
    with the ground event.
    """
    import numba

    from rotframe.app.bench import ceiling
    from rotframe.particles.ensemble import resolve_threads

    # steps: a multiple of 16, the samples of an ensemble run without kept paths
    # (rotframe.particles.ensemble), so that its step is the ceiling's
    n, steps = (20000, 48) if quick else (100000, 192)
    cores = resolve_threads(None)  # --threads N, else every core
    prange_threads = min(cores, numba.config.NUMBA_NUM_THREADS)
    rows = []
    budget = 1.0 if quick else 5.0  # seconds a row, at most: 15 rounds keep the best stable on a shared machine
    saved = numba.get_num_threads()
    try:
        numba.set_num_threads(prange_threads)
        for method, rk4 in (("rotation-splitting", False), ("rk4", True), ("dop853", None)):
            for event in (True, False):
                rows += _ensemble_case(method, rk4, event, n, steps, cores, prange_threads, budget, quick, ceiling)
    finally:
        numba.set_num_threads(saved)
    rows += call_overhead_rows()
    for r in rows:
        r["cpu_count"] = os.cpu_count()
    return rows


#: issue 26's goal: ``integrate_particles`` costs at most this much (s) a call beyond its steps
OVERHEAD_GOAL_S = 10e-6


def call_overhead_rows(repeats=2000):
    """What a call of ``integrate_particles`` costs beyond its steps, beside ``PreparedRun`` and the driver alone.

    One particle, ten steps of the splitting (gravity + Coriolis), one sample: the
    compiled driver's own call with the same arguments (``KernelSetup.call``'s
    driver, timed alone) is the steps; ``overhead_s`` is the rest of a call. The best
    of five rounds of ``repeats`` calls each (the mean of a round), so that a busy
    machine's pauses do not count.
    """
    from rotframe.particles.chunked import KernelSetup
    from rotframe.particles.integrators import METHODS, integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel
    from rotframe.particles.prepared import PreparedRun

    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant([0.0, 4.6e-5, 5.7e-5]),
                          g=np.array([0.0, 0.0, -9.81]))
    r0, v0 = np.array([0.0, 0.0, 100.0]), np.array([1.0, 0.0, 0.0])
    setup = KernelSetup(model, METHODS["rotation-splitting"], 1.0, 1, step=0.1)
    kernel = setup.kernel()
    r, v = r0[None].copy(), v0[None].copy()
    alive = np.ones(1, dtype=np.bool_)
    out_r, out_v = np.empty((1, 1, 3)), np.empty((1, 1, 3))

    def driver():
        kernel(r, v, alive, setup.times, 0, setup.h, setup.sps, 1, setup.P, setup.wt_arg, setup.wv,
               setup.wint, None, out_r, out_v, None, None, None, None, None, 0, setup.rk4, setup.sphere)

    prepared = PreparedRun(model, "rotation-splitting", 1.0, step=0.1, samples=1, n=1)
    calls = {"compiled driver alone (the steps)": driver,
             "integrate_particles": lambda: integrate_particles(model, r0, v0, 1.0, method="rotation-splitting",
                                                                step=0.1, samples=1),
             "PreparedRun": lambda: prepared(r0, v0)}
    per_call = {}
    for name, fn in calls.items():
        fn()
        best = math.inf
        for _ in range(5):
            t0 = time.perf_counter()
            for _ in range(repeats):
                fn()
            best = min(best, (time.perf_counter() - t0) / repeats)
        per_call[name] = best
    steps = per_call["compiled driver alone (the steps)"]
    rows = []
    for name, wall in per_call.items():
        row = {"scenario": "call-overhead", "method": name, "setting": "1 particle x 10 splitting steps, 1 sample",
               "wall_s": wall, "error": math.nan, "error_kind": "time a call (best of 5 rounds)", "nfev": 10,
               "overhead_s": wall - steps}
        if name == "integrate_particles":
            row.update(goal_s=OVERHEAD_GOAL_S, goal_met=bool(wall - steps <= OVERHEAD_GOAL_S))
        rows.append(row)
    return rows


def _ensemble_case(method, rk4, event, n, steps, cores, prange_threads, budget, quick, ceiling):
    """The four rows of one method, with or without the ground event (see `ensemble_rows`)."""
    from rotframe.numerics.dop853 import coefficients
    from rotframe.particles.ensemble import integrate_ensemble
    from rotframe.particles.integrators import Event, integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    dop = rk4 is None
    g = np.array([0.0, 0.0, -9.81])
    rng = np.random.default_rng(1)
    if dop:
        # DOP853 chooses its steps: a fast frame (|w| = 0.5 rad/s) over 20 s, so that each particle
        # takes some hundreds of steps; a tenth of the particles
        n = n // 10
        w = np.array([0.0, 0.3, 0.4])
        duration, h, rtol = 20.0, 0.0, 1e-10
        r0 = rng.normal(size=(n, 3)) + [0, 0, 1e4]
    else:
        w = np.array([0.0, 4.6e-5, 5.7e-5])
        h = 1e-3
        duration, rtol = steps * h, 1e-10
        r0 = rng.normal(size=(n, 3)) + [0, 0, 1000]
    v0 = rng.normal(size=(n, 3))
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=g)
    ground = Event("ground", "r", 2, 0.0, -1, True)
    from rotframe.numerics.step_control import ensemble_scale

    atol = rtol * ensemble_scale(r0, v0)  # the ensemble's own rule
    run = {"step": h or None, "samples": 1, "rtol": rtol}

    from rotframe.particles.ensemble import threads_in_force, threads_scope

    def engine(threads):  # the sweeps' door: one simulate run, the ground a built-in crossing (rotframe.problem.steady)
        from rotframe import forces
        from rotframe.events import crossing
        from rotframe.problem.particles import simulate_particles

        with threads_scope(threads if threads is not None else threads_in_force()):
            res = simulate_particles(omega=w, r0=r0, v0=v0, duration=duration, forces=[forces.gravity(g)],
                                     frame_terms=("coriolis",), method=method, step=h, samples=16, energy=False,
                                     events=[crossing(2, 0.0, direction=-1, terminal=True, name="ground")])
        t_event, state = res.trajectory.first_events("ground")
        return state, int(np.sum(np.isfinite(t_event))), None

    def ours(threads):
        if event and not dop:
            res = integrate_ensemble(model, r0, v0, duration, ground, method=method, run=run, threads=threads)
            return res.state, int(np.sum(np.isfinite(res.t_event))), None

        with threads_scope(threads if threads is not None else threads_in_force()):
            # DOP853 with the event: the ensemble's own call with one sample (an ensemble this small asks
            # for 16, and each sample is landed on: other steps than the ceiling's)
            traj = integrate_particles(model, r0, v0, duration, method=method, step=h or None, rtol=rtol,
                                       atol=atol, samples=1, events=[ground] if event else (), max_events=1,
                                       records=True)
        evb = traj.extras.get("event_records")
        landed = 0 if evb is None else int(np.sum(evb.count > 0))
        return np.concatenate([traj.r[-1], traj.v[-1]], axis=1), landed, traj.steps

    if dop:
        tab = _dop853_table(coefficients())
        hand_steps = np.zeros(n, dtype=np.int64)

        def hand(fn):
            def go(k=n):
                r, v = r0[:k].copy(), v0[:k].copy()
                fn(r, v, g, w, tab, rtol, atol, duration, event, hand_steps[:k])
                return r, v
            return go
        serial, parallel = hand(ceiling.dop853_serial), hand(ceiling.dop853_parallel)
        per_particle = None
    else:
        c, s = ceiling.rotation_cos_sin(w, h)

        def hand(fn):
            def go(k=n):
                r, v = r0[:k].copy(), v0[:k].copy()
                fn(r, v, g, w, c, s, h, steps, rk4, event)
                return r, v
            return go
        serial, parallel = hand(ceiling.serial), hand(ceiling.parallel)
        per_particle = steps
    serial(2)
    parallel(2)
    a = ours(1)
    b = ours(None)
    identical = bool(np.array_equal(a[0], b[0]))
    ref = np.concatenate(serial(), axis=1)
    if dop:
        per_particle = float(np.mean(hand_steps))
    tol = 1e-9 if dop else 1e-12
    same, rel, note = same_state(a[0], a[1], ref, tol)
    if dop:
        same_steps = bool(a[2] == int(hand_steps[0]))
    else:
        from rotframe.particles.chunked import steps_per_sample

        # the ensemble samples its runs 16 times (the fixed step divides the sample interval)
        k = 16 if event else 1
        same_steps = bool(k * steps_per_sample(duration / k, h) == steps)
    what = (f"{method}, gravity + Coriolis, {'with the ground event watched every step' if event else 'no event'}; "
            f"{n} particles x {per_particle:.4g} steps{' (mean; DOP853 chooses them)' if dop else ''}")
    if dop and a[2] is not None:
        note += f"; particle 0 took {a[2]} steps in ours and {int(hand_steps[0])} in the hand-written loop"
    rows = []
    label = f"{method}{' + ground event' if event else ''}"
    door = ("integrate_ensemble" if event and not dop else "integrate_particles") + " (N, 3)"
    cases = [(f"rotframe {door} {label}, 1 thread", 1, lambda: ours(1)),
             (f"rotframe {door} {label}, {cores} threads", cores, lambda: ours(None)),
             (f"hand-written {label}, 1 core", 1, serial),
             (f"hand-written prange {label}, {prange_threads} threads (ceiling)", prange_threads, parallel)]
    if event and not dop:  # and the engine's door, which the tower drop's sweeps run (since 2026-12-01)
        e = engine(1)
        same_engine, rel_engine, _ = same_state(e[0], e[1], ref, tol)
        cases += [(f"rotframe simulate (N, 3) {label}, 1 thread", 1, lambda: engine(1)),
                  (f"rotframe simulate (N, 3) {label}, {cores} threads", cores, lambda: engine(None))]
    walls = best_interleaved([fn for _, _, fn in cases], budget=budget, max_rounds=3 if quick else 15)
    for (name, threads, fn), wall in zip(cases, walls):
        total = n * per_particle
        rows.append({"scenario": "ensemble", "method": name, "setting": what, "wall_s": wall, "error": math.nan,
                     "error_kind": "throughput (best of repeats)", "nfev": int(total), "particle_steps_per_s": total / wall,
                     "threads": threads, "integrator": method, "event": event})
    single, multi = rows[0]["particle_steps_per_s"], rows[1]["particle_steps_per_s"]
    rows[1]["parallel_efficiency"] = multi / (cores * single)
    rows[1]["goal_ratio"] = multi / (0.7 * cores * single)
    rows[1]["bitwise_identical_to_1_thread"] = identical
    rows[3]["parallel_efficiency"] = rows[3]["particle_steps_per_s"] / (prange_threads * rows[2]["particle_steps_per_s"])
    rows[1]["scaling_vs_ceiling"] = rows[1]["parallel_efficiency"] / rows[3]["parallel_efficiency"]
    rows[1]["of_ceiling"] = multi / rows[3]["particle_steps_per_s"]
    rows[0]["of_ceiling"] = single / rows[2]["particle_steps_per_s"]
    for r in rows:
        r.update(same_work=same and same_steps, same_work_max_rel=rel, same_work_note=note, same_steps=same_steps)
    for r, door_row, hand_row in zip(rows[4:], rows[0:2], rows[2:4]):  # the engine's door beside the same ceiling
        r.update(of_ceiling=r["particle_steps_per_s"] / hand_row["particle_steps_per_s"],
                 of_integrate_ensemble=r["particle_steps_per_s"] / door_row["particle_steps_per_s"],
                 same_work=same_engine and same_steps, same_work_max_rel=rel_engine)
    return rows


def _dop853_table(coeffs):
    """The DOP853 tableau as one (16, 13) array (rows 0-11 A, 12 B, 13 C, 14 E3, 15 E5), for the ceiling."""
    A, B, C, E3, E5 = coeffs
    tab = np.zeros((16, 13))
    tab[:12, :12] = A
    tab[12, :12] = B
    tab[13, :12] = C
    tab[14] = E3
    tab[15] = E5
    return tab


def same_state(ours, landed, ref, tol=1e-12):
    """(same, max relative difference, note): do ours and the hand-written loop end in the same states?

    Both must have integrated every particle to the end (ours found no ground event) and
    reach the same final (r, v) (N, 6) to ``tol`` of the state's scale. The two differ only
    in the order of floating-point operations, so their difference is round-off, about
    ``steps x`` 1e-16 (2e-14 at 200 steps), while a missing Coriolis term or another
    splitting order differs by about 1e-7 of it or more.
    """
    # round-off follows the size of the whole vector (a rotation mixes its components): scale by the largest |r|, |v|
    scale = np.repeat([max(np.linalg.norm(ref[:, :3], axis=1).max(), 1.0),
                       max(np.linalg.norm(ref[:, 3:], axis=1).max(), 1.0)], 3)
    rel = float(np.max(np.abs(ours - ref) / scale))
    same = bool(landed == 0 and rel <= tol)
    note = (f"final states agree to {rel:.1e} of their scale (round-off; allowed {tol:g}); "
            f"{landed} particles landed (must be 0)")
    if not same:
        note = "NOT the same work: " + note
    return same, rel, note


def same_work(ours, hand, n, steps, h):
    """`same_state` of an ensemble run ``ours`` and the hand-written loop's ``(r, v)``: (same, rel, note)."""
    r, v = hand
    landed = int(np.sum(np.isfinite(ours.t_event)))
    same, rel, note = same_state(ours.state, landed, np.concatenate([r, v], axis=1))
    return same, rel, f"{'same' if same else 'NOT the same work:'} {n} particles, {steps} steps of {h:g} s: " + (
        note.removeprefix("NOT the same work: "))


def best_interleaved(fns, budget, max_rounds):
    """The shortest wall time of each of ``fns`` over rounds that run each once in turn (at least two rounds).

    Interleaved, so that a shared machine's busy spells fall on all of them alike.
    """
    best = [math.inf] * len(fns)
    spent = 0.0
    rounds = 0
    while rounds < 2 or (rounds < max_rounds and spent < budget * len(fns)):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            fn()
            wall = time.perf_counter() - t0
            best[i] = min(best[i], wall)
            spent += wall
        rounds += 1
    return best


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
    fresh environment. With every scenario, the rows of a problem of your own follow
    (`rotframe.app.bench.problem_startup`).
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
    if scenarios is None:  # and a problem of your own: the first ever, a new one, a changed force
        from rotframe.app.bench.problem_startup import problem_startup_rows

        rows += problem_startup_rows()
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
