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
run, tracks=None)`` integrates the rows in vectorised calls of the engine (every
row a particle of one ``rotframe.simulate`` run, as the tower drop's), one call per fixed
chunk of `ENSEMBLE_CHUNK` rows of the whole sweep;
otherwise each point goes through `rotframe.app.runner.run`. Points are cut
into batches (about 0.2 s to 30 s of work each, at most about four per worker;
whole chunks on the ensemble path); batches run in this process, or as Dask tasks
on a ``LocalCluster`` (``--workers N``) or an existing scheduler (``--scheduler
ADDRESS``, ``--scheduler-file PATH``, ``DASK_SCHEDULER_ADDRESS``). A task carries
the scenario's text and a plugin scene's source, so a worker needs only rotframe.
Every row's numbers are bitwise the same however the rows are cut, wherever they
run and after a resume. The faults of a cluster end in bounded time
(`cluster`). Every finished batch is written at once as a
Parquet part in ``<out>.parts/``; the parts are merged into ``<out>`` at the end,
so an interrupted sweep keeps its finished batches and ``--resume`` computes only
the missing rows, after checking the parts' fingerprint (the spec, the given
points and the scenario's text).

From Python: `rotframe.sweep` (`api`), the same
implementation, returning a pandas DataFrame.

Dask and pyarrow are imported only when needed (``pip install
rotframe[sweep]``). Modules: `spec` (what is swept),
`batch` (one batch of rows), `execute`
(batches here or on Dask), `cluster` (Dask and its faults),
`store` (Parquet parts, merge, resume, lock), `plots` and `recording`; this
module is the ``rotframe sweep`` command.
"""

from __future__ import annotations

import json
import os

from rotframe.app.sweep.batch import MAX_TRACK_SAMPLES, BatchOutput, BatchTask, run_batch
from rotframe.app.sweep.execute import (CONNECT_TIMEOUT_S, MAX_TRACKS, SweepInterrupted, SweepLost, SweepResult,
                                        check_scheduler, check_task_timeout, run_sweep, scheduler_from_env)
from rotframe.app.sweep.plots import write_plots
from rotframe.app.sweep.spec import Axis, SweepSpec, Vary, parse_spec, points_of, sweep_points
from rotframe.app.sweep.store import SweepFiles, check_outputs, metric_columns, read_table
from rotframe.errors import ScenarioError
from rotframe.particles.ensemble import EnsembleRun, group_points, integrate_ensemble  # noqa: F401  (old home)

__all__ = ["Axis", "Vary", "SweepSpec", "SweepResult", "SweepInterrupted", "SweepLost", "parse_spec", "sweep_points", "points_of",
           "run_sweep", "read_table", "run_batch", "BatchTask", "BatchOutput", "write_plots", "check_outputs",
           "check_scheduler", "format_result", "main", "MAX_TRACKS", "MAX_TRACK_SAMPLES", "CONNECT_TIMEOUT_S"]

def main(args) -> int:
    """``rotframe sweep``: run, write, print; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        As built by `rotframe.app.cli` (``name, sets, grid, log_grid, samples, vary, seed, method,
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
    from rotframe.app import messages
    from rotframe.app.options import jsonable, parse_sets
    from rotframe.app.progress import Progress
    from rotframe.app.signals import InterruptScope

    spec = parse_spec(args.name, sets=parse_sets(args.sets), grid=args.grid, log_grid=args.log_grid,
                      samples=args.samples, vary=args.vary, seed=args.seed, method=args.method)
    if args.workers is not None and args.workers < 1:
        raise ScenarioError(f"--workers {args.workers}: must be >= 1")
    most = max(2, 2 * (os.cpu_count() or 1))  # each worker is a process of a few hundred MB
    if args.workers is not None and args.workers > most:
        raise ScenarioError(f"--workers {args.workers}: at most {most} local processes on this machine "
                            f"({os.cpu_count()} CPUs); use --scheduler for a larger cluster")
    check_outputs(spec, args.out, args.resume)
    scheduler_file = getattr(args, "scheduler_file", None)
    task_timeout = getattr(args, "task_timeout", None)
    check_task_timeout(task_timeout)
    scheduler, from_env = args.scheduler, False
    if scheduler is None and scheduler_file is None and args.workers is None:
        scheduler = scheduler_from_env()
        from_env = scheduler is not None
    if scheduler is not None:
        try:
            check_scheduler(scheduler)
        except ScenarioError as exc:
            if not from_env:
                raise
            raise ScenarioError(str(exc).replace("--scheduler", "DASK_SCHEDULER_ADDRESS", 1)) from None
    scope = getattr(args, "scope", None) or InterruptScope()
    progress = Progress("sweep", "rows", enabled=not args.json)
    try:
        result = run_sweep(spec, args.out, workers=args.workers, scheduler=scheduler, resume=args.resume,
                           on_batch=progress.update, scheduler_file=scheduler_file, task_timeout=task_timeout)
    except SweepLost as exc:
        progress.close()
        messages.error(f"sweep: {exc}")
        return 1
    except SweepInterrupted as exc:
        progress.close()
        scope.interrupted = True
        messages.error(f"{scope.verb}: {exc.saved} of {exc.total} rows are saved in {exc.parts}; "
                   "run the same command with --resume to compute the rest")
        return scope.exit_code
    except KeyboardInterrupt as exc:  # while merging, plotting or recording: the parts are still there
        progress.close()
        scope.note(exc)
        messages.error(f"{scope.verb} while writing the results; every computed row is kept in "
                   f"{SweepFiles.for_spec(spec, args.out).parts}; run the same command with --resume to finish")
        return scope.exit_code
    finally:
        progress.close()
    if args.json:
        print(json.dumps(jsonable(result.as_json())))
    else:
        print(format_result(result, spec))
    if result.rows and result.failed == result.rows:
        invalid = sum(1 for e in result.table.column("error").to_pylist()
                      if e.startswith(("ScenarioError", "LimitError", "OutputError")))
        if invalid == result.rows:
            first = result.table.column("error")[0].as_py()
            messages.error(f"every row was invalid input ({first}); the messages are in the error column of "
                       f"{result.out}")
            return messages.EXIT_INPUT
        messages.error(f"every run failed; the messages are in the error column of {result.out}")
        return messages.EXIT_NUMERICAL
    return messages.EXIT_OK


def format_result(result: SweepResult, spec: SweepSpec, head=8, tail=4) -> str:
    """The short text report: the first and last rows of the table, then where things went."""
    table = result.table
    metrics = metric_columns(table, spec)[:4]
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


def _cell(value, width, column):
    if column == "error":
        return (value[:60] + "...") if value and len(value) > 63 else (value or "")
    if isinstance(value, float):
        return f"{value:>{width}.6g}"
    return f"{value!s:>{width}}"
