"""A sweep's rerun recording: every recorded trajectory at once as Points3D at ``world/ensemble``."""

from __future__ import annotations

import numpy as np

from rotframe.app.sweep.batch import MAX_TRACK_SAMPLES
from rotframe.app.sweep.store import column, read_tracks

__all__ = ["write_recording"]


def write_recording(ctx, table):
    """``<stem>.rrd``: every recorded trajectory at once as Points3D at ``world/ensemble``."""
    tracks = read_tracks(ctx.files.parts)
    if not tracks:
        return ctx.files.recording if ctx.files.recording.is_file() else None
    from rotframe.app.record import Recording

    rows = sorted(tracks)
    times, pos = _common_time(tracks, rows)
    rec = Recording(ctx.files.recording, f"{ctx.spec.name}-sweep")
    try:
        extent = float(np.ptp(pos.reshape(-1, 3), axis=0).max()) or 1.0
        rec.points("world/ensemble", times, pos, radius=0.004 * extent, trail=False)
        _log_colors(rec, ctx.spec, table, rows)
        rec.text("scenario", _summary_markdown(ctx, table, len(rows)))
        rec.blueprint(series=())
    except BaseException:
        rec.abandon()
        raise
    return rec.finish()


def _common_time(tracks, rows):
    """Positions of every track on one time grid (held at their last sample after they end)."""
    t_end = max(float(tracks[r][0][-1]) for r in rows)
    n = min(MAX_TRACK_SAMPLES, max(len(tracks[r][0]) for r in rows))
    times = np.linspace(0.0, t_end, n)
    pos = np.empty((n, len(rows), 3))
    for j, r in enumerate(rows):
        t, p = tracks[r]
        for c in range(3):
            pos[:, j, c] = np.interp(times, t, p[:, c])
    return times, pos


def _log_colors(rec, spec, table, rows):
    import matplotlib
    import rerun as rr

    key = spec.keys[0]
    x = column(table, key)[np.asarray(rows)]
    if key in spec.log_keys:
        x = np.log10(x)
    span = np.ptp(x) if len(x) else 0.0
    u = (x - np.min(x)) / span if span > 0 else np.full(len(x), 0.5)
    colors = (np.asarray(matplotlib.colormaps["viridis"](u))[:, :3] * 255).astype(np.uint8)
    rec.rec.log("world/ensemble", rr.Points3D.from_fields(colors=colors), static=True)


def _summary_markdown(ctx, table, n_tracks):
    spec = ctx.spec
    failed = sum(1 for e in table.column("error").to_pylist() if e)
    lines = [f"# Sweep of {spec.name}", "", f"{table.num_rows} runs ({failed} failed), path {ctx.path}; "
             f"{n_tracks} trajectories shown at `world/ensemble`, coloured by `{spec.keys[0]}`.", ""]
    for a in spec.axes:
        lines.append(f"- **{a.key}**: {len(a.values)} {'log-spaced ' if a.log else ''}values "
                     f"{a.values[0]:g} .. {a.values[-1]:g}")
    for v in spec.vary:
        lines.append(f"- **{v.key}** ~ {v.dist}({v.a:g}, {v.b:g}), seed {spec.seed}")
    for k, val in spec.sets.items():
        lines.append(f"- {k} = {val}")
    return "\n".join(lines)
