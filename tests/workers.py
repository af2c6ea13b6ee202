"""Shared by the Dask sweep tests: a worker killed in the middle of a sweep, as a real cluster loses one."""

from __future__ import annotations

import os
import signal


def busy_worker_killer(client, pids):
    """An ``on_batch`` callback that SIGKILLs one worker (a busy one where it can tell) after the first batch.

    ``pids`` maps worker addresses to their process ids (``client.run(os.getpid)``). The callback's
    ``killed`` list holds the victim's address once it has struck.
    """
    killed = []

    def kill(done, total):
        if killed:
            return
        busy = [w for w, keys in client.processing().items() if keys and w in pids]
        victim = (busy or sorted(pids))[0]
        os.kill(pids[victim], signal.SIGKILL)
        killed.append(victim)

    kill.killed = killed
    return kill
