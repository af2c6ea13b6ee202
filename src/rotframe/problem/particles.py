"""Particles of the user's own problem: their forces, their events, any rotating frame.

`simulate_particles` is the numerical core of ``rotframe.simulate``: float64 arrays in
SI units, no printing, no files. It builds (or finds in the cache) a driver compiled for the
problem's functions (`rotframe.problem.codegen`), integrates every particle on its own
(DOP853 with Hairer's step control; RK4 or the rotation splittings of order 2 and 4 at a fixed
step, the splittings with the forces as kicks: `rotframe.problem.terms.check_splitting`; the
exact flow of a linear problem, nothing compiled: `rotframe.problem.exact`), locates the events by bisection
on the method's own re-steps, and reports the energy or the Jacobi integral where the forces
give their potentials.

A force is a function ``f(t, r, v, *params) -> (ax, ay, az)`` (m/s^2; ``r``, ``v`` arrays of
3 in the frame's axes). Attach ``axes="inertial"`` (its result is then turned into frame
axes by the frame's attitude, integrated with the particle) or ``potential=U`` with
``U(t, r, *params)`` (J/kg) by wrapping it in `Force`, or by setting attributes of
those names on the function. An event is ``g(t, r, v, *params) -> float`` with optional
attributes ``terminal`` and ``direction``, as in ``scipy.integrate.solve_ivp``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotframe.errors import IntegrationError, ScenarioError
from rotframe.particles.trajectory import RunInterrupted, Trajectory
from rotframe.problem import callables as uf
from rotframe import method_registry as registry
from rotframe.problem.arguments import (array_of, check_event, check_flag, check_inline, check_params, run_grid,
                                        sequence_of_callables)
from rotframe.problem.codegen import Driver, build_module
from rotframe.problem.frame import frame_spec, origin_spec, stop_times
from rotframe.problem.glue import flatten_params, particle_source
from rotframe.problem.frame_error import frame_interpolation
from rotframe.problem.inlined import Inlining
from rotframe.limits import check_memory, check_run
from rotframe.problem.pacing import Pacer
from rotframe.problem.terms import (FRAME_TERMS, Force, StringConstraint, as_term, check_frame_terms, check_splitting,
                                    model_constants, one_constraint)

__all__ = ["Force", "StringConstraint", "simulate_particles", "ProblemRun", "advance_blocks"]

#: what a particle's status code (`rotframe.problem.engine`) says when it ends a run early
STATUS = {3: "the state became non-finite", 4: "the step size collapsed below round-off of t",
          5: "an event function gave a non-finite value", 6: "a user function raised"}


@dataclass
class ProblemRun:
    """What `simulate_particles` returns: the trajectory and what was measured on it."""

    trajectory: Trajectory
    diagnostics: dict
    warnings: list
    notes: list
    frame: object
    compile_s: float = 0.0
    #: the frame's terms that acted (`rotframe.problem.terms.FRAME_TERMS`, ``frame_terms=``)
    frame_terms: tuple = FRAME_TERMS


def _states(r0, v0):
    r = np.atleast_2d(array_of(r0, "r0"))
    v = np.atleast_2d(array_of(v0, "v0"))
    if r.ndim == 2 and v.ndim == 2 and r.shape[1] == 3 and v.shape[1] == 3 and 1 in (r.shape[0], v.shape[0]):
        n = max(r.shape[0], v.shape[0])  # one start position with N velocities, or the other way round
        r, v = np.repeat(r, n // r.shape[0], axis=0), np.repeat(v, n // v.shape[0], axis=0)
    if r.ndim != 2 or r.shape[1] != 3 or v.shape != r.shape:
        raise ScenarioError(f"r0, v0: shapes {np.shape(r0)} and {np.shape(v0)}; expected both (3,) or both (N, 3)")
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(v))):
        raise ScenarioError("r0, v0: not finite")
    return r, v


def problem_tuple(M, p, frame, origin):
    """The engine's `rotframe.problem.signatures.PROBLEM` tuple of a particle problem."""
    from rotframe.problem.signatures import PARTICLE  # numba's types: imported by the runs that compile

    return (PARTICLE, M, p, *frame.packed(), *origin.packed(derivative=False))


def _bind(frame, origin, forces, events, compiled):
    def prep(f):
        return uf.compiled_for_glue(f) if compiled else uf.plain_function(f)

    functions = {}
    if frame.kind == "function":
        functions["omega_fn"] = prep(frame.funcs[0])
        if len(frame.funcs) > 1:
            functions["omega_dot_fn"] = prep(frame.funcs[1])
    if origin.kind == "function":
        functions["origin_fn"] = prep(origin.funcs[0])
    for k, f in enumerate(forces):
        functions[f"force_{k}"] = prep(f.accel)
        if f.potential is not None:
            functions[f"potential_{k}"] = prep(f.potential)
    for k, g in enumerate(events):
        functions[f"event_{k}"] = prep(g)
    return functions


def _roles(frame, origin, forces, events, labels):
    roles = []
    if frame.kind == "function":
        roles.append(("omega", frame.funcs[0]))
        if len(frame.funcs) > 1:
            roles.append(("omega_dot", frame.funcs[1]))
    if origin.kind == "function":
        roles.append(("origin_acceleration", origin.funcs[0]))
    roles += [(labels[k], f.accel) for k, f in enumerate(forces)]
    roles += [(f"{labels[k]}.potential", f.potential) for k, f in enumerate(forces) if f.potential is not None]
    roles += [(f"events[{k}]", g) for k, g in enumerate(events)]
    return roles


def _check_functions(forces, events, params, r, v, t0, labels):
    """Each force, potential and event once, in plain Python, at the start: shape, finiteness, raises."""
    when = f"at t = {t0:g} s, r = {r.tolist()}, v = {v.tolist()}"
    for k, f in enumerate(forces):
        uf.check_call(labels[k], f.accel, (t0, r.copy(), v.copy(), *f.params_for(params)), (3,), when=when)
        if f.potential is not None:
            uf.check_call(f"{labels[k]}.potential", f.potential, (t0, r.copy(), *f.params_for(params)), (), when=when)
    for k, g in enumerate(events):
        uf.check_call(f"events[{k}]", g, (t0, r.copy(), v.copy(), *params), (), when=when)


def _blame(functions, params, t, y, dt, labels, frame_roles=()):
    """After a failed step: which of ``functions`` (`Force` terms or events, named by ``labels``), called
    at the last finite state ``y``, or of ``frame_roles`` (omega(t), a0(t)), raises or gives non-finite values.

    Returns ``(text, raised)`` (`rotframe.problem.callables.blame_in_step`).
    """
    r, v = y[:3].copy(), y[3:6].copy()
    where = f", r = {r.tolist()}, v = {v.tolist()}"

    def at_state(own):
        return lambda tp: (tp, *uf.read_only_args((r, v)), *own)

    candidates = [(labels[k], f.accel, at_state(f.params_for(params)), where) if isinstance(f, Force)
                  else (labels[k], f, at_state(params), where) for k, f in enumerate(functions)]
    candidates += [(role, f, lambda tp: (tp,), "") for role, f in frame_roles]
    return uf.blame_in_step(candidates, t, dt)


def _scales(r, v, duration, rtol, atol, D):
    """Absolute tolerances, one row per particle ((N, D)): each particle's from its own scales, so that its
    steps, and its numbers, do not depend on the other particles of the ensemble."""
    N = r.shape[0]
    if atol is not None:
        a = array_of(atol, "atol")
        if a.ndim == 0:
            a = np.full(6, float(a))
        if a.shape != (6,) or not np.all(a > 0):
            raise ScenarioError(f"atol={atol!r}: a positive number or 6 positive numbers (r then v)")
        a = np.tile(a, (N, 1))
    else:
        sr = np.maximum(np.max(np.abs(r), axis=1), np.max(np.abs(v), axis=1) * duration)
        sv = np.maximum(np.max(np.abs(v), axis=1), sr / duration)
        still = sr == 0.0
        sr[still], sv[still] = 1.0, 1.0 / duration
        a = np.concatenate([np.repeat(rtol * sr[:, None], 3, axis=1), np.repeat(rtol * sv[:, None], 3, axis=1)],
                           axis=1)
    return np.ascontiguousarray(np.concatenate([a, np.full((N, D - 6), rtol)], axis=1))


def simulate_particles(*, omega, r0, v0, duration, forces=(), params=(), origin_acceleration=None, events=(),
                       method=None, rtol=None, step=None, samples=None, omega_dot=None, atol=None,
                       frame_attitude=None, jit=True, progress=None, max_events=256, device=None,
                       frame_terms=None, inline=None) -> ProblemRun:
    """Integrate particles of the user's problem; see `rotframe.simulate` for the arguments.

    Returns
    -------
    ProblemRun
        ``trajectory`` (a [`rotframe.particles.trajectory.Trajectory`][rotframe.particles.trajectory.Trajectory]: ``times`` (n,),
        ``r``, ``v`` (n, N, 3), ``event_times``/``event_states`` by event name, ``extras``
        with ``frame_q`` (n, 4) where the attitude was integrated and ``energy`` (n, N) where
        it is conserved), ``diagnostics``, ``warnings``, ``notes``.
    """
    import time

    check_flag(jit, "jit")
    check_inline(inline, jit)
    on_gpu = _check_device(device, method, jit)
    method = registry.check(method, "particles", default="dop853", gpu=on_gpu)
    if isinstance(max_events, bool) or not isinstance(max_events, (int, np.integer)) or max_events < 1:
        raise ScenarioError(f"max_events={max_events!r}: a whole number >= 1 (event crossings kept per particle)")
    frame_terms = check_frame_terms(frame_terms)
    r, v = _states(r0, v0)
    N = r.shape[0]
    fixed = method not in ("dop853", "exact")
    duration, samples, times, rtol, hfix = run_grid(duration, samples, rtol, step, fixed=fixed,
                                                    what=f"method {method}", particles=N)
    frame = frame_spec(omega, omega_dot)
    origin = origin_spec(origin_acceleration)
    for spec, what in ((frame, "omega"), (origin, "origin_acceleration")):
        if spec.t_range[1] < duration or spec.t_range[0] > 0.0:
            raise ScenarioError(f"{what}: defined for t in [{spec.t_range[0]:g}, {spec.t_range[1]:g}] s, "
                                f"not over the run's [0, {duration:g}] s")
    terms = [as_term(f, k) for k, f in enumerate(sequence_of_callables(forces, "forces"))]
    forces = [f for f in terms if isinstance(f, Force)]
    labels = [f"forces[{k}]" for k, f in enumerate(terms) if isinstance(f, Force)]  # as the user numbered them
    constraint = one_constraint(terms, r, v)
    events = sequence_of_callables(events, "events")
    for k, g in enumerate(events):
        if not callable(g):
            raise ScenarioError(f"events[{k}]: {g!r} is not callable (a function g(t, r, v, *params) -> float)")
    params = check_params(params)
    if method.startswith("rotation-splitting"):
        check_splitting(method, forces, labels)
    if method == "exact":  # the exact flow of a linear problem: chosen from the terms, nothing compiled
        return _exact_run(terms, frame, origin, events, frame_terms, r, v, duration, samples, progress)
    inertial = any(f.axes == "inertial" for f in forces)
    D = 10 if inertial else 6
    _check_functions(forces, events, params, r[0], v[0], 0.0, labels)
    if frame.kind == "function":
        frame.vector_at([0.0])  # checked in frame_spec; the derivative's form too
    roles = _roles(frame, origin, forces, events, labels)
    for role, f in roles:
        uf.check_compilable(role, f, jit)
    splitting = method.startswith("rotation-splitting")
    glue = particle_source(forces, events, params, splitting=splitting, origin=origin.kind == "function",
                           omega=("function_dot" if len(frame.funcs) > 1 else "function") if frame.kind == "function"
                           else "")
    key, cache_note = uf.cache_key(roles, f"|{[f.axes for f in forces]}")
    cache_notes = [cache_note] if cache_note and jit else []
    t0 = time.perf_counter()
    try:
        driver = Driver(build_module("particle", key, lambda: _bind(frame, origin, forces, events, jit), glue,
                                     compiled=jit, notes=cache_notes), compiled=jit)
    except Exception as exc:
        import numba

        if isinstance(exc, numba.core.errors.NumbaError):
            _compile_failure(exc, roles, params, r[0], v[0], frame,
                             {labels[k] for k, f in enumerate(forces) if not f.takes_params})
        raise
    prob = problem_tuple(model_constants(constraint, next((f for f in forces if f.flow), None) if splitting else None,
                                         frame_terms), flatten_params(params), frame, origin)
    fns = driver.functions(prob)
    slots = max_events if events else 1  # event records: none are kept without events
    n = samples + 1
    check_memory("simulate", {"samples (r, v and state at each sample)": 8.0 * n * N * D,
                              "event slots": 8.0 * N * slots * (D + 2), "per-particle state": 8.0 * N * (3 * D + 16)})
    stops = stop_times((frame, origin), duration)
    check_run(steps=stops.size, particles=N, what="simulate (the frame's knots each end a step)")
    y = np.zeros((N, D))
    y[:, :3] = r
    y[:, 3:6] = v
    if D == 10:
        q0 = np.array([0.0, 0.0, 0.0, 1.0]) if frame_attitude is None else array_of(frame_attitude, "frame_attitude")
        if q0.shape != (4,) or not np.all(np.isfinite(q0)) or not np.any(q0):
            raise ScenarioError(f"frame_attitude: {q0.tolist()}; a scalar-last quaternion (x, y, z, w), 4 finite "
                                "numbers, not all 0")
        if frame_attitude is None and frame.kind == "body":
            q0 = np.asarray(omega.trajectory.q[0], dtype=float)
        y[:, 6:] = q0 / np.linalg.norm(q0)
    y0_first = y[:1].copy()
    atol_arr = _scales(r, v, duration, rtol, atol, D)
    OUT = np.full((n, N, D), np.nan)
    state = dict(TC=np.zeros(N), H=np.zeros(N), IDX=np.zeros(N, np.int64), SUB=np.zeros(N, np.int64),
                 ST=np.zeros(N, np.int64), EVT=np.full((N, slots), np.nan), EVY=np.zeros((N, slots, D)),
                 EVK=np.zeros((N, slots), np.int64), EVN=np.zeros(N, np.int64),
                 GPREV=np.zeros((N, max(len(events), 1))), NSTEP=np.zeros(N, np.int64), NFEV=np.zeros(N, np.int64))
    settings = [check_event(g, k) for k, g in enumerate(events)]
    EDIR = np.array([float(d) for d, _ in settings], dtype=float)
    ETERM = np.array([bool(t) for _, t in settings], dtype=bool)
    pacer = Pacer("simulate", duration, adaptive=method == "dop853")  # calls sized in time: signals and progress between them
    first = True
    if on_gpu:  # the same loop on the GPU: every particle at once, the arrays kept there between calls
        from rotframe.problem.gpu import GpuAdvance

        gpu = GpuAdvance(driver.module, method, bool(events), D)  # the GPU is there: `_check_device`
    else:
        gpu = None
    # the engine's loop, or the same loop with the problem's functions compiled in where the run is long (`inlined`)
    from rotframe.problem.models import model_parts

    inlining = Inlining(driver.module, prob[0], method, events, D, model_parts(prob),
                        inline if jit and not on_gpu else False)

    def advance(*args):  # the engine's loop, or the inlined one once the run has switched to it
        driver.advance(*args, kernel=inlining.kernel)

    try:
        inlining.start()
        if events:
            driver.start_events(0.0, y, state["GPREV"], prob, fns)
        before = (times, y, state["TC"], state["H"], state["IDX"], state["SUB"], state["ST"], OUT, state["EVT"],
                  state["EVY"], state["EVK"], state["EVN"], state["GPREV"], state["NSTEP"], state["NFEV"])
        after = (method, rtol, atol_arr, hfix, EDIR, ETERM, stops, prob, fns)
        while True:
            saved = {key: state[key].copy() for key in _REPLAYED}
            saved["Y"] = y.copy()
            budget = pacer.start()
            try:
                if gpu is not None:
                    gpu(0, N, *before, budget, *after)
                    if gpu.ended.size:  # a user function raised on the GPU: the CPU runs the call again, to the step
                        gpu.fetch()
                        _again_on_the_cpu(gpu.ended, advance, y, state, saved, before + (budget,) + after)
                        if np.all(state["ST"][gpu.ended] == 0):  # it did not raise there: the GPU goes on from it
                            gpu.resume()
                else:
                    advance_blocks(advance, N, before + (budget,) + after)
            except Exception as exc:
                if gpu is not None:
                    gpu.fetch()
                _raised_later(exc, advance, y, saved, {"before": before, "after": after, "budget": budget}, forces,
                              params, method, hfix, times, OUT, state, events, labels)
            if first:
                compile_s = time.perf_counter() - t0  # the glue's compile and the first call (the engine's load)
                first = False
            pacer.done(float(np.sum(state["NSTEP"]) - np.sum(saved["NSTEP"])))
            inlining.after_call(pacer.last_seconds, float(np.sum(state["TC"] - saved["TC"])),
                                float(np.sum(duration - state["TC"][state["ST"] == 0])))
            ST = state["ST"]
            if progress is not None:
                progress(float(np.min(state["IDX"])) / n)
            if np.any(ST >= 3):
                break
            if np.all(ST != 0):
                break
            running = ST == 0
            pacer.check(state["NSTEP"][running], state["TC"][running])
    except KeyboardInterrupt:
        if gpu is not None:
            gpu.fetch()
        traj = _trajectory(times, OUT, state, events, method, int(np.min(state["IDX"])), hfix)
        raise RunInterrupted(traj) from None
    if gpu is not None:
        gpu.fetch()
    traj = _trajectory(times, OUT, state, events, method, n, hfix)
    if np.any(state["ST"] >= 3):
        i = int(np.flatnonzero(state["ST"] >= 3)[0])
        good = int(state["IDX"][i])
        t_bad = float(state["TC"][i])
        # the step that failed: RK4's fixed one, or DOP853's last try (10 times the step it fell back to)
        code = int(state["ST"][i])
        dt_failed = hfix if method != "dop853" else (10.0 if code in (3, 4) else 1.0) * float(state["H"][i])
        if code == 5:
            blame, raised = _blame(events, params, t_bad, y[i], dt_failed, [f"events[{k}]" for k in range(len(events))])
        else:
            blame, raised = _blame(forces, params, t_bad, y[i], dt_failed, labels,
                                   _roles(frame, origin, [], [], []))
        partial = _trajectory(times, OUT, state, events, method, good, hfix)
        state_text = f"r = {y[i, :3].tolist()}, v = {y[i, 3:6].tolist()}"
        if code == 6 or raised:  # a user function raised (compiled: the engine stopped at once)
            raise uf.raised_during_run(f"simulate: particle {i}: a user function raised in the step from "
                                       f"t = {t_bad:.9g} s, {state_text}{blame}; samples up to there are kept",
                                       t_bad, partial)
        raise IntegrationError(f"simulate: particle {i}: {STATUS[code]}{blame} after t = {t_bad:.9g} s (method "
                               f"{method}); samples up to there are kept", t_reached=t_bad, partial=partial)
    warnings, notes, diagnostics = [], list(frame.notes) + cache_notes + ([inlining.note] if inlining.note else []), {}
    if not jit:
        warnings.append("jit=False: the forces and the integrator ran as plain Python, some 100 to 1000 times "
                        "slower than compiled")

    def energies(rotating):
        return driver.energies(traj.times, np.ascontiguousarray(OUT[: traj.times.size]), prob, fns, driver.potential(),
                               rotating)

    _energy_diagnostics(energies, traj, frame, origin, forces, diagnostics, notes, frame_terms)
    try:
        frame_interpolation(driver.advance, frame, origin, y0_first, times, after, OUT, duration, rtol, diagnostics,
                            warnings, notes, lambda spec: problem_tuple(prob[1], prob[2], spec, origin))
    except KeyboardInterrupt:
        raise RunInterrupted(traj) from None
    if D == 10:
        traj.extras["frame_q"] = OUT[:, 0, 6:10].copy()
    dropped = int(np.sum(np.maximum(state["EVN"] - max_events, 0)))
    if dropped:
        warnings.append(f"{dropped} event crossings beyond {max_events} per particle were located but not kept")
    compile_s += inlining.seconds_mid_run  # an inlined loop made after the first call: compile time too
    traj.extras["compile_s"] = compile_s
    return ProblemRun(traj, diagnostics, warnings, notes, frame, compile_s, frame_terms)


def _check_device(device, method, jit) -> bool:
    """Whether the run is on the GPU (``device="gpu"``, `rotframe.problem.gpu`): checked, in one line each."""
    from rotframe.particles.threads import check_device

    if check_device(device, "device") != "gpu":
        return False
    if method is None:
        raise ScenarioError(f"method: none given; device='gpu' runs {', '.join(registry.names('particles', gpu=True))} "
                            "(the default, dop853, runs on the CPU)")
    if not jit:
        raise ScenarioError("jit=False: plain Python runs on the CPU; device='gpu' compiles the forces for the GPU")
    return True


def advance_blocks(advance, N, args):
    """``advance(lo, hi, *args)`` over the blocks of the N particles, on the ensemble's threads.

    The blocks are the particle core's (`rotframe.particles.blocks.block_bounds`: the same
    share for every thread) and each particle is integrated alone, so the numbers never depend
    on the thread count or the cut. The compiled driver releases the GIL, so blocks run in parallel on
    `rotframe.particles.threads.resolve_threads` threads (every core, or ``--threads``).
    """
    from rotframe.particles.blocks import block_bounds
    from rotframe.particles.threads import resolve_threads

    workers = int(resolve_threads(None))
    blocks = block_bounds(N, workers)
    threads = max(1, min(workers, len(blocks)))
    if threads == 1:
        for lo, hi in blocks:
            advance(lo, hi, *args)
        return
    from concurrent.futures import wait

    from rotframe.particles.blocks import thread_pool

    futures = [thread_pool(threads).submit(advance, lo, hi, *args) for lo, hi in blocks]
    wait(futures)  # every block done before a failure is raised (the replay restores the arrays)
    for future in futures:
        future.result()


#: the per-particle arrays a driver call changes besides the samples and event records (copied before each
#: call, so that a call in which a user function raised can be replayed one step at a time)
_REPLAYED = ("TC", "H", "IDX", "SUB", "ST", "EVN", "GPREV", "NSTEP", "NFEV")


def _restore(y, state, saved):
    """The state arrays as they were before a driver call (``saved``), for a replay or a retry."""
    y[...] = saved["Y"]
    for key in _REPLAYED:
        state[key][...] = saved[key]


def _again_on_the_cpu(particles, advance, y, state, saved, args):
    """Run the last call again on the CPU for ``particles``, from the state saved before it (the engine's CPU loop
    stops at the step where a user function raised, status 6, which names it as a CPU run does)."""
    for i in particles:
        y[i] = saved["Y"][i]
        for key in _REPLAYED:
            state[key][i] = saved[key][i]
        advance(int(i), int(i) + 1, *args)


def _raised_later(exc, advance, y, saved, args, forces, params, method, hfix, times, OUT, state, events, labels):
    """A user function raised inside a compiled call: find the step, name the function, give time and state.

    The call is replayed from the state saved before it, one step per call, particle by particle
    (the drivers are deterministic), up to the step where the exception comes again; the force that
    raises there in plain Python is named. Raises `UserFunctionError` (``.t_reached`` and
    ``.partial`` keep the samples up to that step).
    """
    _restore(y, state, saved)
    what = f"{type(exc).__name__}: {exc}".replace("\n", " ")
    where = ""
    for i in np.flatnonzero(state["ST"] == 0):
        for _ in range(int(args["budget"]) + 1):
            t, yi = float(state["TC"][i]), y[i].copy()
            try:
                advance(int(i), int(i) + 1, *args["before"], 1, *args["after"])
            except Exception:  # the user's function raised again: this step
                dt = hfix if method != "dop853" else float(state["H"][i])
                blame = _blame(forces, params, t, yi, dt, labels)[0]
                where = (f"particle {i}: a user function raised {what} in the step from t = {t:.9g} s, "
                         f"r = {yi[:3].tolist()}, v = {yi[3:6].tolist()}" + blame)
                state["TC"][i] = t
                break
            if state["ST"][i] != 0:
                break
        if where:
            break
    if not where:
        t = float(np.min(state["TC"]))
        where = f"a user function raised {what} after t = {t:.9g} s (the last state saved)"
    good = int(np.min(state["IDX"]))
    raise uf.raised_during_run(f"simulate: {where}; samples up to there are kept", float(times[max(good, 1) - 1]),
                               _trajectory(times, OUT, state, events, method, good, hfix)) from None


def _compile_failure(exc, roles, params, r, v, frame, without_params=()):
    """Name the function numba could not compile (``without_params``: the roles of the built-in terms, which take
    no ``params``)."""
    def sample_args(role):
        own = () if role.split(".")[0] in without_params else params
        if role.startswith("forces") and role.endswith("potential"):
            return (0.0, r.copy(), *own)
        if role.startswith(("forces", "events")):
            return (0.0, r.copy(), v.copy(), *own)
        return (0.0,)

    found = uf.diagnose_compile(roles, sample_args)
    reason = found or f"numba cannot compile the problem: {uf.numba_reason(exc)}"
    raise uf.UserFunctionError(f"simulate: {reason}; pass jit=False to run it in plain Python (slow)") from None


def _trajectory(times, OUT, state, events, method, n_kept, step=0.0):
    """The `Trajectory` of the first ``n_kept`` samples; ``step``: a fixed-step method's (``extras["step"]``)."""
    n_kept = max(int(n_kept), 1)
    r = OUT[:n_kept, :, :3].copy()
    v = OUT[:n_kept, :, 3:6].copy()
    steps = int(np.max(state["NSTEP"])) if state["NSTEP"].size else 0
    nfev = int(np.max(state["NFEV"])) if state["NFEV"].size else 0
    complete = n_kept == times.size
    traj = Trajectory(times[:n_kept].copy(), r, v, method, steps, nfev, complete,
                      float(times[n_kept - 1]))
    N = OUT.shape[1]
    kept = np.arange(state["EVT"].shape[1])[None, :] < np.minimum(state["EVN"], state["EVT"].shape[1])[:, None]
    for k, name in enumerate(_event_names(events)):
        # each particle's crossings of event k in time order (ties in the order located), split per particle
        i, j = np.nonzero(kept & (state["EVK"] == k))
        order = np.lexsort((state["EVT"][i, j], i))
        i, j = i[order], j[order]
        cuts = np.cumsum(np.bincount(i, minlength=N))[:-1]
        traj.event_times[name] = np.split(state["EVT"][i, j], cuts)
        traj.event_states[name] = np.split(state["EVY"][i, j, :6], cuts)
    traj.extras["status"] = state["ST"].copy()
    if step:
        traj.extras["step"] = step
    return traj


def _event_names(events):
    names = []
    for k, g in enumerate(events):
        base = getattr(uf.plain_function(g), "__name__", "") or f"event_{k}"
        if base == "<lambda>":
            base = f"event_{k}"
        name = base
        j = 2
        while name in names:
            name = f"{base}_{j}"
            j += 1
        names.append(name)
    return names


def _exact_run(terms, frame, origin, events, frame_terms, r, v, duration, samples, progress) -> ProblemRun:
    """``method="exact"``: the exact flow of the run's linear problem (`rotframe.problem.exact`), the scenes' own
    (`rotframe.particles.integrators.integrate_exact`); the energy diagnostic from the forces' potentials."""
    from rotframe.particles.integrators import integrate_exact
    from rotframe.problem.exact import linear_problem

    model = linear_problem(terms, [f"forces[{k}]" for k in range(len(terms))], frame, origin, events, frame_terms)
    traj = integrate_exact(model, r, v, duration, samples, (), progress, ordered=True)  # per particle, as the engine
    traj.extras["compile_s"] = 0.0
    forces = [f for f in terms if isinstance(f, Force)]
    diagnostics = {}
    notes = list(frame.notes) + ["method exact: the flow of r'' = K r + C v + b (the terms' linear forms and the "
                                 "frame's), to round-off"]

    def energies(rotating):
        n, N = traj.r.shape[:2]
        pos = traj.r.reshape(-1, 3).T  # (3, n N): the built-in potentials are arithmetic on r[0], r[1], r[2]
        t = np.repeat(traj.times, N)
        E = 0.5 * np.sum(traj.v.reshape(-1, 3) ** 2, axis=1)
        for f in forces:
            E = E + np.asarray(f.potential(t, pos), dtype=float)
        if rotating:
            E = E - 0.5 * np.sum(np.cross(frame.data[0], pos.T) ** 2, axis=1)
        return E.reshape(n, N)

    _energy_diagnostics(energies, traj, frame, origin, forces, diagnostics, notes, frame_terms)
    return ProblemRun(traj, diagnostics, [], notes, frame, 0.0, frame_terms)


def _energy_diagnostics(energies, traj, frame, origin, forces, diagnostics, notes, frame_terms):
    """Energy (inertial frame) or Jacobi integral (steadily rotating frame) and its relative drift.

    ``energies(rotating)`` gives the quantity at each sample (n, N), the Jacobi integral where
    ``rotating``.

    The Coriolis term does no work, so in a steadily rotating frame ``v^2/2 + U`` minus the
    centrifugal potential ``|omega x r|^2 / 2`` is kept, or ``v^2/2 + U`` alone where the run left
    the centrifugal term out (``frame_terms``)."""
    if not forces or any(f.potential is None for f in forces):
        return
    if origin.kind != "zero" or not frame.is_constant or frame.kind == "function":
        notes.append("energy is not conserved in a frame whose rotation rate changes or whose origin "
                     "accelerates: no energy diagnostic")
        return
    w = frame.data[0] if frame.kind == "constant" else frame.vector_at([0.0])[0][0]
    rotating = bool(np.any(w != 0.0)) and "centrifugal" in frame_terms
    E = energies(rotating)
    traj.extras["energy"] = E
    name = "jacobi" if rotating else "energy"
    E0 = E[0]
    scale = np.where(E0 != 0.0, np.abs(E0), 1.0)
    drift = float(np.max(np.abs(E - E0) / scale))
    diagnostics[f"{name}_rel_drift"] = drift
    if np.any(E0 == 0.0):
        notes.append(f"{name} is 0 at the start for some particle: its drift is absolute (J/kg) there")
    if rotating:
        notes.append("jacobi_rel_drift: the Jacobi integral v^2/2 + U - |omega x r|^2/2 of the steadily rotating frame")
    elif np.any(w != 0.0):
        notes.append("energy_rel_drift: v^2/2 + U in the rotating frame, kept because the centrifugal term is left "
                     "out (frame_terms) and the Coriolis term does no work")
