"""The one writer of files: a unique temporary file beside the target, renamed when whole.

Every file rotframe writes, from the command line's outputs to the compiled-driver cache of
`rotframe.problem.codegen`, goes first to a temporary file of its own in the target folder (a
unique name per writer, so two processes writing the same path never share one) and is renamed
to its final name only when complete: a file under its final name is never truncated and never
a mix of two writers. A write error (full disk, ``ulimit -f``, a folder that vanished) removes the
temporary file and raises `OutputError`, one line naming the path. Its checks before the work
are `rotframe.app.outputs`'.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from rotframe.errors import ScenarioError

__all__ = ["OutputError", "atomic_path", "write_atomic", "write_bytes_atomic", "write_text_atomic"]


class OutputError(ScenarioError):
    """An output path cannot be written (checked in advance, or a write error); exit code 2."""


def _one_line(exc: Exception) -> str:
    return getattr(exc, "strerror", None) or " ".join(str(exc).split()) or type(exc).__name__


@contextlib.contextmanager
def atomic_path(final, what: str = "file"):
    """Yield a unique temporary path beside ``final``; rename it to ``final`` if the block succeeds.

    On any exception (an OSError becomes `OutputError`) the temporary file is removed.
    """
    final = Path(final)
    try:
        final.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=str(final.parent), prefix=f".{final.name}.", suffix=".tmp")
        os.close(fd)
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        raise OutputError(f"cannot write the {what} {str(final)!r}: {_one_line(exc)}") from None
    try:
        yield Path(tmp)
        _publish(tmp, final)
    except OSError as exc:
        _unlink(tmp)
        raise OutputError(f"cannot write the {what} {str(final)!r}: {_one_line(exc)}") from None
    except BaseException:
        _unlink(tmp)
        raise


def write_atomic(final, write, what: str = "file") -> Path:
    """The one door for every file rotframe writes: ``write(f)`` fills an open binary file, then a rename.

    ``write`` receives a file object opened ``"wb"`` on a unique temporary file in
    ``final``'s folder (``np.savez(f, ...)``, ``fig.savefig(f, format="png")``,
    ``pq.write_table(table, f)``, ``f.write(data)``). Only when it returns is the file
    flushed, synced and renamed to ``final``; on any failure the temporary file is
    removed, an earlier file under ``final`` is left as it was, and an OSError (full
    disk, ``ulimit -f``, no permission, a folder in the way) becomes `OutputError`,
    one line naming the path (a [`RotframeError`][rotframe.errors.RotframeError], exit 2).
    Two writers of the same path at once each publish a whole file of their own.

    Returns
    -------
    Path
        ``final``.
    """
    with atomic_path(final, what) as tmp:
        with open(tmp, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
    return Path(final)


def write_bytes_atomic(final, data: bytes, what: str = "file") -> Path:
    """Write ``data`` to ``final`` through `write_atomic`."""

    def write(f):
        view = memoryview(data)
        for start in range(0, len(view), 1 << 22):  # 4 MiB at a time: a signal is handled between writes
            f.write(view[start:start + (1 << 22)])

    return write_atomic(final, write, what)


def write_text_atomic(final, text: str, what: str = "file") -> Path:
    """Write ``text`` (UTF-8) to ``final`` through `write_atomic`."""
    return write_bytes_atomic(final, text.encode("utf-8"), what)


def _publish(tmp, final):
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the usual permissions
    os.replace(tmp, final)


def _unlink(path):
    try:
        os.unlink(path)
    except OSError:
        pass
