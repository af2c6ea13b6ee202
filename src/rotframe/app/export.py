"""Write a run's trajectory to a file: ``.npz``, ``.csv`` or ``.parquet``.

* ``.npz`` (numpy): the arrays in their natural shapes (``times`` (n,);
  ``r``, ``v`` (n, N, 3) for particles; ``L`` (n, 3), ``q`` (n, 4) for bodies),
  plus ``units`` and ``summary`` as JSON strings.
* ``.csv``: the long table of [`rotframe.app.api.TrajectoryArrays.columns`][rotframe.app.api.TrajectoryArrays.columns]
  (one row per sample and particle), units in the column names; the first
  line is a plain header of the column names, so ``pandas.read_csv(path)``
  and ``numpy.genfromtxt(path, delimiter=",", names=True)`` read it as it
  is. (The frame and the summary live in ``.npz`` and ``.parquet``.)
* ``.parquet`` (needs pyarrow, the ``export`` extra): the same table, with the
  units and the summary in the file's metadata.

Read back with ``numpy.load``, ``pandas.read_csv``, ``numpy.genfromtxt(...,
names=True)`` or ``pyarrow.parquet.read_table``/``pandas.read_parquet``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Mapping

from rotframe.errors import ScenarioError

__all__ = ["FORMATS", "write_trajectory"]

FORMATS = (".npz", ".csv", ".parquet")


def write_trajectory(traj, path: str | Path, summary: Mapping[str, Any] | None = None) -> Path:
    """Write ``traj`` (a [`rotframe.app.api.TrajectoryArrays`][rotframe.app.api.TrajectoryArrays]) to ``path``; the suffix picks the format.

    Parameters
    ----------
    traj : TrajectoryArrays
        The samples.
    path : path-like
        Ends in ``.npz``, ``.csv`` or ``.parquet``. Written through
        `rotframe.app.outputs.write_atomic` (a temporary file of its own, then a
        rename), so an existing file is only replaced by a complete one; a write error
        is an `OutputError`.
    summary : mapping, optional
        The run summary (JSON-ready) to store beside the arrays.
    """
    import numpy as np

    from rotframe.app.outputs import write_atomic

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ScenarioError(f"--export {str(path)!r}: the file must end in {', '.join(FORMATS)}")
    units = dict(traj.units)
    meta = {"scenario": (summary or {}).get("scenario", ""), "frame": traj.frame, "units": units}
    if suffix == ".npz":
        arrays = {"times": traj.times}
        for name in ("r", "v", "L", "q"):
            value = getattr(traj, name)
            if value is not None:
                arrays[name] = value

        def write(f):
            np.savez(f, **arrays, units=json.dumps(units), frame=traj.frame, summary=json.dumps(dict(summary or {})))
    else:
        cols = traj.columns()
        if suffix == ".csv":
            names = list(cols)
            table = np.column_stack([np.asarray(cols[k], dtype=float) for k in names])
            fmt = ["%d" if k == "particle" else "%.17g" for k in names]
            # a plain header line (no "# "): pandas.read_csv and spreadsheets take it as the column names

            def write(f):
                np.savetxt(f, table, delimiter=",", fmt=fmt, header=",".join(names), comments="")
        else:
            pa, pq = _pyarrow(path)
            table = pa.table({k: np.asarray(v) for k, v in cols.items()})
            table = table.replace_schema_metadata({"rotframe": json.dumps(dict(meta, summary=dict(summary or {})))})

            def write(f):
                pq.write_table(table, f)
    return write_atomic(path, write, what="export")


def _pyarrow(path):
    """(pyarrow, pyarrow.parquet), or a one-line ScenarioError naming the ``export`` extra.

    Any failure to import (missing, or a broken install raising something other than
    ImportError) is reported the same way.
    """
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except Exception as exc:  # noqa: BLE001 -- a broken install raises anything; the remedy is the same
        why = "is not installed" if isinstance(exc, ImportError) else \
            f"failed to import ({type(exc).__name__}: {str(exc).splitlines()[0][:120] if str(exc) else ''})"
        raise ScenarioError(f"--export {str(path)!r}: parquet needs pyarrow, which {why}; install the export "
                            'extra (python -m pip install "rotframe[export]"); .npz and .csv need nothing') from None
    return pa, pq
