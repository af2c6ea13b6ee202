"""Speed against error for every method on every scenario (``rotframe bench``).

For each problem (a scenario's equations, initial state and horizon) every
rotframe method runs over a ladder of step sizes or tolerances, and so do the
peers (`rotframe.app.bench.peers`): scipy's ``solve_ivp`` (RK45, DOP853, Radau,
LSODA) with an expert's scalar right-hand side, scipy DOP853 with a
numba-compiled right-hand side, and diffrax (Dopri8, Tsit5; whole solve
jit-compiled, CPU, 64-bit) where the ``bench`` extra is installed. Each row
gives the wall time of a run to the final state (median of repeats, after a
warm-up run that loads or compiles the kernels; that time is reported apart as
``compile_s``), the force evaluations, the final-state error against the
analytic solution or a reference run at much tighter tolerance (``error_kind``
says which) and the invariant error at the end of the run.

Everything is measured in one run on one machine, and claims are ratios:
``summary`` rows give, per problem and error level (1e-3, 1e-6, 1e-9), the
fastest rotframe run reaching that error, the fastest peer run reaching it,
and their ratio; ``speedup`` (text output) compares with plain scipy as before.

Modules: `problems` (the problems and ladders),
`measure` (timing rotframe and the scipy baselines),
`peers` (the peers' right-hand sides), `summary`
(error levels, speed-ups), `throughput` (ensemble, sweep, start-up,
recording), `gpu` (the GPU ensemble beside hand-written kernels and JAX) and
`report` (table, plots, JSON).
"""

from __future__ import annotations

import json
import math
import os

from rotframe.app.bench.measure import PEER_RTOLS, SCIPY_METHODS, Plan, planned_units, run_problem, timed  # noqa: F401
from rotframe.app.bench.problems import EXTRAS, PREPARED, Problem, attitude_error, problems  # noqa: F401
from rotframe.app.bench.report import environment, json_rows, plot, table
from rotframe.app.bench.summary import LEVELS, is_peer, level_summary, problem_keys, speedups  # noqa: F401
from rotframe.app.bench.gpu import gpu_rows
from rotframe.app.bench.throughput import ensemble_rows, record_rows, startup_rows, sweep_rows
from rotframe.app.bench.user_force import user_force_rows

__all__ = ["Problem", "problems", "run_bench", "smoke_runs", "level_summary", "speedups", "main"]

def run_bench(names=None, quick=False, progress=None, on_row=None):
    """All rows for the named benchmarks (default: every problem, ensemble, sweep, start-up, recording).

    ``quick``: short ladders, three repeats, plain scipy at one tolerance (no
    numba or diffrax peers), no sweep or start-up (they start processes). With
    no names it is the smoke test: every problem with its scene's default method
    only (`smoke_runs`) and the recording row, so that a first run compiles
    little; named problems run every method. ``progress(done, total, label)`` is called after each
    timed unit; ``on_row(row)`` with each row. Summary rows (``kind``
    "summary", one per problem and error level) close the list.
    """
    names = list(names or [])
    scenario_names = [n for n in names if n not in EXTRAS]
    rows = []
    notes = []
    plan = Plan(quick, progress)
    probs = problems(scenario_names or None, quick=quick) if (scenario_names or not names) else []
    smoke = quick and not names
    if smoke:
        for p in probs:
            p.runs = smoke_runs(p)
    from rotframe.app.bench import peers

    peers_ok, why = peers.diffrax_available()
    if not quick and not peers_ok:
        notes.append(why)
    if quick:
        notes.append("quick: plain scipy at rtol 1e-6 only (no numba or diffrax peers), short ladders, 3 repeats, "
                     "no sweep or start-up" + ("; the smoke test: each problem's default method only, and no "
                                               "ensemble or user-force rows (name them to run them)" if smoke else ""))
    skipped = ("sweep", "startup") + (("ensemble", "user-force", "gpu") if smoke else ())
    extras = [n for n in EXTRAS if (not names and not (quick and n in skipped)) or n in names]
    plan.total = sum(planned_units(p, quick, peers_ok) for p in probs) + len(extras)
    for p in probs:
        rows.extend(run_problem(p, on_row, plan))
        notes.extend(f"{p.scenario}: {n}" for n in p.notes)
    if "gpu" in extras and "gpu" not in names:
        from rotframe.particles.threads import gpu_available

        if not gpu_available():  # named, it is refused in one line (exit 2); in the whole bench, a note
            extras.remove("gpu")
            notes.append("gpu: not measured: no CUDA GPU here (numba.cuda.is_available() is False)")
    for name in extras:
        fn = {"ensemble": lambda: ensemble_rows(quick), "sweep": lambda: sweep_rows(quick),
              "startup": startup_rows, "record": lambda: record_rows(10**5 if quick else 10**6),
              "user-force": lambda: user_force_rows(quick), "gpu": lambda: gpu_rows(quick)}[name]
        rows.extend(fn())
        plan.step(name)
    rows.extend(level_summary(rows))
    for n in notes:
        rows.append({"scenario": "notes", "method": "note", "setting": None, "wall_s": 0.0, "error": math.nan,
                     "error_kind": "note", "nfev": 0, "kind": "note", "note": n})
    return rows


def smoke_runs(p):
    """The runs of problem ``p`` that `run_bench`'s smoke test keeps: its scene's default method.

    The default method is the first word of the scene's ``DEFAULT_METHOD`` (which may
    say more: "dop853 for the full pendulum; ..."), where the problem runs it, else
    the problem's first method.
    """
    from rotframe import scenes
    from rotframe.app import scenario

    said = getattr(scenes.get(scenario.load(p.scenario).scene), "DEFAULT_METHOD", None) or ""
    default = said.split()[0] if said.split() else None
    method = default if default in p.runs else next(iter(p.runs))
    return {method: p.runs[method]}


def main(args) -> int:
    from rotframe.app.progress import Progress

    if getattr(args, "plots", None):
        from rotframe.app.plot import require_matplotlib

        require_matplotlib()  # the plot extra, checked before the bench runs
    bar = Progress("bench", "runs", enabled=not args.json)  # on a terminal only, never with --json

    def progress(done, total, label):
        bar.label = f"bench {label[:40]}"
        bar.update(done, total)

    try:
        rows = run_bench(args.names, quick=args.quick, progress=progress)
    finally:
        bar.close()
    env = environment()
    rows.append({"scenario": "environment", "method": "environment", "setting": None, "wall_s": 0.0,
                 "error": math.nan, "error_kind": "environment", "nfev": 0, "kind": "environment", **env})
    speed = speedups(rows)
    plots = plot(rows, args.plots) if getattr(args, "plots", None) else []
    if plots:  # keep the numbers beside the pictures
        from rotframe.app.outputs import write_text_atomic

        write_text_atomic(os.path.join(args.plots, "bench.json"), json.dumps(json_rows(rows), indent=0), "bench table")
        write_text_atomic(os.path.join(args.plots, "bench.txt"), table(rows, speed) + "\n", "bench table")
    if args.json:
        print(json.dumps(json_rows(rows)))
    else:
        print(table(rows, speed))
        print("machine: " + ", ".join(f"{k} {v}" for k, v in env.items()))
        for p in plots:
            print(f"plot: {p}")
    return 0
