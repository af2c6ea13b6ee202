"""Timing the ladders: rotframe's methods, then the peers (plain scipy, scipy + numba, diffrax).

Each timed unit is the median wall time of repeats that fit in a budget, after a
warm-up run whose time (loading or compiling kernels) is reported apart as
``compile_s``. A scipy baseline that runs past its budget is stopped and noted.
"""

from __future__ import annotations

import math
import statistics
import time

from rotframe.app.bench.problems import PREPARED

__all__ = ["SCIPY_METHODS", "SCIPY_METHODS_QUICK", "PEER_RTOLS", "MIN_REPEAT_S", "Plan", "timed", "planned_units", "run_problem"]


SCIPY_METHODS = ("RK45", "DOP853", "Radau", "LSODA")


#: tolerances of the strong peers (scipy + numba, diffrax): half decades from 1e-3 to 1e-13, as fine as
#: rotframe's finest ladders, so that no level is lost to a coarse ladder
PEER_RTOLS = (1e-3,) + tuple(float(f"{m}e-{k}") for k in range(4, 14) for m in (3, 1))


#: A repeat of a short run calls it this many seconds' worth of times (timeit's autorange):
#: one call of a 20-microsecond run is within the timer's and the scheduler's jitter.
MIN_REPEAT_S = 0.02


def timed(fn, budget=2.0, max_repeats=5):
    """(median wall time of one call, last result) over repeats that fit in ``budget`` seconds.

    At most ``max_repeats`` repeats. A run shorter than `MIN_REPEAT_S` (judged from its
    first call) is called ``k`` times a repeat, enough to fill that, and each repeat's time is
    divided by ``k`` -- the same rule for rotframe and for every peer.
    """
    t0 = time.perf_counter()
    result = fn()
    first = time.perf_counter() - t0
    k = 1 if first >= MIN_REPEAT_S else min(10_000, max(1, int(MIN_REPEAT_S / max(first, 1e-7))))
    times = [] if k > 1 else [first]
    while len(times) < max_repeats and sum(times) * k <= budget and not (len(times) >= 3 and sum(times) * k > budget / 4):
        t0 = time.perf_counter()
        for _ in range(k):
            result = fn()
        times.append((time.perf_counter() - t0) / k)
    return statistics.median(times), result


def timed_call(p, method, setting):
    """``(call, finish)`` for one rotframe run: ``call()`` is what is timed, ``finish(call())`` the run's triple.

    A prepared run's ``call`` is the user's call alone (``PreparedRun(...)(r0, v0)``), as a peer's
    timed call is its jit-compiled solve; picking the final state out of the samples happens in
    ``finish``, after the timing. A problem's runner offers that as ``run.prepared_call(method,
    setting)``; every other run times ``p.run`` itself.
    """
    prepared_call = getattr(p.run, "prepared_call", None)
    if prepared_call is not None and method.endswith(PREPARED):
        return prepared_call(method, setting)
    return (lambda: p.run(method, setting)), (lambda raw: raw)


class Plan:
    """Settings of a bench run: quick mode, and a ``progress(done, total, label)`` callback."""

    def __init__(self, quick=False, progress=None):
        self.quick = quick
        self.progress = progress
        self.budget = 0.3 if quick else 2.0
        self.repeats = 3 if quick else 5
        self.done = 0
        self.total = 0

    def step(self, label):
        self.done += 1
        if self.progress:
            self.progress(self.done, max(self.total, self.done), label)


def planned_units(p, quick, peers_ok):
    """How many timed units `run_problem` will do for ``p`` (for the progress bar)."""
    n = sum(len(s) for s in p.runs.values())
    n += len(SCIPY_METHODS_QUICK if quick else SCIPY_METHODS) * len(_scipy_rtols(p, quick))
    if not quick:
        n += len(_peer_rtols(p))
        if peers_ok:
            n += len(_peer_rtols(p)) * 2
    return n


SCIPY_METHODS_QUICK = SCIPY_METHODS  # every baseline, at one tolerance


def _scipy_rtols(p, quick):
    return (1e-6,) if quick else p.scipy_rtols


def _peer_rtols(p):
    return tuple(r for r in PEER_RTOLS if r >= min(p.scipy_rtols) / 10)


def run_problem(p, progress=None, plan=None):
    """Rows for one problem: rotframe methods, then the peers (plain scipy, scipy + numba, diffrax)."""
    plan = plan or Plan(progress=None)
    rows = []

    def emit(row):
        rows.append(row)
        if progress:
            progress(row)
        plan.step(f"{p.scenario} {row['method']}")

    from rotframe.errors import IntegrationError

    for method, settings in p.runs.items():
        compile_s = None
        for s in settings:
            try:
                if compile_s is None:
                    t0 = time.perf_counter()
                    p.run(method, s)  # warm-up: loads or compiles the kernels
                    compile_s = time.perf_counter() - t0
                elif method.endswith(PREPARED):
                    p.run(method, s)  # prepares (untimed, like a peer's compilation)
                call, finish = timed_call(p, method, s)
                wall, raw = timed(call, plan.budget, plan.repeats)
                y, nfev, inv = finish(raw)
            except IntegrationError as exc:  # an unstable setting is a result, not the end of the bench
                row = _row(p, method, s, math.nan, math.inf, 0, None, family="rotframe")
                row["note"] = f"failed: {str(exc).splitlines()[0]}"
                emit(row)
                continue
            inv = inv() if callable(inv) else inv  # the invariant is measured after the timing, as for the peers
            emit(_row(p, method, s, wall, p.error(y), nfev, inv, compile_s=compile_s or None, family="rotframe"))
            compile_s = 0.0
    from scipy.integrate import solve_ivp

    scale = None
    if p.spec is not None:
        from rotframe.app.bench.peers import atol_scale

        scale = atol_scale(p.spec, p.y0)
    for method in (SCIPY_METHODS_QUICK if plan.quick else SCIPY_METHODS):
        _scipy_ladder(p, f"scipy-{method}", p.rhs, method, _scipy_rtols(p, plan.quick), scale, plan, emit,
                      solve_ivp)
    if plan.quick or p.spec is None:
        return rows
    from rotframe.app.bench import peers

    t0 = time.perf_counter()
    rhs = peers.numba_rhs(p.spec)
    rhs(0.0, p.y0)
    compile_s = time.perf_counter() - t0
    _scipy_ladder(p, "scipy-numba-DOP853", rhs, "DOP853", _peer_rtols(p), scale, plan, emit, solve_ivp,
                  compile_s=compile_s)
    ok, why = peers.diffrax_available()
    if not ok:
        p.notes.append(why)
        return rows
    for solver in peers.DIFFRAX_SOLVERS:
        run, compile_s = peers.diffrax_solver(p.spec, solver, p.t_end, p.y0, scale)
        for rtol in _peer_rtols(p):
            first = time.perf_counter()
            run(rtol)
            first = time.perf_counter() - first
            if first > p.scipy_budget_s:
                p.notes.append(f"diffrax-{solver} stopped at rtol {rtol:.0e} (over the {p.scipy_budget_s:g} s budget)")
                break
            call, finish = run.timed_call(rtol)  # the jit-compiled solve; the conversion to numpy after
            wall, raw = timed(call, plan.budget, plan.repeats)
            y, nfev = finish(raw)
            emit(_row(p, f"diffrax-{solver}", rtol, wall, p.error(y), nfev, None, compile_s=compile_s, family="peer"))
            compile_s = None
            if first > p.scipy_budget_s / 3:
                break
    return rows


def _scipy_ladder(p, name, rhs_fn, method, rtols, scale, plan, emit, solve_ivp, compile_s=None):
    budget = min(p.scipy_budget_s, 3.0) if plan.quick else p.scipy_budget_s
    for rtol in rtols:
        rhs = _with_deadline(rhs_fn, budget)
        atol = p.atol if scale is None else rtol * scale

        def solve():
            rhs.reset()
            return solve_ivp(rhs, (0.0, p.t_end), p.y0, method=method, rtol=rtol, atol=atol)

        t0 = time.perf_counter()
        try:
            sol = solve()
        except _OverBudget:
            row = _row(p, name, rtol, time.perf_counter() - t0, math.nan, rhs.calls, None, family="peer")
            row["note"] = f"stopped after {budget:g} s (over the budget)"
            emit(row)
            break  # tighter tolerances would take longer still
        first = time.perf_counter() - t0
        wall, sol = (first, sol) if first > 1.0 else timed(solve, plan.budget, plan.repeats)
        ok = sol.status == 0
        inv = p.invariant(sol.t[[0, -1]], sol.y.T[[0, -1]]) if ok else None
        emit(_row(p, name, rtol, wall, p.error(sol.y[:, -1]) if ok else math.nan, sol.nfev, inv,
                  compile_s=compile_s, family="peer"))
        compile_s = None
        if first > budget / 3:
            break  # the next, tighter tolerance would exceed the budget


class _OverBudget(Exception):
    """A scipy baseline ran past its time budget."""


def _with_deadline(rhs, budget_s):
    """Wrap a right-hand side so that a solve stops (``_OverBudget``) after ``budget_s`` seconds."""

    class Wrapped:
        def reset(self):
            self.calls = 0
            self.deadline = time.perf_counter() + budget_s

        def __call__(self, t, y):
            self.calls += 1
            if self.calls % 512 == 0 and time.perf_counter() > self.deadline:
                raise _OverBudget()
            return rhs(t, y)

    wrapped = Wrapped()
    wrapped.reset()
    return wrapped


def _row(p, method, setting, wall, error, nfev, inv, compile_s=None, family="rotframe"):
    row = {"scenario": p.scenario, "method": method, "setting": setting, "wall_s": wall, "error": error,
           "error_kind": p.error_kind, "nfev": int(nfev), "horizon": p.horizon, "invariant_error": inv,
           "family": family}
    if p.ref_error:
        row["reference_error"] = p.ref_error
    if compile_s is not None:
        row["compile_s"] = compile_s
    return row
