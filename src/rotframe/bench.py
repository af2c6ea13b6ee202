"""Speed against error for every method on every scenario (``rotframe bench``).

For each problem (a scenario's equations, initial state and horizon) every
rotframe method runs over a ladder of step sizes or tolerances, and scipy's
``solve_ivp`` (RK45, DOP853, Radau, LSODA) runs the same equations, written
here as a user would write them (a plain Python right-hand side), over rtol
1e-3 to 1e-13. Each row gives the wall time (median of repeats, after a
warm-up run that loads or compiles the kernels; that time is reported apart
as ``compile_s``), the force evaluations, the final-state error against the
analytic solution or a reference run at much tighter tolerance
(``error_kind`` says which) and the worst invariant error along the run.

Everything is measured in one run on one machine, and claims are ratios:
``speedup`` compares, at equal final error, the best rotframe method with the
fastest scipy method.
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

__all__ = ["Problem", "problems", "run_bench", "main"]

SCIPY_METHODS = ("RK45", "DOP853", "Radau", "LSODA")


@dataclass
class Problem:
    """One benchmark problem.

    ``rhs(t, y)`` and ``y0`` are the equations for scipy; ``exact`` the final
    state to compare with; ``error(y)`` the final-state error (and its unit in
    ``error_kind``); ``invariant(Y)`` the worst invariant error over states
    ``Y`` (n, dim); ``runs`` maps a rotframe method to a list of settings and
    ``run(method, setting) -> (y_end, nfev, invariant_error)``.
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


# ---------------------------------------------------------------------------
# problems
# ---------------------------------------------------------------------------


def problems(names=None, quick=False):
    """The benchmark problems (for ``names``, or all)."""
    makers = {"turntable": _turntable, "tower-drop": _tower_drop, "foucault": _foucault,
              "dzhanibekov": _dzhanibekov, "heavy-top": _heavy_top}
    names = list(names or makers)
    unknown = [n for n in names if n not in makers and n not in ("ensemble", "startup", "record")]
    if unknown:
        from rotframe.errors import ScenarioError

        raise ScenarioError(f"bench: no benchmark for {unknown[0]!r}; available: "
                            f"{', '.join(list(makers) + ['ensemble', 'startup', 'record'])}")
    out = []
    for n in names:
        if n in makers:
            out.extend(makers[n](quick))
    return out


def _ladder(quick, full, short):
    return short if quick else full


def _particle_runner(model, r0, v0, t_end, invariant_fn):
    from rotframe.integrators import integrate_particles

    def run(method, setting):
        kw = {"rtol": setting} if method == "dop853" else {"step": setting}
        traj = integrate_particles(model, r0, v0, t_end, method=method, samples=200, **kw)
        Y = np.concatenate([traj.r[:, 0], traj.v[:, 0]], axis=1)
        return Y[-1], traj.nfev, invariant_fn(traj.times, Y)

    return run


def _turntable(quick):
    from rotframe.model import OmegaSchedule, ParticleModel
    from rotframe.scenes.turntable import inertial_line

    w0, alpha, T = 1.0, 0.2, 4.0
    omega = OmegaSchedule.ramp([0, 0, 1], w0, alpha, T)
    model = ParticleModel(("coriolis", "centrifugal", "euler"), omega=omega)
    r0, v0 = np.array([2.0, 0.0, 0.0]), np.array([-1.0, 0.0, 0.0])
    r_end = inertial_line(omega, r0, v0, np.array([T]))[0]

    def rhs(t, y):  # a user's right-hand side
        r, v = y[:3], y[3:]
        w = np.array([0.0, 0.0, w0 + alpha * t])
        wd = np.array([0.0, 0.0, alpha])
        a = -2 * np.cross(w, v) - np.cross(w, np.cross(w, r)) - np.cross(wd, r)
        return np.concatenate([v, a])

    def inertial_speed(t, Y):
        # the inertial speed |v + w x r| is constant on the exact solution
        w = (w0 + alpha * t)[:, None] * np.array([0.0, 0.0, 1.0])
        s = np.linalg.norm(Y[:, 3:] + np.cross(w, Y[:, :3]), axis=1)
        return float(np.max(np.abs(s / s[0] - 1)))

    steps = _ladder(quick, [4e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4], [1e-2, 1e-3])
    runs = {"splitting": steps, "splitting4": steps, "rk4": steps,
            "dop853": _ladder(quick, [1e-4, 1e-6, 1e-8, 1e-10, 1e-12], [1e-6, 1e-10])}
    return [Problem("turntable", "4 s, 0.9 turns", T, np.concatenate([r0, v0]), rhs,
                    lambda y: float(np.linalg.norm(y[:3] - r_end)), "analytic: final position error (m)",
                    inertial_speed, runs, _particle_runner(model, r0, v0, T, inertial_speed), atol=1e-12)]


def _tower_drop(quick):
    from rotframe import earth
    from rotframe.integrators import integrate_particles
    from rotframe.model import OmegaSchedule, ParticleModel

    lat = math.radians(50 + 53 / 60)
    g = float(earth.normal_gravity(lat))
    w = earth.omega_enu(lat)
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=np.array([0, 0, -g]))
    T = 5.0
    r0, v0 = np.array([0, 0, 158.5]), np.zeros(3)
    exact = integrate_particles(model, r0, v0, T, method="exact", samples=1)
    y_exact = np.concatenate([exact.r[-1, 0], exact.v[-1, 0]])

    def rhs(t, y):
        return np.concatenate([y[3:], np.array([0, 0, -g]) - 2 * np.cross(w, y[3:])])

    def energy(t, Y):
        e = 0.5 * np.sum(Y[:, 3:] ** 2, axis=1) + g * Y[:, 2]
        return float(np.max(np.abs(e - e[0])) / abs(e[0]))

    steps = _ladder(quick, [1e-1, 1e-2, 1e-3, 1e-4], [1e-2])
    runs = {"exact": [None], "splitting": steps, "rk4": steps, "dop853": _ladder(quick, [1e-6, 1e-10], [1e-8])}
    base = _particle_runner(model, r0, v0, T, energy)

    def run(method, setting):
        if method == "exact":
            traj = integrate_particles(model, r0, v0, T, method="exact", samples=200)
            Y = np.concatenate([traj.r[:, 0], traj.v[:, 0]], axis=1)
            return Y[-1], 0, energy(traj.times, Y)
        return base(method, setting)

    return [Problem("tower-drop", "5 s fall", T, np.concatenate([r0, v0]), rhs,
                    lambda y: float(np.linalg.norm(y[:3] - y_exact[:3])),
                    "analytic (exact propagator): final position error (m)", energy, runs, run)]


def _foucault(quick):
    from rotframe import earth
    from rotframe.integrators import integrate_particles
    from rotframe.model import OmegaSchedule, ParticleModel

    lat = math.radians(48.846)
    g = float(earth.normal_gravity(lat))
    w = earth.omega_enu(lat)
    L, a = 67.0, 3.0
    T = 600.0 if quick else 3600.0
    pivot = np.array([0.0, 0.0, L])
    model = ParticleModel(("gravity", "coriolis", "pendulum"), omega=OmegaSchedule.constant(w),
                          g=np.array([0, 0, -g]), pendulum_length=L, pivot=pivot)
    r0, v0 = np.array([a, 0, L - math.sqrt(L * L - a * a)]), np.zeros(3)
    ref = integrate_particles(model, r0, v0, T, method="splitting4", step=2e-4, samples=1)
    y_ref = np.concatenate([ref.r[-1, 0], ref.v[-1, 0]])

    def rhs(t, y):  # spherical pendulum with the string force as a Lagrange multiplier
        r, v = y[:3], y[3:]
        n = (r - pivot) / L
        f = np.array([0.0, 0.0, -g]) - 2 * np.cross(w, v)
        return np.concatenate([v, f - (f @ n + v @ v / L) * n])

    def constraint(t, Y):
        return float(np.max(np.abs(np.linalg.norm(Y[:, :3] - pivot, axis=1) - L)))

    steps = _ladder(quick, [5e-2, 2e-2, 1e-2, 5e-3, 2e-3], [2e-2, 5e-3])
    runs = {"splitting": steps, "splitting4": steps, "rk4": steps,
            "dop853": _ladder(quick, [1e-5, 1e-7, 1e-9, 1e-11], [1e-6, 1e-9])}
    return [Problem("foucault", f"{T / 3600:g} h, {T / 16.42:.0f} periods", T, np.concatenate([r0, v0]), rhs,
                    lambda y: float(np.linalg.norm(y[:3] - y_ref[:3])),
                    "reference (splitting4, h = 2e-4 s): final position error (m)", constraint, runs,
                    _particle_runner(model, r0, v0, T, constraint), atol=1e-10,
                    scipy_rtols=tuple(10.0 ** -k for k in range(3, 12)))]


def _rigid_runner(inertia, L0, q0, T, top=None, invariant=None):
    from rotframe.scenes.rigid_base import integrate_body

    def run(method, setting):
        rs = {"samples": 200, "step": setting}
        traj = integrate_body(method, inertia, L0, q0, T, rs, None, top=top)
        Y = np.concatenate([traj.L, traj.q], axis=1)
        return Y[-1], traj.steps, None if invariant is None else invariant(traj.times, Y)

    return run


def _rigid_rhs(inertia, mgl=0.0):
    inertia = np.asarray(inertia, float)

    def rhs(t, y):  # Euler's equations and the quaternion kinematics, scalar-last
        L, q = y[:3], y[3:]
        w = L / inertia
        x, yq, z, s = q
        R3 = np.array([2 * (x * z - s * yq), 2 * (yq * z + s * x), 1 - 2 * (x * x + yq * yq)])  # z_space in body
        torque = mgl * np.array([R3[1], -R3[0], 0.0])
        dL = np.cross(L, w) + torque
        wx, wy, wz = w
        dq = 0.5 * np.array([s * wx + yq * wz - z * wy, s * wy + z * wx - x * wz, s * wz + x * wy - yq * wx,
                             -x * wx - yq * wy - z * wz])
        return np.concatenate([dL, dq])

    return rhs


def _attitude_error(q, q_ref):
    d = abs(float(np.dot(q / np.linalg.norm(q), q_ref / np.linalg.norm(q_ref))))
    return 2 * math.acos(min(1.0, d))


def _dzhanibekov(quick):
    from rotframe import rigid

    inertia = np.array([1.0, 2.0, 3.0])
    L0 = inertia * np.array([0.01, 1.0, 0.01])
    q0 = np.array([0.0, 0.0, 0.0, 1.0])
    out = []
    for T, label in [(100.0, "100 s, 2.6 periods")] + ([] if quick else [(4e4, "4e4 s, 1000 periods")]):
        Lx, qx = rigid.free_body_exact(inertia, L0, q0, np.array([T]))
        M = np.linalg.norm(L0)

        def err(y, Lx=Lx, qx=qx):
            return max(float(np.linalg.norm(y[:3] - Lx[0]) / M), _attitude_error(y[3:], qx[0]))

        def invariant(t, Y):
            E = 0.5 * np.sum(Y[:, :3] ** 2 / inertia, axis=1)
            Mm = np.linalg.norm(Y[:, :3], axis=1)
            return float(max(np.max(np.abs(E / E[0] - 1)), np.max(np.abs(Mm / Mm[0] - 1))))

        long = T > 1000
        steps = _ladder(quick, [1e-1, 3e-2, 1e-2, 3e-3, 1e-3] if not long else [1e-1, 3e-2, 1e-2], [3e-2, 3e-3])
        runs = {"exact": [None], "lie-poisson": steps, "lie-poisson4": steps, "rk4": steps}
        base = _rigid_runner(inertia, L0, q0, T, invariant=invariant)

        def run(method, setting, base=base, T=T):
            if method == "exact":
                times = np.linspace(0, T, 201)
                Ls, qs = rigid.free_body_exact(inertia, L0, q0, times)
                Y = np.concatenate([Ls, qs], axis=1)
                return Y[-1], 0, invariant(times, Y)
            return base(method, setting)

        p = Problem("dzhanibekov", label, T, np.concatenate([L0, q0]), _rigid_rhs(inertia), err,
                    "analytic (elliptic functions): max(|dL|/|L|, attitude angle)", invariant, runs, run,
                    atol=1e-13, scipy_budget_s=10.0 if long else 20.0,
                    scipy_rtols=tuple(10.0 ** -k for k in range(3, 14)) if not long else (1e-3, 1e-5, 1e-7))
        out.append(p)
    return out


def _heavy_top(quick):
    from scipy.integrate import solve_ivp

    from rotframe.scenes.heavy_top import build

    values = {"i1": 1.9e-4, "i3": 2.5e-5, "mass": 0.1, "length": 0.04, "g": 9.81, "theta0": 20.0,
              "phidot0": 0.0, "psidot0": 300.0, "wobble": 0.0}
    inertia, L0, q0 = build(values)
    mgl = values["mass"] * values["g"] * values["length"]
    T = 2.0
    rhs = _rigid_rhs(inertia, mgl)
    ref = solve_ivp(rhs, (0, T), np.concatenate([L0, q0]), method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
    M = np.linalg.norm(L0)

    def err(y):
        return max(float(np.linalg.norm(y[:3] - ref[:3]) / M), _attitude_error(y[3:], ref[3:]))

    def invariant(t, Y):  # energy, with the potential m g l cos(theta)
        L, q = Y[:, :3], Y[:, 3:] / np.linalg.norm(Y[:, 3:], axis=1)[:, None]
        cos_theta = 1 - 2 * (q[:, 0] ** 2 + q[:, 1] ** 2)
        E = 0.5 * np.sum(L * L / inertia, axis=1) + mgl * cos_theta
        return float(np.max(np.abs(E / E[0] - 1)))

    steps = _ladder(quick, [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5], [1e-3, 1e-4])
    runs = {"splitting": steps, "splitting4": steps, "rk4": [s for s in steps if s <= 1e-3]}
    return [Problem("heavy-top", "2 s, 95 spins", T, np.concatenate([L0, q0]), rhs, err,
                    "reference (scipy DOP853, rtol 1e-13): max(|dL|/|L|, attitude angle)", invariant, runs,
                    _rigid_runner(inertia, L0, q0, T, top=(values["mass"], values["length"], values["g"]),
                                  invariant=invariant),
                    atol=1e-14)]


# ---------------------------------------------------------------------------
# measuring
# ---------------------------------------------------------------------------


def _timed(fn, budget=2.0):
    """(median wall time, last result) over repeats that fit in ``budget`` seconds (at most 5)."""
    times = []
    result = None
    while True:
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
        if len(times) >= 5 or sum(times) > budget or (len(times) >= 3 and sum(times) > budget / 4):
            break
    return statistics.median(times), result


def run_problem(p, progress=None):
    """Rows for one problem: rotframe methods, then scipy baselines."""
    rows = []
    for method, settings in p.runs.items():
        t0 = time.perf_counter()
        p.run(method, settings[0])  # warm-up: loads or compiles the kernels
        compile_s = time.perf_counter() - t0
        for s in settings:
            wall, (y, nfev, inv) = _timed(lambda: p.run(method, s))
            rows.append(_row(p, method, s, wall, p.error(y), nfev, inv, compile_s=compile_s))
            compile_s = None
            if progress:
                progress(rows[-1])
    from scipy.integrate import solve_ivp

    for method in SCIPY_METHODS:
        for rtol in p.scipy_rtols:
            rhs = _with_deadline(p.rhs, p.scipy_budget_s)

            def solve():
                rhs.reset()
                return solve_ivp(rhs, (0.0, p.t_end), p.y0, method=method, rtol=rtol, atol=p.atol)

            t0 = time.perf_counter()
            try:
                sol = solve()
            except _OverBudget:
                rows.append(_row(p, f"scipy-{method}", rtol, time.perf_counter() - t0, math.nan, rhs.calls, None))
                rows[-1]["note"] = f"stopped after {p.scipy_budget_s:g} s (over the budget)"
                if progress:
                    progress(rows[-1])
                break  # tighter tolerances would take longer still
            first = time.perf_counter() - t0
            wall, sol = (first, sol) if first > 1.0 else _timed(solve)
            ok = sol.status == 0
            inv = p.invariant(sol.t, sol.y.T) if ok else None
            rows.append(_row(p, f"scipy-{method}", rtol, wall, p.error(sol.y[:, -1]) if ok else math.nan, sol.nfev,
                             inv))
            if progress:
                progress(rows[-1])
            if first > p.scipy_budget_s / 3:
                break  # the next, tighter tolerance would exceed the budget
    return rows


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


def _row(p, method, setting, wall, error, nfev, inv, compile_s=None):
    row = {"scenario": p.scenario, "method": method, "setting": setting, "wall_s": wall, "error": error,
           "error_kind": p.error_kind, "nfev": int(nfev), "horizon": p.horizon, "invariant_error": inv}
    if compile_s is not None:
        row["compile_s"] = compile_s
    return row


def speedups(rows, max_error=1e-2):
    """Per (scenario, horizon): speed ratio of the best rotframe method over the fastest scipy method.

    For each rotframe row, the fastest scipy row whose final error is at least
    as small is found; the ratio of their wall times is reported at the
    rotframe row that maximises it, with the error where it holds. Rows with
    error above ``max_error`` are not accuracy and are left out, and so are rows
    with zero error (a method compared with itself as the reference).
    """
    out = {}
    keys = {(r["scenario"], r["horizon"]) for r in rows if "horizon" in r}
    for key in sorted(keys):
        def usable(r):
            return (r["scenario"], r.get("horizon")) == key and np.isfinite(r["error"]) and 0 < r["error"] <= max_error

        mine = [r for r in rows if usable(r) and not r["method"].startswith("scipy")]
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
    """Particle-steps per second for gravity + Coriolis with the exact-rotation splitting."""
    from numba import njit

    from rotframe.integrators import integrate_particles
    from rotframe.model import OmegaSchedule, ParticleModel

    n, steps = (20000, 100) if quick else (100000, 200)
    w = np.array([0.0, 4.6e-5, 5.7e-5])
    g = np.array([0.0, 0.0, -9.81])
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=g)
    rng = np.random.default_rng(1)
    r0 = rng.normal(size=(n, 3)) + [0, 0, 1000]
    v0 = rng.normal(size=(n, 3))
    h = 1e-3

    def ours():
        return integrate_particles(model, r0, v0, steps * h, method="splitting", step=h, samples=1)

    ceiling = njit(cache=True)(_hand_loop)
    c, s = math.cos(-2 * np.linalg.norm(w) * h), math.sin(-2 * np.linalg.norm(w) * h)
    axis = w / np.linalg.norm(w)
    ceiling(r0[:2].copy(), v0[:2].copy(), g, axis, c, s, h, 2)

    def hand():
        r, v = r0.copy(), v0.copy()
        ceiling(r, v, g, axis, c, s, h, steps)
        return r

    def numpy_rk4():
        r, v = r0.copy(), v0.copy()
        for _ in range(steps // 10):  # a tenth of the steps: numpy is slow
            def acc(vv):
                return g - 2 * np.cross(w, vv)
            k1r, k1v = v, acc(v)
            k2r, k2v = v + 0.5 * h * k1v, acc(v + 0.5 * h * k1v)
            k3r, k3v = v + 0.5 * h * k2v, acc(v + 0.5 * h * k2v)
            k4r, k4v = v + h * k3v, acc(v + h * k3v)
            r = r + h / 6 * (k1r + 2 * k2r + 2 * k3r + k4r)
            v = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        return r

    ours()
    rows = []
    for name, fn, k in [("rotframe splitting", ours, steps), ("hand-written compiled loop (ceiling)", hand, steps),
                        ("numpy-vectorised RK4", numpy_rk4, steps // 10)]:
        wall, _ = _timed(fn, budget=3.0)
        rows.append({"scenario": "ensemble", "method": name, "setting": f"{n} particles x {k} steps",
                     "wall_s": wall, "error": math.nan, "error_kind": "throughput", "nfev": n * k,
                     "particle_steps_per_s": n * k / wall})
    return rows


def _hand_loop(r, v, g, axis, c, s, h, steps):
    """The exact-rotation splitting for gravity + constant Coriolis, written out by hand."""
    ax, ay, az = axis[0], axis[1], axis[2]
    hh = 0.5 * h
    for p in range(r.shape[0]):
        x, y, z = r[p, 0], r[p, 1], r[p, 2]
        vx, vy, vz = v[p, 0], v[p, 1], v[p, 2]
        for _ in range(steps):
            x += hh * vx
            y += hh * vy
            z += hh * vz
            vx += hh * g[0]
            vy += hh * g[1]
            vz += hh * g[2]
            d = ax * vx + ay * vy + az * vz
            cx = ay * vz - az * vy
            cy = az * vx - ax * vz
            cz = ax * vy - ay * vx
            vx, vy, vz = (vx * c + cx * s + ax * d * (1 - c), vy * c + cy * s + ay * d * (1 - c),
                          vz * c + cz * s + az * d * (1 - c))
            vx += hh * g[0]
            vy += hh * g[1]
            vz += hh * g[2]
            x += hh * vx
            y += hh * vy
            z += hh * vz
        r[p, 0], r[p, 1], r[p, 2] = x, y, z
        v[p, 0], v[p, 1], v[p, 2] = vx, vy, vz


def startup_rows():
    """Wall time of ``rotframe run tower-drop --no-record`` in a new process: warm cache, then empty cache."""
    rows = []
    cmd = [sys.executable, "-m", "rotframe", "run", "tower-drop", "--no-record", "--json"]
    with tempfile.TemporaryDirectory() as empty:
        for label, env in [("warm compile cache", dict(os.environ)),
                           ("first-ever run (empty compile cache)", dict(os.environ, NUMBA_CACHE_DIR=empty))]:
            t0 = time.perf_counter()
            subprocess.run(cmd, env=env, capture_output=True, check=True)
            rows.append({"scenario": "startup", "method": "rotframe run tower-drop --no-record", "setting": label,
                         "wall_s": time.perf_counter() - t0, "error": math.nan, "error_kind": "start-up",
                         "nfev": 0})
    # the cached case: median of three
    walls = []
    for _ in range(3):
        t0 = time.perf_counter()
        subprocess.run(cmd, capture_output=True, check=True)
        walls.append(time.perf_counter() - t0)
    rows[0]["wall_s"] = statistics.median(walls)
    return rows


def record_rows(n=10**6):
    """Time to record ``n`` samples of a particle (Points3D + trail + a scalar series)."""
    from rotframe.record import Recording

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


def run_bench(names=None, quick=False, progress=None):
    """All rows for the named benchmarks (default: every problem, ensemble, start-up, recording)."""
    names = list(names or [])
    scenario_names = [n for n in names if n not in ("ensemble", "startup", "record")]
    rows = []
    if scenario_names or not names:
        for p in problems(scenario_names or None, quick=quick):
            rows.extend(run_problem(p, progress))
    if not names or "ensemble" in names:
        rows.extend(ensemble_rows(quick))
    if not names or "startup" in names:
        rows.extend(startup_rows())
    if not names or "record" in names:
        rows.extend(record_rows(10**5 if quick else 10**6))
    return rows


def plot(rows, folder):
    """One work-precision diagram (log error against log wall time) per problem; returns the paths."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    os.makedirs(folder, exist_ok=True)
    paths = []
    keys = []
    for r in rows:
        k = (r["scenario"], r.get("horizon"))
        if r.get("horizon") and k not in keys:
            keys.append(k)
    for scenario, horizon in keys:
        fig = Figure(figsize=(7, 5))
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
        sel = [r for r in rows if r["scenario"] == scenario and r.get("horizon") == horizon]
        for method in dict.fromkeys(r["method"] for r in sel):
            pts = sorted((r["wall_s"], r["error"]) for r in sel if r["method"] == method
                         and np.isfinite(r["error"]) and r["error"] > 0)
            if pts:
                x, y = zip(*pts)
                style = "--" if method.startswith("scipy") else "-"
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


def table(rows, speed) -> str:
    lines = [f"{'scenario':<12} {'horizon':<22} {'method':<22} {'setting':>9} {'wall s':>10} {'error':>10} "
             f"{'invariant':>10} {'nfev':>10}"]
    for r in rows:
        setting = r["setting"] if isinstance(r["setting"], str) else ("-" if r["setting"] is None else f"{r['setting']:.0e}")
        inv = r.get("invariant_error")
        extra = f"  {r['particle_steps_per_s']:.3g} particle-steps/s" if "particle_steps_per_s" in r else ""
        lines.append(f"{r['scenario']:<12} {str(r.get('horizon', '')):<22} {r['method'][:22]:<22} {setting:>9} "
                     f"{r['wall_s']:>10.3g} {r['error']:>10.2e} {('-' if inv is None else f'{inv:.1e}'):>10} "
                     f"{r['nfev']:>10}{extra}")
    lines.append("")
    lines.append("speed at equal final error (best rotframe method / fastest scipy method):")
    for key, s in speed.items():
        lines.append(f"  {key:<40} x{s['speedup']:8.1f} at error {s['error']:.1e}: {s['rotframe']} "
                     f"({s['rotframe_wall_s']:.2g} s) vs {s['scipy']} rtol {s['scipy_rtol']:.0e} ({s['scipy_wall_s']:.2g} s)")
    return "\n".join(lines)


def _json_rows(rows):
    return [{k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in r.items()} for r in rows]


def main(args) -> int:
    def show(row):
        sys.stderr.write(f"\r  {row['scenario']:<12} {row['method']:<24}")
        sys.stderr.flush()

    progress = show if not args.json and sys.stderr.isatty() else None
    rows = run_bench(args.names, quick=args.quick, progress=progress)
    if progress:
        sys.stderr.write("\n")
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
        for p in plots:
            print(f"plot: {p}")
    return 0
