"""Output files: checked before any work starts, written atomically, errors in one line.

Every file rotframe writes (through `rotframe.files`, re-exported here) goes first to a temporary file of its own in the
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

import os
from pathlib import Path

from rotframe.files import OutputError, atomic_path, write_atomic, write_bytes_atomic, write_text_atomic

__all__ = ["OutputError", "check_output_file", "check_output_dir", "atomic_path", "write_atomic",
           "write_bytes_atomic", "write_text_atomic"]


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
