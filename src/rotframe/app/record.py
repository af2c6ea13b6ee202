"""Recordings of runs in rerun's ``.rrd`` format (layout described in README.md, Recordings).

* Timeline ``sim_time`` (a duration, integer nanoseconds rounded here, since
  ``TimeColumn(duration=float seconds)`` would truncate).
* Particles: ``world/<name>`` Points3D per sample, ``world/<name>/trail`` the path
  up to the current time (a line strip that grows with time, the most recent
  samples at full resolution). Rigid bodies: ``world/<name>`` Transform3D per
  sample with the body axes as static Arrows3D below it.
* Diagnostics: ``diagnostics/<quantity>`` Scalars; the closed-form theory of a
  measured series beside it at ``diagnostics/<quantity>/theory``. Summary:
  static TextDocument at ``scenario``. ``world`` is z-up, right-handed (ENU:
  x east, y north, z up). A blueprint opens a 3D view beside one time-series
  view per kind of quantity (angles, lengths, errors and drifts, ...), so that
  numbers of different sizes do not share an axis.
* Error and drift series (names with ``error`` or ``drift``) near round-off would
  print as ``0.000 000 000 4`` on an axis: beside each, ``diagnostics/log10_<name>``
  holds the base-10 logarithm of its largest size so far, an envelope (exact zeros drawn at
  `LOG10_FLOOR`), and the blueprint's error view shows those.
* Playback: the blueprint's time panel plays the run in about
  `PLAYBACK_TARGET_S` seconds (an hour of Foucault's pendulum, 304 days of the
  free top), and a scene may set the 3D view's eye and contents (`view`) so
  that its first frame frames the effect.
* Bulk data goes by columns (``send_columns``); nothing is logged step by step.
  Positions are float32 in rerun, so scenes log them in a local frame (ENU, body).
* Files are deterministic (fixed recording id, no ``log_time``). The recording
  is encoded into memory (rerun's binary stream) and the bytes are written by
  Python to a temporary file of this writer's own in the target folder, then
  renamed (`rotframe.app.outputs`): an earlier complete recording is only ever
  replaced by a complete one, two writers never share a temporary file, and
  every I/O error (full disk, ``ulimit -f``) ends the run with one line and no
  file left behind. An interrupted or failed run is finalised as
  ``<name>.partial.rrd``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rotframe.numerics.sampling import decimate

__all__ = ["Recording", "default_path", "series_kind", "is_error_series", "playback_speed",
           "PLAYBACK_TARGET_S", "LOG10_FLOOR"]

#: seconds of viewing a run's whole timeline takes at the blueprint's playback speed (at least 1x)
PLAYBACK_TARGET_S = 30.0
#: the timeline every series is logged on (a duration, s)
TIMELINE = "sim_time"
#: where log10 of an error series draws an exact zero (below float64 round-off, 1e-16)
LOG10_FLOOR = -18.0


def playback_speed(duration_s: float, target_s: float = PLAYBACK_TARGET_S) -> float:
    """Playback speed that shows ``duration_s`` of simulated time in ``target_s`` seconds (never below 1x).

    >>> playback_speed(3600.0), playback_speed(5.7)
    (120.0, 1.0)
    """
    return max(1.0, float(duration_s) / target_s) if duration_s > 0 else 1.0


def is_error_series(entity: str) -> bool:
    """Whether a series is an error or a drift (drawn as log10 of its size).

    >>> is_error_series("diagnostics/energy_rel_error"), is_error_series("diagnostics/theta_deg")
    (True, False)
    """
    name = entity.rstrip("/").rsplit("/", 1)[-1]
    return "error" in name or "drift" in name


def default_path(scenario_name: str) -> Path:
    """``recordings/<scenario>.rrd`` in the working directory."""
    return Path("recordings") / f"{scenario_name}.rrd"


def partial_path(path: Path) -> Path:
    """``x.rrd`` -> ``x.partial.rrd``."""
    path = Path(path)
    return path.with_name(path.stem + ".partial.rrd")



def series_kind(entity: str) -> str:
    """The time-series view a series goes to, from its name: errors and drifts together, else by unit.

    >>> series_kind("diagnostics/energy_rel_error")
    'errors and drifts (relative)'
    >>> series_kind("diagnostics/swing_angle_deg")
    'angles (deg)'
    >>> series_kind("diagnostics/omega_body/2")
    'omega_body'
    """
    from rotframe.app.units import quantity_unit

    name = entity.rstrip("/").rsplit("/", 1)[-1]
    if "rel_error" in name or "rel_drift" in name:
        return "errors and drifts (relative)"
    if "error" in name or "drift" in name:
        return f"errors ({quantity_unit(name) or 'absolute'})"
    unit = quantity_unit(name)
    if unit == "deg":
        return "angles (deg)"
    if unit:
        return f"{name.rsplit('_', 1)[0].replace('_', ' ')} ({unit})" if unit not in ("m", "mm", "km") else f"lengths ({unit})"
    parent = entity.rstrip("/").rsplit("/", 1)
    return parent[0].rsplit("/", 1)[-1] if len(parent) > 1 and name.isdigit() else name


def _time_column(times):
    import rerun as rr

    ns = np.round(np.asarray(times, dtype=np.float64) * 1e9).astype(np.int64)
    return rr.TimeColumn(TIMELINE, duration=ns.astype("timedelta64[ns]"))


class Recording:
    """One run's recording; use as a context manager or call [`finish`][rotframe.app.record.Recording.finish].

    Parameters
    ----------
    path : path-like
        Final name (``.rrd``). Data is held in memory until [`finish`][rotframe.app.record.Recording.finish] writes it.
    application_id : str
        Shown in the viewer (the scenario name).
    """

    def __init__(self, path, application_id: str):
        import rerun as rr

        self.path = Path(path)
        self.rec = rr.RecordingStream(application_id, recording_id=f"rotframe-{application_id}",
                                      send_properties=False)
        self.rec.set_log_time_enabled(False)
        self.rec.set_log_tick_enabled(False)
        self._stream = self.rec.binary_stream()
        self._done = False
        self._series: list[tuple[str, str]] = []  # (entity, kind) of the scalar series, for the blueprint
        self._data = None
        self.final = None
        self._t_end = 0.0  # the latest time logged: the timeline the blueprint plays
        self.sent_blueprint = None  # the blueprint sent (`blueprint`), None before
        self._view: dict = {}  # the 3D view's eye and contents, set by the scene (`view`)

    # -- logging -------------------------------------------------------------

    def _time(self, times):
        """The ``sim_time`` column of ``times``; remembers the latest time for the playback speed."""
        times = np.asarray(times, dtype=np.float64)
        if times.size:
            last = float(np.nanmax(times))
            if last == last:
                self._t_end = max(self._t_end, last)
        return _time_column(times)

    def view(self, eye=None, look_at=None, up=(0.0, 0.0, 1.0), contents=None, playback_s=None,
             playback_speed=None):
        """How the 3D view opens: an orbital eye at ``eye`` looking at ``look_at`` (world coordinates).

        ``contents`` (entity paths under ``world``, rerun's ``+ path`` / ``- path``
        expressions) limits what the view shows; ``playback_s`` is the simulated
        time the phenomenon takes, played in `PLAYBACK_TARGET_S` seconds (default:
        the whole timeline); ``playback_speed`` sets the speed itself instead, below 1 for
        slow motion (a top spinning 48 turns a second).
        """
        self._view = {"eye": eye, "look_at": look_at, "up": up, "contents": contents, "playback_s": playback_s,
                      "playback_speed": playback_speed}

    def points(self, entity, times, positions, radius=None, color=None, trail=True):
        """Points per sample at ``entity``; ``positions`` (n, 3) or (n, N, 3), m."""
        import rerun as rr

        pos = np.asarray(positions, dtype=np.float64)
        if pos.ndim == 2:
            pos = pos[:, None, :]
        n, count, _ = pos.shape
        flat = pos.reshape(n * count, 3).astype(np.float32)
        cols = rr.Points3D.columns(positions=flat).partition(np.full(n, count))
        self.rec.send_columns(entity, indexes=[self._time(times)], columns=cols)
        static = {}
        if radius is not None:
            static["radii"] = [float(radius)]
        if color is not None:
            static["colors"] = [color]
        if static:
            self.rec.log(entity, rr.Points3D.from_fields(**static), static=True)
        if trail:
            self.trail(f"{entity}/trail", times, pos, color=color)

    def trail(self, entity, times, positions, frames=400, window=600, color=None):
        """The path up to each time: a line strip per frame that grows with time.

        ``positions`` (n, 3) or (n, N, 3). At most ``frames`` frames are logged,
        each with the last ``window`` samples at full resolution (the whole
        path while it is shorter), so the trail of a long run is its recent
        part rather than a blur of the whole.
        """
        import rerun as rr

        pos = np.asarray(positions, dtype=np.float64)
        if pos.ndim == 2:
            pos = pos[:, None, :]
        n, count, _ = pos.shape
        keys = decimate(n, frames)
        strips = []
        for k in keys:
            lo = max(0, int(k) + 1 - window)
            for j in range(count):
                strips.append(pos[lo:k + 1, j, :].astype(np.float32))
        cols = rr.LineStrips3D.columns(strips=strips).partition(np.full(len(keys), count))
        self.rec.send_columns(entity, indexes=[self._time(np.asarray(times)[keys])], columns=cols)
        if color is not None:
            self.rec.log(entity, rr.LineStrips3D.from_fields(colors=[color]), static=True)

    def line(self, entity, points, color=None):
        """A static polyline (m)."""
        import rerun as rr

        self.rec.log(entity, rr.LineStrips3D([np.asarray(points, dtype=np.float32)], colors=color), static=True)

    def segments(self, entity, times, starts, ends, color=None):
        """A moving arrow per sample from ``starts`` to ``ends`` (n, 3)."""
        import rerun as rr

        starts = np.asarray(starts, dtype=np.float32)
        vectors = (np.asarray(ends, dtype=np.float64) - starts).astype(np.float32)
        cols = rr.Arrows3D.columns(origins=starts, vectors=vectors)
        self.rec.send_columns(entity, indexes=[self._time(times)], columns=cols)
        if color is not None:
            self.rec.log(entity, rr.Arrows3D.from_fields(colors=[color]), static=True)

    def body(self, entity, times, quaternions_xyzw, translation=None, axis_length=1.0):
        """A rigid body: Transform3D per sample (scalar-last quaternions, body -> space).

        Its axes e1, e2, e3 are drawn at ``<entity>/axes``, ``axis_length`` long;
        ``axis_length=None`` draws none (a moving frame whose arrows are logged apart).
        """
        import rerun as rr

        q = np.asarray(quaternions_xyzw, dtype=np.float64)
        kwargs = {"quaternion": q.astype(np.float32)}
        if translation is not None:
            kwargs["translation"] = np.asarray(translation, dtype=np.float32)
        self.rec.send_columns(entity, indexes=[self._time(times)], columns=rr.Transform3D.columns(**kwargs))
        if axis_length is None:
            return
        L = float(axis_length)
        self.rec.log(f"{entity}/axes", rr.Arrows3D(
            vectors=[[L, 0, 0], [0, L, 0], [0, 0, L]],
            colors=[[230, 60, 60], [60, 200, 60], [60, 90, 230]], labels=["e1", "e2", "e3"]), static=True)

    def scalars(self, entity, times, values, kind=None, label=None):
        """A time series at ``entity`` (``diagnostics/<quantity>``).

        ``kind`` names the time-series view it goes to (default: from the name,
        see [`series_kind`][rotframe.app.record.series_kind]); ``label`` is its name in the plot legend.
        """
        import rerun as rr

        vals = np.asarray(values, dtype=np.float64)
        self.rec.send_columns(entity, indexes=[self._time(times)], columns=rr.Scalars.columns(scalars=vals))
        if label is not None:
            self.rec.log(entity, rr.SeriesLines(names=[label]), static=True)
        if kind is None and is_error_series(entity):
            self._log10(entity, times, vals)
            return
        self._series.append((entity, kind or series_kind(entity)))

    def _log10(self, entity, times, vals):
        """``diagnostics/log10_<name>``: log10 of the largest size of an error series so far, shown in place of it.

        The envelope reads as the drift it is (a round-off error's own size jumps between
        exact zeros and 1e-16 from sample to sample: a comb of spikes down to the floor); the
        series itself stays at ``entity``.
        """
        import rerun as rr

        from rotframe.app.units import quantity_unit

        head, _, name = entity.rstrip("/").rpartition("/")
        size = np.maximum.accumulate(np.where(np.isfinite(vals), np.abs(vals), 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            logs = np.where(size > 0, np.log10(np.where(size > 0, size, 1.0)), LOG10_FLOOR)
        logs = np.where(np.isfinite(vals), np.maximum(logs, LOG10_FLOOR), np.nan)
        path = f"{head}/log10_{name}" if head else f"log10_{name}"
        self.rec.send_columns(path, indexes=[self._time(times)], columns=rr.Scalars.columns(scalars=logs))
        self.rec.log(path, rr.SeriesLines(names=[f"log10 of the largest |{name}| so far"]), static=True)
        unit = quantity_unit(name) or ""
        self._series.append((path, f"errors: log10 of their size{' in ' + unit if unit else ' (relative)'}"))

    def reference(self, entity, times, values, label="theory", name="theory"):
        """The closed-form value of the series at ``entity``, logged beside it at ``<entity>/<name>``.

        Drawn grey and thin, in the same view as the measured series.
        """
        import rerun as rr

        vals = np.asarray(values, dtype=np.float64)
        if vals.ndim == 0:
            vals = np.full(len(times), float(vals))
        path = f"{entity}/{name}"
        self.rec.send_columns(path, indexes=[self._time(times)], columns=rr.Scalars.columns(scalars=vals))
        self.rec.log(path, rr.SeriesLines(colors=[[150, 150, 150]], widths=[1.0], names=[label]), static=True)

    def frame_axes(self, entity, length, labels=("E", "N", "U"), omega=None):
        """Static axes of the frame the scene is seen in (labelled), and its rotation vector if given.

        ``omega`` (3,) rad/s in that frame: drawn as an arrow of twice ``length``
        along it, labelled with its size.
        """
        import rerun as rr

        L = float(length)
        self.rec.log(entity, rr.Arrows3D(vectors=[[L, 0, 0], [0, L, 0], [0, 0, L]], labels=list(labels),
                                         colors=[[200, 80, 80], [80, 180, 80], [80, 110, 220]]), static=True)
        if omega is not None:
            w = np.asarray(omega, dtype=np.float64)
            norm = float(np.linalg.norm(w))
            if norm > 0:
                # twice the axes: its label (at the middle) clears those of the axes it lies between (N and U)
                self.rec.log(f"{entity}/omega", rr.Arrows3D(vectors=[(2.0 * L * w / norm).astype(np.float32)],
                                                            colors=[[250, 200, 40]],
                                                            labels=[f"omega ({norm:.4g} rad/s)"]), static=True)

    def static(self, entity, archetype: str, **fields):
        """A static rerun archetype at ``entity``, named (``"Boxes3D"``, ``"Arrows3D"``), from plain fields.

        For what the other methods do not cover, so that scenes log through the
        Recording and never import rerun: ``fields`` are the archetype's
        ``from_fields`` arguments as lists or numpy arrays (``half_sizes``,
        ``vectors``, ``colors``, ``labels``, ``show_labels``...). Logged on an
        entity that has time-varying data, they add to it (a label on a moving arrow).
        """
        import rerun as rr

        kind = getattr(rr, archetype, None)
        if not archetype[:1].isupper() or not hasattr(kind, "from_fields"):
            raise ValueError(f"Recording.static: {archetype!r} is not a rerun archetype")
        self.rec.log(entity, kind.from_fields(**fields), static=True)

    def exact_values(self, entity, **arrays):
        """Static float64 arrays (exact state that tests may read back) via AnyValues."""
        import rerun as rr

        self.rec.log(entity, rr.AnyValues(**{k: np.asarray(v, dtype=np.float64).ravel() for k, v in arrays.items()}),
                     static=True)

    def text(self, entity, markdown: str):
        import rerun as rr

        self.rec.log(entity, rr.TextDocument(markdown, media_type=rr.MediaType.MARKDOWN), static=True)

    def blueprint(self, series=("diagnostics",)):
        """3D view of ``world`` beside one time-series view per kind of quantity and the summary text.

        Also declares ``world`` right-handed and z-up (ENU) for the viewer.
        The kinds are those given to (or inferred by) [`scalars`][rotframe.app.record.Recording.scalars]; with no
        series logged through it, one view per root in ``series``.
        """
        import rerun as rr
        import rerun.blueprint as rrb

        self.rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        groups: dict[str, list[str]] = {}
        for entity, kind in self._series:
            groups.setdefault(kind, []).append(entity)
        # every time series shows the whole run: all its data visible, the axis from 0 to the last time
        # (rerun's default window around the cursor shows a minute of an hour-long run)
        whole = dict(time_ranges=[rrb.VisibleTimeRange(TIMELINE, start=rrb.TimeRangeBoundary.infinite(),
                                                       end=rrb.TimeRangeBoundary.infinite())],
                     axis_x=rrb.archetypes.TimeAxis(view_range=rr.TimeRange(
                         start=rrb.TimeRangeBoundary.absolute(seconds=0.0),
                         end=rrb.TimeRangeBoundary.absolute(seconds=float(self._t_end)))))
        if groups:
            views = [rrb.TimeSeriesView(origin="/", name=kind, contents=[f"+ /{e.strip('/')}/**" for e in entities],
                                        **whole) for kind, entities in groups.items()]
        else:
            views = [rrb.TimeSeriesView(origin=f"/{s}", name=s, **whole) for s in series]
        view = self._view
        eye = None
        if view.get("eye") is not None:
            target = view.get("look_at")
            up = view.get("up")
            eye = rrb.EyeControls3D(kind=rrb.Eye3DKind.Orbital, position=[float(x) for x in view["eye"]],
                                    look_target=[float(x) for x in (target if target is not None else (0, 0, 0))],
                                    eye_up=[float(x) for x in (up if up is not None else (0, 0, 1))])
        world = rrb.Spatial3DView(origin="/world", name="world", contents=view.get("contents") or "$origin/**",
                                  eye_controls=eye)
        span = view.get("playback_s") or self._t_end
        speed = view.get("playback_speed") or playback_speed(span)
        bp = rrb.Blueprint(
            rrb.Horizontal(
                world,
                rrb.Vertical(*views, rrb.TextDocumentView(origin="/scenario", name="summary")),
                column_shares=[3, 2],
            ),
            rrb.TimePanel(state="collapsed", timeline=TIMELINE, playback_speed=speed,
                          play_state=rrb.components.PlayState.Playing, loop_mode=rrb.components.LoopMode.All),
            collapse_panels=True,
        )
        self.sent_blueprint = bp  # what the viewer opens on (tests read it)
        self.rec.send_blueprint(bp)

    # -- finishing -----------------------------------------------------------


    def finish(self, complete: bool = True) -> Path:
        """Encode, write through a temporary file and rename to the final or partial name.

        ``complete`` may be a callable, asked once the bytes are encoded. Raises
        `rotframe.app.outputs.OutputError` (nothing left behind) when the file cannot be
        written. If the write is interrupted, ``finish(complete=False)`` may be called again:
        the encoded bytes are kept until a write succeeds.
        """
        from rotframe.app.outputs import write_bytes_atomic

        if self._done:
            return self.final
        data = self._encoded()
        if callable(complete):  # decided once the bytes are ready (a signal held meanwhile makes it a partial)
            complete = complete()
        final = self.path if complete else partial_path(self.path)
        write_bytes_atomic(final, data, what="recording")
        self._done = True
        self.final = final
        return final

    def _encoded(self) -> bytes:
        """Everything logged, as the bytes of an ``.rrd`` file (read from rerun once)."""
        if self._data is None:
            self.rec.flush()
            self._data = self._stream.read(flush=True) or b""
            self.rec.disconnect()
        return self._data

    def abandon(self):
        """Drop what was logged (nothing is written)."""
        if not self._done:
            self._done = True
            try:
                self._encoded()  # drained, so that rerun does not warn about dropped data
            except Exception:  # noqa: BLE001 -- nothing is kept anyway
                pass
            self._data = None
