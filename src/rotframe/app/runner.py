"""Run a scenario: values in, summary and result out (no printing, no recording).

The command line (`rotframe.app.cli`) and the Python convenience function
`run` share this path; recording is downstream of a finished or
interrupted run (`record_result`).
"""

from __future__ import annotations

import time

from rotframe.errors import ScenarioError

__all__ = ["run", "simulate", "summarize", "unused_settings", "record_result"]


def run(name_or_path, sets=None, *, method=None, terms=None, progress=None):
    """Load, simulate and analyse a scenario; returns ``(summary, result)``.

    Parameters
    ----------
    name_or_path : str or Scenario
        Scenario name in ``scenarios/``, a path to a ``.toml`` file, or one already loaded
        (a sweep loads it once for all its rows).
    sets : dict, optional
        Parameter overrides ``{key: value}`` as on the command line.
    method : str, optional
        Integrator; default from the scenario's ``[run]`` or the scene.
    terms : list of str, optional
        Model terms replacing the scenario's ``model`` list.
    """
    from rotframe.app import scenario as sc
    scn = name_or_path if isinstance(name_or_path, sc.Scenario) else sc.load(name_or_path)
    values = scn.with_values(sets or {})
    t0 = time.perf_counter()
    result = simulate(scn, values, method=method, terms=terms, progress=progress)
    simulate_s = time.perf_counter() - t0
    summary = summarize(scn, values, result, {"simulate_s": simulate_s}, given=sets or ())
    return summary, result


def simulate(scn, values, *, method=None, terms=None, progress=None):
    """Run the scene of ``scn`` with resolved ``values``; returns a SceneResult."""
    from rotframe import scenes

    scene = scenes.get(scn.scene)
    run_settings = dict(values["run"])
    method = method or run_settings.get("method")
    method = method.lower() if isinstance(method, str) else method  # scipy's "DOP853" is dop853
    allowed = getattr(scene, "METHODS", None)
    if method is not None and allowed is not None and method not in allowed:
        raise ScenarioError(f"--method {method!r}: allowed for {scn.name}: {', '.join(allowed)}")
    params = {k: v for k, v in values.items() if k != "run"}
    terms = list(scn.model if terms is None else terms)
    from rotframe.particles import gpu, threads

    before = gpu.launches()
    result = scene.simulate(params, terms, method, run_settings, progress)
    if threads.device_in_force() == "gpu" and gpu.launches() == before:
        result.extras["gpu_unused"] = True  # said in the summary's warnings (`summarize`)
    return result


def summarize(scn, values, result, timing, given=()):
    """The run summary (the JSON contract described in README.md).

    Besides the contract's keys it always has ``warnings`` (a list of strings,
    empty on a clean run) and ``theory_notes`` ({metric: what its theory value is:
    "exact ..." or an approximation with its assumptions and accuracy}). A warning
    is raised for every metric that differs from its theory by more than the
    scene's stated tolerance (``tolerance`` in the scene's analysis: the method's
    accuracy for an exact theory, the approximation's accuracy otherwise; a metric
    with no tolerance is compared with an indicative theory only), plus the
    scene's own warnings, plus one for each run setting in ``given`` (the keys the
    caller set) that the method does not read (`unused_settings`). A run stopped at its first
    sample has nothing to analyse: its summary is `summarize_minimal`'s.
    """
    from rotframe import scenes

    if len(result.trajectory.times) < 2:
        return summarize_minimal(scn, values, result, timing)
    scene = scenes.get(scn.scene)
    params = {k: v for k, v in values.items() if k != "run"}
    analysis = unresolved_metrics(scene.analyse(params, result))
    theory = analysis.get("theory", {})
    summary = {
        "scenario": scn.name,
        "params": params,
        "model": list(result.terms),
        "method": result.method,
        "steps": int(result.steps),
        "metrics": _plain(analysis["metrics"]),
        "theory": _plain(theory),
        "theory_notes": dict(analysis.get("theory_notes", {})),
        "diagnostics": _plain(analysis.get("diagnostics", {})),
        "warnings": list(analysis.get("warnings", [])) + theory_warnings(
            analysis["metrics"], theory, analysis.get("tolerance", {}), analysis.get("theory_notes", {}))
        + unused_settings(given, values["run"], result.method) + _gpu_unused(scn, result),
        "timing": dict(timing),
        "recording": None,
    }
    if analysis.get("notes"):
        summary["notes"] = analysis["notes"]
    if not result.complete:
        summary["complete"] = False
        summary["t_reached_s"] = float(result.trajectory.t_reached)
    return summary


def unused_settings(given, run, method):
    """Warnings for the run settings a caller set (keys in ``given``) that ``method`` does not read.

    The registry's one rule (`rotframe.method_registry.unread_settings`): ``exact`` reads neither
    ``step`` nor ``rtol``, ``dop853`` (adaptive) chooses its own steps from ``rtol``, and every
    other method (particle and rigid) takes fixed steps and has no tolerance. A setting the
    scenario file gives is not warned about: files set both for whichever method runs.

    >>> unused_settings({"step": "0.5"}, {"step": 0.5, "rtol": 1e-10}, "dop853")
    ['step = 0.5 is not used: dop853 is adaptive and chooses its own steps (set rtol instead)']
    """
    from rotframe.method_registry import unread_settings

    return unread_settings(method, {key: run.get(key) for key in given})


def _gpu_unused(scn, result):
    """A warning when the GPU was asked for (``--device gpu``) and this run had no ensemble for it."""
    if not result.extras.get("gpu_unused"):
        return []
    return [f"device = gpu is not used: this run of {scn.name} has no ensemble (the GPU runs the ensembles of the "
            f"fixed-step methods); it ran on the CPU"]


def _plain(values: dict) -> dict:
    """Numbers as Python's own (a numpy scalar becomes a float, int or bool), as JSON will have them."""
    return {k: v.item() if hasattr(v, "item") and getattr(v, "ndim", 1) == 0 else v for k, v in values.items()}


def _finite_numbers(*values) -> bool:
    """Whether every value is a finite int or float (not a bool, not None, not nan)."""
    import math

    return all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in values)


def unresolved_metrics(analysis):
    """A scene's analysis with every metric that its own stated accuracy cannot resolve made null, with a note.

    A metric is unresolved when its tolerance (the largest |simulated - theory|
    the run allows) is at least the size of its nonzero theory value: whatever
    the run gives is then within "accuracy" of zero as much as of the answer, a
    number with no digit to trust (a projectile at 1e-12 m/s: lateral deflection
    1e-42 m, tolerance 1e-34 m from the positions' round-off, simulated -1.2e-41 m).
    A theory of exactly zero (an error metric, whose ideal is 0) is kept.
    """
    import math

    metrics, theory = dict(analysis["metrics"]), analysis.get("theory", {})
    notes = list(analysis.get("notes", []))
    for key, tol in analysis.get("tolerance", {}).items():
        ref = theory.get(key)
        if _finite_numbers(tol, ref, metrics.get(key)) and ref != 0 and abs(ref) <= tol:
            metrics[key] = math.nan
            notes.append(f"{key} not measured: the run resolves it only to +-{tol:.3g}, more than its size "
                         f"({ref:.3g} in theory)")
    return dict(analysis, metrics=metrics, notes=notes)


def theory_warnings(metrics, theory, tolerance, notes=None):
    """Warnings for metrics farther from their theory than the stated tolerance allows.

    ``tolerance`` maps a metric to the largest absolute difference |simulated -
    theory| that the method's accuracy and the theory's stated accuracy allow
    together. A metric with no tolerance, or with a missing (null) value on either
    side, is not compared.
    """
    notes = notes or {}
    out = []
    for key, tol in tolerance.items():
        value, ref = metrics.get(key), theory.get(key)
        if tol is None or not _finite_numbers(value, ref):
            continue
        diff = abs(value - ref)
        if diff > tol:
            what = notes.get(key, "theory")
            out.append(f"{key}: simulated {value:.6g} differs from theory {ref:.6g} ({what}) by {diff:.3g}, "
                       f"more than the stated accuracy {tol:.3g}")
    return out


def summarize_minimal(scn, values, result, timing):
    """A summary without metrics, for a partial run whose analysis is not possible."""
    params = {k: v for k, v in values.items() if k != "run"}
    return {"scenario": scn.name, "params": params, "model": list(result.terms), "method": result.method,
            "steps": int(result.steps), "metrics": {}, "theory": {}, "theory_notes": {}, "diagnostics": {},
            "warnings": ["the run stopped early and could not be analysed"],
            "timing": dict(timing), "recording": None, "complete": False,
            "t_reached_s": float(result.trajectory.t_reached)}


def record_result(scn, values, result, summary, path, complete=True, scene=None):
    """Write the recording; returns the final path (``.partial.rrd`` if not complete).

    ``scene``: the object that records (default: the scenario's registered scene).
    """
    from rotframe import scenes
    from rotframe.app.record import Recording
    from rotframe.app.signals import deferred

    scene = scene if scene is not None else scenes.get(scn.scene)
    params = {k: v for k, v in values.items() if k != "run"}
    # a signal while recording is held until the file is written whole (a recording cut short is unreadable, and
    # the run in it lost); then raised, with the file's path on it (`rotframe.app.signals.deferred`)
    with deferred() as held:
        rec = Recording(path, scn.name)
        try:
            scene.record(rec, params, result)
            rec.text("scenario", summary_markdown(scn, summary))
            rec.blueprint()
        except BaseException as exc:
            if isinstance(exc, KeyboardInterrupt):  # a script's own Ctrl-C (no scope): what was logged, as partial
                exc.recording = rec.finish(complete=False)
            else:
                rec.abandon() if isinstance(exc, Exception) and not complete else rec.finish(complete=False)
            raise
        try:  # a stopped command never writes the final name: asked once the bytes are ready
            final = rec.finish(complete=lambda: complete and not held.signalled)
        except KeyboardInterrupt as exc:  # a script's own Ctrl-C while writing: the same bytes as the partial
            exc.recording = rec.finish(complete=False) if complete else None
            raise
        held.attach(recording=final)
    return final


def summary_markdown(scn, summary) -> str:
    """The summary as Markdown for the recording's TextDocument."""
    lines = [f"# {scn.title or scn.name}", "", scn.description, "", "## Parameters", ""]
    for key, value in summary["params"].items():
        unit = scn.parameters[key].unit if key in scn.parameters else ""
        lines.append(f"- **{key}** = {value} {unit}")
    lines += ["", f"Model: {', '.join(summary['model'])}; method: {summary['method']}; steps: {summary['steps']}",
              "", "## Metrics (simulated / theory)", ""]
    for key, value in summary["metrics"].items():
        theory = summary["theory"].get(key)
        lines.append(f"- **{key}** = {value:.6g}" + (f" / {theory:.6g}" if isinstance(theory, float) else ""))
    lines += ["", "## Diagnostics", ""]
    lines += [f"- {k} = {v:.3g}" for k, v in summary["diagnostics"].items() if isinstance(v, float)]
    return "\n".join(lines)
