"""The ``rotframe`` command line.

Exit codes: 0 done; 2 bad input (one line on stderr naming the file, key, value
and what is allowed; no traceback); 3 numerical failure (the message gives the
simulated time reached; the recording keeps everything up to it); 130 / 143
interrupted by Ctrl-C / SIGTERM (the recording keeps what was computed).

This module imports only the standard library at start-up: numpy, astropy,
numba and rerun are imported by the commands that need them, so that
``rotframe list`` and ``rotframe --help`` stay instant.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import sys
import time

EXIT_OK, EXIT_INPUT, EXIT_NUMERICAL = 0, 2, 3
_T_START = time.perf_counter()


class _Terminated(KeyboardInterrupt):
    """SIGTERM, delivered as an interrupt so the run stops cleanly between chunks."""


def main(argv=None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if not getattr(args, "command", None):
        parser.print_help()
        return EXIT_OK
    from rotframe.errors import IntegrationError, RotframeError

    try:
        return args.func(args)
    except IntegrationError as exc:
        _error(f"numerical failure: {exc}")
        return EXIT_NUMERICAL
    except RotframeError as exc:
        _error(str(exc))
        return EXIT_INPUT


def _parser():
    p = argparse.ArgumentParser(
        prog="rotframe",
        description="Dynamics seen from rotating frames: run named scenarios, record them for the rerun "
                    "viewer, benchmark methods.",
        epilog="Examples: rotframe list | rotframe show foucault | rotframe run foucault --set latitude=0 | "
               "rotframe run tower-drop --json --no-record")
    from rotframe import __version__

    p.add_argument("--version", action="version", version=f"rotframe {__version__}",
                   help="print the version and exit")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")

    q = sub.add_parser("list", help="list the scenarios")
    q.add_argument("--json", action="store_true", help="print a JSON list")
    q.set_defaults(func=cmd_list)

    q = sub.add_parser("show", help="show a scenario's description, parameters and defaults")
    q.add_argument("name", metavar="NAME", help="a scenario name ('rotframe list') or a path to a .toml file")
    q.set_defaults(func=cmd_show)

    q = sub.add_parser("run", help="run a scenario and record it")
    q.add_argument("name", metavar="NAME|FILE.toml", help="a scenario name ('rotframe list') or a path to a .toml file")
    q.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help="change a parameter: a number in its documented unit (SI, angles in degrees), a quantity "
                        "string such as '520 ft' or '50d54m', or comma-separated numbers for vectors")
    q.add_argument("--method", metavar="M", help="integrator (see 'rotframe show NAME')")
    g = q.add_mutually_exclusive_group()
    g.add_argument("--out", metavar="PATH", help="recording path (default recordings/<scenario>.rrd)")
    g.add_argument("--no-record", action="store_true", help="do not write a recording")
    q.add_argument("--json", action="store_true", help="print one JSON object on stdout and nothing else")
    q.add_argument("--audit", action="store_true",
                   help="also rerun with each optional model term toggled and report what each term changes")
    q.add_argument("--export", metavar="FILE", default=None,
                   help="also write the trajectory to FILE: .npz (arrays), .csv or .parquet (a table, one row per "
                        "sample and particle; SI units in the column names)")
    q.add_argument("--png", metavar="FILE", default=None, help="also write a picture of the run (PNG, matplotlib)")
    q.set_defaults(func=cmd_run)

    q = sub.add_parser("bench", help="speed against error for every method")
    q.add_argument("names", nargs="*", metavar="NAME", help="problems to run (default: all)")
    q.add_argument("--json", action="store_true", help="print a JSON list of rows on stdout and nothing else")
    q.add_argument("--quick", action="store_true", help="a short ladder, for a smoke test")
    q.add_argument("--plots", metavar="DIR", default=None, help="write work-precision PNGs to DIR")
    q.set_defaults(func=cmd_bench)

    q = sub.add_parser("sweep", help="run a scenario over a grid or Monte Carlo samples of parameters")
    q.add_argument("name", metavar="NAME|FILE.toml", help="a scenario name ('rotframe list') or a path to a .toml file")
    q.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help="fix a parameter for every run, as in 'run'")
    q.add_argument("--grid", action="append", default=[], metavar="KEY=START:STOP:N",
                   help="N evenly spaced values from START to STOP (inclusive)")
    q.add_argument("--log-grid", action="append", default=[], metavar="KEY=START:STOP:N",
                   help="N logarithmically spaced values from START to STOP (inclusive, both > 0)")
    q.add_argument("--samples", type=int, default=None, metavar="N", help="Monte Carlo samples")
    q.add_argument("--vary", action="append", default=[], metavar="KEY=normal(MEAN,SD)|uniform(LO,HI)",
                   help="draw KEY from a distribution for each Monte Carlo sample (with --samples)")
    q.add_argument("--seed", type=int, default=0, metavar="S", help="random seed of the Monte Carlo samples")
    q.add_argument("--method", metavar="M", help="integrator (see 'rotframe show NAME')")
    g = q.add_mutually_exclusive_group()
    g.add_argument("--workers", type=int, default=None, metavar="N", help="a LocalCluster of N processes")
    g.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler, e.g. tcp://host:8786")
    q.add_argument("--out", metavar="PATH.parquet", default=None,
                   help="result table (default sweeps/<name>.parquet; plots and a recording go beside it)")
    q.add_argument("--resume", action="store_true", help="compute only the rows missing from --out")
    q.add_argument("--json", action="store_true", help="print the result as JSON on stdout and nothing else")
    q.set_defaults(func=cmd_sweep)

    q = sub.add_parser("view", help="open a recording in the rerun viewer",
                       description="Open a recording in the rerun viewer. Without a display (no DISPLAY or "
                                   "WAYLAND_DISPLAY) it prints a text summary instead and says how to use --web.")
    q.add_argument("path", metavar="PATH", help="a .rrd recording")
    g = q.add_mutually_exclusive_group()
    g.add_argument("--web", action="store_true",
                   help="serve rerun's web viewer instead of opening a window (open the printed URL in a browser)")
    g.add_argument("--summary", action="store_true",
                   help="print a text summary of the recording (entities, samples, time range, the run summary)")
    q.set_defaults(func=cmd_view)

    q = sub.add_parser("section", help="properties of a cross-section (area, centroid, principal axes)",
                       description="SHAPE is rectangle, circle, tube, i-beam, angle, channel or polygon; "
                                   "'rotframe section shapes' lists each shape's parameters and defaults.")
    q.add_argument("shape", metavar="SHAPE", help="a shape name, or 'shapes' to list them")
    q.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help="a dimension of the shape: metres, or a quantity string such as '4 inch'")
    q.add_argument("--png", metavar="PATH", default=None, help="write a drawing of the section")
    q.add_argument("--json", action="store_true", help="print one JSON object on stdout and nothing else")
    q.set_defaults(func=cmd_section)
    return p


# ---------------------------------------------------------------------------
# commands
# ---------------------------------------------------------------------------


def cmd_list(args) -> int:
    import tomllib

    from rotframe.scenario import scenario_dir

    rows = []
    for path in sorted(scenario_dir().glob("*.toml")):
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except (OSError, tomllib.TOMLDecodeError) as exc:
            rows.append({"name": path.stem, "title": f"(unreadable: {exc})"})
            continue
        rows.append({"name": data.get("name", path.stem), "title": data.get("title", ""),
                     "model": data.get("model", []), "path": str(path)})
    if args.json:
        print(json.dumps(rows))
    else:
        width = max((len(r["name"]) for r in rows), default=4)
        for r in rows:
            print(f"{r['name']:<{width}}  {r['title']}")
    return EXIT_OK


def cmd_show(args) -> int:
    from rotframe import scenario as sc

    scn = sc.load(args.name)
    print(f"{scn.name}: {scn.title}\n")
    if scn.description:
        print(scn.description + "\n")
    print(f"model terms: {', '.join(scn.model) or '(none)'}")
    if scn.optional_terms:
        print(f"optional terms (--audit toggles them): {', '.join(scn.optional_terms)}")
    from rotframe import scenes

    methods = getattr(scenes.get(scn.scene), "METHODS", None)
    run = {k: v for k, v in scn.run.items() if v is not None}
    print("run: " + ", ".join(f"{k} = {v}" for k, v in run.items()))
    if methods:
        print(f"methods: {', '.join(methods)}")
    print("\nparameters (--set KEY=VALUE):")
    width = max((len(k) for k in scn.parameters), default=4)
    for key, p in scn.parameters.items():
        print(f"  {key:<{width}}  {p.describe():<28}  {p.doc}")
    return EXIT_OK


def cmd_run(args) -> int:
    from rotframe import runner, scenario as sc, scenes
    from rotframe.errors import IntegrationError
    from rotframe.integrators import RunInterrupted

    sets = _parse_sets(args.sets)
    scn = sc.load(args.name)
    values = scn.with_values(sets)
    out = None if args.no_record else (args.out or str(_default_recording(scn.name)))
    if out is not None:
        _check_writable(out)
    _check_outputs(args)
    _install_sigterm()
    progress = _Progress(enabled=sys.stderr.isatty() and not args.json)
    scenes.get(scn.scene)  # import the scene (and astropy, numba) before the clock starts
    t0 = time.perf_counter()
    status = EXIT_OK
    message = None
    try:
        result = runner.simulate(scn, values, method=args.method, progress=progress)
    except IntegrationError as exc:
        status = EXIT_NUMERICAL
        result = exc.partial
        message = f"numerical failure: {exc} (simulated time reached: {exc.t_reached:.6g} s)"
    except RunInterrupted as exc:
        status = 143 if _TERMINATED[0] else 130
        result = exc.partial
        reached = result.trajectory.t_reached if result is not None else 0.0
        message = f"{'terminated' if _TERMINATED[0] else 'interrupted'} at simulated time {reached:.6g} s"
    finally:
        progress.close()
    simulate_s = time.perf_counter() - t0
    if result is None:
        _error((message or "run failed") + "; nothing was computed, so nothing was recorded")
        return status
    try:
        summary = runner.summarize(scn, values, result, {"simulate_s": simulate_s})
    except Exception:
        if status == EXIT_OK:
            raise
        summary = runner.summarize_minimal(scn, values, result, {"simulate_s": simulate_s})
    record_s = 0.0
    if out is not None:
        t1 = time.perf_counter()
        final = runner.record_result(scn, values, result, summary, out, complete=status == EXIT_OK)
        record_s = time.perf_counter() - t1
        summary["recording"] = str(final)
    compile_s = float(getattr(result.trajectory, "extras", {}).get("compile_s", 0.0))
    summary["timing"].update({"compile_s": compile_s, "simulate_s": simulate_s - compile_s,
                              "record_s": record_s, "total_s": time.perf_counter() - _T_START})
    summary["units"] = _units(scn, summary)
    _write_outputs(args, scn, values, result, summary)
    if args.audit and status == EXIT_OK:
        from rotframe.audit import audit

        summary["audit"] = audit(scn, values, result, summary, method=args.method)
    if args.json:
        print(json.dumps(_jsonable(summary)))
    else:
        print(_format_summary(scn, summary))
    if message:
        where = f"; the recording up to then is in {summary['recording']}" if summary.get("recording") else ""
        _error(message + where)
    return status


def cmd_bench(args) -> int:
    from rotframe.bench import main as bench_main

    return bench_main(args)


def cmd_sweep(args) -> int:
    from rotframe.sweep import main as sweep_main

    return sweep_main(args)


def cmd_view(args) -> int:
    import subprocess

    if not os.path.isfile(args.path):
        raise _input_error(f"view: no recording at {args.path!r}")
    if args.summary:
        from rotframe.recording_summary import describe

        print(describe(args.path))
        return EXIT_OK
    if args.web:
        return subprocess.call([sys.executable, "-m", "rerun", "--web-viewer", args.path])
    if not _has_display():
        from rotframe.recording_summary import describe

        print(f"rotframe: view: no display here (DISPLAY and WAYLAND_DISPLAY are unset), so a text summary "
              f"follows; 'rotframe view {args.path} --web' serves rerun's web viewer to a browser", file=sys.stderr)
        print(describe(args.path))
        return EXIT_OK
    return subprocess.call([sys.executable, "-m", "rerun", args.path])


def _has_display() -> bool:
    """True where a window can open: macOS and Windows, or X11/Wayland with a display set."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def cmd_section(args) -> int:
    from rotframe.section_cli import run_section, shapes_help

    if args.shape == "shapes":
        print(shapes_help())
        return EXIT_OK
    return run_section(args.shape, args.sets, args.png, args.json)


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------


_TERMINATED = [False]


def _install_sigterm():
    def handler(signum, frame):
        _TERMINATED[0] = True
        raise _Terminated()

    try:
        signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread
        pass


def _parse_sets(items):
    sets = {}
    for item in items:
        if "=" not in item:
            raise _input_error(f"--set {item!r}: expected KEY=VALUE")
        key, value = item.split("=", 1)
        sets[key.strip()] = value.strip()
    return sets


def _default_recording(name):
    from pathlib import Path

    return Path("recordings") / f"{name}.rrd"


def _check_writable(out):
    folder = os.path.dirname(os.path.abspath(out)) or "."
    if not out.endswith(".rrd"):
        raise _input_error(f"--out {out!r}: a recording path must end in .rrd")
    if os.path.exists(folder) and not os.access(folder, os.W_OK):
        raise _input_error(f"--out {out!r}: folder {folder!r} is not writable")
    if os.path.exists(folder) and not os.path.isdir(folder):
        raise _input_error(f"--out {out!r}: {folder!r} is not a folder")


def _check_outputs(args):
    """Refuse a bad --export or --png path before the run starts."""
    from rotframe.export import FORMATS

    export, png = getattr(args, "export", None), getattr(args, "png", None)
    if export is not None and os.path.splitext(export)[1].lower() not in FORMATS:
        raise _input_error(f"--export {export!r}: the file must end in {', '.join(FORMATS)}")
    if png is not None and not png.lower().endswith(".png"):
        raise _input_error(f"--png {png!r}: the file must end in .png")


def _units(scn, summary):
    from rotframe.units import summary_units

    return summary_units(scn.parameters, summary)


def _write_outputs(args, scn, values, result, summary):
    """--export and --png: the trajectory and a picture, from the same Result the Python API gives."""
    if not (getattr(args, "export", None) or getattr(args, "png", None)):
        return
    from rotframe.api import Result

    res = Result(scn, values, result, summary)
    if args.export:
        summary["export"] = str(res.export(args.export))
    if args.png:
        import matplotlib

        matplotlib.use("Agg")
        res.plot(args.png)
        summary["png"] = args.png


def _input_error(message):
    from rotframe.errors import ScenarioError

    return ScenarioError(message)


def _error(message):
    print(f"rotframe: error: {message}", file=sys.stderr)


def _jsonable(obj):
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if hasattr(obj, "item") and callable(obj.item):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None  # JSON has no inf or nan: an infinite period (no rotation) or a missing value
    return obj


def _format_summary(scn, s) -> str:
    """The run summary as a text table; each theory is named and each warning has its own line."""
    lines = [f"{scn.name}: {scn.title}"]
    params = ", ".join(f"{k}={_short(v)}{(' ' + scn.parameters[k].unit) if k in scn.parameters and scn.parameters[k].unit else ''}"
                       for k, v in s["params"].items())
    lines.append(f"  parameters  {params}")
    lines.append(f"  model       {', '.join(s['model'])}")
    lines.append(f"  method      {s['method']} ({s['steps']} steps)")
    lines.append("  metric                          simulated        theory    rel. diff")
    for key, value in s["metrics"].items():
        theory = s["theory"].get(key)
        shown = _short(value) if _is_number(value) else "null"
        if _is_number(theory) and _is_number(value):
            diff = abs(value - theory) / abs(theory) if theory else abs(value - theory)
            lines.append(f"  {key:<30} {value:>11.6g}  {theory:>12.6g}  {diff:>10.2g}")
        elif _is_number(theory):
            lines.append(f"  {key:<30} {shown:>11}  {theory:>12.6g}")
        else:
            lines.append(f"  {key:<30} {shown:>11}")
    for key, value in s["diagnostics"].items():
        lines.append(f"  {key:<30} {_short(value) if value is not None else 'null':>11}")
    for key, what in s.get("theory_notes", {}).items():
        if key in s["theory"]:
            lines.append(f"  theory of {key}: {what}")
    for note in s.get("notes", []):
        lines.append(f"  note: {note}")
    for warning in s.get("warnings", []):
        lines.append(f"  warning: {warning}")
    if "audit" in s:
        lines.append(s["audit"]["text"])
    t = s["timing"]
    lines.append(f"  timing      simulate {t['simulate_s']:.3f} s (+ {t.get('compile_s', 0):.3f} s loading or "
                 f"compiling kernels), record {t['record_s']:.3f} s, total {t['total_s']:.3f} s")
    lines.append(f"  recording   {s['recording'] or '(none)'}")
    return "\n".join(lines)


def _is_number(v) -> bool:
    """A finite int or float (not a bool): what the table prints as a number."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _short(v):
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, list):
        return ",".join(_short(x) for x in v)
    return str(v)


class _Progress:
    """A progress bar on stderr, shown only once a run has taken more than a second."""

    def __init__(self, enabled=True, delay=1.0):
        self.enabled = enabled
        self.delay = delay
        self.start = time.perf_counter()
        self.shown = False

    def __call__(self, fraction):
        if not self.enabled:
            return
        elapsed = time.perf_counter() - self.start
        if elapsed < self.delay:
            return
        self.shown = True
        width = 30
        filled = int(round(width * min(max(fraction, 0.0), 1.0)))
        eta = elapsed * (1 - fraction) / fraction if fraction > 0 else float("nan")
        sys.stderr.write(f"\r  [{'#' * filled}{'.' * (width - filled)}] {100 * fraction:5.1f}%  "
                         f"{elapsed:6.1f} s elapsed, {eta:6.1f} s left ")
        sys.stderr.flush()

    def close(self):
        if self.shown:
            sys.stderr.write("\n")
            sys.stderr.flush()
