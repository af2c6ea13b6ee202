"""A text summary of a recording, for machines without a display (``rotframe view PATH --summary``).

Reads the ``.rrd`` back with ``rerun.chunk.RrdReader`` and lists each entity
with its archetype columns, its number of samples and its ``sim_time`` range,
then prints the run summary that the recording carries (the ``scenario``
TextDocument).
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["entities", "describe"]


def entities(path: str | Path) -> dict:
    """``{entity_path: {"rows", "static", "columns", "t_min", "t_max"}}`` of a recording (times in s)."""
    import numpy as np
    from rerun.chunk import RrdReader

    out: dict = {}
    for chunk in RrdReader(str(path)).stream():
        rb = chunk.to_record_batch()
        info = out.setdefault(chunk.entity_path, {"rows": 0, "static": True, "columns": set(),
                                                  "t_min": None, "t_max": None, "text": None})
        cols = [n for n in rb.schema.names if ":" in n and not n.startswith("rerun.")]
        info["columns"] |= set(cols)
        if chunk.is_static:
            for name in cols:
                if name.endswith("TextDocument:text"):
                    info["text"] = rb.column(name).to_pylist()[0]
                    if isinstance(info["text"], list):
                        info["text"] = info["text"][0]
            continue
        info["static"] = False
        info["rows"] += chunk.num_rows
        if "sim_time" in rb.schema.names:
            ns = np.asarray(rb.column("sim_time").cast("int64").to_numpy(zero_copy_only=False))
            if len(ns):
                lo, hi = ns.min() / 1e9, ns.max() / 1e9
                info["t_min"] = lo if info["t_min"] is None else min(info["t_min"], lo)
                info["t_max"] = hi if info["t_max"] is None else max(info["t_max"], hi)
    return out


def describe(path: str | Path) -> str:
    """The text summary of the recording at ``path``."""
    found = entities(path)
    lines = [f"recording {path}: {len(found)} entities (timeline sim_time, seconds)"]
    width = max((len(e) for e in found), default=6)
    text = None
    for entity in sorted(found):
        info = found[entity]
        kinds = ", ".join(sorted({c.split(":")[0] for c in info["columns"]}))
        if info["static"]:
            when = "static"
        else:
            when = f"{info['rows']} samples, t = {info['t_min']:.6g} .. {info['t_max']:.6g} s"
        lines.append(f"  {entity:<{width}}  {kinds:<22}  {when}")
        if info["text"] and entity.rstrip("/").endswith("scenario"):
            text = info["text"]
    if text:
        lines += ["", text]
    return "\n".join(lines)
