"""Output files: checked before any work starts, written atomically, errors in one line.

Every file rotframe writes goes first to a temporary file of its own in the
target folder (a unique name per writer, so two processes writing the same
path never share one) and is renamed to its final name only when complete:
a file under its final name is never truncated and never a mix of two writers.
A write error (full disk, ``ulimit -f``, a folder that vanished) removes the
temporary file and raises `OutputError`, one line naming the path.

The ``check_*`` functions find, before computing starts, an output that could
not be written: a path that is a folder, a folder that is a file, a folder
without write permission.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from rotframe.errors import ScenarioError

__all__ = ["OutputError", "check_output_file", "check_output_dir", "atomic_path", "write_atomic",
           "write_bytes_atomic", "write_text_atomic"]


class OutputError(ScenarioError):
    """An output path cannot be written (checked in advance, or a write error); exit code 2."""


def _first_existing_parent(folder: Path) -> Path:
    p = folder
    while not p.exists():
        if p.parent == p:
            break
        p = p.parent
    return p


def check_output_dir(path, option: str, shown=None) -> Path:
    """``path`` is (or can be made) a writable folder; returns it.

    Raises OutputError when ``path`` or one of its parents is a file, or the nearest
    existing folder is not writable. ``shown`` is the value the user typed (default ``path``).
    """
    folder = Path(path)
    shown = str(path) if shown is None else str(shown)
    if folder.exists() and not folder.is_dir():
        if shown == str(path):
            raise OutputError(f"{option} {shown!r}: exists and is not a folder; allowed: a folder path")
        raise OutputError(f"{option} {shown!r}: {str(folder)!r} is a file, so it cannot hold a folder")
    base = _first_existing_parent(folder)
    if not base.is_dir():
        raise OutputError(f"{option} {shown!r}: {str(base)!r} is a file, so it cannot hold a folder; "
                          "allowed: a path under a folder")
    if not os.access(base, os.W_OK | os.X_OK):
        raise OutputError(f"{option} {shown!r}: folder {str(base)!r} is not writable")
    return folder


def check_output_file(path, option: str, suffix: str | None = None) -> Path:
    """``path`` can be written as a file: not a folder, its folder writable; returns it."""
    text = str(path)
    p = Path(path)
    if text.endswith(("/", os.sep)) or p.is_dir():
        raise OutputError(f"{option} {text!r}: is a folder; allowed: a file path ending in {suffix or 'a name'}")
    if suffix and not text.endswith(suffix):
        raise OutputError(f"{option} {text!r}: the path must end in {suffix}")
    if p.name in ("", ".", "..") or (suffix and p.name == suffix):
        raise OutputError(f"{option} {text!r}: no file name; allowed: e.g. out{suffix or ''}")
    if p.exists() and not os.access(p, os.W_OK) and not os.access(p.parent, os.W_OK):
        raise OutputError(f"{option} {text!r}: exists and cannot be replaced")
    check_output_dir(p.parent if str(p.parent) else Path("."), option, shown=text)
    return p


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
