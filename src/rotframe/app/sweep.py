"""Parameter sweeps: a scenario over a grid or Monte Carlo samples, as one table.

``rotframe sweep NAME`` runs the scenario once per grid point (the Cartesian
product of ``--grid`` / ``--log-grid`` axes, grids first, the last axis
varying fastest) or per Monte Carlo sample (``--samples N`` with ``--vary``
distributions drawn in order from ``numpy.random.default_rng(seed)``), with
``--set`` fixing the other parameters. A swept key is a numeric parameter or
one component of a vector parameter (``omega[0]``).

The result is one table, one row per point: ``row`` (the point's index, the
same for the same grid or seed), the swept values (in the parameters'
documented units), every metric, ``theory_<metric>`` where the scene gives a
closed form, and ``error`` (empty when the run was fine; the message when it
failed, so that one failure never ends a sweep). It is written as Parquet,
with one PNG per metric against each swept parameter and a rerun recording of
the ensemble next to it.

Execution. A scene module with ``simulate_ensemble(values_list, terms, method,
run, tracks=None)`` integrates a whole batch of points in one vectorised call
of the compiled core (:func:`integrate_ensemble` helps it); otherwise each
point goes through :func:`rotframe.app.runner.run`. Points are cut into batches
(about 0.2 s to 30 s of work each, at most about four per worker); batches run
in this process, or as Dask tasks on a ``LocalCluster`` (``--workers N``) or an
existing scheduler (``--scheduler ADDRESS``), retried when a worker is lost.
Every finished batch is written at once as a Parquet part in
``<out>.parts/``; the parts are merged into ``<out>`` at the end, so an
interrupted sweep keeps its finished batches and ``--resume`` computes only
the missing rows.

Dask and pyarrow are imported only when needed (``pip install
rotframe[sweep]``).
"""

from __future__ import annotations

import itertools
import json
import math
import os
import re
import shutil
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from rotframe.numerics.sampling import decimate

from rotframe.particles.ensemble import EnsembleRun, group_points, integrate_ensemble  # noqa: F401  (moved; kept importable)
from rotframe.errors import RotframeError, ScenarioError

__all__ = ["Axis", "Vary", "SweepSpec", "SweepResult", "SweepInterrupted", "EnsembleRun", "parse_spec",
           "sweep_points", "run_sweep", "read_table", "run_batch", "integrate_ensemble", "group_points", "main"]

#: at most this many trajectories and samples per trajectory in the recording
MAX_TRACKS = 2000
MAX_TRACK_SAMPLES = 500  # the same as rotframe.particles.ensemble.MAX_TRACK_SAMPLES
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
_DISTRIBUTIONS = {"normal": ("MEAN", "SD"), "uniform": ("LO", "HI")}
_META_KEY = b"rotframe.app.sweep"


# ---------------------------------------------------------------------------
# public API
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Axis:
    """One grid axis: ``key`` swept over ``values`` (documented unit); ``log`` for a log-spaced grid."""

    key: str
    values: tuple
    log: bool = False


@dataclass(frozen=True)
class Vary:
    """One Monte Carlo distribution: ``normal(a=mean, b=sd)`` or ``uniform(a=lo, b=hi)``."""

    key: str
    dist: str
    a: float
    b: float


@dataclass
class SweepSpec:
    """What to sweep: validated by :func:`parse_spec`, turned into rows by :func:`sweep_points`.

    Attributes
    ----------
    scenario : str
        Scenario name or ``.toml`` path, as given.
    name : str
        The scenario's name (default output names).
    sets : dict
        ``--set`` values fixed for every row.
    axes : list of Axis
        Grid axes (empty for a Monte Carlo sweep).
    samples : int or None
        Monte Carlo sample count.
    vary : list of Vary
    seed : int
    method : str or None
    """

    scenario: str
    name: str
    sets: dict
    axes: list = field(default_factory=list)
    samples: int | None = None
    vary: list = field(default_factory=list)
    seed: int = 0
    method: str | None = None

    @property
    def keys(self) -> list:
        """Swept keys, in column order."""
        return [a.key for a in self.axes] + [v.key for v in self.vary]

    @property
    def log_keys(self) -> set:
        """Keys on a log-spaced grid (plotted on a log axis)."""
        return {a.key for a in self.axes if a.log}

    @property
    def n_rows(self) -> int:
        """Number of points."""
        if self.axes:
            return int(np.prod([len(a.values) for a in self.axes]))
        return int(self.samples or 0)

    def describe(self) -> dict:
        """A JSON-able description, stored in every Parquet file of the sweep."""
        return {"scenario": self.name, "sets": dict(self.sets),
                "axes": [[a.key, list(a.values), a.log] for a in self.axes], "samples": self.samples,
                "vary": [asdict(v) for v in self.vary], "seed": self.seed, "method": self.method,
                "keys": self.keys, "rows": self.n_rows}


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


def main(args) -> int:
    """``rotframe sweep``: run, write, print; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        As built by :mod:`rotframe.app.cli` (``name, sets, grid, log_grid, samples, vary, seed, method,
        workers, scheduler, out, resume, json``).

    Returns
    -------
    int
        0 done (failed rows are reported in the table, not fatal); 3 every row failed (the table
        holds the messages); 130 / 143 interrupted (finished batches kept).

    Raises
    ------
    ScenarioError
        Bad input (the command line turns it into exit code 2 and one line).
    """
    from rotframe.app import cli
    from rotframe.app.progress import Progress
    from rotframe.app.signals import InterruptScope

    spec = parse_spec(args.name, sets=cli._parse_sets(args.sets), grid=args.grid, log_grid=args.log_grid,
                      samples=args.samples, vary=args.vary, seed=args.seed, method=args.method)
    if args.workers is not None and args.workers < 1:
        raise ScenarioError(f"--workers {args.workers}: must be >= 1")
    most = max(2, 2 * (os.cpu_count() or 1))  # each worker is a process of a few hundred MB
    if args.workers is not None and args.workers > most:
        raise ScenarioError(f"--workers {args.workers}: at most {most} local processes on this machine "
                            f"({os.cpu_count()} CPUs); use --scheduler for a larger cluster")
    check_outputs(spec, args.out, args.resume)
    if args.scheduler is not None:
        check_scheduler(args.scheduler)
    scope = getattr(args, "_scope", None) or InterruptScope()
    progress = Progress("sweep", "rows", enabled=not args.json)
    try:
        result = run_sweep(spec, args.out, workers=args.workers, scheduler=args.scheduler, resume=args.resume,
                           on_batch=progress.update)
    except SweepInterrupted as exc:
        progress.close()
        scope.interrupted = True
        cli._error(f"{scope.verb}: {exc.saved} of {exc.total} rows are saved in {exc.parts}; "
                   "run the same command with --resume to compute the rest")
        return scope.exit_code
    except KeyboardInterrupt as exc:  # while merging, plotting or recording: the parts are still there
        progress.close()
        scope.note(exc)
        cli._error(f"{scope.verb} while writing the results; every computed row is kept in "
                   f"{_Files.for_spec(spec, args.out).parts}; run the same command with --resume to finish")
        return scope.exit_code
    finally:
        progress.close()
    if args.json:
        print(json.dumps(cli._jsonable(result.as_json())))
    else:
        print(format_result(result, spec))
    if result.rows and result.failed == result.rows:
        invalid = sum(1 for e in result.table.column("error").to_pylist()
                      if e.startswith(("ScenarioError", "LimitError", "OutputError")))
        if invalid == result.rows:
            first = result.table.column("error")[0].as_py()
            cli._error(f"every row was invalid input ({first}); the messages are in the error column of "
                       f"{result.out}")
            return cli.EXIT_INPUT
        cli._error(f"every run failed; the messages are in the error column of {result.out}")
        return cli.EXIT_NUMERICAL
    return cli.EXIT_OK


def check_outputs(spec, out, resume=False):
    """Every path the sweep will write can be written: checked before any computing starts."""
    from rotframe.app.outputs import check_output_dir, check_output_file

    files = _Files.for_spec(spec, out)
    option = "--out" if out else "sweep output"
    check_output_file(files.out, option, ".parquet")
    if files.parts.exists() and not files.parts.is_dir():
        raise ScenarioError(f"{option} {str(files.out)!r}: {str(files.parts)!r} (where finished batches go) "
                            "is a file, not a folder; remove it or choose another --out")
    check_output_dir(files.parts, option, shown=files.out)
    if files.recording.is_dir():
        raise ScenarioError(f"{option} {str(files.out)!r}: {str(files.recording)!r} (the recording) is a folder")
    return files


def check_scheduler(address, timeout=None):
    """A Dask scheduler address: ``tcp://HOST:PORT`` (or ``tls://``), reachable within ``timeout`` seconds.

    Only the TCP connection is tried here; the Dask handshake itself is bounded in
    :func:`_connect`. Raises ScenarioError in one line.
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


def parse_spec(scenario, *, sets=None, grid=(), log_grid=(), samples=None, vary=(), seed=0, method=None):
    """Validate the sweep's command-line pieces into a :class:`SweepSpec`.

    Parameters
    ----------
    scenario : str
        Scenario name or ``.toml`` path.
    sets : dict, optional
        ``{key: value}`` fixed for every row (validated as ``rotframe run --set``).
    grid, log_grid : sequence of str
        ``KEY=START:STOP:N``: N linearly (logarithmically, both bounds > 0) spaced values, inclusive.
    samples : int, optional
        Monte Carlo sample count (with ``vary``).
    vary : sequence of str
        ``KEY=normal(MEAN,SD)`` or ``KEY=uniform(LO,HI)``.
    seed : int
    method : str, optional
        Integrator, checked against the scene's methods.

    Raises
    ------
    ScenarioError
        One line naming the option, key and value and what is allowed.
    """
    from rotframe.app import scenario as sc
    scn = sc.load(scenario)
    sets = dict(sets or {})
    base = scn.with_values(sets)
    _check_method(scn, method)
    axes = [_parse_axis(scn, base, text, log=False) for text in grid]
    axes += [_parse_axis(scn, base, text, log=True) for text in log_grid]
    varies = [_parse_vary(scn, base, text) for text in vary]
    _check_shape(axes, varies, samples)
    from rotframe import limits

    rows = math.prod(len(a.values) for a in axes) if axes else int(samples or 0)
    limits.check_rows(rows, what="sweep")
    spec = SweepSpec(scenario=str(scenario), name=scn.name, sets=sets, axes=axes, samples=samples,
                     vary=varies, seed=int(seed), method=method)
    _check_keys_once(spec)
    return spec


def sweep_points(spec: SweepSpec) -> np.ndarray:
    """The swept values, one row per point: a (rows, keys) float array in :attr:`SweepSpec.keys` order.

    Grid rows are the Cartesian product of the axes (last axis fastest); Monte Carlo
    rows are drawn from ``default_rng(seed)``, one distribution after the other, so the
    same spec always gives the same rows.
    """
    if spec.axes:
        grid = list(itertools.product(*[a.values for a in spec.axes]))
        return np.array(grid, dtype=np.float64).reshape(len(grid), len(spec.axes))
    rng = np.random.default_rng(spec.seed)
    cols = [rng.normal(v.a, v.b, spec.samples) if v.dist == "normal" else rng.uniform(v.a, v.b, spec.samples)
            for v in spec.vary]
    return np.stack(cols, axis=1).astype(np.float64)


def points_of(spec: SweepSpec, rows) -> np.ndarray:
    """The swept values of the given ``rows`` only (as :func:`sweep_points` would give them).

    Grid points are computed from their row index, so a large grid is never held
    whole; Monte Carlo rows are drawn in order from the seed.
    """
    rows = np.asarray(rows, dtype=np.int64)
    if spec.axes:
        shape = tuple(len(a.values) for a in spec.axes)
        idx = np.unravel_index(rows, shape) if len(rows) else [np.zeros(0, np.int64)] * len(shape)
        cols = [np.asarray(a.values, dtype=np.float64)[i] for a, i in zip(spec.axes, idx)]
        return np.stack(cols, axis=1) if cols else np.zeros((len(rows), 0))
    return sweep_points(spec)[rows]


def run_sweep(spec: SweepSpec, out=None, *, workers=None, scheduler=None, client=None, resume=False,
              batch_rows=None, on_batch=None, plots=True, recording=True) -> SweepResult:
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

    Returns
    -------
    SweepResult

    Raises
    ------
    SweepInterrupted
        On Ctrl-C / SIGTERM; the finished batches stay in ``<out>.parts/``.
    ScenarioError
        ``out`` not ending in ``.parquet``; ``--resume`` of a different sweep; an unreachable scheduler.
    """
    t_start = time.perf_counter()
    _require("pyarrow", "rotframe sweep")
    files = _Files.for_spec(spec, out)
    with _exclusive(files):
        return _run_sweep_locked(spec, files, t_start, workers, scheduler, client, resume, batch_rows, on_batch, plots,
                                 recording)


def _exclusive(files):
    """Hold ``.<out>.lock`` beside the table: a second sweep into the same ``out`` is refused, not interleaved."""
    import contextlib

    @contextlib.contextmanager
    def lock():
        try:
            import fcntl
        except ImportError:  # not POSIX: no lock
            yield
            return
        from rotframe.app.outputs import OutputError

        try:
            files.out.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(files.out.parent / f".{files.out.name}.lock", os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise OutputError(f"--out {str(files.out)!r}: cannot create a lock beside it ({exc.strerror})") from None
        try:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                raise OutputError(f"--out {str(files.out)!r}: another sweep is writing it now; wait for it or "
                                  "choose another --out") from None
            yield
        finally:
            os.close(fd)

    return lock()


def _run_sweep_locked(spec, files, t_start, workers, scheduler, client, resume, batch_rows, on_batch, plots,
                      recording):
    meta = spec.describe()
    done = _prepare(files, meta, resume)
    pending = np.setdiff1d(np.arange(spec.n_rows), np.fromiter(done, dtype=np.int64, count=len(done)))
    ctx = _Context.create(spec, files, meta)
    t0 = time.perf_counter()
    computed, batches = _compute(ctx, pending, len(done), workers, scheduler, client, batch_rows, on_batch)
    timing = {"compute_s": time.perf_counter() - t0}
    t0 = time.perf_counter()
    table = _merge(files, meta, spec, include_out=resume)
    timing["merge_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    pngs = write_plots(table, spec, files.plot_stem) if plots else []
    timing["plot_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    rrd = _write_recording(ctx, table) if recording else None
    timing["record_s"] = time.perf_counter() - t0
    shutil.rmtree(files.parts, ignore_errors=True)
    timing["total_s"] = time.perf_counter() - t_start
    failed = int(sum(1 for e in table.column("error").to_pylist() if e))
    return SweepResult(scenario=spec.name, table=table, out=str(files.out), plots=[str(p) for p in pngs],
                       recording=str(rrd) if rrd else None, path=ctx.path, rows=table.num_rows, failed=failed,
                       computed=computed, batches=batches, timing=timing)


def read_table(path):
    """A sweep's Parquet table (pyarrow) and its description: ``(table, spec dict)``."""
    import pyarrow.parquet as pq

    table = pq.read_table(str(path))
    meta = (table.schema.metadata or {}).get(_META_KEY)
    return table, (json.loads(meta) if meta else {})


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


@dataclass
class BatchOutput:
    """Rows computed by :func:`run_batch`; ``tracks`` maps a row to (times, positions) for the recording."""

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

    with limits.applied(task.limits or limits.current()):
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


def write_plots(table, spec: SweepSpec, stem) -> list:
    """One PNG per metric, ``<stem>-<metric>.png``, against each swept key (matplotlib Agg).

    A one-axis grid is drawn as a line, anything else as a scatter; ``theory_<metric>``
    is overlaid when present; log-grid keys get a log x axis. A Monte Carlo sweep adds
    the metric's histogram (its dispersion: mean and standard deviation in the legend).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    for metric in _metric_columns(table, spec):
        y = _column(table, metric)
        if not np.any(np.isfinite(y)):
            continue
        theory = _column(table, "theory_" + metric) if "theory_" + metric in table.column_names else None
        panels = len(spec.keys) + (1 if spec.vary else 0)
        fig, axs = plt.subplots(1, panels, figsize=(5.5 * panels, 4.2), squeeze=False)
        for ax, key in zip(axs[0], spec.keys):
            _plot_one(ax, _column(table, key), y, theory, key, metric, spec)
        if spec.vary:
            _histogram(axs[0][-1], y, metric)
        fig.suptitle(f"{spec.name}: {metric} ({table.num_rows} runs)")
        fig.tight_layout()
        path = Path(f"{stem}-{_safe(metric)}.png")
        from rotframe.app.outputs import atomic_path

        try:
            with atomic_path(path, "plot") as tmp:
                fig.savefig(tmp, dpi=110, format="png")
        finally:
            plt.close(fig)
        paths.append(path)
    return paths


def format_result(result: SweepResult, spec: SweepSpec, head=8, tail=4) -> str:
    """The short text report: the first and last rows of the table, then where things went."""
    table = result.table
    metrics = _metric_columns(table, spec)[:4]
    cols = ["row"] + spec.keys + metrics + ["error"]
    n = table.num_rows
    shown = list(range(n)) if n <= head + tail else list(range(head)) + [None] + list(range(n - tail, n))
    data = {c: table.column(c).to_pylist() for c in cols}
    widths = {c: max(12, len(c)) for c in cols}
    lines = ["  ".join(f"{c:>{widths[c]}}" if c != "error" else c for c in cols)]
    for i in shown:
        if i is None:
            lines.append("  ".join(f"{'...':>{widths[c]}}" if c != "error" else "" for c in cols))
            continue
        lines.append("  ".join(_cell(data[c][i], widths[c], c) for c in cols))
    t = result.timing
    lines.append(f"{result.scenario}: {result.rows} rows ({result.failed} failed, {result.computed} computed now "
                 f"in {result.batches} batches, path {result.path}); compute {t['compute_s']:.2f} s, "
                 f"total {t['total_s']:.2f} s")
    lines.append(f"  table      {result.out}")
    lines.append(f"  plots      {', '.join(result.plots) or '(none)'}")
    lines.append(f"  recording  {result.recording or '(none)'}")
    return "\n".join(lines)


# ---------------------------------------------------------------------------
# parsing helpers
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class _Key:
    """A swept key: a parameter, or one component of a vector parameter (``omega[0]``)."""

    text: str
    param: str
    index: int | None = None


def _parse_key(scn, option, text):
    m = re.fullmatch(r"\s*([A-Za-z_][\w-]*)\s*(?:\[\s*(\d+)\s*\])?\s*", text)
    allowed = _sweepable(scn)
    if not m or m.group(1) not in scn.parameters:
        word = m.group(1) if m else text
        raise ScenarioError(f"{option}: unknown key {text!r} for scenario {scn.name!r}"
                            f"{_did_you_mean(word, allowed)}; sweepable: {', '.join(allowed)}")
    p = scn.parameters[m.group(1)]
    if p.type == "vector":
        size = p.shape or len(p.default)
        if m.group(2) is None or int(m.group(2)) >= size:
            raise ScenarioError(f"{option}: {text!r} is a vector of {size}; sweep one component, "
                                f"{m.group(1)}[0] to {m.group(1)}[{size - 1}]")
        return _Key(f"{m.group(1)}[{int(m.group(2))}]", m.group(1), int(m.group(2)))
    if p.type not in ("float", "int") or m.group(2) is not None:
        raise ScenarioError(f"{option}: {text!r} is not a numeric parameter ({p.type}); "
                            f"sweepable: {', '.join(allowed)}")
    return _Key(m.group(1), m.group(1))


def _sweepable(scn):
    out = []
    for name, p in scn.parameters.items():
        if p.type in ("float", "int"):
            out.append(name)
        elif p.type == "vector":
            out.append(f"{name}[i]")
    return out


def _parse_axis(scn, base, text, log):
    option = "--log-grid" if log else "--grid"
    key_text, spec = _split_assignment(option, text, "KEY=START:STOP:N")
    key = _parse_key(scn, option, key_text)
    parts = spec.split(":")
    if len(parts) != 3:
        raise ScenarioError(f"{option} {text!r}: expected KEY=START:STOP:N (N values from START to STOP)")
    n = _parse_count(option, text, parts[2])
    from rotframe import limits

    limits.check_rows(n, what=f"{option} {text!r}")
    lo, hi = (_parse_number(scn, key, option, text, s) for s in parts[:2])
    if log and not (lo > 0 and hi > 0):
        raise ScenarioError(f"{option} {text!r}: START and STOP must both be > 0 for a logarithmic grid")
    values = np.geomspace(lo, hi, n) if log else np.linspace(lo, hi, n)
    if key.index is None and scn.parameters[key.param].type == "int":
        values = np.unique(np.round(values))
    _check_value(scn, base, key, option, text, values)
    return Axis(key.text, tuple(float(x) for x in values), log)


def _parse_vary(scn, base, text):
    key_text, spec = _split_assignment("--vary", text, "KEY=normal(MEAN,SD) or KEY=uniform(LO,HI)")
    key = _parse_key(scn, "--vary", key_text)
    m = re.fullmatch(r"\s*([A-Za-z_]\w*)\s*\(\s*([^,()]+?)\s*,\s*([^,()]+?)\s*\)\s*", spec)
    allowed = "normal(MEAN,SD), uniform(LO,HI)"
    if not m:
        raise ScenarioError(f"--vary {text!r}: expected KEY=normal(MEAN,SD) or KEY=uniform(LO,HI)")
    dist = m.group(1)
    if dist not in _DISTRIBUTIONS:
        raise ScenarioError(f"--vary {text!r}: unknown distribution {dist!r}"
                            f"{_did_you_mean(dist, list(_DISTRIBUTIONS))}; allowed: {allowed}")
    a, b = (_parse_number(scn, key, "--vary", text, s) for s in m.groups()[1:])
    if dist == "normal" and b < 0:
        raise ScenarioError(f"--vary {text!r}: SD = {b:g} must be >= 0")
    if dist == "uniform" and b < a:
        raise ScenarioError(f"--vary {text!r}: LO = {a:g} must not exceed HI = {b:g}")
    centre = np.array([a if dist == "normal" else 0.5 * (a + b)])
    _check_value(scn, base, key, "--vary", text, centre)
    return Vary(key.text, dist, a, b)


def _split_assignment(option, text, form):
    if "=" not in text:
        raise ScenarioError(f"{option} {text!r}: expected {form}")
    key, value = text.split("=", 1)
    return key.strip(), value.strip()


def _parse_count(option, text, raw):
    try:
        n = int(raw.strip())
    except ValueError:
        raise ScenarioError(f"{option} {text!r}: N = {raw.strip()!r} must be a whole number >= 1") from None
    if n < 1:
        raise ScenarioError(f"{option} {text!r}: N = {n} must be >= 1")
    return n


def _parse_number(scn, key, option, text, raw):
    """A number (or quantity string) in the parameter's unit; bounds are checked later."""
    from rotframe.app.scenario import Parameter, parse_value

    p = Parameter(name=key.text, default=0.0, unit=scn.parameters[key.param].unit)
    try:
        return float(parse_value(p, raw.strip(), source=f"{option} {text!r}"))
    except ScenarioError as exc:
        raise ScenarioError(str(exc)) from None


def _check_value(scn, base, key, option, text, values):
    """The extreme grid values (or the distribution's centre) must be valid values of the parameter."""
    for x in {float(np.min(values)), float(np.max(values))}:
        try:
            _apply(scn, dict(base), [key], [x])
        except ScenarioError as exc:
            raise ScenarioError(f"{option} {text!r}: {exc}") from None


def _check_shape(axes, varies, samples):
    if axes and (varies or samples is not None):
        raise ScenarioError("sweep: give either --grid/--log-grid or --samples with --vary, not both")
    if samples is not None and samples < 1:
        raise ScenarioError(f"--samples {samples}: must be >= 1")
    if varies and samples is None:
        raise ScenarioError("--vary needs --samples N (the number of Monte Carlo samples)")
    if samples is not None and not varies:
        raise ScenarioError(f"--samples {samples}: give at least one --vary KEY=normal(MEAN,SD)|uniform(LO,HI)")
    if not axes and not varies:
        raise ScenarioError("sweep: nothing to sweep; give --grid KEY=START:STOP:N, --log-grid or --samples N "
                            "with --vary")


def _check_keys_once(spec):
    seen = set()
    for key in spec.keys:
        if key in seen:
            raise ScenarioError(f"sweep: key {key!r} is swept twice")
        seen.add(key)
        param = key.split("[")[0]
        if param in spec.sets and "[" not in key:
            raise ScenarioError(f"sweep: key {key!r} is both fixed by --set and swept")


def _check_method(scn, method):
    if method is None:
        return
    from rotframe import scenes
    from rotframe.particles.integrators import METHOD_NAMES

    allowed = getattr(scenes.get(scn.scene), "METHODS", None) or list(METHOD_NAMES)
    if method not in allowed:
        raise ScenarioError(f"--method {method!r}: allowed for {scn.name}: {', '.join(allowed)}"
                            f"{_did_you_mean(method, list(allowed))}")


def _did_you_mean(word, options):
    from rotframe.app.scenario import _did_you_mean as suggest

    plain = [o.split("[")[0] for o in options]
    return suggest(word, plain) or suggest(word, list(options))


def _apply(scn, values, keys, row):
    """``values`` with the swept keys set to ``row`` (validated); vector components replace one entry."""
    from rotframe.app.scenario import parse_value

    for key, x in zip(keys, row):
        p = scn.parameters[key.param]
        if key.index is None:
            values[key.param] = parse_value(p, float(x))
        else:
            vec = list(values[key.param])
            vec[key.index] = float(x)
            values[key.param] = parse_value(p, vec)
    return values


# ---------------------------------------------------------------------------
# files, parts and merging
# ---------------------------------------------------------------------------


@dataclass
class _Files:
    out: Path
    parts: Path
    plot_stem: Path
    recording: Path

    @classmethod
    def for_spec(cls, spec, out):
        out = Path(out) if out else Path("sweeps") / f"{spec.name}.parquet"
        if out.suffix != ".parquet":
            raise ScenarioError(f"--out {str(out)!r}: the table path must end in .parquet")
        stem = out.with_suffix("")
        return cls(out=out, parts=out.with_name(out.name + ".parts"), plot_stem=stem,
                   recording=stem.with_suffix(".rrd"))


def _prepare(files, meta, resume):
    """Rows already done (``--resume``), or a clean slate; checks they belong to this sweep."""
    files.out.parent.mkdir(parents=True, exist_ok=True)
    if not resume:
        shutil.rmtree(files.parts, ignore_errors=True)
        files.parts.mkdir()
        return set()
    files.parts.mkdir(exist_ok=True)
    done = set()
    for path in _tables(files, include_out=True):
        try:
            table, found = read_table(path)
            table.column("row")
        except (OSError, ValueError, KeyError, TypeError) as exc:  # pyarrow's ArrowInvalid is a ValueError
            raise ScenarioError(f"--resume: {str(path)!r} is not a readable sweep table ({_one_line(exc)[:160]}); "
                                "remove it or run without --resume") from None
        if _fingerprint(found) != _fingerprint(meta):
            raise ScenarioError(f"--resume: {str(path)!r} belongs to a different sweep "
                                f"({_describe_difference(found, meta)}); remove it or run without --resume")
        done.update(table.column("row").to_pylist())
    return done


def _tables(files, include_out):
    paths = sorted(files.parts.glob("part-*.parquet")) if files.parts.is_dir() else []
    if include_out and files.out.is_file():
        paths.append(files.out)
    return paths


def _fingerprint(meta):
    return json.dumps({k: meta.get(k) for k in ("scenario", "sets", "axes", "samples", "vary", "seed", "method")},
                      sort_keys=True)


def _describe_difference(found, meta):
    diff = [k for k in ("scenario", "sets", "axes", "samples", "vary", "seed", "method")
            if json.dumps(found.get(k), sort_keys=True) != json.dumps(meta.get(k), sort_keys=True)]
    return "different " + ", ".join(diff) if diff else "no sweep description"


def _write_part(files, output, keys, meta):
    """One batch's rows (and tracks) to ``<out>.parts/``, atomically."""
    import pyarrow.parquet as pq

    if not output.rows:
        return
    first = min(r["row"] for r in output.rows)
    table = _rows_table(output.rows, keys, meta)
    path = files.parts / f"part-{first:09d}.parquet"
    from rotframe.app.outputs import atomic_path

    with atomic_path(path, "sweep part") as tmp:
        pq.write_table(table, str(tmp))
        if output.tracks:
            _write_tracks(files.parts / f"tracks-{first:09d}.npz", output.tracks)


def _rows_table(rows, keys, meta):
    import pyarrow as pa

    metrics = _ordered_union(r["metrics"] for r in rows)
    theory = _ordered_union(r["theory"] for r in rows)
    cols = {"row": pa.array([r["row"] for r in rows], pa.int64())}
    for i, key in enumerate(keys):
        cols[key] = pa.array([r["values"][i] for r in rows], pa.float64())
    for m in metrics:
        cols[m] = pa.array([r["metrics"].get(m, math.nan) for r in rows], pa.float64())
    for m in theory:
        cols["theory_" + m] = pa.array([r["theory"].get(m, math.nan) for r in rows], pa.float64())
    cols["error"] = pa.array([r["error"] for r in rows], pa.string())
    return pa.table(cols).replace_schema_metadata({_META_KEY: json.dumps(meta)})


def _ordered_union(dicts):
    seen = {}
    for d in dicts:
        for k in d:
            seen.setdefault(k, None)
    return list(seen)


def _merge(files, meta, spec, include_out):
    """Every part (and, resuming, the earlier ``out``) into ``out``: one row per point, sorted, atomically."""
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    tables = [read_table(p)[0] for p in _tables(files, include_out)]
    table = pa.concat_tables([t.replace_schema_metadata(None) for t in tables], promote_options="default")
    table = table.sort_by("row")
    rows = table.column("row").to_numpy()
    first = np.concatenate([[True], rows[1:] != rows[:-1]]) if len(rows) else np.zeros(0, bool)
    table = table.filter(pa.array(first))
    if table.num_rows != spec.n_rows:
        raise RotframeError(f"sweep: {table.num_rows} of {spec.n_rows} rows after merging {files.parts}")
    columns = {}
    for name in _column_order(table, spec):
        col = table.column(name)
        if name == "error":
            col = pc.fill_null(col, "")
        elif name != "row":
            col = pc.fill_null(col.cast(pa.float64()), math.nan)
        columns[name] = col
    merged = pa.table(columns).replace_schema_metadata({_META_KEY: json.dumps(meta)})
    from rotframe.app.outputs import atomic_path

    with atomic_path(files.out, "sweep table") as tmp:
        pq.write_table(merged, str(tmp))
    return merged


def _column_order(table, spec):
    names = table.column_names
    fixed = ["row"] + spec.keys
    metrics = [c for c in names if c not in fixed and c != "error" and not c.startswith("theory_")]
    theory = [c for c in names if c.startswith("theory_")]
    return fixed + metrics + theory + ["error"]


def _metric_columns(table, spec):
    return [c for c in table.column_names
            if c not in ("row", "error") and c not in spec.keys and not c.startswith("theory_")]


def _column(table, name):
    return np.asarray(table.column(name).to_numpy(zero_copy_only=False), dtype=np.float64)


def _write_tracks(path, tracks):
    rows = sorted(tracks)
    lengths = [len(tracks[r][0]) for r in rows]
    from rotframe.app.outputs import atomic_path

    with atomic_path(path, "sweep tracks") as tmp, open(tmp, "wb") as f:
        np.savez(f, rows=np.array(rows, np.int64), offsets=np.concatenate([[0], np.cumsum(lengths)]),
                 t=np.concatenate([tracks[r][0] for r in rows]), pos=np.concatenate([tracks[r][1] for r in rows]))


def _read_tracks(parts):
    tracks = {}
    for path in sorted(Path(parts).glob("tracks-*.npz")):
        with np.load(path) as data:
            rows, off, t, pos = data["rows"], data["offsets"], data["t"], data["pos"]
        for i, row in enumerate(rows):
            tracks[int(row)] = (t[off[i]:off[i + 1]], pos[off[i]:off[i + 1]])
    return tracks


# ---------------------------------------------------------------------------
# execution
# ---------------------------------------------------------------------------


@dataclass
class _Context:
    spec: SweepSpec
    files: _Files
    meta: dict
    scenario_path: str
    path: str
    points: object  # (rows, keys) array of a Monte Carlo sweep; None for a grid (computed per batch)
    track_rows: frozenset

    @classmethod
    def create(cls, spec, files, meta):
        from rotframe import scenes
        from rotframe.app import scenario as sc
        from rotframe.numerics.sampling import decimate

        scn = sc.load(spec.scenario)
        path = "ensemble" if hasattr(scenes.get(scn.scene), "simulate_ensemble") else "runs"
        track_rows = frozenset(int(i) for i in decimate(spec.n_rows, MAX_TRACKS))
        points = None if spec.axes else sweep_points(spec)  # a grid is computed row by row, lazily
        return cls(spec, files, meta, str(scn.path.resolve()), path, points, track_rows)

    def task(self, index, rows):
        rows = np.asarray(rows, dtype=np.int64)
        values = points_of(self.spec, rows) if self.points is None else self.points[rows]
        return BatchTask(index=index, scenario=self.scenario_path, sets=dict(self.spec.sets), keys=self.spec.keys,
                         rows=rows, values=values, method=self.spec.method, path=self.path, limits=_limits_now(),
                         track_rows=self.track_rows.intersection(rows.tolist()))


def _limits_now():
    from rotframe import limits

    return limits.current()


def _compute(ctx, pending, n_done, workers, scheduler, client, batch_rows, on_batch):
    """Run the pending rows batch by batch, writing each part as it finishes; (rows, batches) computed."""
    if len(pending) == 0:
        return 0, 0
    state = {"done": n_done, "computed": 0, "batches": 0}

    def finished(output):
        _write_part(ctx.files, output, ctx.spec.keys, ctx.meta)
        state["done"] += len(output.rows)
        state["computed"] += len(output.rows)
        state["batches"] += 1
        if on_batch is not None:
            on_batch(state["done"], ctx.spec.n_rows)

    try:
        _execute(ctx, pending, workers, scheduler, client, batch_rows, finished)
    except KeyboardInterrupt:
        raise SweepInterrupted(state["done"], ctx.spec.n_rows, str(ctx.files.parts)) from None
    return state["computed"], state["batches"]


def _execute(ctx, pending, workers, scheduler, client, batch_rows, finished):
    own = None
    if client is None and (workers or scheduler):
        own = client = _connect(workers, scheduler)
    try:
        n_workers = max(1, sum(client.nthreads().values())) if client is not None else 1
        if ctx.path == "ensemble":
            size = batch_rows or _ensemble_batch_size(len(pending), n_workers, client is not None)
        else:
            if batch_rows is None:
                pending, batch_rows = _probe(ctx, pending, n_workers, finished)
            size = batch_rows
        tasks = (ctx.task(i, pending[s:s + size]) for i, s in enumerate(range(0, len(pending), size)))
        if client is None:  # one batch generated at a time
            for task in tasks:
                finished(run_batch(task))
        else:
            _execute_dask(client, list(tasks), finished)
    finally:
        if own is not None:
            _close(own)


def _probe(ctx, pending, n_workers, finished):
    """Run the first two rows here to time them; returns the rest and the rows per batch."""
    output = run_batch(ctx.task(0, pending[:2]))
    finished(output)
    rest = pending[2:]
    per_row = max(min(output.seconds) if output.seconds else 0.0, 1e-4)
    total = per_row * len(rest)
    target = min(max(total / (BATCHES_PER_WORKER * n_workers), MIN_BATCH_S), MAX_BATCH_S)
    return rest, max(1, int(math.ceil(target / per_row)))


def _ensemble_batch_size(n, n_workers, distributed):
    if not distributed:
        return ENSEMBLE_BATCH
    size = int(math.ceil(n / (BATCHES_PER_WORKER * n_workers)))
    return int(min(max(size, MIN_ENSEMBLE_BATCH), ENSEMBLE_BATCH))


def _connect(workers, scheduler):
    import logging

    _require("distributed", "--scheduler" if scheduler else "--workers")
    from distributed import Client, LocalCluster

    if scheduler:
        return _client_bounded(Client, check_scheduler(scheduler), scheduler)
    cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True, dashboard_address=None,
                           silence_logs=logging.ERROR)
    return Client(cluster)


def _client_bounded(Client, address, given, timeout=None):
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
            box["client"] = Client(address, timeout=f"{timeout}s", set_as_default=False)
        except BaseException as exc:  # noqa: BLE001 -- reported below
            box["error"] = exc

    with _quiet_dask_logs():
        worker = threading.Thread(target=make, daemon=True, name="rotframe-dask-connect")
        worker.start()
        worker.join(timeout + 2.0)
    if "client" in box:
        return box["client"]
    _quiet_dask_unraisable()
    why = _one_line(box["error"])[:200] if "error" in box else f"no Dask handshake within {timeout:g} s"
    raise ScenarioError(f"--scheduler {given!r}: not a Dask scheduler or not answering ({why})")


def _quiet_dask_unraisable():
    """A half-made Dask client prints a traceback from its ``__del__`` (at exit): keep that one quiet."""
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


def _quiet_dask_logs():
    import contextlib
    import logging

    @contextlib.contextmanager
    def quiet():
        loggers = [logging.getLogger(n) for n in ("distributed", "distributed.comm", "distributed.core",
                                                  "distributed.client", "tornado")]
        levels = [lg.level for lg in loggers]
        for lg in loggers:
            lg.setLevel(logging.CRITICAL)
        try:
            yield
        finally:
            for lg, level in zip(loggers, levels):
                lg.setLevel(level)

    return quiet()


def _require(module, what):
    import importlib.util

    if importlib.util.find_spec(module) is None:
        raise ScenarioError(f"{what} needs the {module!r} package: pip install 'rotframe[sweep]'")


def _close(client):
    cluster = client.cluster if hasattr(client, "cluster") else None
    client.close()
    if cluster is not None:
        cluster.close()


def _execute_dask(client, tasks, finished):
    """Submit every batch (with ``retries``); write each as it completes.

    Dask reschedules the tasks of a lost worker and retries a failed task; a batch that
    still fails is submitted again, and finally computed here, so no row is lost.
    """
    from distributed import as_completed

    futures = {client.submit(run_batch, t, retries=RETRIES, pure=False): (t, 0) for t in tasks}
    queue = as_completed(list(futures))
    try:
        for future in queue:
            task, attempt = futures.pop(future)
            try:
                output = future.result()
            except Exception:  # noqa: BLE001 -- KilledWorker, CommClosedError, a worker's MemoryError ...
                if attempt >= RETRIES:
                    finished(run_batch(task))
                    continue
                again = client.submit(run_batch, task, retries=RETRIES, pure=False)
                futures[again] = (task, attempt + 1)
                queue.add(again)
                continue
            finished(output)
    finally:
        client.cancel(list(futures))


def _ensemble_batch(task, scn, scene, base):
    """All valid rows of the batch through ``scene.simulate_ensemble`` in one call."""
    rows, values_list, where = _start_rows(task), [], []
    keys = [_key_of(k) for k in task.keys]
    params = {k: v for k, v in base.items() if k != "run"}
    for i, row in enumerate(task.values):
        try:
            values_list.append(_apply(scn, dict(params), keys, row))
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
    """One :func:`rotframe.app.runner.run` per row; a failure goes to the row's ``error``."""
    from rotframe.app import runner
    from rotframe.particles.integrators import RunInterrupted

    rows, tracks, seconds = _start_rows(task), {}, []
    keys = [_key_of(k) for k in task.keys]
    for i, row in enumerate(task.values):
        t0 = time.perf_counter()
        try:
            sets = dict(task.sets)
            overrides = _apply(scn, {k: v for k, v in base.items() if k != "run"}, keys, row)
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


def _key_of(text):
    m = re.fullmatch(r"(.+)\[(\d+)\]", text)
    return _Key(text, m.group(1), int(m.group(2))) if m else _Key(text, text)


def _float(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def _error_text(exc):
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _one_line(exc):
    return " ".join(str(exc).split()) or type(exc).__name__


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


# ---------------------------------------------------------------------------
# ensembles
# ---------------------------------------------------------------------------


# ---------------------------------------------------------------------------
# plots and recording
# ---------------------------------------------------------------------------


def _plot_one(ax, x, y, theory, key, metric, spec):
    ok = np.isfinite(x) & np.isfinite(y)
    line = len(spec.axes) == 1
    order = np.argsort(x[ok], kind="stable")
    xs, ys = x[ok][order], y[ok][order]
    if line:
        ax.plot(xs, ys, "o-", ms=3.5, lw=1.2, label="simulated")
    else:
        pick = decimate(len(xs), 20000)
        ax.plot(xs[pick], ys[pick], ".", ms=2.0, alpha=0.5, rasterized=True, label="simulated")
    if theory is not None and np.any(np.isfinite(theory[ok])):
        th = theory[ok][order]
        if line:
            ax.plot(xs, th, "-", color="k", lw=0.9, alpha=0.7, label="theory")
        else:
            pick = decimate(len(xs), 20000)
            ax.plot(xs[pick], th[pick], ".", ms=1.0, color="k", alpha=0.4, rasterized=True, label="theory")
    if key in spec.log_keys:
        ax.set_xscale("log")
    ax.set_xlabel(_label(spec, key))
    ax.set_ylabel(metric)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)


def _histogram(ax, y, metric):
    y = y[np.isfinite(y)]
    bins = int(np.clip(np.sqrt(len(y)), 10, 100))
    ax.hist(y, bins=bins, color="C0", alpha=0.8,
            label=f"mean {np.mean(y):.6g}\nsd {np.std(y, ddof=1) if len(y) > 1 else 0.0:.3g}")
    ax.set_xlabel(metric)
    ax.set_ylabel("runs")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)



def _label(spec, key):
    from rotframe.app import scenario as sc
    param = key.split("[")[0]
    p = sc.load(spec.scenario).parameters.get(param)
    return f"{key} [{p.unit}]" if p is not None and p.unit else key


def _safe(name):
    return re.sub(r"[^\w.-]+", "_", name)


def _write_recording(ctx, table):
    """``<stem>.rrd``: every recorded trajectory at once as Points3D at ``world/ensemble``."""
    tracks = _read_tracks(ctx.files.parts)
    if not tracks:
        return ctx.files.recording if ctx.files.recording.is_file() else None
    from rotframe.app.record import Recording

    rows = sorted(tracks)
    times, pos = _common_time(tracks, rows)
    rec = Recording(ctx.files.recording, f"{ctx.spec.name}-sweep")
    try:
        extent = float(np.ptp(pos.reshape(-1, 3), axis=0).max()) or 1.0
        rec.points("world/ensemble", times, pos, radius=0.004 * extent, trail=False)
        _log_colors(rec, ctx.spec, table, rows)
        rec.text("scenario", _summary_markdown(ctx, table, len(rows)))
        rec.blueprint(series=())
    except BaseException:
        rec.abandon()
        raise
    return rec.finish()


def _common_time(tracks, rows):
    """Positions of every track on one time grid (held at their last sample after they end)."""
    t_end = max(float(tracks[r][0][-1]) for r in rows)
    n = min(MAX_TRACK_SAMPLES, max(len(tracks[r][0]) for r in rows))
    times = np.linspace(0.0, t_end, n)
    pos = np.empty((n, len(rows), 3))
    for j, r in enumerate(rows):
        t, p = tracks[r]
        for c in range(3):
            pos[:, j, c] = np.interp(times, t, p[:, c])
    return times, pos


def _log_colors(rec, spec, table, rows):
    import matplotlib
    import rerun as rr

    key = spec.keys[0]
    x = _column(table, key)[np.asarray(rows)]
    if key in spec.log_keys:
        x = np.log10(x)
    span = np.ptp(x) if len(x) else 0.0
    u = (x - np.min(x)) / span if span > 0 else np.full(len(x), 0.5)
    colors = (np.asarray(matplotlib.colormaps["viridis"](u))[:, :3] * 255).astype(np.uint8)
    rec.rec.log("world/ensemble", rr.Points3D.from_fields(colors=colors), static=True)


def _summary_markdown(ctx, table, n_tracks):
    spec = ctx.spec
    failed = sum(1 for e in table.column("error").to_pylist() if e)
    lines = [f"# Sweep of {spec.name}", "", f"{table.num_rows} runs ({failed} failed), path {ctx.path}; "
             f"{n_tracks} trajectories shown at `world/ensemble`, coloured by `{spec.keys[0]}`.", ""]
    for a in spec.axes:
        lines.append(f"- **{a.key}**: {len(a.values)} {'log-spaced ' if a.log else ''}values "
                     f"{a.values[0]:g} .. {a.values[-1]:g}")
    for v in spec.vary:
        lines.append(f"- **{v.key}** ~ {v.dist}({v.a:g}, {v.b:g}), seed {spec.seed}")
    for k, val in spec.sets.items():
        lines.append(f"- {k} = {val}")
    return "\n".join(lines)


def _cell(value, width, column):
    if column == "error":
        return (value[:60] + "...") if value and len(value) > 63 else (value or "")
    if isinstance(value, float):
        return f"{value:>{width}.6g}"
    return f"{value!s:>{width}}"

