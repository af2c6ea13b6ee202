"""Where a sweep's rows live: Parquet parts, the merged table, resume and the lock on ``out``.

Every finished batch is written at once, atomically, as ``<out>.parts/part-<row>.parquet``
(with its recorded trajectories in ``tracks-<row>.npz``); the parts are merged into
``<out>`` at the end, so an interrupted sweep keeps its finished batches and
``--resume`` computes only the missing rows. pyarrow is imported only here, when needed.
"""

from __future__ import annotations

import json
import math
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rotframe.app.messages import one_line as _one_line
from rotframe.errors import RotframeError, ScenarioError

__all__ = ["META_KEY", "SweepFiles", "check_outputs", "exclusive", "read_table", "prepare", "write_part",
           "merge", "metric_columns", "column", "read_tracks"]


META_KEY = b"rotframe.app.sweep"


@dataclass
class SweepFiles:
    out: Path
    parts: Path
    plot_stem: Path
    recording: Path

    @classmethod
    def for_spec(cls, spec, out):
        out = Path(out) if out else Path("sweeps") / f"{spec.name}.parquet"
        if out.suffix != ".parquet":
            raise ScenarioError(f"--out {str(out)!r}: the table path must end in .parquet")
        stem = out.with_suffix("")
        return cls(out=out, parts=out.with_name(out.name + ".parts"), plot_stem=stem,
                   recording=stem.with_suffix(".rrd"))


def check_outputs(spec, out, resume=False):
    """Every path the sweep will write can be written: checked before any computing starts."""
    from rotframe.app.outputs import check_output_dir, check_output_file

    files = SweepFiles.for_spec(spec, out)
    option = "--out" if out else "sweep output"
    check_output_file(files.out, option, ".parquet")
    if files.parts.exists() and not files.parts.is_dir():
        raise ScenarioError(f"{option} {str(files.out)!r}: {str(files.parts)!r} (where finished batches go) "
                            "is a file, not a folder; remove it or choose another --out")
    check_output_dir(files.parts, option, shown=files.out)
    if files.recording.is_dir():
        raise ScenarioError(f"{option} {str(files.out)!r}: {str(files.recording)!r} (the recording) is a folder")
    return files


def exclusive(files):
    """Hold ``.<out>.lock`` beside the table: a second sweep into the same ``out`` is refused, not interleaved."""
    import contextlib

    @contextlib.contextmanager
    def lock():
        try:
            import fcntl
        except ImportError:  # not POSIX: no lock
            yield
            return
        from rotframe.app.outputs import OutputError

        try:
            files.out.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(files.out.parent / f".{files.out.name}.lock", os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise OutputError(f"--out {str(files.out)!r}: cannot create a lock beside it ({exc.strerror})") from None
        try:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                raise OutputError(f"--out {str(files.out)!r}: another sweep is writing it now; wait for it or "
                                  "choose another --out") from None
            yield
        finally:
            os.close(fd)

    return lock()


def read_table(path):
    """A sweep's Parquet table (pyarrow) and its description: ``(table, spec dict)``."""
    import pyarrow.parquet as pq

    table = pq.read_table(str(path))
    meta = (table.schema.metadata or {}).get(META_KEY)
    return table, (json.loads(meta) if meta else {})


def prepare(files, meta, resume):
    """Rows already done (``--resume``), or a clean slate; checks they belong to this sweep."""
    files.out.parent.mkdir(parents=True, exist_ok=True)
    if not resume:
        shutil.rmtree(files.parts, ignore_errors=True)
        files.parts.mkdir()
        return set()
    files.parts.mkdir(exist_ok=True)
    done = set()
    for path in _tables(files, include_out=True):
        try:
            table, found = read_table(path)
            table.column("row")
        except (OSError, ValueError, KeyError, TypeError) as exc:  # pyarrow's ArrowInvalid is a ValueError
            raise ScenarioError(f"--resume: {str(path)!r} is not a readable sweep table ({_one_line(exc)[:160]}); "
                                "remove it or run without --resume") from None
        if _fingerprint(found) != _fingerprint(meta):
            raise ScenarioError(f"--resume: {str(path)!r} belongs to a different sweep "
                                f"({_describe_difference(found, meta)}); remove it or run without --resume")
        done.update(table.column("row").to_pylist())
    return done


def _tables(files, include_out):
    paths = sorted(files.parts.glob("part-*.parquet")) if files.parts.is_dir() else []
    if include_out and files.out.is_file():
        paths.append(files.out)
    return paths


#: what makes two sweeps the same: the spec, the given points' digest and the scenario's text (and plugin source)
_SAME = ("scenario", "sets", "axes", "samples", "vary", "seed", "method", "points", "scenario_sha256")


def _fingerprint(meta):
    return json.dumps({k: meta.get(k) for k in _SAME}, sort_keys=True)


def _describe_difference(found, meta):
    diff = [k for k in _SAME if json.dumps(found.get(k), sort_keys=True) != json.dumps(meta.get(k), sort_keys=True)]
    if diff == ["scenario_sha256"]:
        return ("the scenario file, its plugin scene or rotframe's version changed since its rows were computed"
                if found.get("scenario_sha256") else "it has no fingerprint of the scenario's text (an older rotframe)")
    words = {"points": "given points", "scenario_sha256": "scenario text"}
    return "different " + ", ".join(words.get(k, k) for k in diff) if diff else "no sweep description"


def write_part(files, output, keys, meta):
    """One batch's rows (and tracks) to ``<out>.parts/``, atomically."""
    import pyarrow.parquet as pq

    if not len(output.rows):
        return
    first = int(np.min(output.rows))
    table = _rows_table(output, keys, meta)
    path = files.parts / f"part-{first:09d}.parquet"
    from rotframe.app.outputs import atomic_path

    with atomic_path(path, "sweep part") as tmp:
        pq.write_table(table, str(tmp))
        if output.tracks:
            _write_tracks(files.parts / f"tracks-{first:09d}.npz", output.tracks)


def _rows_table(output, keys, meta):
    """A batch's columns (`rotframe.app.sweep.batch.BatchOutput`) as an Arrow table."""
    import pyarrow as pa

    n = len(output.rows)
    cols = {"row": pa.array(np.asarray(output.rows, np.int64), pa.int64())}
    values = np.asarray(output.values, np.float64).reshape(n, len(keys))
    for i, key in enumerate(keys):
        cols[key] = pa.array(values[:, i], pa.float64())
    for m, col in output.metrics.items():
        cols[m] = pa.array(np.asarray(col, np.float64), pa.float64())
    for m, col in output.theory.items():
        cols["theory_" + m] = pa.array(np.asarray(col, np.float64), pa.float64())
    cols["error"] = pa.array(list(output.errors), pa.string())
    return pa.table(cols).replace_schema_metadata({META_KEY: json.dumps(meta)})


def merge(files, meta, spec, include_out):
    """Every part (and, resuming, the earlier ``out``) into ``out``: one row per point, sorted, atomically."""
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    tables = [read_table(p)[0] for p in _tables(files, include_out)]
    table = pa.concat_tables([t.replace_schema_metadata(None) for t in tables], promote_options="default")
    table = table.sort_by("row")
    rows = table.column("row").to_numpy()
    first = np.concatenate([[True], rows[1:] != rows[:-1]]) if len(rows) else np.zeros(0, bool)
    table = table.filter(pa.array(first))
    if table.num_rows != spec.n_rows:
        raise RotframeError(f"sweep: {table.num_rows} of {spec.n_rows} rows after merging {files.parts}")
    columns = {}
    for name in _column_order(table, spec):
        col = table.column(name)
        if name == "error":
            col = pc.fill_null(col, "")
        elif name != "row":
            col = pc.fill_null(col.cast(pa.float64()), math.nan)
        columns[name] = col
    merged = pa.table(columns).replace_schema_metadata({META_KEY: json.dumps(meta)})
    from rotframe.app.outputs import atomic_path

    with atomic_path(files.out, "sweep table") as tmp:
        pq.write_table(merged, str(tmp))
    return merged


def _column_order(table, spec):
    names = table.column_names
    fixed = ["row"] + spec.keys
    metrics = [c for c in names if c not in fixed and c != "error" and not c.startswith("theory_")]
    theory = [c for c in names if c.startswith("theory_")]
    return fixed + metrics + theory + ["error"]


def metric_columns(table, spec):
    return [c for c in table.column_names
            if c not in ("row", "error") and c not in spec.keys and not c.startswith("theory_")]


def column(table, name):
    return np.asarray(table.column(name).to_numpy(zero_copy_only=False), dtype=np.float64)


def _write_tracks(path, tracks):
    rows = sorted(tracks)
    lengths = [len(tracks[r][0]) for r in rows]
    from rotframe.app.outputs import atomic_path

    with atomic_path(path, "sweep tracks") as tmp, open(tmp, "wb") as f:
        np.savez(f, rows=np.array(rows, np.int64), offsets=np.concatenate([[0], np.cumsum(lengths)]),
                 t=np.concatenate([tracks[r][0] for r in rows]), pos=np.concatenate([tracks[r][1] for r in rows]))


def read_tracks(parts):
    tracks = {}
    for path in sorted(Path(parts).glob("tracks-*.npz")):
        with np.load(path) as data:
            rows, off, t, pos = data["rows"], data["offsets"], data["t"], data["pos"]
        for i, row in enumerate(rows):
            tracks[int(row)] = (t[off[i]:off[i + 1]], pos[off[i]:off[i + 1]])
    return tracks
