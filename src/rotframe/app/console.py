"""The command-line entry point: Ctrl-C and SIGTERM are handled before anything else is imported.

While rotframe starts (imports, argument parsing) nothing has been computed or
written, so a signal then ends the process at once with one line and the shell's
exit code (130 after Ctrl-C, 143 after SIGTERM) instead of a traceback from an
import. :func:`rotframe.app.cli.main` then installs its own handlers for the command.

When the command is over the process only has to end: :func:`main` freezes the
garbage collector's objects (:func:`gc.freeze`) so that the interpreter's shutdown
does not walk every object numba, scipy and astropy created (measured: 0.25 s of a
1 s ``rotframe run foucault``). Everything the command writes is written and
flushed before it returns; ``atexit`` handlers still run.
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
    rotframe``), which exits with the code: the collector is frozen first (see above).
    """
    code = _cli_main()
    gc.freeze()  # the process ends now: its shutdown need not traverse every live object
    return code
