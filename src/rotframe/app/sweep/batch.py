"""One batch of a sweep's rows, computed in this process or on a Dask worker.

A scene module with ``simulate_ensemble(values_list, terms, method, run, tracks=None)``
integrates the whole batch in one vectorised call of the compiled core (through
`rotframe.particles.ensemble.integrate_ensemble`); otherwise each row goes
through `rotframe.app.runner.run`. A failed row is data (its ``error``), never
the end of the sweep.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from rotframe.app.sweep.spec import apply_row, key_of
from rotframe.errors import RotframeError, ScenarioError
from rotframe.particles.ensemble import MAX_TRACK_SAMPLES  # at most this many samples per recorded path

__all__ = ["MAX_TRACK_SAMPLES", "BatchTask", "BatchOutput", "run_batch"]


@dataclass
class BatchTask:
    """One batch: what a worker needs to compute some rows (pickled to Dask workers)."""

    index: int
    scenario: str
    sets: dict
    keys: list
    rows: np.ndarray
    values: np.ndarray
    method: str | None
    path: str
    track_rows: frozenset
    limits: object = None  # the command's rotframe.limits.Limits, applied on the worker too
    threads: int | None = None  # threads of a vectorised ensemble batch (None: every core of the worker)


@dataclass
class BatchOutput:
    """Rows computed by `run_batch`; ``tracks`` maps a row to (times, positions) for the recording."""

    index: int
    rows: list
    tracks: dict
    seconds: list


def run_batch(task: BatchTask) -> BatchOutput:
    """Compute the rows of one batch (in this process or on a Dask worker).

    On the ``ensemble`` path the valid rows go to the scene's ``simulate_ensemble`` in
    one call; if that call fails as a whole (one particle's numerical failure), the
    batch falls back to one run per row so the failure lands in that row's ``error``.
    """
    from rotframe import limits
    from rotframe.particles.ensemble import threads_scope

    with limits.applied(task.limits or limits.current()), threads_scope(task.threads):
        return _run_batch(task)


def _run_batch(task):
    from rotframe import scenes
    from rotframe.app import scenario as sc
    from rotframe.particles.integrators import RunInterrupted

    scn = sc.load(task.scenario)
    base = scn.with_values(task.sets)
    try:
        if task.path == "ensemble":
            try:
                return _ensemble_batch(task, scn, scenes.get(scn.scene), base)
            except (RotframeError, ArithmeticError):
                pass
        return _runs_batch(task, scn, base)
    except RunInterrupted:  # Ctrl-C inside an integration: the sweep stops, the batch is not written
        raise KeyboardInterrupt from None


def _ensemble_batch(task, scn, scene, base):
    """All valid rows of the batch through ``scene.simulate_ensemble`` in one call."""
    rows, values_list, where = _start_rows(task), [], []
    keys = [key_of(k) for k in task.keys]
    params = {k: v for k, v in base.items() if k != "run"}
    for i, row in enumerate(task.values):
        try:
            values_list.append(apply_row(scn, dict(params), keys, row))
            where.append(i)
        except ScenarioError as exc:
            rows[i]["error"] = _error_text(exc)
    tracks = {j: None for j, i in enumerate(where) if int(task.rows[i]) in task.track_rows}
    t0 = time.perf_counter()
    run = dict(base["run"], samples=min(int(base["run"].get("samples") or MAX_TRACK_SAMPLES), MAX_TRACK_SAMPLES))
    metrics = scene.simulate_ensemble(values_list, list(scn.model), task.method, run, tracks=tracks) \
        if values_list else []
    theory = getattr(scene, "ensemble_theory", None)  # the theory columns single runs have
    for j, i in enumerate(where):
        rows[i]["metrics"] = {k: _float(v) for k, v in metrics[j].items()}
        if theory is not None:
            rows[i]["theory"] = {k: _float(v) for k, v in theory(values_list[j]).items()}
    out_tracks = {int(task.rows[where[j]]): _decimated(*tr) for j, tr in tracks.items() if tr is not None}
    seconds = [(time.perf_counter() - t0) / max(len(rows), 1)] * len(rows)
    return BatchOutput(task.index, rows, out_tracks, seconds)


def _runs_batch(task, scn, base):
    """One `rotframe.app.runner.run` per row; a failure goes to the row's ``error``."""
    from rotframe.app import runner
    from rotframe.particles.integrators import RunInterrupted

    rows, tracks, seconds = _start_rows(task), {}, []
    keys = [key_of(k) for k in task.keys]
    for i, row in enumerate(task.values):
        t0 = time.perf_counter()
        try:
            sets = dict(task.sets)
            overrides = apply_row(scn, {k: v for k, v in base.items() if k != "run"}, keys, row)
            sets.update({k.param: overrides[k.param] for k in keys})
            summary, result = runner.run(task.scenario, sets, method=task.method)
            rows[i]["metrics"] = {k: _float(v) for k, v in summary["metrics"].items()}
            rows[i]["theory"] = {k: _float(v) for k, v in summary.get("theory", {}).items()}
            if int(task.rows[i]) in task.track_rows:
                track = _track(result)
                if track is not None:
                    tracks[int(task.rows[i])] = track
        except RunInterrupted:
            raise
        except Exception as exc:  # noqa: BLE001 -- a failed row is data, not the end of the sweep
            rows[i]["error"] = _error_text(exc)
        seconds.append(time.perf_counter() - t0)
    return BatchOutput(task.index, rows, tracks, seconds)


def _start_rows(task):
    return [{"row": int(r), "values": [float(x) for x in v], "metrics": {}, "theory": {}, "error": ""}
            for r, v in zip(task.rows, task.values)]


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
