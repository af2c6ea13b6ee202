"""The ``rotframe`` command line.

Exit codes: 0 done; 2 bad input (one line on stderr naming the file, key, value
and what is allowed; no traceback); 3 numerical failure (the message gives the
simulated time reached; the recording keeps everything up to it); 130 / 143
interrupted by Ctrl-C / SIGTERM (the recording keeps what was computed); 1 an
internal error (one line; ``ROTFRAME_DEBUG=1`` shows the traceback).

Work is estimated before it starts (`rotframe.limits`: ``--max-steps``,
``--max-samples``, ``--max-rows``), outputs are checked before computing and
written atomically (`rotframe.app.outputs`), signals are handled per command
(`rotframe.app.signals`) and long work shows a progress line on a terminal
(`rotframe.app.progress`). With ``--json`` only the JSON document reaches stdout.

This module imports only the standard library at start-up: numpy, astropy,
numba and rerun are imported by the commands that need them, so that
``rotframe list`` and ``rotframe --help`` stay instant.
"""

from __future__ import annotations

import json
import os
import sys
import time
import warnings

from rotframe.app.arguments import UsageError
from rotframe.app.arguments import build_parser
from rotframe.app.messages import EXIT_INPUT, EXIT_INTERNAL, EXIT_NUMERICAL, EXIT_OK  # noqa: F401  (public here too)
from rotframe.app.messages import error as _error
from rotframe.app.messages import one_line as _one_line
from rotframe.app.options import jsonable as _jsonable
from rotframe.app.options import parse_sets as _parse_sets


def main(argv=None) -> int:
    """Run one command; returns its exit code (never raises for a user's error, a signal or an I/O error)."""
    from rotframe.app.signals import InterruptScope

    t_start = time.perf_counter()
    parser = build_parser({"list": cmd_list, "show": cmd_show, "run": cmd_run, "bench": cmd_bench,
                           "sweep": cmd_sweep, "view": cmd_view, "section": cmd_section})
    try:
        args = parser.parse_args(argv)
    except UsageError as exc:
        _error(str(exc))
        return EXIT_INPUT
    if not getattr(args, "command", None):
        parser.print_help()
        return EXIT_OK
    args.t_start = t_start
    code = EXIT_OK
    # from the command line (argv None) a signal after the work ends the process with the
    # command's own exit code, never a traceback from the interpreter's shutdown
    json_out = _JsonStdout(getattr(args, "json", False))
    with InterruptScope(final=argv is None) as scope, json_out, warnings.catch_warnings():
        if argv is None:
            # on the command line numpy's overflow warnings are not messages for the user: an
            # overflow that matters is caught as a non-finite value and reported in one line
            warnings.simplefilter("ignore", RuntimeWarning)
        args.scope = scope
        try:
            code = _dispatch(args)
        except KeyboardInterrupt as exc:
            scope.closing = True  # a second signal does not cut the one line short
            scope.note(exc)
            _error(f"{scope.verb}; stopped before any result was written")
            code = scope.exit_code
        finally:
            scope.exit_status = code
            scope.closing = True
    if json_out.failed is not None and code == EXIT_OK:
        if not isinstance(json_out.failed, BrokenPipeError):  # the reader went away (| head): nothing to say
            _error(f"cannot write the JSON document to stdout: "
                   f"{getattr(json_out.failed, 'strerror', None) or json_out.failed}")
        code = EXIT_INPUT
        scope.exit_status = code
    return code


def _dispatch(args) -> int:
    try:
        return args.func(args)
    except Exception as exc:  # noqa: BLE001 -- sorted by _failure, unless a signal caused it
        scope = getattr(args, "scope", None)
        if scope is None or not scope.interrupted:
            return _failure(exc)
        # a signal that arrived inside a library (numba compiling, an import) surfaces as whatever that
        # library raises: it is still the signal, answered with its exit code and one line
        _error(f"{scope.verb} (during {type(exc).__name__}); stopped before any result was written")
        return scope.exit_code


def _failure(exc) -> int:
    """The exit code and one line for an exception of the command (not a signal)."""
    from rotframe.errors import IntegrationError, RotframeError

    try:
        raise exc
    except IntegrationError as exc:
        _error(f"numerical failure: {_one_line(exc)}")
        return EXIT_NUMERICAL
    except RotframeError as exc:
        _error(_one_line(exc))
        return EXIT_INPUT
    except BrokenPipeError:  # the reader of stdout went away (``| head``): nothing more to say
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):
            pass
        return EXIT_INPUT
    except MemoryError:
        _error("out of memory; ask for less work (fewer samples, rows or a shorter duration)")
        return EXIT_NUMERICAL
    except OSError as exc:
        where = f" {exc.filename!r}" if getattr(exc, "filename", None) else ""
        _error(f"cannot read or write{where}: {exc.strerror or _one_line(exc)}")
        return EXIT_INPUT
    except (KeyboardInterrupt, SystemExit):
        raise
    except Exception as exc:  # noqa: BLE001 -- a bug: one line, the traceback only on request
        from rotframe.app.optional import missing_package

        message = missing_package(exc)  # an optional package broken at import, where no need() guarded it
        if message is not None:
            _error(message)
            return EXIT_INPUT
        if os.environ.get("ROTFRAME_DEBUG"):
            raise
        _error(f"internal error ({type(exc).__name__}: {_one_line(exc)}); set ROTFRAME_DEBUG=1 for the traceback "
               "and please report it")
        return EXIT_INTERNAL



class _JsonStdout:
    """With --json, file descriptor 1 is pointed at stderr while a command runs.

    Only the JSON document itself goes to the real stdout (through ``sys.stdout``,
    which writes to a saved copy of fd 1): a C library (LAPACK, a BLAS, numba)
    printing to fd 1 cannot spoil it. In-process callers whose ``sys.stdout`` has no
    file descriptor (pytest's capsys) are left as they are.
    """

    def __init__(self, enabled):
        self.enabled = bool(enabled)
        self.saved = None
        #: the OSError of writing the document out, if that failed
        self.failed = None

    def __enter__(self):
        if not self.enabled:
            return self
        try:
            if sys.stdout.fileno() != 1:
                return self
            sys.stdout.flush()
            self.saved = os.dup(1)
            os.dup2(2, 1)
        except (AttributeError, ValueError, OSError):
            self.saved = None
            return self
        self._old = sys.stdout
        sys.stdout = open(self.saved, "w", closefd=False, encoding=getattr(self._old, "encoding", None) or "utf-8")
        return self

    def __exit__(self, *exc):
        if self.saved is not None:
            try:
                sys.stdout.flush()
            except (OSError, ValueError) as err:  # a full disk, /dev/full: the command reports it in one line
                self.failed = err
            try:
                sys.stdout.close()
            except (OSError, ValueError):  # the same write failing again: reported once
                pass
            sys.stdout = self._old
            os.dup2(self.saved, 1)
            os.close(self.saved)
            self.saved = None
        return False


# ---------------------------------------------------------------------------
# commands
# ---------------------------------------------------------------------------


def cmd_list(args) -> int:
    import tomllib

    from rotframe.app.scenario import scenario_dir
    from rotframe.scenes import SCENARIO_FILES, load_plugins

    load_plugins()  # scenes registered by $ROTFRAME_PLUGINS, with their scenario files, are listed too
    paths = {p.stem: p for p in scenario_dir().glob("*.toml")}
    paths.update(SCENARIO_FILES)
    rows = []
    for path in (paths[k] for k in sorted(paths)):
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
    from rotframe.app import scenario as sc
    scn = sc.load(args.name)
    print(f"{scn.name}: {scn.title}\n")
    if scn.description:
        print(scn.description + "\n")
    print(f"model terms: {', '.join(scn.model) or '(none)'}")
    if scn.optional_terms:
        print(f"optional terms (--audit toggles them): {', '.join(scn.optional_terms)}")
    from rotframe import scenes

    scene = scenes.get(scn.scene)
    methods = getattr(scene, "METHODS", None)
    run = {k: v for k, v in scn.run.items() if v is not None}
    print("run: " + ", ".join(f"{k} = {v}" for k, v in run.items()))
    default = getattr(scene, "DEFAULT_METHOD", None)
    if default and "method" not in run:
        print(f"default method: {default}")
    if methods:
        print(f"methods: {', '.join(methods)}")
    print("\nparameters (--set KEY=VALUE):")
    width = max((len(k) for k in scn.parameters), default=4)
    for key, p in scn.parameters.items():
        print(f"  {key:<{width}}  {p.describe():<28}  {p.doc}")
    return EXIT_OK


def _limits(args):
    from rotframe import limits

    return limits.applied(limits.current().with_overrides(
        max_steps=getattr(args, "max_steps", None), max_samples=getattr(args, "max_samples", None),
        max_rows=getattr(args, "max_rows", None), max_memory=getattr(args, "max_memory", None)))


def _threads(args):
    """The command's ``--threads`` in force for the command only (`rotframe.particles.ensemble.threads_scope`)."""
    from rotframe.particles.ensemble import threads_scope

    return threads_scope(getattr(args, "threads", None))


def _device(args):
    """The command's ``--device`` for its ensembles, checked (gpu without one: exit 2, one line)."""
    from rotframe.particles.ensemble import device_scope

    return device_scope(getattr(args, "device", None))


def cmd_run(args) -> int:
    with _limits(args), _threads(args), _device(args):
        return _run(args)


def _run(args) -> int:
    from rotframe import scenes
    from rotframe.app import runner
    from rotframe.app import scenario as sc
    from rotframe.particles.integrators import RunInterrupted
    from rotframe.errors import IntegrationError
    from rotframe.app.progress import Progress
    from rotframe.app.record import default_path
    from rotframe.app.summary_text import format_summary

    scope = args.scope
    sets = _parse_sets(args.sets)
    scn = sc.load(args.name)
    values = scn.with_values(sets)
    out = None if args.no_record else (args.out or str(default_path(scn.name)))
    if out is not None:
        _check_writable(out)
    _check_outputs(args)
    progress = Progress("run", "%", enabled=not args.json)
    scenes.get(scn.scene)  # import the scene (and astropy, numba) before the clock starts
    t0 = time.perf_counter()
    status = EXIT_OK
    message = None
    try:
        result = runner.simulate(scn, values, method=args.method, progress=progress)
    except IntegrationError as exc:
        status = EXIT_NUMERICAL
        result = exc.partial
        message = f"numerical failure: {_one_line(exc)} (simulated time reached: {exc.t_reached:.6g} s)"
    except RunInterrupted as exc:
        scope.interrupted = True
        status = scope.exit_code
        result = exc.partial
        reached = result.trajectory.t_reached if result is not None else 0.0
        message = f"{scope.verb} at simulated time {reached:.6g} s"
    except KeyboardInterrupt as exc:  # while the scene prepared (compiling, an oracle): nothing to keep
        scope.note(exc)
        _error(f"{scope.verb} before the integration started; nothing was recorded")
        return scope.exit_code
    finally:
        progress.close()
    simulate_s = time.perf_counter() - t0
    if result is None:
        _error((message or "run failed") + "; nothing was computed, so nothing was recorded")
        return status
    try:
        summary = runner.summarize(scn, values, result, {"simulate_s": simulate_s}, given=sets)
    except KeyboardInterrupt as exc:  # during the analysis: keep the trajectory as a partial recording
        scope.note(exc)
        status = scope.exit_code
        message = message or f"{scope.verb} during the analysis"
        summary = runner.summarize_minimal(scn, values, result, {"simulate_s": simulate_s})
    except Exception:
        if status == EXIT_OK:
            raise
        summary = runner.summarize_minimal(scn, values, result, {"simulate_s": simulate_s})
    record_s = 0.0
    if out is not None:
        t1 = time.perf_counter()
        try:
            final = runner.record_result(scn, values, result, summary, out, complete=status == EXIT_OK)
        except KeyboardInterrupt as exc:  # during the recording: what there is was written as a partial
            scope.note(exc)
            status = scope.exit_code
            message = message or f"{scope.verb} while recording"
            final = getattr(exc, "recording", None)
            if final is None:
                final = runner.record_result(scn, values, result, summary, out, complete=False)
        record_s = time.perf_counter() - t1
        summary["recording"] = str(final)
    compile_s = float(getattr(result.trajectory, "extras", {}).get("compile_s", 0.0))
    summary["timing"].update({"compile_s": compile_s, "simulate_s": simulate_s - compile_s,
                              "record_s": record_s, "total_s": time.perf_counter() - args.t_start})
    summary["units"] = _units(scn, summary)
    _write_outputs(args, scn, values, result, summary)
    if args.audit and status == EXIT_OK:
        from rotframe.app.audit import audit

        try:
            summary["audit"] = audit(scn, values, result, summary, method=args.method)
        except KeyboardInterrupt as exc:  # the run and its recording are complete; the audit is dropped
            scope.note(exc)
            status = scope.exit_code
            message = f"{scope.verb} during the audit (the run itself is complete)"
    if args.json:
        print(json.dumps(_jsonable(summary)))
    else:
        print(format_summary(scn, summary))
    if message:
        where = f"; the recording up to then is in {summary['recording']}" if summary.get("recording") else ""
        _error(message + where)
    return status


def cmd_bench(args) -> int:
    from rotframe.app.bench import main as bench_main

    if args.plots:
        from rotframe.app.outputs import check_output_dir

        check_output_dir(args.plots, "--plots")

    with _threads(args):
        return bench_main(args)


def cmd_sweep(args) -> int:
    from rotframe.app.sweep import main as sweep_main

    with _limits(args), _threads(args), _device(args):
        return sweep_main(args)


def cmd_view(args) -> int:
    import subprocess

    path = args.path
    if not os.path.isfile(path):
        raise _input_error(f"view: no recording at {path!r}" + (" (a folder)" if os.path.isdir(path) else ""))
    _check_recording(path)
    bind = args.bind
    if not bind or any(c.isspace() for c in bind):
        raise _input_error(f"view --bind {bind!r}: expected an IP address such as 127.0.0.1")
    if args.summary:
        from rotframe.app.recording_summary import describe

        print(describe(path))
        return EXIT_OK
    if args.web:
        from rotframe.app.web_view import serve

        return serve(path, bind)  # the URL in one line; rerun's server stops with the command
    if not _has_display():
        from rotframe.app.recording_summary import describe

        print(f"rotframe: view: no display here (DISPLAY and WAYLAND_DISPLAY are unset), so a text summary "
              f"follows; 'rotframe view {path} --web' serves rerun's web viewer to a browser", file=sys.stderr)
        print(describe(path))
        return EXIT_OK
    return subprocess.call([sys.executable, "-m", "rerun", "--bind", bind, path])


def _check_recording(path):
    """A readable rerun recording: the RRD magic, then every chunk decodes."""
    try:
        with open(path, "rb") as f:
            head = f.read(4)
    except OSError as exc:
        raise _input_error(f"view: cannot read {path!r}: {exc.strerror or exc}") from None
    if head[:3] != b"RRF":
        raise _input_error(f"view: {path!r} is not a rerun recording (.rrd); allowed: a file written by "
                           "'rotframe run' or 'rotframe sweep'")
    import warnings

    from rerun.chunk import RrdReader

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "no footer": a truncated file, reported below if it does not decode
            for _ in RrdReader(str(path)).stream():
                pass
    except Exception as exc:  # noqa: BLE001 -- rerun raises RuntimeError/ValueError for damaged files
        raise _input_error(f"view: {path!r} is a damaged or truncated recording ({_one_line(exc)[:200]})") from None


def _has_display() -> bool:
    """True where a window can open: macOS and Windows, or X11/Wayland with a display set."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def cmd_section(args) -> int:
    from rotframe.app.section_cli import run_section, shapes_help

    if args.shape == "shapes":
        print(shapes_help())
        return EXIT_OK
    return run_section(args.shape, args.sets, args.png, args.json)


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------


def _check_writable(out):
    """The recording (and its partial) can be written: checked before any computing starts."""
    from rotframe.app.outputs import check_output_file
    from rotframe.app.record import partial_path

    check_output_file(out, "--out", ".rrd")
    partial = partial_path(out)
    if os.path.isdir(partial):
        raise _input_error(f"--out {out!r}: {str(partial)!r} (where an interrupted run goes) is a folder")


def _check_outputs(args):
    """Refuse a bad --export or --png path before the run starts (suffix, folder, writable)."""
    from rotframe.app.export import FORMATS
    from rotframe.app.outputs import check_output_file

    export, png = getattr(args, "export", None), getattr(args, "png", None)
    if export is not None:
        if os.path.splitext(export)[1].lower() not in FORMATS:
            raise _input_error(f"--export {export!r}: the file must end in {', '.join(FORMATS)}")
        check_output_file(export, "--export")
    if png is not None:
        check_output_file(png, "--png", ".png")
        from rotframe.app.plot import require_matplotlib

        require_matplotlib()  # before the run: a missing extra is a one-line error (exit 2), not a lost run


def _units(scn, summary):
    from rotframe.app.units import summary_units

    return summary_units(scn.parameters, summary)


def _write_outputs(args, scn, values, result, summary):
    """--export and --png: the trajectory and a picture, from the same Result the Python API gives."""
    if not (getattr(args, "export", None) or getattr(args, "png", None)):
        return
    from rotframe.app.api import Result

    res = Result(scn, values, result, summary)
    if args.export:
        summary["export"] = str(res.export(args.export))
    if args.png:
        res.plot(args.png)  # a pyplot-free Figure: no backend, no window
        summary["png"] = args.png


def _input_error(message):
    from rotframe.errors import ScenarioError

    return ScenarioError(message)
