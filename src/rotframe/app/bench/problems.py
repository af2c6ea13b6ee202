"""The benchmark problems: each scenario's equations, initial state, horizon, reference and method ladders.

A `Problem` carries the equations for scipy (``rhs``, ``y0``), the exact or
reference final state, the error and invariant measures, and for every rotframe
method a ladder of step sizes or tolerances (short ones with ``quick``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Problem", "problems", "EXTRAS", "PREPARED", "attitude_error"]


@dataclass
class Problem:
    """One benchmark problem.

    ``rhs(t, y)`` and ``y0`` are the equations for scipy; ``exact`` the final
    state to compare with; ``error(y)`` the final-state error (and its unit in
    ``error_kind``); ``invariant(Y)`` the worst invariant error over states
    ``Y`` (n, dim); ``runs`` maps a rotframe method to a list of settings and
    ``run(method, setting) -> (y_end, nfev, invariant_error)``, the invariant
    error as a function to call after the timing (or None). A runner with
    prepared methods also carries ``run.prepared_call(method, setting) -> (call,
    finish)``, so that the bench times the prepared call alone
    (`rotframe.app.bench.measure.timed_call`).
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


def problems(names=None, quick=False):
    """The benchmark problems (for ``names``, or all)."""
    makers = {"turntable": _turntable, "tower-drop": _tower_drop, "foucault": _foucault,
              "dzhanibekov": _dzhanibekov, "free-top": _free_top, "heavy-top": _heavy_top}
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
EXTRAS = ("ensemble", "sweep", "startup", "record", "user-force", "gpu")


#: rtol ladder of the rigid bodies' dop853: 1e-4 to 1e-13 in half decades (3e-k between), so that the
#: summary finds a setting near each error level (a decade apart, the cheapest run can be 3 times too accurate)
HALF_DECADES = [float(f"{m}e-{k}") for k in range(4, 14) for m in (3, 1)][1:]


def _ladder(quick, full, short):
    return short if quick else full


#: suffix of a rotframe method run set up once (untimed): `rotframe.problem.prepared.PreparedProblem`, `PreparedBody`
PREPARED = " prepared"


def _with_prepared(runs, quick):
    """Add prepared-run ladders (the same settings) for dop853, rk4 and the exact flow, where benched."""
    out = dict(runs)
    for m in ("dop853", "rk4", "exact") if not quick else ("dop853", "exact"):
        if m in runs:
            out[m + PREPARED] = runs[m]
    return out


def _engine_runner(problem, r0, v0, t_end, invariant_fn, atol_scale=None):
    """A runner of a scene built on the engine (`rotframe.problem`): ``rotframe.simulate``'s core for a whole run,
    `rotframe.problem.prepared.PreparedProblem` (set up once, untimed) for the prepared methods. ``problem``: the
    engine's arguments of the scene's model (``omega``, ``forces``, ``frame_terms``); ``atol_scale``: DOP853's
    absolute tolerance is ``rtol`` times it, where the scene gives its own (`rotframe.scenes.foucault`)."""
    from rotframe.problem.particles import simulate_particles
    from rotframe.problem.prepared import PreparedProblem

    prepared = {}
    times = np.array([0.0, t_end])
    problem = dict(problem, duration=t_end, samples=1)

    def settings(method, setting):
        if method == "dop853":
            return {"rtol": setting} if atol_scale is None else {"rtol": setting, "atol": setting * atol_scale}
        return {"step": setting} if setting is not None else {}

    def final(out, at=times):  # the final state and the invariant's path (after the timing, where timed)
        r, v, nfev = (*out, 0) if isinstance(out, tuple) else (out.r, out.v, out.nfev)
        Y = np.concatenate([r[:, 0], v[:, 0]], axis=1)
        return Y[-1], nfev, lambda: invariant_fn(at, Y)

    def prepared_call(method, setting):
        base = method.removesuffix(PREPARED)
        pr = prepared.get((base, setting))
        if pr is None:
            pr = prepared[(base, setting)] = PreparedProblem(r0=r0, v0=v0, method=base, **problem,
                                                             **settings(base, setting))

        # the exact flow's samples as arrays (`PreparedProblem.states`, as the scenes' PreparedRun gives them); the
        # integrators' Trajectory, whose count of evaluations the bench reports
        return (lambda: pr.states(r0, v0)) if base == "exact" else (lambda: pr.run(r0, v0)), final

    def run(method, setting):
        if method.endswith(PREPARED):
            call, finish = prepared_call(method, setting)
            return finish(call())
        # compiled from the first run, whose time is the compile column's: the plain tier of a first run (a latency
        # the start-up table measures) would leave the loop to compile in a timed repeat
        traj = simulate_particles(r0=r0, v0=v0, method=method, plain_tier=False, **problem,
                                  **settings(method, setting)).trajectory
        return final(traj, traj.times)

    run.prepared_call = prepared_call
    return run


def _turntable(quick):
    from rotframe.particles.model import OmegaSchedule
    from rotframe.scenes.turntable import inertial_line

    w0, alpha, T = 1.0, 0.2, 4.0
    z = np.array([0.0, 0.0, 1.0])
    omega = OmegaSchedule.ramp(z, w0, alpha, T)  # the oracle's exact angle
    frame = (np.array([0.0, T]), np.array([w0 * z, (w0 + alpha * T) * z]), "linear")  # the scene's frame on the engine
    r0, v0 = np.array([2.0, 0.0, 0.0]), np.array([-1.0, 0.0, 0.0])
    r_end = inertial_line(omega, r0, v0, np.array([T]))[0]
    spec = {"kind": "particle", "w": (0.0, 0.0, 0.0), "g": (0.0, 0.0, 0.0), "ramp": (w0, alpha), "pendulum": None}

    def inertial_speed(t, Y):
        # the inertial speed |v + w x r| is constant on the exact solution
        w = (w0 + alpha * t)[:, None] * np.array([0.0, 0.0, 1.0])
        s = np.linalg.norm(Y[:, 3:] + np.cross(w, Y[:, :3]), axis=1)
        return float(np.max(np.abs(s / s[0] - 1)))

    steps = _ladder(quick, [4e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4], [1e-3])
    # the puck is force-free: its exact flow (the inertial line turned by the rate's exact angle) is a method too
    runs = _with_prepared({"exact": [None], "rotation-splitting": steps, "rotation-splitting4": steps, "rk4": steps,
                           "dop853": _ladder(quick, [1e-4, 1e-6, 1e-8, 1e-10, 1e-12], [1e-8])}, quick)
    y0 = np.concatenate([r0, v0])
    from rotframe.app.bench.peers import python_rhs

    return [Problem("turntable", "4 s, 0.9 turns", T, y0, python_rhs(spec),
                    lambda y: float(np.linalg.norm(y[:3] - r_end)), "analytic: final position error (m)",
                    inertial_speed, runs, _engine_runner({"omega": frame, "frame_terms": ("coriolis", "centrifugal",
                                                                                          "euler")},
                                                         r0, v0, T, inertial_speed), spec=spec)]


def _tower_drop(quick):
    from rotframe import analytic, earth
    from rotframe.app.bench.peers import python_rhs
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    lat = math.radians(50 + 53 / 60)
    g = float(earth.normal_gravity(lat))
    w = earth.omega_enu(lat)
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=np.array([0, 0, -g]))
    T = 5.0
    r0, v0 = np.array([0, 0, 158.5]), np.zeros(3)
    # the oracle: the closed form of gravity + Coriolis (sines, no matrix exponential), independent of
    # the exact method's expm; the two agree to ~1e-13 m here (tests/test_exact_flow.py)
    r_exact, _ = analytic.coriolis_uniform_gravity(w, [0, 0, -g], r0, v0, T)
    spec = {"kind": "particle", "w": tuple(w), "g": (0.0, 0.0, -g), "ramp": None, "pendulum": None}

    def energy(t, Y):
        e = 0.5 * np.sum(Y[:, 3:] ** 2, axis=1) + g * Y[:, 2]
        return float(np.max(np.abs(e - e[0])) / abs(e[0]))

    steps = _ladder(quick, [1e-1, 1e-2, 1e-3, 1e-4], [1e-2])
    runs = _with_prepared({"exact": [None], "rotation-splitting": steps, "rk4": steps,
                           "dop853": _ladder(quick, [1e-4, 1e-6, 1e-8, 1e-10, 1e-12], [1e-8])}, quick)
    # the scene on the engine: its model as the engine takes it (rotframe.forces' gravity, the frame's Coriolis term)
    from rotframe.scenes.base import engine_terms

    omega, forces, frame_terms = engine_terms(model)
    return [Problem("tower-drop", "5 s fall", T, np.concatenate([r0, v0]), python_rhs(spec),
                    lambda y: float(np.linalg.norm(y[:3] - r_exact)),
                    "analytic (closed form, gravity + Coriolis): final position error (m)", energy, runs,
                    _engine_runner({"omega": omega, "forces": forces, "frame_terms": frame_terms}, r0, v0, T, energy),
                    spec=spec)]


def _foucault(quick):
    from rotframe import earth
    from rotframe.app.bench.peers import python_rhs
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel
    from rotframe.scenes.base import engine_terms
    from rotframe.scenes.foucault import swing_scale

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
    ref = integrate_particles(model, r0, v0, T, method="rotation-splitting4", step=2e-4 if not quick else 1e-3, samples=1)
    y_ref = np.concatenate([ref.r[-1, 0], ref.v[-1, 0]])

    def constraint(t, Y):
        return float(np.max(np.abs(np.linalg.norm(Y[:, :3] - pivot, axis=1) - L)))

    steps = _ladder(quick, [5e-2, 2e-2, 1e-2, 5e-3, 2e-3], [1e-2])
    runs = _with_prepared({"rotation-splitting": steps, "rotation-splitting4": steps, "rk4": steps,
                           "dop853": _ladder(quick, [1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 1e-11, 1e-13],
                                             [1e-9])}, quick)
    ref_kind = "rotation-splitting4, h = 2e-4 s" if not quick else "rotation-splitting4, h = 1e-3 s (quick)"
    # the scene on the engine (its terms as rotframe.forces', the steady loop under dop853), with the scene's own
    # absolute tolerance, rtol max(1 m, |r0|, |v0|) (rotframe.scenes.foucault)
    omega, forces, frame_terms = engine_terms(model)
    runner = _engine_runner({"omega": omega, "forces": forces, "frame_terms": frame_terms}, r0, v0, T, constraint,
                            atol_scale=swing_scale(r0, v0))
    return [Problem("foucault", f"{T / 3600:g} h, {T / 16.42:.0f} periods", T, np.concatenate([r0, v0]),
                    python_rhs(spec), lambda y: float(np.linalg.norm(y[:3] - y_ref[:3])),
                    f"reference ({ref_kind}): final position error (m)", constraint, runs, runner, atol=1e-10,
                    scipy_rtols=tuple(10.0 ** -k for k in range(3, 12)), spec=spec,
                    ref_error=3e-9)]


def _rigid_runner(inertia, L0, q0, T, top=None, invariant=None):
    """A runner of a rigid scene, on the engine as the scene runs: ``simulate_body``'s core for a whole run (compiled
    from its first), `rotframe.problem.prepared_body.PreparedBody` (set up once, untimed) for the prepared methods.
    ``top = (mass, length, g)``: the heavy top's gravity (`rotframe.torques.gravity`). The evaluations reported are
    DOP853's right-hand sides, and a fixed step's steps."""
    from rotframe import torques
    from rotframe.problem.body import simulate_rigid_body
    from rotframe.problem.prepared_body import PreparedBody

    torque = None if top is None else torques.gravity(*top)
    body = dict(inertia=inertia, duration=T, torque=torque, samples=1)
    ends = np.array([0.0, T])
    prepared = {}

    def settings(method, setting):
        return {"rtol": setting} if method == "dop853" else {"step": setting} if setting is not None else {}

    def prepared_call(method, setting):  # set up once (untimed): simulate_body's samples to the bit
        base = method.removesuffix(PREPARED)
        pr = prepared.get((base, setting))
        if pr is None:
            pr = prepared[(base, setting)] = PreparedBody(L0=L0, q0=q0, method=base, **body, **settings(base, setting))

        def finish(Lq):  # the final state and the invariant's path, after the timing
            L, q = Lq
            return (np.concatenate((L[-1], q[-1])), pr.nfev if base == "dop853" else pr.steps,
                    None if invariant is None else (lambda: invariant(ends, np.concatenate([L, q], axis=1))))

        return (lambda: pr.states(L0, q0)), finish

    def run(method, setting):
        if method.endswith(PREPARED):
            call, finish = prepared_call(method, setting)
            return finish(call())
        res = simulate_rigid_body(L0=L0, q0=q0, method=method, plain_tier=False, **body, **settings(method, setting))
        Y = np.concatenate([res.L, res.q], axis=1)
        return (Y[-1], res.nfev if method == "dop853" else res.steps,
                None if invariant is None else (lambda: invariant(res.times, Y)))

    run.prepared_call = prepared_call
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
    from rotframe.rigid import free_body_exact as free_body_flow  # the compiled closed form

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
        rtols = HALF_DECADES
        runs = {"exact": [None], "dop853": _ladder(quick, rtols, [1e-8]), "lie-poisson": steps,
                "lie-poisson4": steps, "lie-poisson8": _ladder(quick, [3e-1, 1e-1, 3e-2, 1e-2], [1e-1]),
                "rk4": steps}
        if long:
            runs = {"exact": [None], "dop853": [1e-6, 1e-8, 1e-10, 1e-12], "lie-poisson4": steps}
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


def _free_top(quick):
    """The free-top scenario's Earth (its defaults): 2 Euler periods, 616 turns of the spin.

    The reference is the closed form of the free symmetric top (two commuting rotations,
    rigid.free_body_exact), which is also the ``exact`` method: its zero error counts only for it.
    """
    from rotframe.app.bench.peers import python_rhs
    from rotframe.rigid import dynamics as rigid

    i1, i3, w3, w_perp, T = 8.0101e37, 8.03641e37, 7.292115e-5, 7.292115e-11, 5.3e7
    inertia = np.array([i1, i1, i3])
    L0 = inertia * np.array([w_perp, 0.0, w3])
    q0 = np.array([0.0, 0.0, 0.0, 1.0])
    spec = {"kind": "rigid", "inertia": tuple(inertia), "mgl": 0.0}
    Lx, qx = rigid.free_body_exact(inertia, L0, q0, np.array([T]))
    M = np.linalg.norm(L0)

    def err(y):
        return max(float(np.linalg.norm(y[:3] - Lx[0]) / M), attitude_error(y[3:], qx[0]))

    def invariant(t, Y):
        E = 0.5 * np.sum(Y[:, :3] ** 2 / inertia, axis=1)
        Mm = np.linalg.norm(Y[:, :3], axis=1)
        return float(max(np.max(np.abs(E / E[0] - 1)), np.max(np.abs(Mm / Mm[0] - 1))))

    base = _rigid_runner(inertia, L0, q0, T, invariant=invariant)
    runs = {"exact": [None], "dop853": _ladder(quick, HALF_DECADES, [1e-8]),
            "lie-poisson": _ladder(quick, [1e6, 1e5, 1e4], [1e5]), "rk4": _ladder(quick, [3e3, 1e3, 3e2, 1e2], [1e3])}
    return [Problem("free-top", "5.3e7 s, 616 turns, 2 Euler periods", T, np.concatenate([L0, q0]),
                    python_rhs(spec), err, "analytic (free symmetric top): max(|dL|/|L|, attitude angle)",
                    invariant, runs, base, atol=1e-13, spec=spec)]


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
    rtols = _ladder(quick, HALF_DECADES[:-2], [1e-8])  # to 1e-12: the reference is good to ~1e-12
    steps8 = _ladder(quick, [1e-1, 6e-2, 4e-2, 3e-2, 2e-2, 1.5e-2, 1e-2, 5e-3], [2e-2])
    runs = {"dop853": rtols, "top-splitting": steps, "top-splitting4": steps,
            "top-splitting6": _ladder(quick, [2e-2, 1e-2, 5e-3, 2e-3], [1e-2]), "top-splitting8": steps8,
            "rk4": [s for s in steps if s <= 1e-3],
            # prepared runs (rigid.prepared): the fourth-order splitting on a finer ladder near the 1e-6 level
            "top-splitting4" + PREPARED: _ladder(quick, [1e-2, 5e-3, 3e-3, 2e-3, 1.5e-3, 1e-3, 3e-4, 1e-4], [1e-3]),
            "top-splitting8" + PREPARED: steps8, "dop853" + PREPARED: rtols}
    return [Problem("heavy-top", "2 s, 95 spins", T, np.concatenate([L0, q0]), rhs, err,
                    "reference (scipy DOP853, rtol 1e-13): max(|dL|/|L|, attitude angle)", invariant, runs,
                    _rigid_runner(inertia, L0, q0, T, top=(values["mass"], values["length"], values["g"]),
                                  invariant=invariant),
                    atol=1e-14, spec=spec)]
