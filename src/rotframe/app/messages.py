"""Exit codes and the one-line error message of every command (standard library only).

Exit codes: 0 done; 2 bad input; 3 numerical failure; 1 an internal error
(130 / 143 after Ctrl-C / SIGTERM come from `rotframe.app.signals`).
"""

from __future__ import annotations

import sys

__all__ = ["EXIT_OK", "EXIT_INPUT", "EXIT_NUMERICAL", "EXIT_INTERNAL", "error", "one_line"]

EXIT_OK, EXIT_INPUT, EXIT_NUMERICAL, EXIT_INTERNAL = 0, 2, 3, 1


def error(message: str) -> None:
    """Print ``rotframe: error: MESSAGE`` on stderr."""
    print(f"rotframe: error: {message}", file=sys.stderr)


def one_line(exc) -> str:
    """An exception's message on one line (whitespace collapsed), or its type name if it has none."""
    return " ".join(str(exc).split()) or type(exc).__name__
