"""The ``rotframe`` command line's arguments: the parser, its sub-commands and value types.

Standard library only, so that ``rotframe --help`` stays instant. The commands themselves
live in `rotframe.app.cli`, which passes them in (`build_parser`).
"""

from __future__ import annotations

import argparse
import math
import os

__all__ = ["UsageError", "Parser", "build_parser", "add_limits", "add_threads", "add_device", "threads_count", "positive_count",
           "seed_value", "whole_count"]


class UsageError(Exception):
    """argparse's usage error, turned into one line and exit code 2."""


class Parser(argparse.ArgumentParser):
    def error(self, message):
        where = self.prog.partition(" ")[2]
        raise UsageError(f"{where + ': ' if where else ''}{message} (see '{self.prog} --help')")


def add_limits(q, rows=False):
    q.add_argument("--max-steps", type=positive_count, default=None, metavar="N",
                   help="refuse a run of more integration steps than N (default 2e9)")
    q.add_argument("--max-samples", type=positive_count, default=None, metavar="N",
                   help="refuse a run that keeps more output samples than N (default 5e6)")
    q.add_argument("--max-memory", type=positive_count, default=None, metavar="BYTES",
                   help="refuse a run whose arrays need more than BYTES in all (default 4e9)")
    if rows:
        q.add_argument("--max-rows", type=positive_count, default=None, metavar="N",
                       help="refuse a sweep of more rows than N (default 2e6)")


def add_threads(q, what):
    q.add_argument("--threads", type=threads_count, default=None, metavar="N",
                   help=f"threads for {what} (default: every core, {os.cpu_count() or 1} here); the results do not "
                        "depend on it")


def add_device(q, what):
    q.add_argument("--device", choices=("cpu", "gpu"), default=None,
                   help=f"where {what} run: cpu (default; every core) or gpu (a CUDA GPU, float64; the "
                        "fixed-step methods); gpu without a CUDA GPU is refused")


def threads_count(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number >= 1") from None
    if not (math.isfinite(value) and value == int(value) and value >= 1):
        raise argparse.ArgumentTypeError(f"{text!r} must be a whole number >= 1") from None
    return int(value)


def positive_count(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (value >= 1 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"{text!r} must be a finite number >= 1")
    return value


def seed_value(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 0 <= value < 2 ** 63:
        raise argparse.ArgumentTypeError(f"{value} is out of range; allowed 0 <= seed < 2**63")
    return value


def whole_count(text):
    try:
        value = int(text)
    except ValueError:
        try:
            f = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        if not (math.isfinite(f) and f == int(f)):
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        value = int(f)
    return value


def build_parser(commands):
    """The ``rotframe`` argument parser; ``commands`` maps each command name to its function (``func``)."""
    p = Parser(
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
    q.set_defaults(func=commands["list"])

    q = sub.add_parser("show", help="show a scenario's description, parameters and defaults")
    q.add_argument("name", metavar="NAME", help="a scenario name ('rotframe list') or a path to a .toml file")
    q.set_defaults(func=commands["show"])

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
    add_limits(q)
    add_threads(q, "ensembles of particles (a scene's run of a few particles uses one)")
    add_device(q, "ensembles of particles")
    q.set_defaults(func=commands["run"])

    q = sub.add_parser("bench", help="speed against error for every method")
    q.add_argument("names", nargs="*", metavar="NAME",
                   help="scenario problems, or ensemble, sweep, startup, record, user-force, gpu (default: all; "
                        "gpu only where a CUDA GPU is)")
    q.add_argument("--json", action="store_true", help="print a JSON list of rows on stdout and nothing else")
    q.add_argument("--quick", action="store_true", help="the smoke test: each problem's default method, plain scipy at one tolerance; named problems run every method on short ladders")
    q.add_argument("--plots", metavar="DIR", default=None, help="write work-precision PNGs to DIR")
    add_threads(q, "the all-core ensemble rows")
    q.set_defaults(func=commands["bench"])

    q = sub.add_parser("sweep", help="run a scenario over a grid or Monte Carlo samples of parameters")
    q.add_argument("name", metavar="NAME|FILE.toml", help="a scenario name ('rotframe list') or a path to a .toml file")
    q.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help="fix a parameter for every run, as in 'run'")
    q.add_argument("--grid", action="append", default=[], metavar="KEY=START:STOP:N",
                   help="N evenly spaced values from START to STOP (inclusive)")
    q.add_argument("--log-grid", action="append", default=[], metavar="KEY=START:STOP:N",
                   help="N logarithmically spaced values from START to STOP (inclusive, both > 0)")
    q.add_argument("--samples", type=whole_count, default=None, metavar="N", help="Monte Carlo samples")
    q.add_argument("--vary", action="append", default=[], metavar="KEY=normal(MEAN,SD)|uniform(LO,HI)",
                   help="draw KEY from a distribution for each Monte Carlo sample (with --samples)")
    q.add_argument("--seed", type=seed_value, default=0, metavar="S",
                   help="random seed of the Monte Carlo samples, 0 <= S < 2**63")
    q.add_argument("--method", metavar="M", help="integrator (see 'rotframe show NAME')")
    g = q.add_mutually_exclusive_group()
    g.add_argument("--workers", type=whole_count, default=None, metavar="N", help="a LocalCluster of N processes")
    g.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler, e.g. tcp://host:8786 "
                   "(default: $DASK_SCHEDULER_ADDRESS where set, else this process)")
    g.add_argument("--scheduler-file", metavar="PATH", default=None,
                   help="an existing Dask scheduler named by its file (dask scheduler --scheduler-file PATH)")
    q.add_argument("--task-timeout", type=float, default=None, metavar="S",
                   help="on Dask: fail the rows of a batch that runs longer than S seconds on a worker")
    q.add_argument("--out", metavar="PATH.parquet", default=None,
                   help="result table (default sweeps/<name>.parquet; plots and a recording go beside it)")
    q.add_argument("--resume", action="store_true", help="compute only the rows missing from --out")
    q.add_argument("--json", action="store_true", help="print the result as JSON on stdout and nothing else")
    add_limits(q, rows=True)
    add_threads(q, "vectorised ensemble batches (per batch; a LocalCluster of W workers shares the cores)")
    add_device(q, "vectorised ensemble batches (in this process)")
    q.set_defaults(func=commands["sweep"])

    q = sub.add_parser("view", help="open a recording in the rerun viewer",
                       description="Open a recording in the rerun viewer. Without a display (no DISPLAY or "
                                   "WAYLAND_DISPLAY) it prints a text summary instead and says how to use --web.")
    q.add_argument("path", metavar="PATH", help="a .rrd recording")
    q.add_argument("--bind", metavar="ADDRESS", default="127.0.0.1",
                   help="address the viewer's server listens on (default 127.0.0.1, this machine only)")
    g = q.add_mutually_exclusive_group()
    g.add_argument("--web", action="store_true",
                   help="serve rerun's web viewer instead of opening a window (open the printed URL in a browser)")
    g.add_argument("--summary", action="store_true",
                   help="print a text summary of the recording (entities, samples, time range, the run summary)")
    q.set_defaults(func=commands["view"])

    q = sub.add_parser("section", help="properties of a cross-section (area, centroid, principal axes)",
                       description="SHAPE is rectangle, circle, tube, i-beam, angle, channel or polygon; "
                                   "'rotframe section shapes' lists each shape's parameters and defaults.")
    q.add_argument("shape", metavar="SHAPE", help="a shape name, or 'shapes' to list them")
    q.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help="a dimension of the shape: metres, or a quantity string such as '4 inch'")
    q.add_argument("--png", metavar="PATH", default=None, help="write a drawing of the section")
    q.add_argument("--json", action="store_true", help="print one JSON object on stdout and nothing else")
    q.set_defaults(func=commands["section"])
    return p
