"""Ctrl-C and SIGTERM for one command, as a context object.

`InterruptScope` installs a SIGTERM handler that raises
`Terminated` (a `KeyboardInterrupt`, so every ``except
KeyboardInterrupt`` that finalises a partial result handles both) and restores
the previous handlers when the command ends. Nothing outlives the ``with``
block: a second command in the same process starts with a clean scope.

Exit codes follow the shell's convention: 130 after Ctrl-C (SIGINT), 143 after
SIGTERM.
"""

from __future__ import annotations

import os
import signal
import sys

__all__ = ["Terminated", "InterruptScope", "EXIT_SIGINT", "EXIT_SIGTERM"]

EXIT_SIGINT, EXIT_SIGTERM = 130, 143


class Terminated(KeyboardInterrupt):
    """SIGTERM, delivered as an interrupt so that a run stops cleanly where it is."""


class InterruptScope:
    """Handle SIGINT and SIGTERM for the duration of a ``with`` block.

    Attributes
    ----------
    terminated : bool
        True once SIGTERM arrived (else an interrupt was Ctrl-C).
    interrupted : bool
        True once either signal arrived.
    """

    def __init__(self, final: bool = False):
        self.terminated = False
        self.interrupted = False
        #: set once the command's work is over (its files are in place, its output written):
        #: a signal from then on no longer raises into the code that is closing up
        self.closing = False
        #: a whole process's command (the command line, not an in-process call): on leaving the
        #: scope, a late signal ends the process at once with the command's own exit code
        #: instead of a traceback from the interpreter's shutdown or a death by signal
        self.final = final
        self.exit_status = 0
        self._previous = {}
        self._active = False

    # the handlers --------------------------------------------------------------

    def _on_term(self, signum, frame):
        if self.closing:
            return
        self.terminated = True
        self.interrupted = True
        raise Terminated()

    def _on_int(self, signum, frame):
        if self.closing:
            return
        self.interrupted = True
        raise KeyboardInterrupt()

    def _on_late(self, signum, frame):
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except Exception:  # a write the signal cut into: what was written stays written
                pass
        os._exit(self.exit_status)

    def _unraisable(self, info):
        """A signal's exception raised inside a weakref callback or ``__del__`` is swallowed by Python.

        It is not printed (no traceback); the signal is delivered again a moment later, when
        the main thread is most likely back in ordinary code, so that the stop is not lost.
        """
        if isinstance(info.exc_value, KeyboardInterrupt) and not self.closing:
            import threading

            sig = signal.SIGTERM if isinstance(info.exc_value, Terminated) else signal.SIGINT
            timer = threading.Timer(0.05, self._redeliver, (sig,))
            timer.daemon = True
            timer.start()
            return
        if isinstance(info.exc_value, KeyboardInterrupt):
            return
        self._previous_hook(info)

    def _redeliver(self, sig):
        """The signal again, while this scope still handles it (never to a process that has moved on)."""
        if self._active and not self.closing:
            os.kill(os.getpid(), sig)

    def __enter__(self):
        self._active = True
        self._previous_hook = sys.unraisablehook
        sys.unraisablehook = self._unraisable
        # SIGXFSZ (a write beyond ``ulimit -f``) ignored: the write fails with EFBIG instead of killing the
        # process, and the one writer (rotframe.app.outputs.write_atomic) removes its temporary file
        handlers = [(signal.SIGTERM, self._on_term), (signal.SIGINT, self._on_int)]
        if hasattr(signal, "SIGXFSZ"):
            handlers.append((signal.SIGXFSZ, signal.SIG_IGN))
        for sig, handler in handlers:
            try:
                self._previous[sig] = signal.signal(sig, handler)
            except (ValueError, OSError):  # not the main thread: signals stay as they are
                pass
        return self

    def __exit__(self, *exc):
        self._active = False
        if sys.unraisablehook == self._unraisable:
            sys.unraisablehook = self._previous_hook
        for sig, handler in self._previous.items():
            if self.final and sig in (signal.SIGTERM, signal.SIGINT):
                handler = self._on_late
            try:
                signal.signal(sig, handler if handler is not None else signal.SIG_DFL)
            except (ValueError, OSError):
                pass
        self._previous.clear()
        return False

    def note(self, exc: BaseException) -> None:
        """Record that ``exc`` (a KeyboardInterrupt) ended the work."""
        self.interrupted = True
        if isinstance(exc, Terminated):
            self.terminated = True

    @property
    def exit_code(self) -> int:
        """130 (Ctrl-C) or 143 (SIGTERM)."""
        return EXIT_SIGTERM if self.terminated else EXIT_SIGINT

    @property
    def verb(self) -> str:
        """'terminated' or 'interrupted', for the one-line message."""
        return "terminated" if self.terminated else "interrupted"
