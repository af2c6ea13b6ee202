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

import contextlib
import os
import signal
import sys

__all__ = ["Terminated", "InterruptScope", "EXIT_SIGINT", "EXIT_SIGTERM", "deferred"]

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
        #: inside `deferred` blocks: a signal is held (``pending``) until the block ends
        self.deferring = 0
        self.pending = None
        self._previous = {}
        self._active = False

    # the handlers --------------------------------------------------------------

    def _on_term(self, signum, frame):
        if self.closing:
            return
        self.terminated = True
        self.interrupted = True
        if self.deferring:
            self.pending = Terminated
            return
        raise Terminated()

    def _on_int(self, signum, frame):
        if self.closing:
            return
        self.interrupted = True
        if self.deferring:
            self.pending = self.pending or KeyboardInterrupt
            return
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
        _SCOPES.append(self)
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
        if self in _SCOPES:
            _SCOPES.remove(self)
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


#: the scopes in force in this process, innermost last
_SCOPES: list = []


class _Held:
    """What a `deferred` block holds: the signal's exception, raised when the block ends, with ``attached`` on it."""

    def __init__(self, scope=None):
        self.attached = {}
        self._scope = scope

    @property
    def signalled(self) -> bool:
        """A signal arrived during the block (it will be raised when the block ends)."""
        return self._scope is not None and self._scope.pending is not None

    def attach(self, **values):
        """Attributes for the held exception (``recording=path``: the file the block wrote)."""
        self.attached.update(values)


@contextlib.contextmanager
def deferred():
    """Hold Ctrl-C and SIGTERM while the block runs; raise the held one when it ends.

    For work that must not be cut in the middle, whatever the signal: writing a recording (a
    file cut short by a signal is unreadable, and the run it holds is lost). Every signal during
    the block is held, a second SIGTERM too, and the exception it would have raised is raised
    when the block ends, with the attributes given to `_Held.attach`. Outside an
    `InterruptScope` (a script's own call), the block runs as it is.
    """
    scope = _SCOPES[-1] if _SCOPES else None
    held = _Held(scope)
    if scope is None:
        yield held
        return
    scope.deferring += 1
    try:
        yield held
    finally:
        scope.deferring -= 1
        if not scope.deferring and scope.pending is not None:
            exc = scope.pending()
            scope.pending = None
            for key, value in held.attached.items():
                setattr(exc, key, value)
            raise exc
