"""One batch of a sweep's rows, computed in this process or on a Dask worker.

A task carries everything a worker needs and nothing of the client's disk: the
scenario's text (`ScenarioSource`, parsed once per process and text), the
source of a plugin scene's module, the swept values and the limits in force. A
worker needs only rotframe installed.

A scene module with ``simulate_ensemble(values_list, terms, method, run, tracks=None)``
integrates the rows in vectorised calls of the compiled core. The rows of one call
are always those of one fixed chunk of `ENSEMBLE_CHUNK` consecutive rows of
the whole sweep (valid rows only), so a row's numbers never depend on how the sweep
was cut into batches, on the worker count, the backend or a resume; where a chunk's
call fails as a whole (one particle's numerical failure), each of its rows runs as
an ensemble of one, and the failure lands in that row's ``error``. Other scenes run
each row through `rotframe.app.runner.run`. A failed row is data (its
``error``), never the end of the sweep. BLAS is held to one thread inside the
batch (the threads are the batch's own, or the worker's), so that no run
oversubscribes the cores.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import math
import os
import sys
import time
from dataclasses import dataclass, field

import numpy as np

from rotframe.app.sweep.spec import apply_row, key_of
from rotframe.errors import RotframeError, ScenarioError
from rotframe.particles.ensemble import MAX_TRACK_SAMPLES  # at most this many samples per recorded path

__all__ = ["MAX_TRACK_SAMPLES", "ENSEMBLE_CHUNK", "ENSEMBLE_SAMPLES", "ScenarioSource", "BatchTask", "BatchOutput", "run_batch",
           "failed_output", "blas_single_thread"]


#: rows of one vectorised ensemble call: a fixed cut of the whole sweep's rows (row // ENSEMBLE_CHUNK)
ENSEMBLE_CHUNK = 2048


#: output samples of an ensemble call for the metrics (the recorded rows' paths are computed again, finer)
ENSEMBLE_SAMPLES = 16


@dataclass(frozen=True)
class ScenarioSource:
    """A scenario as text (and its plugin scene's module source), loadable on any machine.

    Attributes
    ----------
    filename : str
        The file's name (its stem is the scenario's name when the file has no ``name``).
    text : str
        The scenario file's text.
    plugin : tuple or None
        ``(scene name, module name, module source)`` of a scene that is not built in.
    version : str
        The rotframe version that wrote the task.
    """

    filename: str
    text: str
    plugin: tuple | None = None
    version: str = ""

    @classmethod
    def of(cls, scenario):
        """The source of a scenario name or path, read here (the client)."""
        from rotframe import __version__
        from rotframe.app import scenario as sc

        scn = sc.load(scenario)
        try:
            text = scn.path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise ScenarioError(f"scenario {str(scenario)!r}: cannot be read ({exc})") from None
        return cls(scn.path.name, text, _plugin_source(scn.scene), __version__)

    @functools.cached_property
    def digest(self) -> str:
        """sha256 of everything a worker runs from (the resume fingerprint uses it); made once."""
        h = hashlib.sha256()
        for part in (self.filename, self.text, repr(self.plugin), self.version):
            h.update(part.encode("utf-8", "surrogatepass"))
            h.update(b"\0")
        return h.hexdigest()

    def load(self):
        """The parsed `rotframe.app.scenario.Scenario`, once per process and source."""
        key = self.digest
        found = _LOADED.get(key)
        if found is None:
            found = _LOADED[key] = self._load()
        return found

    def _load(self):
        import tempfile
        from pathlib import Path

        from rotframe.app import scenario as sc

        if self.plugin is not None:
            _install_plugin(*self.plugin)
        folder = Path(tempfile.gettempdir()) / f"rotframe-sweep-{os.getuid() if hasattr(os, 'getuid') else 0}" / \
            self.digest[:24]
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / self.filename
        if not path.is_file() or path.read_text(encoding="utf-8") != self.text:
            tmp = folder / f".{self.filename}.{os.getpid()}.tmp"
            tmp.write_text(self.text, encoding="utf-8")
            os.replace(tmp, path)
        return sc.load(str(path))


#: digest -> Scenario, per process
_LOADED: dict = {}


def _plugin_source(scene):
    """(scene, module name, source) of a scene that is not built in; None for a built-in one."""
    import importlib.util
    import inspect

    from rotframe import scenes

    entry = scenes.SCENES.get(scene)
    if isinstance(entry, str):
        if entry.startswith("rotframe.scenes."):
            return None
        spec = importlib.util.find_spec(entry)
        origin = getattr(spec, "origin", None)
        name = entry
    else:
        module = entry if inspect.ismodule(entry) else inspect.getmodule(entry)
        if module is None:
            return None
        name, origin = module.__name__, getattr(module, "__file__", None)
    if not origin or not str(origin).endswith(".py"):
        return None  # a compiled or package module must be installed on the workers
    try:
        with open(origin, encoding="utf-8") as f:
            return (scene, name, f.read())
    except OSError:
        return None


def _install_plugin(scene, name, source):
    """Run a plugin scene's module source here (a worker) and register its scene, unless it is there."""
    import types

    from rotframe import scenes

    if scene in scenes.SCENES:
        return
    module = sys.modules.get(name)
    if module is None:
        module = types.ModuleType(name)
        module.__file__ = f"<rotframe sweep plugin {name}>"
        sys.modules[name] = module
        try:
            exec(compile(source, module.__file__, "exec"), module.__dict__)  # noqa: S102 -- the user's own plugin
        except BaseException:
            sys.modules.pop(name, None)
            raise
    if scene not in scenes.SCENES:
        scenes.register(scene, module)


@dataclass
class BatchTask:
    """One batch: what a worker needs to compute some rows (pickled to Dask workers)."""

    index: int
    scenario: ScenarioSource
    sets: dict
    keys: list
    rows: np.ndarray
    values: np.ndarray
    method: str | None
    path: str
    track_rows: frozenset
    limits: object = None  # the command's rotframe.limits.Limits, applied on the worker too
    threads: int | None = None  # threads of the batch (None: every core here, or the Dask worker's own)
    device: str | None = None  # the command's --device ("gpu" checked on the worker too; None: the CPU)


@dataclass
class BatchOutput:
    """Rows computed by `run_batch`, as columns.

    ``metrics`` and ``theory`` map a name to a float array (NaN where a row has none),
    ``errors`` is one string per row (empty when fine), ``tracks`` maps a row to
    (times, positions) for the recording, ``seconds`` is the time of each row.
    """

    index: int
    rows: np.ndarray
    values: np.ndarray
    metrics: dict
    theory: dict
    errors: list
    tracks: dict = field(default_factory=dict)
    seconds: np.ndarray = None

    def __len__(self):
        return len(self.rows)


def failed_output(task: BatchTask, message: str) -> BatchOutput:
    """Every row of ``task`` failed with ``message`` (a batch that killed its workers, or timed out)."""
    n = len(task.rows)
    return BatchOutput(task.index, np.asarray(task.rows, np.int64), np.asarray(task.values, np.float64), {}, {},
                       [message] * n, {}, np.zeros(n))


def run_batch(task: BatchTask) -> BatchOutput:
    """Compute the rows of one batch (in this process or on a Dask worker)."""
    from rotframe import limits
    from rotframe.particles.ensemble import device_scope, threads_scope

    threads = task.threads if task.threads is not None else _worker_threads()
    # a Dask worker's context has no --device of the command's: the task carries it ("gpu" is checked there)
    with limits.applied(task.limits or limits.current()), threads_scope(threads), device_scope(task.device), \
            blas_single_thread():
        return _run_batch(task)


def _worker_threads():
    """On a Dask worker: its own threads shared among the tasks it runs now; elsewhere None (every core)."""
    if "distributed" not in sys.modules:
        return None
    try:
        from distributed import get_worker

        state = get_worker().state
        return max(1, int(state.nthreads) // max(1, len(state.executing)))
    except (ValueError, AttributeError, TypeError):  # not on a worker
        return None


def blas_single_thread():
    """A context holding BLAS to one thread (threadpoolctl where installed; else nothing to do).

    A sweep's parallelism is its batches and ensemble chunks; BLAS threads on top of
    them (small ``expm`` and products) only oversubscribe the cores: 5 to 20 times
    slower rows on a busy machine. The libraries are looked up once, after
    ``scipy.linalg`` (which brings its own BLAS) is loaded, so none escapes the limit.
    """
    if not _CONTROLLER:
        try:
            import scipy.linalg  # noqa: F401 -- its BLAS must be loaded to be limited
            from threadpoolctl import ThreadpoolController

            _CONTROLLER.append(ThreadpoolController())  # (tens of ms: once per process)
        except Exception:  # noqa: BLE001 -- not installed, or a library it cannot inspect: no limit
            _CONTROLLER.append(None)
    if _CONTROLLER[0] is None:
        return contextlib.nullcontext()
    return _CONTROLLER[0].limit(limits=1, user_api="blas")


#: the process's threadpoolctl controller (made after numpy's and scipy's BLAS are loaded), or None
_CONTROLLER: list = []


def _run_batch(task):
    from rotframe import scenes
    from rotframe.particles.integrators import RunInterrupted

    scn = task.scenario.load()
    base = scn.with_values(task.sets)
    try:
        if task.path == "ensemble":
            return _ensemble_batch(task, scn, scenes.get(scn.scene), base)
        return _runs_batch(task, scn, base)
    except RunInterrupted:  # Ctrl-C inside an integration: the sweep stops, the batch is not written
        raise KeyboardInterrupt from None


class _Columns:
    """Metric and theory columns of a batch, filled row by row or chunk by chunk."""

    def __init__(self, n):
        self.n, self.metrics, self.theory = n, {}, {}

    def put(self, table, name, index, values):
        col = table.get(name)
        if col is None:
            col = table[name] = np.full(self.n, math.nan)
        col[index] = values


def _ensemble_batch(task, scn, scene, base):
    """The batch's valid rows through ``scene.simulate_ensemble``, one call per fixed chunk of the sweep."""
    from rotframe.particles.ensemble import resolve_threads

    n = len(task.rows)
    errors, cols = [""] * n, _Columns(n)
    keys = [key_of(k) for k in task.keys]
    params = {k: v for k, v in base.items() if k != "run"}
    values_list, where = [], []
    for i, row in enumerate(task.values):
        try:
            values_list.append(apply_row(scn, dict(params), keys, row))
            where.append(i)
        except ScenarioError as exc:
            errors[i] = _error_text(exc)
    # the metrics at ENSEMBLE_SAMPLES output samples (the same for every row: events are located on the flow or
    # inside the steps, never from the samples); the recorded rows' paths again, at up to MAX_TRACK_SAMPLES
    run = dict(base["run"], samples=ENSEMBLE_SAMPLES)
    run_paths = dict(base["run"], samples=min(int(base["run"].get("samples") or MAX_TRACK_SAMPLES),
                                              MAX_TRACK_SAMPLES))
    chunk_of = np.asarray(task.rows, np.int64)[where] // ENSEMBLE_CHUNK if where else np.zeros(0, np.int64)
    chunks = [np.nonzero(chunk_of == c)[0] for c in np.unique(chunk_of)]  # indices into where / values_list
    tracks = {}

    def one(members):
        vals = [values_list[m] for m in members]
        wanted = [j for j, m in enumerate(members) if int(task.rows[where[m]]) in task.track_rows]
        try:
            out, errs = _ensemble_call(scene, scn, task, run, vals, None), None
        except (RotframeError, ArithmeticError):
            out, errs = [], []
            for v in vals:  # the chunk failed as a whole: each row alone, so the failure is its own
                try:
                    out.append(_ensemble_call(scene, scn, task, run, [v], None)[0])
                    errs.append("")
                except Exception as exc:  # noqa: BLE001 -- a failed row is data
                    out.append(None)
                    errs.append(_error_text(exc))
        return members, out, _paths(scene, scn, task, run_paths, vals, wanted, out), errs

    t0 = time.perf_counter()
    cores = resolve_threads(None)
    threads = min(cores, len(chunks)) if chunks else 1
    if threads > 1:
        import contextvars
        from concurrent.futures import ThreadPoolExecutor

        results = [one(chunks[0])]  # compiles (or loads) the kernels once, so that the pool does not wait on them
        # each chunk runs in a copy of this thread's context: the device and limits in force reach the pool's
        # threads (a ContextVar is per thread; a new thread would see the defaults: all cores, the CPU)
        contexts = [contextvars.copy_context() for _ in chunks[1:]]
        with ThreadPoolExecutor(max_workers=threads) as pool:
            # (each chunk runs on one thread: `_ensemble_call`; the chunks are the parallelism)
            results += list(pool.map(lambda job: job[0].run(one, job[1]), zip(contexts, chunks[1:])))
    else:
        results = [one(c) for c in chunks]
    theory = getattr(scene, "ensemble_theory", None)  # the theory columns single runs have
    for members, metrics, wanted, errs in results:
        idx = np.asarray([where[m] for m in members], np.int64)
        ok = [j for j in range(len(members)) if metrics[j] is not None]
        for j in range(len(members)):
            if errs is not None and errs[j]:
                errors[idx[j]] = errs[j]
        for name in _ordered_keys(metrics[j] for j in ok):
            cols.put(cols.metrics, name, idx[ok], [_float(metrics[j].get(name)) for j in ok])
        if theory is not None and ok:
            th = [theory(values_list[members[j]]) for j in ok]
            for name in _ordered_keys(th):
                cols.put(cols.theory, name, idx[ok], [_float(t.get(name)) for t in th])
        for j, tr in wanted.items():
            tracks[int(task.rows[idx[j]])] = _decimated(*tr)
    seconds = np.full(n, (time.perf_counter() - t0) / max(n, 1))
    return BatchOutput(task.index, np.asarray(task.rows, np.int64), np.asarray(task.values, np.float64),
                       cols.metrics, cols.theory, errors, tracks, seconds)


def _paths(scene, scn, task, run, vals, wanted, metrics):
    """{index in vals: (times, positions)} of the recorded rows that ran (a second call, for their paths only)."""
    wanted = [j for j in wanted if metrics[j] is not None]
    if not wanted:
        return {}
    tracks = {k: None for k in range(len(wanted))}
    try:
        _ensemble_call(scene, scn, task, run, [vals[j] for j in wanted], tracks)
    except (RotframeError, ArithmeticError):  # paths are for the picture only
        return {}
    return {j: tracks[k] for k, j in enumerate(wanted) if tracks.get(k) is not None}


def _ensemble_call(scene, scn, task, run, values_list, tracks):
    from rotframe.particles.ensemble import threads_scope

    with threads_scope(1):  # the chunks are the parallelism; the result does not depend on it
        return scene.simulate_ensemble(values_list, list(scn.model), task.method, run, tracks=tracks)


def _ordered_keys(dicts):
    seen = {}
    for d in dicts:
        for k in d:
            seen.setdefault(k, None)
    return list(seen)


def _runs_batch(task, scn, base):
    """One `rotframe.app.runner.run` per row; a failure goes to the row's ``error``."""
    from rotframe.app import runner
    from rotframe.particles.integrators import RunInterrupted

    n = len(task.rows)
    errors, cols, tracks, seconds = [""] * n, _Columns(n), {}, np.zeros(n)
    keys = [key_of(k) for k in task.keys]
    params = {k: v for k, v in base.items() if k != "run"}
    for i, row in enumerate(task.values):
        t0 = time.perf_counter()
        try:
            sets = dict(task.sets)
            overrides = apply_row(scn, dict(params), keys, row)
            sets.update({k.param: overrides[k.param] for k in keys})
            summary, result = runner.run(scn, sets, method=task.method)
            for name, value in summary["metrics"].items():
                cols.put(cols.metrics, name, i, _float(value))
            for name, value in summary.get("theory", {}).items():
                cols.put(cols.theory, name, i, _float(value))
            if int(task.rows[i]) in task.track_rows:
                track = _track(result)
                if track is not None:
                    tracks[int(task.rows[i])] = track
        except RunInterrupted:
            raise
        except Exception as exc:  # noqa: BLE001 -- a failed row is data, not the end of the sweep
            errors[i] = _error_text(exc)
        seconds[i] = time.perf_counter() - t0
    return BatchOutput(task.index, np.asarray(task.rows, np.int64), np.asarray(task.values, np.float64),
                       cols.metrics, cols.theory, errors, tracks, seconds)


def _float(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def _error_text(exc):
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _track(result):
    """(times, points) to show one run in the ensemble recording, decimated; None if there is nothing.

    Particles: the position up to the ground event. Rigid bodies: the direction of
    the angular momentum in body axes (the run's polhode on the unit sphere).
    """
    from rotframe.scenes.base import until_event

    traj = result.trajectory
    times = getattr(traj, "times", None)
    if times is None or len(times) == 0:
        return None
    r, L = getattr(traj, "r", None), getattr(traj, "L", None)
    if r is not None and np.ndim(r) == 3:
        if "ground" in getattr(traj, "event_times", {}):
            times, pos, _ = until_event(traj, "ground")
            return _decimated(times, pos)
        return _decimated(times, r[:, 0])
    if L is not None and np.ndim(L) == 2:
        return _decimated(times, L / np.maximum(np.linalg.norm(L, axis=1), 1e-300)[:, None])
    return None


def _decimated(times, pos):
    from rotframe.numerics.sampling import decimate

    idx = decimate(len(times), MAX_TRACK_SAMPLES)
    return np.asarray(times, np.float64)[idx], np.asarray(pos, np.float64)[idx].astype(np.float32)
