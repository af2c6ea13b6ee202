"""Running a sweep: batches sized from their cost, in this process or on Dask, each part written as it finishes.

Points are cut into batches (about 0.2 s to 30 s of work each, at most about four
per worker; on the ensemble path whole chunks of `ENSEMBLE_CHUNK`
rows, so that a row's numbers never depend on the cut); batches run here, or as Dask
tasks on a ``LocalCluster`` (``--workers N``) or an existing scheduler
(``--scheduler ADDRESS``, ``--scheduler-file PATH`` or ``DASK_SCHEDULER_ADDRESS``),
with the faults of a cluster handled in `cluster`. Dask is
imported only when needed.
"""

from __future__ import annotations

import json
import math
import shutil
import time
from dataclasses import dataclass

import numpy as np

from rotframe.app.messages import one_line as _one_line
from rotframe.app.sweep.batch import ENSEMBLE_CHUNK, BatchTask, ScenarioSource, run_batch
from rotframe.app.sweep.cluster import SweepLost, quiet_dask_logs
from rotframe.app.sweep.plots import write_plots
from rotframe.app.sweep.recording import write_recording
from rotframe.app.sweep.spec import SweepSpec, points_of, sweep_points
from rotframe.app.optional import need
from rotframe.app.sweep.store import SweepFiles, exclusive, merge, prepare, write_part
from rotframe.errors import ScenarioError

__all__ = ["SweepResult", "SweepInterrupted", "SweepLost", "run_sweep", "check_scheduler", "scheduler_from_env",
           "check_task_timeout", "quiet_dask_logs", "batch_threads", "MAX_TRACKS", "CONNECT_TIMEOUT_S"]


#: at most this many trajectories and samples per trajectory in the recording
MAX_TRACKS = 2000


#: wall time of one batch of runs (s): long enough that task overhead stays small, short enough to lose little
MIN_BATCH_S = 0.2


MAX_BATCH_S = 30.0


BATCHES_PER_WORKER = 4


#: rows per vectorised ensemble batch, and the smallest ensemble batch worth a Dask task
ENSEMBLE_BATCH = 1 << 17


MIN_ENSEMBLE_BATCH = 4096


#: Dask retries of a task whose worker failed
RETRIES = 3


#: seconds allowed to connect to a scheduler and for the Dask handshake, each
CONNECT_TIMEOUT_S = 10.0


@dataclass
class SweepResult:
    """A finished sweep: the merged table and where everything was written."""

    scenario: str
    table: object
    out: str
    plots: list
    recording: str | None
    path: str
    rows: int
    failed: int
    computed: int
    batches: int
    timing: dict

    def as_json(self) -> dict:
        """The ``--json`` object."""
        return {"scenario": self.scenario, "rows": self.rows, "failed": self.failed, "out": self.out,
                "plots": self.plots, "recording": self.recording, "timing": self.timing, "path": self.path,
                "computed": self.computed, "batches": self.batches}


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C (or SIGTERM) during a sweep; every finished batch is kept in ``parts``."""

    def __init__(self, saved: int, total: int, parts: str):
        super().__init__(f"{saved} of {total} rows saved")
        self.saved, self.total, self.parts = saved, total, parts


def run_sweep(spec: SweepSpec, out=None, *, workers=None, scheduler=None, client=None, resume=False,
              batch_rows=None, on_batch=None, plots=True, recording=True, scheduler_file=None,
              task_timeout=None) -> SweepResult:
    """Run a sweep, writing each batch as it finishes; merge, plot and record at the end.

    Parameters
    ----------
    spec : SweepSpec
    out : path-like, optional
        Parquet file (default ``sweeps/<name>.parquet``); parts go to ``<out>.parts/``,
        plots to ``<stem>-<metric>.png`` and the recording to ``<stem>.rrd`` beside it.
    workers : int, optional
        Run batches on a ``distributed.LocalCluster`` of this many single-threaded processes.
    scheduler : str, optional
        Address of an existing Dask scheduler.
    scheduler_file : path-like, optional
        A Dask scheduler file (``dask scheduler --scheduler-file``) naming the scheduler.
    client : distributed.Client, optional
        Use this client (not closed here) instead of ``workers`` / ``scheduler``.
    resume : bool
        Keep the rows already in ``out`` and its parts; compute only the missing ones.
    batch_rows : int, optional
        Rows per batch (default: sized from the time of the first runs).
    on_batch : callable(done, total), optional
        Called after each batch is written (progress; tests use it to interrupt).
    plots, recording : bool
        Write the PNGs and the rerun recording.
    task_timeout : float, optional
        On Dask: seconds a batch may run on a worker before its rows are failed with a TimeoutError.

    Returns
    -------
    SweepResult

    Raises
    ------
    SweepInterrupted
        On Ctrl-C / SIGTERM; the finished batches stay in ``<out>.parts/``.
    SweepLost
        The Dask scheduler went away (noticed within `rotframe.app.sweep.cluster.LOST_S`
        seconds); the finished batches stay in ``<out>.parts/``.
    ScenarioError
        ``out`` not ending in ``.parquet``; ``--resume`` of a different sweep; an unreachable scheduler.
    """
    t_start = time.perf_counter()
    need("pyarrow", "rotframe sweep")
    files = SweepFiles.for_spec(spec, out)
    check_task_timeout(task_timeout)
    where = {"workers": workers, "scheduler": scheduler, "scheduler_file": scheduler_file, "client": client,
             "task_timeout": task_timeout}
    with exclusive(files):
        return _run_sweep_locked(spec, files, t_start, where, resume, batch_rows, on_batch, plots, recording)


def _run_sweep_locked(spec, files, t_start, where, resume, batch_rows, on_batch, plots, recording):
    source = ScenarioSource.of(spec.scenario)
    meta = dict(spec.describe(), scenario_sha256=source.digest)
    done = prepare(files, meta, resume)
    pending = np.setdiff1d(np.arange(spec.n_rows), np.fromiter(done, dtype=np.int64, count=len(done)))
    ctx = _Context.create(spec, files, meta, source)
    t0 = time.perf_counter()
    computed, batches = _compute(ctx, pending, len(done), where, batch_rows, on_batch)
    timing = {"compute_s": time.perf_counter() - t0}
    t0 = time.perf_counter()
    table = merge(files, meta, spec, include_out=resume)
    timing["merge_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    pngs = write_plots(table, spec, files.plot_stem) if plots else []
    timing["plot_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    rrd = write_recording(ctx, table) if recording else None
    timing["record_s"] = time.perf_counter() - t0
    shutil.rmtree(files.parts, ignore_errors=True)
    timing["total_s"] = time.perf_counter() - t_start
    failed = int(sum(1 for e in table.column("error").to_pylist() if e))
    return SweepResult(scenario=spec.name, table=table, out=str(files.out), plots=[str(p) for p in pngs],
                       recording=str(rrd) if rrd else None, path=ctx.path, rows=table.num_rows, failed=failed,
                       computed=computed, batches=batches, timing=timing)


@dataclass
class _Context:
    spec: SweepSpec
    files: SweepFiles
    meta: dict
    source: ScenarioSource
    path: str
    points: object  # (rows, keys) array of a Monte Carlo sweep; None for a grid (computed per batch)
    track_rows: frozenset
    threads: int | None = None  # threads of each vectorised batch (`batch_threads`)
    seconds: list = None  # seconds per row of the last batch written (the probe's timing)

    @classmethod
    def create(cls, spec, files, meta, source):
        from rotframe import scenes
        from rotframe.numerics.sampling import decimate

        scn = source.load()
        path = "ensemble" if hasattr(scenes.get(scn.scene), "simulate_ensemble") else "runs"
        _check_gpu_sweep(scn, spec, path)
        track_rows = frozenset(int(i) for i in decimate(spec.n_rows, MAX_TRACKS))
        points = None if spec.axes else sweep_points(spec)  # a grid is computed row by row, lazily
        return cls(spec, files, meta, source, path, points, track_rows)

    def task(self, index, rows):
        rows = np.asarray(rows, dtype=np.int64)
        values = points_of(self.spec, rows) if self.points is None else self.points[rows]
        return BatchTask(index=index, scenario=self.source, sets=dict(self.spec.sets), keys=self.spec.keys,
                         rows=rows, values=values, method=self.spec.method, path=self.path, limits=_limits_now(),
                         track_rows=self.track_rows.intersection(rows.tolist()), threads=self.threads,
                         device=_device_now())


def check_task_timeout(task_timeout):
    """ScenarioError in one line unless ``task_timeout`` is None or a number of seconds > 0."""
    if task_timeout is not None and not (float(task_timeout) > 0):
        raise ScenarioError(f"--task-timeout {float(task_timeout):g}: must be > 0 seconds")


def _check_gpu_sweep(scn, spec, path):
    """ScenarioError in one line when the GPU is asked for (``--device gpu``) and no row could use it.

    The GPU runs the ensembles of the fixed-step methods: a scene swept run by run, or an ensemble
    of another method, would run every row on the CPU (or fail each row) after the user asked for it.
    """
    if _device_now() != "gpu":
        return
    from rotframe.particles.gpu import check_method

    if path != "ensemble":
        raise ScenarioError(f"device: 'gpu' for a sweep of {scn.name}, which runs one run a row (the GPU runs "
                            "the ensembles of scenes such as tower-drop); use --device cpu")
    method = spec.method or scn.with_values(dict(spec.sets))["run"].get("method")
    if method is not None:
        check_method(method)


def _device_now():
    """The device in force (``--device``, ``device=``) for a batch task: None for the CPU."""
    from rotframe.particles.ensemble import device_in_force

    device = device_in_force()
    return None if device == "cpu" else device


def batch_threads(local_workers=None, here=False):
    """Threads of one vectorised ensemble batch.

    The count in force (``--threads N``) wherever the batch runs. Without one:
    every core for batches run in this process (``here``); the cores shared out
    over a ``LocalCluster`` of ``local_workers`` single-threaded processes, so
    that the workers do not oversubscribe the machine; None (every core of that
    worker) on an existing scheduler, whose machines this process cannot see.
    The results do not depend on it (`rotframe.particles.ensemble`).
    """
    from rotframe.particles.ensemble import resolve_threads, threads_in_force

    given = threads_in_force()
    if given is not None or here:
        return resolve_threads(given)
    if local_workers:
        return max(1, resolve_threads(None) // int(local_workers))
    return None


def _limits_now():
    from rotframe import limits

    return limits.current()


def _compute(ctx, pending, n_done, where, batch_rows, on_batch):
    """Run the pending rows batch by batch, writing each part as it finishes; (rows, batches) computed."""
    if len(pending) == 0:
        return 0, 0
    state = {"done": n_done, "computed": 0, "batches": 0}

    def finished(output):
        write_part(ctx.files, output, ctx.spec.keys, ctx.meta)
        ctx.seconds = [float(t) for t, e in zip(output.seconds, output.errors) if not e]
        state["done"] += len(output.rows)
        state["computed"] += len(output.rows)
        state["batches"] += 1
        if on_batch is not None:
            on_batch(state["done"], ctx.spec.n_rows)

    try:
        _execute(ctx, pending, where, batch_rows, finished)
    except KeyboardInterrupt:
        raise SweepInterrupted(state["done"], ctx.spec.n_rows, str(ctx.files.parts)) from None
    except SweepLost as exc:
        raise SweepLost(exc.why, state["done"], ctx.spec.n_rows, str(ctx.files.parts)) from None
    return state["computed"], state["batches"]


def _execute(ctx, pending, where, batch_rows, finished):
    from rotframe.app.sweep import cluster

    client, workers = where["client"], where["workers"]
    scheduler, scheduler_file = where["scheduler"], where["scheduler_file"]
    if client is None and not (workers or scheduler or scheduler_file):
        scheduler = scheduler_from_env()
    own = None
    if client is None and (workers or scheduler or scheduler_file):
        own = client = _connect(workers, scheduler, scheduler_file)
    try:
        n_workers = max(1, sum(client.nthreads().values())) if client is not None else 1
        local = workers if (own is not None and not (scheduler or scheduler_file)) else None
        ctx.threads = batch_threads(local_workers=local, here=client is None)
        def run(tasks):
            if client is None:  # one batch generated at a time
                for task in tasks:
                    finished(run_batch(task))
            else:
                with quiet_dask_logs():
                    cluster.run_on_dask(client, list(tasks), finished, split=ctx.path == "runs",
                                        task_timeout=where["task_timeout"])

        if ctx.path == "ensemble":
            size = batch_rows or _ensemble_batch_size(len(pending), n_workers, client is not None)
            batches = _chunk_aligned(pending, size)
        else:
            if batch_rows is None:
                pending, batch_rows = _probe(ctx, pending, n_workers, run)
            batches = (pending[s:s + batch_rows] for s in range(0, len(pending), batch_rows))
        run(ctx.task(i, rows) for i, rows in enumerate(batches, start=1))
    except KeyboardInterrupt:
        if client is not None:
            cluster.silence_late_callbacks()
        raise
    finally:
        if own is not None:
            cluster.close_bounded(own)


def _chunk_aligned(pending, size):
    """Batches of about ``size`` rows made of whole ensemble chunks (so that the cut never changes a number)."""
    chunk = pending // ENSEMBLE_CHUNK
    starts = np.concatenate([[0], np.nonzero(np.diff(chunk))[0] + 1, [len(pending)]])
    per = max(1, int(size) // ENSEMBLE_CHUNK)
    for i in range(0, len(starts) - 1, per):
        yield pending[starts[i]:starts[min(i + per, len(starts) - 1)]]


def _probe(ctx, pending, n_workers, run):
    """Run the first two rows where the batches run (on Dask: never here) to time them.

    Returns the rest and the rows per batch.
    """
    ctx.seconds = []
    run([ctx.task(0, pending[:2])])
    rest = pending[2:]
    per_row = max(min(ctx.seconds) if ctx.seconds else 0.01, 1e-4)  # a probe that failed: a guess of 10 ms
    total = per_row * len(rest)
    target = min(max(total / (BATCHES_PER_WORKER * n_workers), MIN_BATCH_S), MAX_BATCH_S)
    return rest, max(1, int(math.ceil(target / per_row)))


def _ensemble_batch_size(n, n_workers, distributed):
    if not distributed:
        return ENSEMBLE_BATCH
    size = int(math.ceil(n / (BATCHES_PER_WORKER * n_workers)))
    return int(min(max(size, MIN_ENSEMBLE_BATCH), ENSEMBLE_BATCH))


def scheduler_from_env():
    """``DASK_SCHEDULER_ADDRESS`` where set (as Dask's own clients read it), else None."""
    import os

    return os.environ.get("DASK_SCHEDULER_ADDRESS", "").strip() or None


def check_scheduler(address, timeout=None):
    """A Dask scheduler address: ``tcp://HOST:PORT`` (or ``tls://``), reachable within ``timeout`` seconds.

    Only the TCP connection is tried here; the Dask handshake itself is bounded in
    `_connect`. Raises ScenarioError in one line.
    """
    import socket
    from urllib.parse import urlsplit

    allowed = "allowed: tcp://HOST:PORT, e.g. tcp://127.0.0.1:8786"
    timeout = CONNECT_TIMEOUT_S if timeout is None else timeout
    text = str(address).strip()
    if "://" not in text:
        text_full = "tcp://" + text
    else:
        text_full = text
    try:
        parts = urlsplit(text_full)
        host, port = parts.hostname, parts.port
    except ValueError as exc:
        raise ScenarioError(f"--scheduler {address!r}: not an address ({exc}); {allowed}") from None
    if parts.scheme not in ("tcp", "tls") or not host or port is None or parts.path not in ("", "/"):
        raise ScenarioError(f"--scheduler {address!r}: not a scheduler address; {allowed}")
    try:
        with socket.create_connection((host, port), timeout=timeout):
            pass
    except OSError as exc:
        why = "timed out" if isinstance(exc, (TimeoutError, socket.timeout)) else (exc.strerror or str(exc))
        raise ScenarioError(f"--scheduler {address!r}: cannot connect to {host}:{port} ({why})") from None
    return f"{parts.scheme}://{host}:{port}"


def _connect(workers, scheduler, scheduler_file=None):
    import logging
    import warnings

    need("distributed", "--scheduler" if (scheduler or scheduler_file) else "--workers")
    from distributed import Client, LocalCluster

    if scheduler_file:
        return _client_bounded(Client, None, scheduler_file, scheduler_file=_scheduler_file(scheduler_file))
    if scheduler:
        return _client_bounded(Client, check_scheduler(scheduler), scheduler)
    with quiet_dask_logs(), _children_ignore_sigint(), warnings.catch_warnings():
        # no dashboard wanted; its HTTP server (health checks) takes any free port, and says nothing about 8787
        warnings.filterwarnings("ignore", message=".*already in use", category=UserWarning)
        cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True, dashboard_address=":0",
                               silence_logs=logging.CRITICAL)
        return Client(cluster, set_as_default=False)


def _children_ignore_sigint():
    """Worker processes started inside ignore Ctrl-C (a terminal sends it to the whole group): this
    process handles it and closes them, without a traceback from each."""
    import contextlib
    import signal
    import threading

    @contextlib.contextmanager
    def ignoring():
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
        try:
            yield
        finally:
            signal.signal(signal.SIGINT, previous)

    return ignoring()


def _scheduler_file(path):
    from pathlib import Path

    p = Path(path)
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
        address = data["address"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        why = exc.strerror if isinstance(exc, OSError) else "not a Dask scheduler file (JSON with an 'address')"
        raise ScenarioError(f"--scheduler-file {str(path)!r}: cannot be read ({why})") from None
    check_scheduler(address)
    return str(p)


def _client_bounded(Client, address, given, timeout=None, scheduler_file=None):
    """A Dask client of ``address``, or ScenarioError within ``timeout`` s whatever answers there.

    Dask's own connect timeout does not bound the handshake: a listener that is not a
    scheduler can keep it waiting for ever (or send a frame header announcing exabytes).
    The client is made in a daemon thread that this one waits for at most ``timeout``.
    """
    import threading

    timeout = CONNECT_TIMEOUT_S if timeout is None else timeout
    box = {}

    def make():
        try:
            box["client"] = Client(address, timeout=f"{timeout}s", set_as_default=False,
                                   scheduler_file=scheduler_file)
        except BaseException as exc:  # noqa: BLE001 -- reported below
            box["error"] = exc

    with quiet_dask_logs():
        worker = threading.Thread(target=make, daemon=True, name="rotframe-dask-connect")
        worker.start()
        worker.join(timeout + 2.0)
    _quiet_dask_unraisable()
    if "client" in box:
        return box["client"]
    why = _one_line(box["error"])[:200] if "error" in box else f"no Dask handshake within {timeout:g} s"
    option = "--scheduler-file" if scheduler_file else "--scheduler"
    raise ScenarioError(f"{option} {given!r}: not a Dask scheduler or not answering ({why})")


def _quiet_dask_unraisable():
    """Keep quiet the tracebacks Dask's objects print from their ``__del__`` at exit: a half-made client's, and a
    future's that a signal cut while it was made (``'Future' object has no attribute '_cleared'``, seen in CI on
    2026-12-02). They are the library's own, and nothing a user can act on; the sweep's own message (with its
    ``--resume`` hint) is what an interrupted run prints. Made once a process, for every client."""
    import sys

    previous = sys.unraisablehook
    if getattr(previous, "_rotframe_quiet", False):
        return

    def hook(unraisable):
        obj = unraisable.object
        module = getattr(obj, "__module__", "") or getattr(type(obj), "__module__", "") or ""
        if str(module).startswith(("distributed", "tornado")):
            return
        previous(unraisable)

    hook._rotframe_quiet = True
    sys.unraisablehook = hook
