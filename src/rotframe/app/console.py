"""The command-line entry point: Ctrl-C and SIGTERM are handled before anything else is imported.

While rotframe starts (imports, argument parsing) nothing has been computed or
written, so a signal then ends the process at once with one line and the shell's
exit code (130 after Ctrl-C, 143 after SIGTERM) instead of a traceback from an
import. `rotframe.app.cli.main` then installs its own handlers for the command.

The garbage collector, tuned for one command in one process. Importing numba, scipy
and astropy creates about a million objects, none of them garbage, and the collector's
default young-generation threshold (700 allocations) makes it walk them again and
again: `main` raises that threshold to 100000 (measured: 0.07 to 0.17 s, 6 to
10 %, of a warm ``rotframe run``). Cyclic garbage is still collected, only in larger
batches (at most that many objects wait). When the command is over the process only
has to end: `main` freezes the collector's objects (`gc.freeze`) so that
the interpreter's shutdown does not walk every object those libraries created
(measured: 0.2 s of a 1 s ``rotframe run foucault``). Everything the command writes
is written and flushed before it returns; ``atexit`` handlers still run.
"""

import gc
import os
import signal


def _starting(signum, frame):
    verb = "terminated" if signum == signal.SIGTERM else "interrupted"
    try:
        os.write(2, f"rotframe: error: {verb} while starting; nothing was done\n".encode())
    except OSError:
        pass
    os._exit(143 if signum == signal.SIGTERM else 130)


for _sig in (signal.SIGINT, signal.SIGTERM):
    try:
        signal.signal(_sig, _starting)
    except (ValueError, OSError):  # not the main thread
        pass

from rotframe.app.cli import main as _cli_main  # noqa: E402


def main() -> int:
    """Run the command named on the command line (``sys.argv``); returns its exit code.

    The caller is the process's entry point (the ``rotframe`` script, ``python -m
    rotframe``), which exits with the code: the collector is tuned for one command and
    frozen when it is over (see above).
    """
    gc.set_threshold(100_000, 10, 10)  # young collections every 100000 allocations, not 700 (see above)
    code = _cli_main()
    gc.freeze()  # the process ends now: its shutdown need not traverse every live object
    return code
