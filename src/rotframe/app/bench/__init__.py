"""Speed against error for every method on every scenario (``rotframe bench``).

For each problem (a scenario's equations, initial state and horizon) every
rotframe method runs over a ladder of step sizes or tolerances, and so do the
peers (:mod:`rotframe.app.bench.peers`): scipy's ``solve_ivp`` (RK45, DOP853, Radau,
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
"""

from __future__ import annotations

import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Problem", "problems", "run_bench", "level_summary", "speedups", "main"]

SCIPY_METHODS = ("RK45", "DOP853", "Radau", "LSODA")
#: error levels of the summary
LEVELS = (1e-3, 1e-6, 1e-9)
#: tolerances of the diffrax and scipy-numba peers
PEER_RTOLS = tuple(10.0 ** -k for k in range(3, 14))


@dataclass
class Problem:
    """One benchmark problem.

    ``rhs(t, y)`` and ``y0`` are the equations for scipy; ``exact`` the final
    state to compare with; ``error(y)`` the final-state error (and its unit in
    ``error_kind``); ``invariant(Y)`` the worst invariant error over states
    ``Y`` (n, dim); ``runs`` maps a rotframe method to a list of settings and
    ``run(method, setting) -> (y_end, nfev, invariant_error)``, the invariant
    error as a function to call after the timing (or None).
    """

    scenario: str
    horizon: str
    t_end: float
    y0: np.ndarray
    rhs: object
    error: object
    error_kind: str
    invariant: object
    runs: dict
    run: object
    atol: float = 1e-12
    scipy_budget_s: float = 20.0
    scipy_rtols: tuple = tuple(10.0 ** -k for k in range(3, 14))
    notes: list = field(default_factory=list)
    spec: dict = None  # the equations for the peers (rotframe.app.bench.peers)
    ref_error: float = 0.0  # accuracy of the reference itself: smaller errors are not resolved


# ---------------------------------------------------------------------------
# problems
# ---------------------------------------------------------------------------


def problems(names=None, quick=False):
    """The benchmark problems (for ``names``, or all)."""
    makers = {"turntable": _turntable, "tower-drop": _tower_drop, "foucault": _foucault,
              "dzhanibekov": _dzhanibekov, "heavy-top": _heavy_top}
    names = list(names or makers)
    unknown = [n for n in names if n not in makers and n not in EXTRAS]
    if unknown:
        from rotframe.errors import ScenarioError

        raise ScenarioError(f"bench: no benchmark for {unknown[0]!r}; available: "
                            f"{', '.join(list(makers) + list(EXTRAS))}")
    out = []
    for n in names:
        if n in makers:
            out.extend(makers[n](quick))
    return out


#: benchmarks that are not problems
EXTRAS = ("ensemble", "sweep", "startup", "record")


def _ladder(quick, full, short):
    return short if quick else full


#: suffix of a rotframe method run through rotframe.particles.prepared.PreparedRun (prepared once, untimed)
PREPARED = " prepared"


def _particle_runner(model, r0, v0, t_end, invariant_fn):
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.prepared import PreparedRun

    prepared = {}
    times = np.array([0.0, t_end])

    def run(method, setting):
        base = method.removesuffix(PREPARED)
        kw = {"rtol": setting} if base == "dop853" else {"step": setting}
        if method.endswith(PREPARED):
            pr = prepared.get((base, setting))
            if pr is None:
                pr = prepared[(base, setting)] = PreparedRun(model, base, t_end, **kw)
            r, v = pr(r0, v0)
            Y = np.concatenate([r[:, 0], v[:, 0]], axis=1)
            return Y[-1], pr.nfev, lambda: invariant_fn(times, Y)
        traj = integrate_particles(model, r0, v0, t_end, method=method, samples=1, **kw)
        Y = np.concatenate([traj.r[:, 0], traj.v[:, 0]], axis=1)
        return Y[-1], traj.nfev, lambda: invariant_fn(traj.times, Y)

    return run


def _with_prepared(runs, quick):
    """Add prepared-run ladders (the same settings) for dop853 and the first fixed-step method."""
    out = dict(runs)
    for m in ("dop853", "rk4") if not quick else ("dop853",):
        if m in runs:
            out[m + PREPARED] = runs[m]
    return out


def _turntable(quick):
    from rotframe.particles.model import OmegaSchedule, ParticleModel
    from rotframe.scenes.turntable import inertial_line

    w0, alpha, T = 1.0, 0.2, 4.0
    omega = OmegaSchedule.ramp([0, 0, 1], w0, alpha, T)
    model = ParticleModel(("coriolis", "centrifugal", "euler"), omega=omega)
    r0, v0 = np.array([2.0, 0.0, 0.0]), np.array([-1.0, 0.0, 0.0])
    r_end = inertial_line(omega, r0, v0, np.array([T]))[0]
    spec = {"kind": "particle", "w": (0.0, 0.0, 0.0), "g": (0.0, 0.0, 0.0), "ramp": (w0, alpha), "pendulum": None}

    def inertial_speed(t, Y):
        # the inertial speed |v + w x r| is constant on the exact solution
        w = (w0 + alpha * t)[:, None] * np.array([0.0, 0.0, 1.0])
        s = np.linalg.norm(Y[:, 3:] + np.cross(w, Y[:, :3]), axis=1)
        return float(np.max(np.abs(s / s[0] - 1)))

    steps = _ladder(quick, [4e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4], [1e-3])
    runs = _with_prepared({"splitting": steps, "splitting4": steps, "rk4": steps,
                           "dop853": _ladder(quick, [1e-4, 1e-6, 1e-8, 1e-10, 1e-12], [1e-8])}, quick)
    y0 = np.concatenate([r0, v0])
    from rotframe.app.bench.peers import python_rhs

    return [Problem("turntable", "4 s, 0.9 turns", T, y0, python_rhs(spec),
                    lambda y: float(np.linalg.norm(y[:3] - r_end)), "analytic: final position error (m)",
                    inertial_speed, runs, _particle_runner(model, r0, v0, T, inertial_speed), spec=spec)]


def _tower_drop(quick):
    from rotframe import earth
    from rotframe.app.bench.peers import python_rhs
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    lat = math.radians(50 + 53 / 60)
    g = float(earth.normal_gravity(lat))
    w = earth.omega_enu(lat)
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=np.array([0, 0, -g]))
    T = 5.0
    r0, v0 = np.array([0, 0, 158.5]), np.zeros(3)
    exact = integrate_particles(model, r0, v0, T, method="exact", samples=1)
    y_exact = np.concatenate([exact.r[-1, 0], exact.v[-1, 0]])
    spec = {"kind": "particle", "w": tuple(w), "g": (0.0, 0.0, -g), "ramp": None, "pendulum": None}

    def energy(t, Y):
        e = 0.5 * np.sum(Y[:, 3:] ** 2, axis=1) + g * Y[:, 2]
        return float(np.max(np.abs(e - e[0])) / abs(e[0]))

    steps = _ladder(quick, [1e-1, 1e-2, 1e-3, 1e-4], [1e-2])
    runs = _with_prepared({"exact": [None], "splitting": steps, "rk4": steps,
                           "dop853": _ladder(quick, [1e-4, 1e-6, 1e-8, 1e-10, 1e-12], [1e-8])}, quick)
    base = _particle_runner(model, r0, v0, T, energy)

    def run(method, setting):
        if method == "exact":
            traj = integrate_particles(model, r0, v0, T, method="exact", samples=1)
            Y = np.concatenate([traj.r[:, 0], traj.v[:, 0]], axis=1)
            return Y[-1], 0, lambda: energy(traj.times, Y)
        return base(method, setting)

    return [Problem("tower-drop", "5 s fall", T, np.concatenate([r0, v0]), python_rhs(spec),
                    lambda y: float(np.linalg.norm(y[:3] - y_exact[:3])),
                    "analytic (exact propagator): final position error (m)", energy, runs, run, spec=spec)]


def _foucault(quick):
    from rotframe import earth
    from rotframe.app.bench.peers import python_rhs
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    lat = math.radians(48.846)
    g = float(earth.normal_gravity(lat))
    w = earth.omega_enu(lat)
    L, a = 67.0, 3.0
    T = 600.0 if quick else 3600.0
    pivot = np.array([0.0, 0.0, L])
    model = ParticleModel(("gravity", "coriolis", "pendulum"), omega=OmegaSchedule.constant(w),
                          g=np.array([0, 0, -g]), pendulum_length=L, pivot=pivot)
    r0, v0 = np.array([a, 0, L - math.sqrt(L * L - a * a)]), np.zeros(3)
    spec = {"kind": "particle", "w": tuple(w), "g": (0.0, 0.0, -g), "ramp": None, "pendulum": (L, tuple(pivot))}
    # reference: the 4th-order splitting at h = 2e-4 s. After 1 h it differs from the same at 4e-4 and
    # 1e-4 s, from rotframe's DOP853 at rtol 1e-13 and from scipy's DOP853 at rtol 1e-13 by 0.5 to 2.7e-9 m
    # (round-off over 1.8e7 steps and 2.2e5 periods): errors below 3e-9 m are not resolved. The quick
    # bench's 10 min at 1e-3 s has a smaller truncation error (splitting4 at 5e-3 s over 1 h is within
    # 1.4e-9 m of the fine reference) and is given the same floor
    ref = integrate_particles(model, r0, v0, T, method="splitting4", step=2e-4 if not quick else 1e-3, samples=1)
    y_ref = np.concatenate([ref.r[-1, 0], ref.v[-1, 0]])

    def constraint(t, Y):
        return float(np.max(np.abs(np.linalg.norm(Y[:, :3] - pivot, axis=1) - L)))

    steps = _ladder(quick, [5e-2, 2e-2, 1e-2, 5e-3, 2e-3], [1e-2])
    runs = _with_prepared({"splitting": steps, "splitting4": steps, "rk4": steps,
                           "dop853": _ladder(quick, [1e-5, 1e-7, 1e-9, 1e-11, 1e-13], [1e-9])}, quick)
    ref_kind = "splitting4, h = 2e-4 s" if not quick else "splitting4, h = 1e-3 s (quick)"
    return [Problem("foucault", f"{T / 3600:g} h, {T / 16.42:.0f} periods", T, np.concatenate([r0, v0]),
                    python_rhs(spec), lambda y: float(np.linalg.norm(y[:3] - y_ref[:3])),
                    f"reference ({ref_kind}): final position error (m)", constraint, runs,
                    _particle_runner(model, r0, v0, T, constraint), atol=1e-10,
                    scipy_rtols=tuple(10.0 ** -k for k in range(3, 12)), spec=spec,
                    ref_error=3e-9)]


def _rigid_runner(inertia, L0, q0, T, top=None, invariant=None):
    from rotframe.rigid.adaptive import rigid_dop853
    from rotframe.scenes.rigid_base import integrate_body

    mgl = 0.0 if top is None else top[0] * top[1] * top[2]
    ends = np.array([0.0, T])

    def run(method, setting):
        if method == "dop853":
            res = rigid_dop853(inertia, L0, q0, ends, rtol=setting, mgl=mgl)
            Y = np.concatenate([res.L, res.q], axis=1)
            return Y[-1], res.nfev, None if invariant is None else (lambda: invariant(ends, Y))
        rs = {"samples": 1, "step": setting}
        traj = integrate_body(method, inertia, L0, q0, T, rs, None, top=top)
        Y = np.concatenate([traj.L, traj.q], axis=1)
        return Y[-1], traj.steps, None if invariant is None else (lambda: invariant(traj.times, Y))

    return run


def attitude_error(q, q_ref):
    """Rotation angle (rad) between two attitudes given as quaternions (any norm, either sign).

    ``|q - q_ref| = 2 sin(angle / 4)`` for unit quaternions of the closer sign;
    the arccos of their dot product would lose half the digits (a floor near 1e-8).
    """
    q = np.asarray(q, float) / np.linalg.norm(q)
    q_ref = np.asarray(q_ref, float) / np.linalg.norm(q_ref)
    if q @ q_ref < 0:
        q_ref = -q_ref
    return 4 * math.asin(min(1.0, 0.5 * float(np.linalg.norm(q - q_ref))))


def _dzhanibekov(quick):
    from rotframe.rigid import dynamics as rigid
    from rotframe.app.bench.peers import python_rhs
    from rotframe.rigid.exact_flow import free_body_flow

    inertia = np.array([1.0, 2.0, 3.0])
    L0 = inertia * np.array([0.01, 1.0, 0.01])
    q0 = np.array([0.0, 0.0, 0.0, 1.0])
    spec = {"kind": "rigid", "inertia": tuple(inertia), "mgl": 0.0}
    out = []
    for T, label in [(100.0, "100 s, 2.6 periods")] + ([] if quick else [(4e4, "4e4 s, 1000 periods")]):
        Lx, qx = rigid.free_body_exact(inertia, L0, q0, np.array([T]))
        M = np.linalg.norm(L0)

        def err(y, Lx=Lx, qx=qx):
            return max(float(np.linalg.norm(y[:3] - Lx[0]) / M), attitude_error(y[3:], qx[0]))

        def invariant(t, Y):
            E = 0.5 * np.sum(Y[:, :3] ** 2 / inertia, axis=1)
            Mm = np.linalg.norm(Y[:, :3], axis=1)
            return float(max(np.max(np.abs(E / E[0] - 1)), np.max(np.abs(Mm / Mm[0] - 1))))

        long = T > 1000
        steps = _ladder(quick, [1e-1, 3e-2, 1e-2, 3e-3, 1e-3] if not long else [1e-1, 3e-2, 1e-2], [3e-3])
        rtols = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13]
        runs = {"exact": [None], "dop853": _ladder(quick, rtols, [1e-8]), "lie-poisson": steps,
                "lie-poisson4": steps, "rk4": steps}
        if long:
            runs = {"exact": [None], "dop853": rtols[2::2], "lie-poisson4": steps}
        base = _rigid_runner(inertia, L0, q0, T, invariant=invariant)

        def run(method, setting, base=base, T=T):
            if method == "exact":  # the closed form, compiled (rigid_exact.free_body_flow)
                times = np.array([0.0, T])
                Ls, qs = free_body_flow(inertia, L0, q0, times)
                Y = np.concatenate([Ls, qs], axis=1)
                return Y[-1], 0, lambda: invariant(times, Y)
            return base(method, setting)

        p = Problem("dzhanibekov", label, T, np.concatenate([L0, q0]), python_rhs(spec), err,
                    "analytic (elliptic functions): max(|dL|/|L|, attitude angle)", invariant, runs, run,
                    atol=1e-13, scipy_budget_s=10.0 if long else 20.0,
                    scipy_rtols=tuple(10.0 ** -k for k in range(3, 14)) if not long else (1e-3, 1e-5, 1e-7),
                    spec=spec)
        out.append(p)
    return out


def _heavy_top(quick):
    from scipy.integrate import solve_ivp

    from rotframe.app.bench.peers import numba_rhs, python_rhs
    from rotframe.scenes.heavy_top import build

    values = {"i1": 1.9e-4, "i3": 2.5e-5, "mass": 0.1, "length": 0.04, "g": 9.81, "theta0": 20.0,
              "phidot0": 0.0, "psidot0": 300.0, "wobble": 0.0, "duration": 2.0}
    inertia, L0, q0 = build(values)
    mgl = values["mass"] * values["g"] * values["length"]
    spec = {"kind": "rigid", "inertia": tuple(inertia), "mgl": mgl}
    T = 2.0
    rhs = python_rhs(spec)
    # reference: scipy DOP853 at rtol 1e-13 (an independent integrator; its own error ~1e-12)
    ref = solve_ivp(numba_rhs(spec), (0, T), np.concatenate([L0, q0]), method="DOP853", rtol=1e-13,
                    atol=1e-13 * np.array([np.linalg.norm(L0)] * 3 + [1.0] * 4)).y[:, -1]
    M = np.linalg.norm(L0)

    def err(y):
        return max(float(np.linalg.norm(y[:3] - ref[:3]) / M), attitude_error(y[3:], ref[3:]))

    def invariant(t, Y):  # energy, with the potential m g l cos(theta)
        L, q = Y[:, :3], Y[:, 3:] / np.linalg.norm(Y[:, 3:], axis=1)[:, None]
        cos_theta = 1 - 2 * (q[:, 0] ** 2 + q[:, 1] ** 2)
        E = 0.5 * np.sum(L * L / inertia, axis=1) + mgl * cos_theta
        return float(np.max(np.abs(E / E[0] - 1)))

    steps = _ladder(quick, [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5], [1e-4])
    runs = {"dop853": _ladder(quick, [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12], [1e-8]),
            "splitting": steps, "splitting4": steps, "rk4": [s for s in steps if s <= 1e-3]}
    return [Problem("heavy-top", "2 s, 95 spins", T, np.concatenate([L0, q0]), rhs, err,
                    "reference (scipy DOP853, rtol 1e-13): max(|dL|/|L|, attitude angle)", invariant, runs,
                    _rigid_runner(inertia, L0, q0, T, top=(values["mass"], values["length"], values["g"]),
                                  invariant=invariant),
                    atol=1e-14, spec=spec)]


# ---------------------------------------------------------------------------
# measuring
# ---------------------------------------------------------------------------


def _timed(fn, budget=2.0, max_repeats=5):
    """(median wall time, last result) over repeats that fit in ``budget`` seconds (at most ``max_repeats``)."""
    times = []
    result = None
    while True:
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
        if len(times) >= max_repeats or sum(times) > budget or (len(times) >= 3 and sum(times) > budget / 4):
            break
    return statistics.median(times), result


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
    """How many timed units :func:`run_problem` will do for ``p`` (for the progress bar)."""
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

    for method, settings in p.runs.items():
        t0 = time.perf_counter()
        p.run(method, settings[0])  # warm-up: loads or compiles the kernels
        compile_s = time.perf_counter() - t0
        for s in settings:
            if method.endswith(PREPARED) and s is not settings[0]:
                p.run(method, s)  # prepares (untimed, like a peer's compilation)
            wall, (y, nfev, inv) = _timed(lambda: p.run(method, s), plan.budget, plan.repeats)
            inv = inv() if callable(inv) else inv  # the invariant is measured after the timing, as for the peers
            emit(_row(p, method, s, wall, p.error(y), nfev, inv, compile_s=compile_s, family="rotframe"))
            compile_s = None
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
            wall, (y, nfev) = _timed(lambda: run(rtol), plan.budget, plan.repeats)
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
        wall, sol = (first, sol) if first > 1.0 else _timed(solve, plan.budget, plan.repeats)
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


def _is_peer(r):
    return r.get("family") == "peer" or r["method"].startswith(("scipy", "diffrax"))



def _problem_keys(rows):
    """The (scenario, horizon) of each benchmarked problem, in order of first appearance."""
    keys = []
    for r in rows:
        k = (r["scenario"], r.get("horizon"))
        if r.get("horizon") and r.get("kind") != "summary" and k not in keys:
            keys.append(k)
    return keys


def level_summary(rows, levels=LEVELS):
    """Summary rows: per (scenario, horizon) and error level, the fastest rotframe and peer runs and their ratio.

    A run counts for a level when its final error is at most the level. A
    rotframe row with zero error counts only for the ``exact`` method (the
    reference is that flow). ``ratio`` = peer time / rotframe time; ``note``
    says why a level has no ratio.
    """
    out = []
    keys = _problem_keys(rows)
    for scenario, horizon in keys:
        sel = [r for r in rows if (r["scenario"], r.get("horizon")) == (scenario, horizon)
               and r.get("kind") != "summary" and r["error"] is not None and np.isfinite(r["error"])]
        mine = [r for r in sel if not _is_peer(r) and (r["error"] > 0 or r["method"] == "exact")]
        theirs = [r for r in sel if _is_peer(r)]
        ref_error = max((r.get("reference_error") or 0.0 for r in sel), default=0.0)
        for level in levels:
            if level < ref_error:
                out.append({"scenario": scenario, "method": "summary", "setting": level, "wall_s": None,
                            "error": None, "error_kind": sel[0]["error_kind"], "nfev": 0, "horizon": horizon,
                            "kind": "summary", "level": level, "rotframe_method": None, "rotframe_setting": None,
                            "peer": None, "peer_setting": None, "peer_wall_s": None, "peer_error": None,
                            "peer_compile_s": None, "ratio": None,
                            "note": f"not measurable: the reference itself is good to {ref_error:.0e} only"})
                continue
            m = [r for r in mine if r["error"] <= level]
            t = [r for r in theirs if r["error"] <= level]
            best_m = min(m, key=lambda r: r["wall_s"]) if m else None
            best_t = min(t, key=lambda r: r["wall_s"]) if t else None
            row = {"scenario": scenario, "method": "summary", "setting": level,
                   "wall_s": best_m["wall_s"] if best_m else None, "error": best_m["error"] if best_m else None,
                   "error_kind": sel[0]["error_kind"] if sel else "", "nfev": best_m["nfev"] if best_m else 0,
                   "horizon": horizon, "kind": "summary", "level": level,
                   "rotframe_method": best_m["method"] if best_m else None,
                   "rotframe_setting": best_m["setting"] if best_m else None,
                   "peer": best_t["method"] if best_t else None, "peer_setting": best_t["setting"] if best_t else None,
                   "peer_wall_s": best_t["wall_s"] if best_t else None, "peer_error": best_t["error"] if best_t else None,
                   "peer_compile_s": _compile_of(rows, best_t) if best_t else None,
                   "ratio": (best_t["wall_s"] / best_m["wall_s"]) if (best_m and best_t) else None}
            notes = []
            if not best_m:
                finest = min((r["error"] for r in mine), default=None)
                notes.append("no rotframe run reached this error" +
                             (f" (smallest {finest:.1e})" if finest is not None else ""))
            if not best_t:
                finest = min((r["error"] for r in theirs), default=None)
                notes.append("no peer run reached this error" +
                             (f" (smallest {finest:.1e})" if finest is not None else " (no peer rows)"))
            if row["ratio"] is not None and row["ratio"] < 10:
                notes.append(f"below the 10x goal by a factor {10 / row['ratio']:.1f}")
            if notes:
                row["note"] = "; ".join(notes)
            out.append(row)
    return out


def _compile_of(rows, r):
    """The compile time reported with the first row of ``r``'s method."""
    for s in rows:
        if (s["scenario"], s.get("horizon"), s["method"]) == (r["scenario"], r.get("horizon"), r["method"]) \
                and "compile_s" in s:
            return s["compile_s"]
    return None


def speedups(rows, max_error=1e-2):
    """Per (scenario, horizon): speed ratio of the best rotframe method over the fastest scipy method.

    For each rotframe row, the fastest scipy row whose final error is at least
    as small is found; the ratio of their wall times is reported at the
    rotframe row that maximises it, with the error where it holds. Rows with
    error above ``max_error`` are not accuracy and are left out, and so are rows
    with zero error (a method compared with itself as the reference).
    """
    out = {}
    keys = {(r["scenario"], r["horizon"]) for r in rows if r.get("horizon") and r.get("kind") != "summary"}
    for key in sorted(keys):
        def usable(r):
            return (r["scenario"], r.get("horizon")) == key and r.get("kind") != "summary" and \
                r["error"] is not None and np.isfinite(r["error"]) and 0 < r["error"] <= max_error

        mine = [r for r in rows if usable(r) and not _is_peer(r)]
        theirs = [r for r in rows if usable(r) and r["method"].startswith("scipy")]
        if not mine or not theirs:
            continue
        best = None
        for r in mine:
            candidates = [s["wall_s"] for s in theirs if s["error"] <= r["error"]]
            if not candidates:
                continue
            ratio = min(candidates) / r["wall_s"]
            if best is None or ratio > best[0]:
                fastest = min((s for s in theirs if s["error"] <= r["error"]), key=lambda s: s["wall_s"])
                best = (ratio, r, fastest)
        if best:
            ratio, r, s = best
            out[f"{key[0]} ({key[1]})"] = {"speedup": ratio, "error": r["error"], "rotframe": r["method"],
                                           "rotframe_setting": r["setting"], "rotframe_wall_s": r["wall_s"],
                                           "scipy": s["method"], "scipy_rtol": s["setting"], "scipy_wall_s": s["wall_s"]}
    return out


# ---------------------------------------------------------------------------
# throughput, start-up, recording
# ---------------------------------------------------------------------------


def ensemble_rows(quick):
    """Particle-steps per second of the tower-drop ensemble path on one core and on all, beside hand-written loops.

    rotframe: :func:`rotframe.particles.ensemble.integrate_ensemble` (gravity + Coriolis,
    exact-rotation splitting, the ground event watched every step) with
    ``threads=1`` and with every core. Ceiling: the same splitting written out
    by hand (no event), serial and with ``prange``. ``parallel_efficiency`` is
    the N-core rate over ``cores x`` the single-core rate; the goal is 0.7.
    """
    import numba

    from rotframe.app.bench import ceiling
    from rotframe.particles.ensemble import integrate_ensemble, resolve_threads
    from rotframe.particles.integrators import Event
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    n, steps = (20000, 50) if quick else (100000, 200)
    cores = resolve_threads(None)
    w = np.array([0.0, 4.6e-5, 5.7e-5])
    g = np.array([0.0, 0.0, -9.81])
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=g)
    rng = np.random.default_rng(1)
    r0 = rng.normal(size=(n, 3)) + [0, 0, 1000]
    v0 = rng.normal(size=(n, 3))
    h = 1e-3
    ground = Event("ground", "r", 2, 0.0, -1, True)

    def ours(threads):
        return integrate_ensemble(model, r0, v0, steps * h, ground, method="splitting", run={"step": h, "samples": 1},
                                  threads=threads)

    c, s = math.cos(-2 * np.linalg.norm(w) * h), math.sin(-2 * np.linalg.norm(w) * h)
    axis = w / np.linalg.norm(w)
    ceiling.serial(r0[:2].copy(), v0[:2].copy(), g, axis, c, s, h, 2)
    ceiling.parallel(r0[:2].copy(), v0[:2].copy(), g, axis, c, s, h, 2)

    def hand(fn):
        def go():
            r, v = r0.copy(), v0.copy()
            fn(r, v, g, axis, c, s, h, steps)
            return r
        return go

    ours(1)
    a = ours(1)
    b = ours(None)
    identical = bool(np.array_equal(a.state, b.state) and np.array_equal(a.t_event, b.t_event, equal_nan=True))
    rows = []
    budget = 1.0 if quick else 3.0
    saved = numba.get_num_threads()
    try:
        numba.set_num_threads(cores)
        for name, fn in [("rotframe ensemble, 1 thread", lambda: ours(1)),
                         (f"rotframe ensemble, {cores} threads", lambda: ours(None)),
                         ("hand-written loop, 1 core", hand(ceiling.serial)),
                         (f"hand-written prange loop, {cores} cores (ceiling)", hand(ceiling.parallel))]:
            wall, _ = _timed(fn, budget=budget, max_repeats=3 if quick else 5)
            rows.append({"scenario": "ensemble", "method": name, "setting": f"{n} particles x {steps} steps",
                         "wall_s": wall, "error": math.nan, "error_kind": "throughput", "nfev": n * steps,
                         "particle_steps_per_s": n * steps / wall, "threads": 1 if ", 1 " in name else cores})
    finally:
        numba.set_num_threads(saved)
    single, multi = rows[0]["particle_steps_per_s"], rows[1]["particle_steps_per_s"]
    rows[1]["parallel_efficiency"] = multi / (cores * single)
    rows[1]["goal_ratio"] = multi / (0.7 * cores * single)
    rows[1]["bitwise_identical_to_1_thread"] = identical
    rows[3]["parallel_efficiency"] = rows[3]["particle_steps_per_s"] / (cores * rows[2]["particle_steps_per_s"])
    rows[1]["of_ceiling"] = multi / rows[3]["particle_steps_per_s"]
    return rows


def sweep_rows(quick):
    """Rows per second of a Foucault sweep (one run per row) on a Dask ``LocalCluster`` of 1, 2 and all workers."""
    import shutil

    from rotframe.particles.ensemble import resolve_threads
    from rotframe.app.sweep import parse_spec, run_sweep

    cores = resolve_threads(None)
    n = 8 if quick else 32
    spec = parse_spec("foucault", sets={"duration": 60.0}, grid=[f"latitude=5:85:{n}"])
    rows = []
    for workers in sorted({1, 2, cores}):
        d = tempfile.mkdtemp()
        try:
            t0 = time.perf_counter()
            res = run_sweep(spec, os.path.join(d, "s.parquet"), workers=workers, plots=False, recording=False)
            wall = time.perf_counter() - t0
        finally:
            shutil.rmtree(d, ignore_errors=True)
        rows.append({"scenario": "sweep", "method": f"LocalCluster, {workers} worker(s)",
                     "setting": f"foucault 60 s x {n} latitudes", "wall_s": wall, "error": math.nan,
                     "error_kind": "throughput (cluster start included)", "nfev": 0, "rows": res.rows,
                     "rows_per_s": res.rows / wall, "workers": workers})
    return rows


def startup_rows(scenario="foucault"):
    """Wall time of ``rotframe run SCENARIO --no-record`` in a new process: warm cache, then empty cache.

    ``import_s`` is the time of ``import rotframe.app.cli`` plus numpy/scipy in a new process, to
    tell the compile time (``wall_s - import_s``) apart.
    """
    rows = []
    cmd = [sys.executable, "-m", "rotframe", "run", scenario, "--no-record", "--json"]
    imp = [sys.executable, "-c", "import rotframe.app.cli, numpy, scipy, numba"]
    t0 = time.perf_counter()
    subprocess.run(imp, capture_output=True, check=True)
    import_s = time.perf_counter() - t0
    subprocess.run(cmd, capture_output=True, check=True)  # fills the cache
    walls = []
    for _ in range(3):
        t0 = time.perf_counter()
        subprocess.run(cmd, capture_output=True, check=True)
        walls.append(time.perf_counter() - t0)
    rows.append({"scenario": "startup", "method": f"rotframe run {scenario} --no-record", "setting": "warm compile cache",
                 "wall_s": statistics.median(walls), "error": math.nan, "error_kind": "start-up", "nfev": 0,
                 "import_s": import_s})
    with tempfile.TemporaryDirectory() as empty:
        t0 = time.perf_counter()
        subprocess.run(cmd, env=dict(os.environ, NUMBA_CACHE_DIR=empty), capture_output=True, check=True)
        rows.append({"scenario": "startup", "method": f"rotframe run {scenario} --no-record",
                     "setting": "first-ever run (empty compile cache)", "wall_s": time.perf_counter() - t0,
                     "error": math.nan, "error_kind": "start-up", "nfev": 0, "import_s": import_s})
    return rows


def record_rows(n=10**6):
    """Time to record ``n`` samples of a particle (Points3D + trail + a scalar series)."""
    from rotframe.app.record import Recording

    times = np.linspace(0, 100, n)
    pos = np.stack([np.cos(times), np.sin(times), times * 0.01], axis=1)
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        rec = Recording(os.path.join(d, "bench.rrd"), "bench")
        rec.points("world/p", times, pos)
        rec.scalars("diagnostics/x", times, pos[:, 0])
        rec.finish()
        wall = time.perf_counter() - t0
    return [{"scenario": "record", "method": "Recording.points + scalars", "setting": f"{n} samples",
             "wall_s": wall, "error": math.nan, "error_kind": "recording", "nfev": 0}]


# ---------------------------------------------------------------------------
# output
# ---------------------------------------------------------------------------


def run_bench(names=None, quick=False, progress=None, on_row=None):
    """All rows for the named benchmarks (default: every problem, ensemble, sweep, start-up, recording).

    ``quick``: short ladders, three repeats, plain scipy at one tolerance (no
    numba or diffrax peers), no sweep or start-up (they start processes); every
    problem still runs once. ``progress(done, total, label)`` is called after each
    timed unit; ``on_row(row)`` with each row. Summary rows (``kind``
    "summary", one per problem and error level) close the list.
    """
    names = list(names or [])
    scenario_names = [n for n in names if n not in EXTRAS]
    rows = []
    notes = []
    plan = Plan(quick, progress)
    probs = problems(scenario_names or None, quick=quick) if (scenario_names or not names) else []
    from rotframe.app.bench import peers

    peers_ok, why = peers.diffrax_available()
    if not quick and not peers_ok:
        notes.append(why)
    if quick:
        notes.append("quick: plain scipy at rtol 1e-6 only (no numba or diffrax peers), short ladders, 3 repeats, "
                     "no sweep or start-up")
    extras = [n for n in EXTRAS if (not names and not (quick and n in ("sweep", "startup"))) or n in names]
    plan.total = sum(planned_units(p, quick, peers_ok) for p in probs) + len(extras)
    for p in probs:
        rows.extend(run_problem(p, on_row, plan))
        notes.extend(f"{p.scenario}: {n}" for n in p.notes)
    for name in extras:
        fn = {"ensemble": lambda: ensemble_rows(quick), "sweep": lambda: sweep_rows(quick),
              "startup": startup_rows, "record": lambda: record_rows(10**5 if quick else 10**6)}[name]
        rows.extend(fn())
        plan.step(name)
    rows.extend(level_summary(rows))
    for n in notes:
        rows.append({"scenario": "notes", "method": "note", "setting": None, "wall_s": 0.0, "error": math.nan,
                     "error_kind": "note", "nfev": 0, "kind": "note", "note": n})
    return rows


def environment():
    """Machine and versions, for the record."""
    import platform

    import numba
    import scipy

    out = {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__,
           "numba": numba.__version__, "machine": platform.machine(), "cpus": os.cpu_count(),
           "processor": platform.processor() or platform.machine()}
    try:
        import diffrax
        import jax

        out["jax"], out["diffrax"] = jax.__version__, diffrax.__version__
    except Exception:  # noqa: BLE001
        pass
    return out


def plot(rows, folder):
    """One work-precision diagram (log error against log wall time) per problem; returns the paths."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    os.makedirs(folder, exist_ok=True)
    paths = []
    keys = _problem_keys(rows)
    for scenario, horizon in keys:
        fig = Figure(figsize=(7, 5))
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
        sel = [r for r in rows if r["scenario"] == scenario and r.get("horizon") == horizon and r.get("kind") != "summary"]
        for method in dict.fromkeys(r["method"] for r in sel):
            pts = sorted((r["wall_s"], r["error"]) for r in sel if r["method"] == method
                         and r["error"] is not None and np.isfinite(r["error"]) and r["error"] > 0)
            if pts:
                x, y = zip(*pts)
                style = "--" if _is_peer(sel[[r["method"] for r in sel].index(method)]) else "-"
                ax.loglog(x, y, style, marker="o", ms=3, label=method)
        ax.set_xlabel("wall time per run (s)")
        ax.set_ylabel("final error")
        ax.set_title(f"{scenario}: {horizon}\n{sel[0]['error_kind']}", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        path = os.path.join(folder, f"bench-{scenario}-{len(paths)}.png")
        fig.savefig(path, dpi=110, bbox_inches="tight")
        paths.append(path)
    return paths


def _fmt_setting(v):
    return v if isinstance(v, str) else ("-" if v is None else f"{v:.0e}")


def table(rows, speed) -> str:
    body = [r for r in rows if r.get("kind") not in ("summary", "note")]
    lines = [f"{'scenario':<12} {'horizon':<22} {'method':<22} {'setting':>9} {'wall s':>10} {'error':>10} "
             f"{'invariant':>10} {'nfev':>10} {'compile s':>9}"]
    for r in body:
        inv = r.get("invariant_error")
        extra = ""
        if "particle_steps_per_s" in r:
            extra = f"  {r['particle_steps_per_s']:.3g} particle-steps/s"
            if "goal_ratio" in r:
                extra += (f", {r['parallel_efficiency']:.2f} of cores x single-core "
                          f"({r['goal_ratio']:.2f} of the 0.7 goal), {r['of_ceiling']:.2f} of the ceiling, "
                          f"bitwise identical to 1 thread: {r['bitwise_identical_to_1_thread']}")
        if "rows_per_s" in r:
            extra = f"  {r['rows_per_s']:.3g} rows/s"
        if "import_s" in r:
            extra = f"  (imports {r['import_s']:.2f} s)"
        err = r["error"]
        comp = r.get("compile_s")
        lines.append(f"{r['scenario']:<12} {str(r.get('horizon', '')):<22} {r['method'][:22]:<22} "
                     f"{_fmt_setting(r['setting']):>9} {r['wall_s']:>10.3g} "
                     f"{(err if err is not None else math.nan):>10.2e} {('-' if inv is None else f'{inv:.1e}'):>10} "
                     f"{r['nfev']:>10} {('' if comp is None else f'{comp:.2g}'):>9}{extra}")
    summ = [r for r in rows if r.get("kind") == "summary"]
    if summ:
        lines.append("")
        lines.append("at equal final error: fastest rotframe run, fastest peer run (scipy, scipy + numba, diffrax), "
                     "ratio (peer time / rotframe time); compile time of the peer apart")
        lines.append(f"{'scenario':<12} {'horizon':<22} {'error <=':>8} {'rotframe':>24} {'s':>9} {'peer':>24} "
                     f"{'s':>9} {'compile s':>9} {'ratio':>8}")
        for r in summ:
            mine = f"{r['rotframe_method']} {_fmt_setting(r['rotframe_setting'])}" if r["rotframe_method"] else "-"
            peer = f"{r['peer']} {_fmt_setting(r['peer_setting'])}" if r["peer"] else "-"
            pc = r.get("peer_compile_s")
            lines.append(f"{r['scenario']:<12} {str(r['horizon']):<22} {r['level']:>8.0e} {mine[:24]:>24} "
                         f"{(r['wall_s'] or math.nan):>9.2g} {peer[:24]:>24} {(r['peer_wall_s'] or math.nan):>9.2g} "
                         f"{('' if pc is None else f'{pc:.2g}'):>9} "
                         f"{('x' + format(r['ratio'], '.1f')) if r['ratio'] else '-':>8}"
                         + (f"  {r['note']}" if r.get("note") else ""))
    if speed:
        lines.append("")
        lines.append("speed at equal final error (best rotframe method / fastest plain scipy method):")
        for key, s in speed.items():
            lines.append(f"  {key:<40} x{s['speedup']:8.1f} at error {s['error']:.1e}: {s['rotframe']} "
                         f"({s['rotframe_wall_s']:.2g} s) vs {s['scipy']} rtol {s['scipy_rtol']:.0e} "
                         f"({s['scipy_wall_s']:.2g} s)")
    notes = [r["note"] for r in rows if r.get("kind") == "note"]
    if notes:
        lines.append("")
        lines.extend(f"note: {n}" for n in notes)
    return "\n".join(lines)


def _json_rows(rows):
    def clean(v):
        if isinstance(v, float) and not math.isfinite(v):
            return None
        if isinstance(v, (np.floating, np.integer, np.bool_)):
            return clean(v.item())
        return v

    return [{k: clean(v) for k, v in r.items()} for r in rows]


def main(args) -> int:
    from rotframe.app.progress import Progress

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
        with open(os.path.join(args.plots, "bench.json"), "w") as f:
            json.dump(_json_rows(rows), f, indent=0)
        with open(os.path.join(args.plots, "bench.txt"), "w") as f:
            f.write(table(rows, speed) + "\n")
    if args.json:
        print(json.dumps(_json_rows(rows)))
    else:
        print(table(rows, speed))
        print("machine: " + ", ".join(f"{k} {v}" for k, v in env.items()))
        for p in plots:
            print(f"plot: {p}")
    return 0
