"""A sweep's batches on Dask, and the faults of a cluster, each ended in bounded time.

Batches are submitted a few more than the cluster has threads, and their futures are
polled (no Dask default client is needed, and Ctrl-C or SIGTERM is seen within
`POLL_S`). What can go wrong, and what the sweep does:

- A worker dies (killed, out of memory): the scheduler runs its tasks elsewhere. A
  batch whose workers die again and again (Dask's ``distributed.scheduler.allowed-failures``,
  3 by default) comes back as ``KilledWorker``; a batch of single runs is then split in
  halves and tried again on the cluster, down to the row that kills, and that row is
  failed with the cause in its ``error``. Nothing is ever computed in this process
  instead.
- A batch raises on its worker (a plugin the worker cannot import, a MemoryError): its
  rows are failed with the worker's exception.
- A batch runs longer than ``task_timeout`` seconds (counted from when a worker thread
  was free for it): its rows are failed with a TimeoutError and the sweep goes on.
- No batch finishes for `STALL_S` seconds: a line on stderr says so (and how many
  workers the scheduler has); the sweep keeps waiting.
- The scheduler goes away: after `LOST_S` seconds without it the sweep ends with
  `SweepLost` (exit 1, the finished batches kept for
  ``--resume``).
"""

from __future__ import annotations

import sys
import threading
import time
from collections import deque

from rotframe.errors import RotframeError

__all__ = ["SweepLost", "run_on_dask", "close_bounded", "quiet_dask_logs", "silence_late_callbacks", "POLL_S",
           "LOST_S", "STALL_S"]

#: seconds between looks at the futures
POLL_S = 0.02
#: seconds without a scheduler before the sweep gives up
LOST_S = 10.0
#: seconds without a finished batch before the sweep says it is stalled (again each such interval)
STALL_S = 60.0
#: seconds allowed to fetch a finished batch's rows from its worker
FETCH_S = 60.0


class SweepLost(RotframeError):
    """The Dask scheduler went away during a sweep; every finished batch is kept in ``parts``."""

    def __init__(self, why: str, saved: int = 0, total: int = 0, parts: str = ""):
        super().__init__(f"{why}; {saved} of {total} rows are saved in {parts}; run the same command with "
                         "--resume once the scheduler is back")
        self.why, self.saved, self.total, self.parts = why, saved, total, parts


def run_on_dask(client, tasks, finished, *, split=False, task_timeout=None):
    """Run ``tasks`` on ``client``'s cluster, calling ``finished(output)`` for each in this thread.

    Parameters
    ----------
    client : distributed.Client
    tasks : list of BatchTask
    finished : callable(BatchOutput)
    split : bool
        A batch that keeps killing its workers is split in halves (rows computed one by
        one, so the cut changes no number) down to the row that kills.
    task_timeout : float, optional

    Raises
    ------
    SweepLost
        The scheduler went away.
    KeyboardInterrupt
        Ctrl-C / SIGTERM (the unfinished batches are cancelled, in bounded time).
    """
    from rotframe.app.sweep.batch import run_batch

    queue = deque(tasks)
    inflight = {}  # future -> [task, started (monotonic) or None]
    order = deque()  # futures in submission order
    last = time.monotonic()
    stall_said = last
    lost_since = None
    threads, counted = 1, 0.0
    try:
        while queue or inflight:
            if time.monotonic() - counted > 1.0 and getattr(client, "status", "running") == "running":
                threads, counted = _threads(client), time.monotonic()  # a call to the scheduler: once a second
            while queue and len(inflight) < max(2, 2 * threads):
                task = queue.popleft()
                future = client.submit(run_batch, task, pure=False, retries=0,
                                       key=f"rotframe-sweep-{task.index}-{int(task.rows[0])}-{len(task.rows)}-"
                                           f"{time.monotonic_ns()}")
                inflight[future] = [task, None]
                order.append(future)
            now = time.monotonic()
            _start_clocks(order, inflight, threads, now)
            progressed = False
            for future in list(order):
                status = future.status
                if status == "pending":
                    continue
                task = inflight[future][0]
                if status not in ("finished", "error"):  # cancelled or lost: the scheduler forgot it
                    if getattr(client, "status", "running") == "running":  # (a lost connection is checked below)
                        _forget(future, inflight, order)
                        again = _forgotten(task, finished)
                        if again is not None:
                            queue.appendleft(again)
                    continue
                output, exc = _outcome(client, future)
                _forget(future, inflight, order)
                if exc is None:
                    finished(output)
                else:
                    queue.extendleft(reversed(_after_failure(task, exc, split, finished)))
                progressed = True
            if progressed:
                last = stall_said = time.monotonic()
            lost_since = _check_connection(client, lost_since)
            _check_timeouts(order, inflight, task_timeout, finished)
            if time.monotonic() - stall_said > STALL_S:
                stall_said = time.monotonic()
                _say_stalled(client, len(inflight), time.monotonic() - last)
            time.sleep(POLL_S)
    finally:
        if inflight:
            _bounded(lambda: client.cancel(list(inflight), force=True), 5.0)


def silence_late_callbacks():
    """Keep tornado's callback log quiet for good after an interrupt.

    A Ctrl-C or SIGTERM that lands inside a Dask call (``client.sync``) makes distributed
    schedule a ``cancel`` callback on its event loop; that callback can run after this
    sweep has reported the interrupt, and distributed 2026.8 logs it as a ``NameError``
    traceback on ``tornado.application``. The sweep has said what happened and how to resume.
    """
    import logging

    logging.getLogger("tornado.application").setLevel(logging.CRITICAL)


def _threads(client):
    try:
        return max(1, sum(client.nthreads().values()))
    except Exception:  # noqa: BLE001 -- a client that lost its scheduler: the connection check decides
        return 1


def _start_clocks(order, inflight, threads, now):
    """The oldest ``threads`` unfinished batches are running (Dask runs them first): start their clocks."""
    for k, future in enumerate(order):
        if k >= threads:
            break
        if inflight[future][1] is None:
            inflight[future][1] = now


def _forget(future, inflight, order):
    inflight.pop(future, None)
    try:
        order.remove(future)
    except ValueError:
        pass


def _outcome(client, future):
    """(output, None) of a finished batch, or (None, the exception it raised on the cluster).

    A connection that failed while the rows were on their way is a lost scheduler, not a failed batch.
    """
    try:
        return future.result(timeout=FETCH_S), None
    except Exception as exc:  # noqa: BLE001 -- KilledWorker, a worker's exception, or a lost connection
        lost = type(exc).__name__ in ("CommClosedError", "CancelledError", "TimeoutError", "FutureCancelledError") \
            or isinstance(exc, (OSError, TimeoutError)) or getattr(client, "status", "running") != "running"
        if lost:
            raise SweepLost(f"lost the Dask scheduler while fetching a finished batch ({_why(exc)})") from None
        return None, exc


def _after_failure(task, exc, split, finished):
    """What to do with a batch that failed on the cluster: halves to run again, or failed rows (returned [])."""
    from rotframe.app.sweep.batch import failed_output

    killed = type(exc).__name__ == "KilledWorker"
    if killed and split and len(task.rows) > 1:
        half = len(task.rows) // 2
        return [_sub(task, slice(0, half)), _sub(task, slice(half, None))]
    if killed:
        why = ("KilledWorker: every worker that ran this batch died (a crash or running out of memory?); "
               "the batch was not run anywhere else")
    else:
        why = f"{type(exc).__name__} on a Dask worker: {_why(exc)}"
    finished(failed_output(task, why))
    return []


def _forgotten(task, finished, most=3):
    """A batch the scheduler forgot (a scheduler restarted under a running client): again, at most ``most`` times.

    Returns the task to submit again, or None after its rows were failed.
    """
    from dataclasses import replace

    from rotframe.app.sweep.batch import failed_output

    tries = getattr(task, "_forgotten", 0) + 1
    if tries > most:
        finished(failed_output(task, f"CancelledError: the Dask scheduler forgot this batch {most} times"))
        return None
    again = replace(task)
    again._forgotten = tries
    return again


def _sub(task, part):
    from dataclasses import replace

    rows = task.rows[part]
    return replace(task, rows=rows, values=task.values[part],
                   track_rows=frozenset(task.track_rows.intersection(rows.tolist())))


def _check_connection(client, lost_since):
    """None while the scheduler is there; the time it went; SweepLost after `LOST_S`."""
    status = getattr(client, "status", "running")
    if status == "running":
        return None
    now = time.monotonic()
    if lost_since is None:
        return now
    if status in ("closed", "closing") or now - lost_since > LOST_S:
        raise SweepLost(f"lost the Dask scheduler (client {status} for {now - lost_since:.0f} s)")
    return lost_since


def _check_timeouts(order, inflight, task_timeout, finished):
    if not task_timeout:
        return
    from rotframe.app.sweep.batch import failed_output

    now = time.monotonic()
    for future in list(order):
        task, started = inflight[future]
        if started is not None and now - started > task_timeout:
            _forget(future, inflight, order)
            _bounded(lambda f=future: f.cancel(force=True), 5.0)
            finished(failed_output(task, f"TimeoutError: the batch ran longer than --task-timeout {task_timeout:g} s "
                                         "on a Dask worker (its worker thread may still be busy)"))


def _say_stalled(client, running, quiet_s):
    try:
        workers = len(client.scheduler_info().get("workers", {}))
    except Exception:  # noqa: BLE001
        workers = "?"
    sys.stderr.write(f"sweep: no batch has finished for {quiet_s:.0f} s ({running} waiting, {workers} workers "
                     "on the scheduler); still waiting (Ctrl-C stops, --resume continues)\n")
    sys.stderr.flush()


def _why(exc):
    from rotframe.app.messages import one_line

    return one_line(exc)[:200]


def _bounded(fn, seconds):
    """Call ``fn`` in a daemon thread, waiting at most ``seconds`` (a Dask call to a scheduler that is gone)."""
    worker = threading.Thread(target=lambda: _call(fn), daemon=True, name="rotframe-dask-cleanup")
    worker.start()
    worker.join(seconds)


def _call(fn):
    try:
        return fn()
    except BaseException:  # noqa: BLE001 -- cleanup only
        return None


def close_bounded(client, seconds=10.0):
    """Close a client this sweep made (and its LocalCluster), within ``seconds`` whatever the scheduler does."""
    cluster = getattr(client, "cluster", None)

    def close():
        with quiet_dask_logs():
            client.close(timeout=seconds / 2)
            if cluster is not None:
                cluster.close(timeout=seconds / 2)

    _bounded(close, seconds)


def quiet_dask_logs():
    """A context in which Dask's and tornado's loggers print nothing (the sweep reports faults itself)."""
    import contextlib
    import logging

    @contextlib.contextmanager
    def quiet():
        loggers = [logging.getLogger(n) for n in ("distributed", "distributed.comm", "distributed.core",
                                                  "distributed.client", "distributed.node", "tornado",
                                                  "tornado.application")]
        levels = [lg.level for lg in loggers]
        for lg in loggers:
            lg.setLevel(logging.CRITICAL)
        try:
            yield
        finally:
            for lg, level in zip(loggers, levels):
                lg.setLevel(level)

    return quiet()


