"""rotframe from Python: list, inspect and run scenarios; results as numpy arrays.

This is the module behind ``rotframe.scenarios``, ``rotframe.load`` and
``rotframe.run`` (``import rotframe`` reaches it lazily, so the import stays
cheap). A run goes the same way as ``rotframe run NAME`` on the command line:
the scenario file is loaded and checked, the values are converted once to the
documented units, the scene is simulated and analysed, and a [`Result`][rotframe.app.api.Result]
holds the summary (the same keys as ``rotframe run --json``) and the
trajectory as plain float64 arrays in SI units.

Parameter values may be given as

* numbers in the parameter's documented unit (SI; angles in degrees), as in
  ``rotframe show NAME``;
* astropy quantities of the right dimension (``67 * u.m``, ``50.9 * u.deg``);
* the strings the command line takes (``"520 ft"``, ``"50d54m"``,
  ``"48d50m46s N"``, ``"0,1,1e-3"`` for vectors).

Bad values raise [`rotframe.errors.ScenarioError`][rotframe.errors.ScenarioError] (a ``ValueError``)
naming the scenario, the key, the value and what is allowed.

Examples
--------
>>> import rotframe
>>> "foucault" in rotframe.scenarios()
True
>>> scn = rotframe.load("tower-drop")
>>> p = scn.parameters["height"]
>>> p.unit, p.default, p.bounds, p.doc
('m', 158.5, (0, None), 'drop height above the ground')
>>> r = rotframe.run("tower-drop", height="520 ft", latitude=50.9)
>>> round(r.metrics["east_deflection_m"] * 1000, 1)   # mm east of the foot
27.6
>>> r.trajectory.r.shape[1:]                            # (samples, particles, xyz)
(1, 3)
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping

from rotframe.app.choices import did_you_mean
from rotframe.app.options import jsonable
from rotframe.errors import ScenarioError

__all__ = ["scenarios", "load", "run", "Result", "TrajectoryArrays", "register_scene"]

ProgressLike = Callable[[float], Any] | bool | None


# ---------------------------------------------------------------------------
# scenarios
# ---------------------------------------------------------------------------


def scenarios() -> list[str]:
    """Names of the built-in scenarios and of those registered with [`register_scene`][rotframe.app.api.register_scene].

    Examples
    --------
    >>> import rotframe
    >>> rotframe.scenarios()[:3]
    ['cr3bp', 'dzhanibekov', 'foucault']
    """
    from rotframe.app import scenario as sc
    from rotframe.scenes import SCENARIO_FILES, load_plugins

    load_plugins()  # as the command line: the modules named in $ROTFRAME_PLUGINS register theirs
    return sorted(set(sc.names()) | set(SCENARIO_FILES))


def load(name_or_path: str | Path):
    """Load and check a scenario; returns a `rotframe.app.scenario.Scenario`.

    Its ``parameters`` map each name to a `rotframe.app.scenario.Parameter`
    with ``name``, ``unit``, ``default`` (in that unit), ``bounds`` = ``(min, max)``
    (``exclusive_min``/``exclusive_max`` say whether they are allowed),
    ``choices`` and ``doc``. ``scenario.run`` holds the run settings
    (``method``, ``step``, ``rtol``, ``samples``), ``scenario.model`` the force
    terms.

    Parameters
    ----------
    name_or_path : str or path
        A name from [`scenarios`][rotframe.app.api.scenarios] or a path to a ``.toml`` file.

    Examples
    --------
    >>> import rotframe
    >>> scn = rotframe.load("foucault")
    >>> scn.scene, scn.parameters["latitude"].unit
    ('foucault', 'deg')
    >>> print(scn.parameters["length"].describe())
    67 m (> 0)
    """
    from rotframe.app import scenario as sc
    return sc.load(str(name_or_path))


# ---------------------------------------------------------------------------
# running
# ---------------------------------------------------------------------------


def run(name_or_path: str | Path, method: str | None = None, *, progress: ProgressLike = None,
        threads: int | None = None, device: str | None = None, **params: Any) -> "Result":
    """Run a scenario; returns a [`Result`][rotframe.app.api.Result].

    Parameters
    ----------
    name_or_path : str or path
        A name from [`scenarios`][rotframe.app.api.scenarios] or a path to a ``.toml`` scenario file.
    method : str, optional
        Integrator (``rotframe.load(name)`` and ``rotframe show NAME`` list the
        scene's methods); default the scenario's.
    progress : callable or bool, optional
        ``progress(fraction)`` is called as the run advances (0 to 1);
        ``True`` draws a bar: tqdm's (``tqdm.auto``: a widget in Jupyter) when
        tqdm is installed, else a text line on stderr.
    threads : int, optional
        Threads for ensembles of particles during this run only (default:
        every core); the results do not depend on it. Not a whole number
        >= 1: ScenarioError.
    device : str, optional
        ``"cpu"`` (default) or ``"gpu"``: where ensembles of particles run during
        this run (a CUDA GPU, float64, the fixed-step methods;
        [`rotframe.particles.gpu`][rotframe.particles.gpu]). ``"gpu"`` without one: ScenarioError.
    **params
        Parameter values (numbers in the documented unit, astropy quantities or
        strings such as ``"520 ft"``), and the run settings ``step`` (s),
        ``rtol`` and ``samples``.

    Warns
    -----
    rotframe.errors.RotframeWarning
        One for each entry of the result's ``warnings`` (what the run could not
        resolve or should be read with care); the list stays on the result.

    Raises
    ------
    rotframe.errors.ScenarioError
        Unknown scenario, key or method, wrong unit, value out of range.
    rotframe.errors.IntegrationError
        Numerical failure; ``exc.partial`` holds a [`Result`][rotframe.app.api.Result] of what was
        computed up to ``exc.t_reached``.
    rotframe.particles.integrators.RunInterrupted
        Ctrl-C during the run; ``exc.partial`` holds a [`Result`][rotframe.app.api.Result] of what was computed.

    Examples
    --------
    >>> import rotframe
    >>> r = rotframe.run("foucault", latitude=-33.9, duration=600)
    >>> r.metrics["precession_rate_deg_per_hour"] < 0      # anticlockwise in the south
    True
    >>> rotframe.run("foucault", lenght=10)
    Traceback (most recent call last):
    ...
    rotframe.errors.ScenarioError: foucault: unknown parameter 'lenght' (did you mean 'length'?); allowed: ...
    """
    from rotframe import scenes
    from rotframe.app import runner
    from rotframe.errors import IntegrationError
    from rotframe.particles.ensemble import check_device, check_threads, device_scope, threads_scope
    from rotframe.particles.integrators import RunInterrupted

    t_start = time.perf_counter()
    check_threads(threads)
    check_device(device)
    scn = load(name_or_path)
    values = resolve_values(scn, params)
    scene = scenes.get(scn.scene)
    method = method.lower() if isinstance(method, str) else method  # scipy's "DOP853" is dop853
    allowed = getattr(scene, "METHODS", None)
    if method is not None and allowed is not None and method not in allowed:
        raise ScenarioError(f"{scn.name}: method={method!r} is not one of {', '.join(allowed)}")
    callback = _progress_callback(progress)
    t0 = time.perf_counter()
    try:
        with threads_scope(threads), device_scope(device):
            scene_result = runner.simulate(scn, values, method=method, progress=callback)
    except (IntegrationError, RunInterrupted) as exc:
        if exc.partial is not None:
            simulate_s = time.perf_counter() - t0
            summary = runner.summarize_minimal(scn, values, exc.partial, {"simulate_s": simulate_s})
            exc.partial = Result(scn, values, exc.partial, _finish_summary(scn, summary, exc.partial, simulate_s, t_start))
        raise
    finally:
        if progress is True:  # the bar is ours to end
            callback.close()
    simulate_s = time.perf_counter() - t0
    summary = runner.summarize(scn, values, scene_result, {"simulate_s": simulate_s}, given=params or ())
    result = Result(scn, values, scene_result, _finish_summary(scn, summary, scene_result, simulate_s, t_start))
    _warn(result.warnings)
    return result


def _warn(texts) -> None:
    """One `rotframe.errors.RotframeWarning` per entry of a result's ``warnings`` (the list stays)."""
    import warnings

    from rotframe.errors import RotframeWarning

    for text in texts:
        warnings.warn(text, RotframeWarning, stacklevel=3)  # points at the caller of rotframe.run


def resolve_values(scn, params: Mapping[str, Any]) -> dict:
    """Parameter values of ``scn`` (documented units) with ``params`` applied; run settings under ``"run"``.

    Quantities are converted here, at the edge; strings and numbers go through
    the same checks as the scenario file's values.
    """
    from rotframe.app import scenario as sc
    values = {k: p.default for k, p in scn.parameters.items()}
    run_settings = dict(scn.run)
    for key, raw in params.items():
        if key in scn.parameters:
            p = scn.parameters[key]
            values[key] = sc.parse_value(p, _plain(raw, p.unit, key, scn.name), source=scn.name)
        elif key in sc.RUN_KEYS and key != "method":
            unit = "s" if key == "step" else ""
            run_settings[key] = sc.parse_run_value(key, _plain(raw, unit, key, scn.name), source=scn.name)
        else:
            allowed = list(scn.parameters) + [k for k in sc.RUN_KEYS if k != "method"]
            raise ScenarioError(f"{scn.name}: unknown parameter {key!r}{did_you_mean(key, allowed)}; "
                                f"allowed: {', '.join(allowed)}")
    values["run"] = run_settings
    return values


def _plain(raw, unit: str, key: str, where: str):
    """An astropy Quantity in ``unit`` as a float (or list); other values unchanged (numpy scalars -> Python)."""
    if hasattr(raw, "unit") and hasattr(raw, "to_value"):
        import astropy.units as u

        try:
            value = raw.to_value(u.Unit(unit) if unit else u.dimensionless_unscaled)
        except u.UnitsError:
            raise ScenarioError(f"{where}: {key} = {raw}: wrong dimension; expected a value in "
                                f"{unit or 'no unit'}") from None
        return value.tolist() if getattr(value, "ndim", 0) else float(value)
    if hasattr(raw, "tolist") and not isinstance(raw, (str, bytes)):
        return raw.tolist()  # numpy arrays and scalars
    return raw


def _finish_summary(scn, summary, scene_result, simulate_s, t_start):
    from rotframe.app.units import summary_units

    compile_s = float(getattr(scene_result.trajectory, "extras", {}).get("compile_s", 0.0))
    summary["timing"].update({"compile_s": compile_s, "simulate_s": simulate_s - compile_s, "record_s": 0.0,
                              "total_s": time.perf_counter() - t_start})
    summary.setdefault("warnings", [])
    summary["units"] = summary_units(scn.parameters, summary)
    return summary


# ---------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------


@dataclass
class TrajectoryArrays:
    """A run's samples as plain numpy arrays (float64, SI units).

    Attributes
    ----------
    kind : str
        ``"particles"`` or ``"body"`` (or ``"other"`` for a user's scene
        whose trajectory is neither).
    times : ndarray (n,)
        Sample times, s.
    r, v : ndarray (n, N, 3) or None
        Particles: positions (m) and velocities (m/s) in the scene's frame
        (ENU for Earth scenes: x east, y north, z up; the turntable's frame
        for the turntable). After a terminal event (the ground) the samples
        keep the state at the event.
    L : ndarray (n, 3) or None
        Rigid bodies: angular momentum in the body (principal) axes, kg m^2/s.
    q : ndarray (n, 4) or None
        Rigid bodies: unit quaternions (x, y, z, w), scalar last, rotating body
        components into space components (scipy's ``Rotation.from_quat``).
    event_times : dict
        Event name -> a sequence (per particle: index it, iterate it, ``len``) of arrays of times, s.
    units : dict
        Array name -> unit string.
    frame : str
        In words, the frame the vectors are in.
    """

    kind: str
    times: Any
    r: Any = None
    v: Any = None
    L: Any = None
    q: Any = None
    event_times: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    frame: str = ""

    @classmethod
    def from_scene(cls, traj, scene_name: str = "") -> "TrajectoryArrays":
        import numpy as np

        times = np.asarray(traj.times, dtype=float)
        if getattr(traj, "r", None) is not None:
            frame = ("the turntable's rotating frame (z along the spin axis)" if scene_name == "turntable"
                     else "local ENU frame on the rotating Earth (x east, y north, z up)")
            return cls("particles", times, r=np.asarray(traj.r, dtype=float), v=np.asarray(traj.v, dtype=float),
                       event_times=dict(getattr(traj, "event_times", {}) or {}),
                       units={"times": "s", "r": "m", "v": "m/s"}, frame=frame)
        if getattr(traj, "L", None) is not None:
            return cls("body", times, L=np.asarray(traj.L, dtype=float), q=np.asarray(traj.q, dtype=float),
                       units={"times": "s", "L": "kg m^2/s", "q": ""},
                       frame="L in the body's principal axes; q rotates body components into space components")
        return cls("other", times, units={"times": "s"})

    def columns(self) -> dict:
        """The samples as a table of 1-D columns (long format: one row per sample and particle).

        Particles: ``time_s, particle, x_m, y_m, z_m, vx_m_s, vy_m_s, vz_m_s``;
        bodies: ``time_s, L1_kg_m2_s, L2_kg_m2_s, L3_kg_m2_s`` (body axes), ``qx, qy, qz, qw``
        (a unit quaternion, dimensionless: no unit in its name). Every name with a unit ends in it.
        """
        import numpy as np

        if self.kind == "particles":
            n, count, _ = self.r.shape
            cols = {"time_s": np.repeat(self.times, count), "particle": np.tile(np.arange(count), n)}
            for k, axis in enumerate("xyz"):
                cols[f"{axis}_m"] = self.r[:, :, k].ravel()
            for k, axis in enumerate("xyz"):
                cols[f"v{axis}_m_s"] = self.v[:, :, k].ravel()
            return cols
        if self.kind == "body":
            cols = {"time_s": self.times}
            for k in range(3):
                cols[f"L{k + 1}_kg_m2_s"] = self.L[:, k]
            for k, name in enumerate(("qx", "qy", "qz", "qw")):
                cols[name] = self.q[:, k]
            return cols
        return {"time_s": self.times}


class Result:
    """One run: its summary (as ``rotframe run --json``) and its trajectory.

    Attributes
    ----------
    metrics, theory, diagnostics : dict
        Measured values, their closed-form theory, and checks (drifts,
        conserved quantities); names end in their unit (`units`).
    warnings : list of str
        What the run could not resolve or should be read with care (empty on a clean run).
    params : dict
        Parameter values as resolved, in the documented units.
    timing : dict
        Seconds: ``compile_s``, ``simulate_s``, ``record_s``, ``total_s``.
    units : dict
        Parameter and metric name -> unit string.
    trajectory : TrajectoryArrays
        The samples as numpy arrays.
    scenario : rotframe.app.scenario.Scenario
        The loaded scenario.
    """

    def __init__(self, scenario, values, scene_result, summary, scene=None):
        self.scenario = scenario
        self._scene = scene  # a problem posed in Python (rotframe.simulate) records through its own scene
        self._values = values
        self._scene_result = scene_result
        self._summary = _python_scalars(summary)  # np.float64(11.3) -> 11.3: reads as the JSON does
        self.trajectory = TrajectoryArrays.from_scene(scene_result.trajectory, scenario.scene)

    metrics = property(lambda self: self._summary["metrics"])
    theory = property(lambda self: self._summary.get("theory", {}))
    diagnostics = property(lambda self: self._summary.get("diagnostics", {}))
    warnings = property(lambda self: list(self._summary.get("warnings", [])))
    notes = property(lambda self: list(self._summary.get("notes", [])))
    params = property(lambda self: self._summary["params"])
    timing = property(lambda self: self._summary["timing"])
    units = property(lambda self: self._summary.get("units", {}))
    method = property(lambda self: self._summary["method"])
    complete = property(lambda self: bool(self._summary.get("complete", True)))
    recording = property(lambda self: self._summary.get("recording"))

    def __repr__(self) -> str:
        shown = ", ".join(f"{k}={v:.6g}" if isinstance(v, float) else f"{k}={v}" for k, v in self.metrics.items())
        return f"<rotframe.Result {self.scenario.name} ({self.method}): {shown}>"

    def _repr_markdown_(self) -> str:
        from rotframe.app.display import markdown, result_rows
        return markdown(*result_rows(self))

    def _repr_html_(self) -> str:
        from rotframe.app.display import html_table, result_rows
        return html_table(*result_rows(self))

    def sol(self, t):
        """The state at any time ``t`` (s) of a finished ``dop853`` particle run, as ``solve_ivp``'s ``sol(t)``.

        Returns ``(r, v)`` in the trajectory's frame and units: (N, 3) each for a
        number ``t``, (m, N, 3) for an array of m times. Restarts the run's own
        integrator and tolerances from the last sample before ``t``, so it is as
        accurate as the samples (see `rotframe.app.dense`); a run of another
        method, a rigid body or a frame whose rate changes raise ScenarioError.
        """
        from rotframe.app.dense import DenseSolution

        if getattr(self, "_dense", None) is None:
            self._dense = DenseSolution(self.scenario.name, self._scene_result, self._values.get("run", {}))
        return self._dense(t)

    def quantities(self) -> dict:
        """Metrics, theory and diagnostics as astropy Quantities in their units (`units`).

        Returns ``{"metrics": {...}, "theory": {...}, "diagnostics": {...}}``; a value
        whose unit is not known stays a plain number, and so do non-numbers. The
        plain floats of `metrics`, `theory` and `diagnostics` stay the default.

        Examples
        --------
        >>> import rotframe
        >>> q = rotframe.run("tower-drop").quantities()
        >>> q["metrics"]["east_deflection_m"].to("mm").round(1)
        <Quantity 27.6 mm>
        """
        from rotframe.app.quantities import as_quantities

        return {part: as_quantities(getattr(self, part), self.units)
                for part in ("metrics", "theory", "diagnostics")}

    def to_dict(self) -> dict:
        """The summary as a JSON-ready dict, with the keys of ``rotframe run --json`` (NaN -> None)."""
        return jsonable(self._summary)

    def to_json(self, **kwargs: Any) -> str:
        """The summary as one JSON object, as ``rotframe run --json`` prints it."""
        return json.dumps(self.to_dict(), **kwargs)

    def record(self, path: str | Path | None = None) -> Path:
        """Write the recording (the same ``.rrd`` as the command line); returns its path.

        The default path is ``recordings/<scenario>.rrd`` in the working directory.
        """
        from rotframe.app import runner
        from rotframe.app.record import default_path

        path = Path(path) if path is not None else default_path(self.scenario.name)
        if path.suffix != ".rrd":
            raise ScenarioError(f"record({str(path)!r}): a recording path must end in .rrd")
        t0 = time.perf_counter()
        final = runner.record_result(self.scenario, self._values, self._scene_result, self._summary, str(path),
                                     complete=self.complete, scene=self._scene)
        self._summary["timing"]["record_s"] = time.perf_counter() - t0
        self._summary["recording"] = str(final)
        return Path(final)

    def export(self, path: str | Path) -> Path:
        """Write the trajectory to ``.npz``, ``.csv`` or ``.parquet`` (see [`rotframe.app.export`][rotframe.app.export])."""
        from rotframe.app.export import write_trajectory

        return write_trajectory(self.trajectory, path, summary=self.to_dict())

    def plot(self, path: str | Path | None = None):
        """A matplotlib figure of the run (``path``: also save it as PNG); see `rotframe.app.plot`."""
        from rotframe.app.plot import plot_result

        return plot_result(self, path)

    def to_dataframe(self):
        """The trajectory as a pandas DataFrame ([`TrajectoryArrays.columns`][rotframe.app.api.TrajectoryArrays.columns]); needs pandas."""
        from rotframe.app.optional import need

        return need("pandas", "to_dataframe()").DataFrame(self.trajectory.columns())

    def show(self, path: str | Path | None = None):
        """Show the recording: in Jupyter, rerun's viewer in the notebook; elsewhere, say how to open it.

        The notebook viewer needs the ``notebook`` extra (``pip install "rotframe[notebook]"``).
        Writes the recording first if it was not written yet; returns its path
        outside a notebook.
        """
        if path is not None or not self.recording:
            self.record(path)
        rrd = Path(self.recording)
        if _in_notebook():
            try:
                import rerun as rr
                from rerun.notebook import Viewer

                stream = rr.RecordingStream(self.scenario.name, recording_id=f"rotframe-{self.scenario.name}")
                viewer = Viewer(recording=stream)  # the viewer first: it receives what is logged after it
                viewer.display()
                stream.log_file_from_path(rrd)  # rerun's own loader reads the .rrd back
                return None
            except ImportError:
                print('the notebook viewer needs the notebook extra: python -m pip install "rotframe[notebook]"; '
                      f"meanwhile open {rrd} with: rotframe view {rrd}", file=sys.stderr)
                return rrd
        print(f"recording written to {rrd}; open it with: rotframe view {rrd} "
              f"(or, without a display: rotframe view {rrd} --web)", file=sys.stderr)
        return rrd


def _in_notebook() -> bool:
    shell = sys.modules.get("IPython")
    if shell is None:
        return False
    try:
        ip = shell.get_ipython()
    except Exception:  # pragma: no cover
        return False
    return ip is not None and "IPKernelApp" in getattr(ip, "config", {})


def _python_scalars(obj):
    """``obj`` with numpy scalars turned into Python numbers (in dicts and lists; arrays and NaN kept)."""
    if isinstance(obj, dict):
        return {k: _python_scalars(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_python_scalars(v) for v in obj]
    if type(obj).__module__ == "numpy" and getattr(obj, "ndim", None) == 0:
        return obj.item()
    return obj


# ---------------------------------------------------------------------------
# progress
# ---------------------------------------------------------------------------


def _progress_callback(progress: ProgressLike):
    from rotframe.app.progress import progress_callback

    return progress_callback(progress, "run")


# ---------------------------------------------------------------------------
# user scenes
# ---------------------------------------------------------------------------


def register_scene(name: str, scene: Any, scenario: str | Path | None = None, override: bool = False) -> None:
    """Make a scene of your own runnable like the built-in ones.

    Parameters
    ----------
    name : str
        The scene name that scenario files give as ``scene = "NAME"``.
    scene : module or object
        Anything with the scene protocol (see `rotframe.scenes`):
        ``simulate(values, terms, method, run, progress) -> SceneResult``,
        ``analyse(values, result) -> {"metrics", "theory", "diagnostics", "notes"}``,
        ``record(recording, values, result)``, and optionally ``METHODS``.
        May also be a module name (``"mypkg.myscene"``), imported now.
    scenario : path, optional
        A scenario file whose ``scene`` is ``name``; ``rotframe.run(name)`` and
        ``rotframe run NAME`` then find it by ``name``.
    override : bool
        Allow ``name`` (or the scenario's name) to replace a built-in one; refused otherwise.

    Raises
    ------
    ScenarioError
        One line naming the plugin: a module that is missing or raises on import, a scene
        without the protocol's functions, a scenario file that is not TOML, a built-in name.

    Notes
    -----
    To make the command line see a scene, put the module that calls
    ``register_scene`` in ``ROTFRAME_PLUGINS`` (comma-separated module names or
    ``.py`` paths), e.g. ``ROTFRAME_PLUGINS=examples/my_scene.py rotframe run my-scene``.
    """
    from rotframe import scenes

    scenes.register(name, scene, scenario, override=override)
