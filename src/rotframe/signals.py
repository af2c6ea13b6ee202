"""Ctrl-C and SIGTERM for one command, as a context object.

:class:`InterruptScope` installs a SIGTERM handler that raises
:class:`Terminated` (a :class:`KeyboardInterrupt`, so every ``except
KeyboardInterrupt`` that finalises a partial result handles both) and restores
the previous handlers when the command ends. Nothing outlives the ``with``
block: a second command in the same process starts with a clean scope.

Exit codes follow the shell's convention: 130 after Ctrl-C (SIGINT), 143 after
SIGTERM.
"""

from __future__ import annotations

import signal

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

    def __init__(self):
        self.terminated = False
        self.interrupted = False
        self._previous = {}

    # the handlers --------------------------------------------------------------

    def _on_term(self, signum, frame):
        self.terminated = True
        self.interrupted = True
        raise Terminated()

    def _on_int(self, signum, frame):
        self.interrupted = True
        raise KeyboardInterrupt()

    def __enter__(self):
        for sig, handler in ((signal.SIGTERM, self._on_term), (signal.SIGINT, self._on_int)):
            try:
                self._previous[sig] = signal.signal(sig, handler)
            except (ValueError, OSError):  # not the main thread: signals stay as they are
                pass
        return self

    def __exit__(self, *exc):
        for sig, handler in self._previous.items():
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
