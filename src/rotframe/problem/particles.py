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

import math
import time
from dataclasses import dataclass

import numpy as np

from rotframe.errors import IntegrationError, ScenarioError
from rotframe.particles.trajectory import RunInterrupted, Trajectory, per_particle
from rotframe.problem import callables as uf
from rotframe.problem.frame_error import frame_interpolation
from rotframe.problem.inlined import Inlining
from rotframe.problem.pacing import Pacer
from rotframe.problem.particle_setup import (checked_atol, checked_attitude, function_roles, problem_tuple, run_state,
                                             set_up, start_states)
from rotframe.problem.terms import FRAME_TERMS, Force, StringConstraint, energy_by_numpy
from rotframe.problem.tiers import PlainTierFailed, SteadyLoopFailed, Tier, run_falling_back

__all__ = ["Force", "StringConstraint", "simulate_particles", "ProblemRun", "advance_blocks", "raise_if_failed",
           "raised_later", "trajectory_of", "exact_model"]

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


def simulate_particles(**kwargs) -> ProblemRun:
    """Integrate particles of the user's problem; see `rotframe.simulate` for the arguments.

    A run begun in the plain tier that fails (a user function raised, a state not finite) runs
    again compiled from its start (`rotframe.problem.tiers`): a failure is met and reported as the
    compiled loop meets it, whatever the caches held.
    """
    return run_falling_back(_simulate_particles, kwargs)


def _simulate_particles(*, omega, r0, v0, duration, forces=(), params=(), origin_acceleration=None, events=(),
                        method=None, rtol=None, step=None, samples=None, omega_dot=None, atol=None,
                        frame_attitude=None, jit=True, progress=None, max_events=256, device=None,
                        frame_terms=None, inline=None, plain_tier=True, steady=True, energy=True) -> ProblemRun:
    """Integrate particles of the user's problem; see `rotframe.simulate` for the arguments.

    Returns
    -------
    ProblemRun
        ``trajectory`` (a [`rotframe.particles.trajectory.Trajectory`][rotframe.particles.trajectory.Trajectory]: ``times`` (n,),
        ``r``, ``v`` (n, N, 3), ``event_times``/``event_states`` by event name, ``extras``
        with ``frame_q`` (n, 4) where the attitude was integrated and ``energy`` (n, N) where
        it is conserved), ``diagnostics``, ``warnings``, ``notes``. ``energy=False`` (a caller that reads the
        samples and events alone: a sweep's ensemble) measures no energy and notes none.
    """
    s = set_up(r0, v0, omega=omega, duration=duration, forces=forces, params=params,
               origin_acceleration=origin_acceleration, events=events, method=method, rtol=rtol, step=step,
               samples=samples, omega_dot=omega_dot, jit=jit, max_events=max_events, device=device,
               frame_terms=frame_terms, inline=inline, steady=steady, ahead=plain_tier)
    r, v = s.r, s.v
    attitude = None if frame_attitude is None else checked_attitude(frame_attitude)  # refused even where unread
    if s.method == "exact":  # the exact flow of a linear problem: chosen from the terms, nothing compiled
        return _exact_run(s.terms, s.frame, s.origin, s.events, s.frame_terms, r, v, s.duration, s.times.size - 1,
                          progress, energy)
    if s.steady is not None:  # a steady loop: chosen from the terms, compiled once for every such problem
        if s.on_gpu:
            from rotframe.problem.steady_gpu import steady_gpu_trajectory

            traj, note = steady_gpu_trajectory(s, progress)
            return _steady_result(s, traj, [], list(s.frame.notes) + [note], energy)
        if s.method != "dop853":
            return _steady_fixed_run(s, progress, energy)
        return _steady_run(s, checked_atol(atol), progress, energy)
    method, duration, times, rtol, hfix, D, N = s.method, s.duration, s.times, s.rtol, s.hfix, s.D, r.shape[0]
    frame, origin, forces, events = s.frame, s.origin, s.forces, s.events
    driver, prob, fns, slots, n, t0, on_gpu = s.driver, s.prob, s.fns, s.slots, s.times.size, s.t0, s.on_gpu
    frame_terms, cache_notes, EDIR, ETERM, stops = s.frame_terms, s.cache_notes, s.EDIR, s.ETERM, s.stops
    y, atol_arr = start_states(s, r, v, checked_atol(atol), attitude, omega)
    y0_first = y[:1].copy()
    OUT = np.full((n, N, D), np.nan)
    OUT[0] = y  # the start, as the loop writes it: a run stopped before its first call keeps it
    state = run_state(N, D, slots, len(events))
    pacer = Pacer(f"method {method}", duration, adaptive=method == "dop853")  # calls sized in time: signals and progress between them
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
    # a first run whose loop is not compiled yet begins as the loop's plain-Python remake (`rotframe.problem.tiers`)
    tier = Tier(driver, fns, s.plain_driver if gpu is None and inline is not True and plain_tier else None,
                (prob[0], method, bool(events), D), prob, N)

    def advance(*args):  # the plain tier's loop, the engine's, or the inlined one once the run has switched to it
        tier.driver.advance(*args, kernel=None if tier.plain else inlining.kernel)

    try:
        inlining.start()
        if events:
            tier.driver.start_events(0.0, y, state["GPREV"], prob, tier.fns)
        before = (times, y, state["TC"], state["H"], state["IDX"], state["SUB"], state["ST"], OUT, state["EVT"],
                  state["EVY"], state["EVK"], state["EVN"], state["GPREV"], state["NSTEP"], state["NFEV"])
        while True:
            after = (method, rtol, atol_arr, hfix, EDIR, ETERM, stops, prob, tier.fns)
            # the state before the call, to replay it from where a user function raised in it; the GPU keeps its own
            # copy (`GpuAdvance.saved`), brought back only for a replay
            saved = _saved(y, state) if gpu is None else None
            steps_before = np.sum(state["NSTEP"])
            budget = tier.budget(pacer.start())
            t_call = time.perf_counter()
            try:
                if gpu is not None:
                    gpu(0, N, *before, budget, *after)
                    if gpu.ended.size:  # a user function raised on the GPU: the CPU runs the call again, to the step
                        gpu.fetch()
                        _again_on_the_cpu(gpu.ended, advance, y, state, gpu.saved(), before + (budget,) + after)
                        if np.all(state["ST"][gpu.ended] == 0):  # it did not raise there: the GPU goes on from it
                            gpu.resume()
                else:
                    with tier.quiet():
                        advance_blocks(advance, N, before + (budget,) + after)
            except Exception as exc:
                if tier.plain:  # met again compiled, from the start (`simulate_particles`)
                    raise PlainTierFailed from None
                if gpu is not None:
                    gpu.fetch()
                    saved = gpu.saved() or _saved(y, state)  # None: nothing went to the GPU, the arrays are as before
                raised_later(exc, advance, y, saved, {"before": before, "after": after, "budget": budget}, s, OUT,
                             state)
            if first:  # the glue's compile and the first call (the engine's load); begun plain, the glue's alone
                compile_s = (t_call if tier.began_plain else time.perf_counter()) - t0
                first = False
            if not tier.plain:  # the plain tier's calls are counted in steps, and say nothing of the compiled pace
                pacer.done(float(np.sum(state["NSTEP"]) - steps_before))
                if saved is not None:  # the GPU's run never switches loops (`Inlining`, off there)
                    inlining.after_call(pacer.last_seconds, float(np.sum(state["TC"] - saved["TC"])),
                                        float(np.sum(duration - state["TC"][state["ST"] == 0])))
            ST = state["ST"]
            if progress is not None:
                progress(float(np.min(state["IDX"])) / n)
            # in the plain tier: a failure met again compiled; where the run goes on, compiled from here once long
            tier.after_call(state["NFEV"], state["NSTEP"], state["TC"], ST, duration)
            if np.any(ST >= 3):
                break
            if np.all(ST != 0):
                break
            running = ST == 0
            pacer.check(state["NSTEP"][running], state["TC"][running], state["H"][running])
    except KeyboardInterrupt:
        if gpu is not None:
            gpu.fetch()
        traj = trajectory_of(times, OUT, state, events, method, int(np.min(state["IDX"])), hfix)
        raise RunInterrupted(traj) from None
    if gpu is not None:
        gpu.fetch()
    traj = trajectory_of(times, OUT, state, events, method, n, hfix)
    raise_if_failed(s, state, y, OUT)
    notes = list(frame.notes) + cache_notes + [note for note in (tier.note, inlining.note) if note]
    warnings, diagnostics = [], {}
    if not jit:
        warnings.append("jit=False: the forces and the integrator ran as plain Python, some 100 to 1000 times "
                        "slower than compiled")

    def energies(rotating):  # numpy's where it can; else compiled, or plain where few and not compiled yet (`Tier`)
        if energy_by_numpy(forces):
            return array_energies(traj, forces, frame, rotating)
        driver, fns = tier.energy_driver(traj.times.size * N)
        return driver.energies(traj.times, np.ascontiguousarray(OUT[: traj.times.size]), prob, fns,
                               driver.potential(), rotating)

    if energy:
        _energy_diagnostics(energies, traj, frame, origin, forces, diagnostics, notes, frame_terms)
    try:
        frame_interpolation(tier.driver.advance, frame, origin, y0_first, times, after, OUT, duration, rtol, diagnostics,
                            warnings, notes, lambda spec: problem_tuple(prob[1], prob[2], spec, origin))
    except KeyboardInterrupt:
        raise RunInterrupted(traj) from None
    if D == 10:
        traj.extras["frame_q"] = OUT[:, 0, 6:10].copy()
    warnings += _dropped_records(state["EVN"], state["EVT"].shape[1])
    compile_s += inlining.seconds_mid_run + tier.seconds_mid_run  # loops made after the first call: compile time too
    traj.extras["compile_s"] = compile_s
    if method == "dop853":  # the rows the loop took: a particle's own filled in where it began (`rotframe.problem.engine`)
        traj.extras["atol"] = atol_arr[:, :6].copy()
    return ProblemRun(traj, diagnostics, warnings, notes, frame, compile_s, frame_terms)


def raise_if_failed(s, state, y, OUT):
    """Where a particle of the run set up as ``s`` (`rotframe.problem.particle_setup.SetUp`) ended early (status 3 to
    6): an error naming it, the time, the state and the function to blame, with the samples up to there."""
    if not (state["ST"] >= 3).any():
        return
    times, events, method, hfix = s.times, s.events, s.method, s.hfix
    i = int(np.flatnonzero(state["ST"] >= 3)[0])
    good = int(state["IDX"][i])
    t_bad = float(state["TC"][i])
    # the step that failed: RK4's fixed one, or DOP853's last try (10 times the step it fell back to)
    code = int(state["ST"][i])
    dt_failed = hfix if method != "dop853" else (10.0 if code in (3, 4) else 1.0) * float(state["H"][i])
    if code == 5:
        blame, raised = _blame(events, s.params, t_bad, y[i], dt_failed, [f"events[{k}]" for k in range(len(events))])
    else:
        blame, raised = _blame(s.forces, s.params, t_bad, y[i], dt_failed, s.labels,
                               function_roles(s.frame, s.origin, [], [], []))
    partial = trajectory_of(times, OUT, state, events, method, good, hfix)
    state_text = f"r = {y[i, :3].tolist()}, v = {y[i, 3:6].tolist()}"
    if code == 6 or raised:  # a user function raised (compiled: the engine stopped at once)
        raise uf.raised_during_run(f"simulate: particle {i}: a user function raised in the step from "
                                   f"t = {t_bad:.9g} s, {state_text}{blame}; samples up to there are kept",
                                   t_bad, partial)
    raise IntegrationError(f"simulate: particle {i}: {STATUS[code]}{blame} after t = {t_bad:.9g} s (method "
                           f"{method}); samples up to there are kept", t_reached=t_bad, partial=partial)


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


def _saved(y, state):
    """Copies of the per-particle state (``Y`` and `_REPLAYED`), what a call is replayed from."""
    saved = {key: state[key].copy() for key in _REPLAYED}
    saved["Y"] = y.copy()
    return saved


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


def raised_later(exc, advance, y, saved, args, s, OUT, state):
    """A user function raised inside a call: find the step, name the function, give time and state.

    The call is replayed from the state saved before it, one step per call, particle by particle
    (the drivers are deterministic), up to the step where the exception comes again; the force, the
    event function or the frame's function of the run set up as ``s``
    (`rotframe.problem.particle_setup.SetUp`) that raises there in plain Python is named. Raises
    `UserFunctionError` (``.t_reached`` and ``.partial`` keep the samples up to that step).
    """
    times, events, method, hfix = s.times, s.events, s.method, s.hfix
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
                # a force, an event function or the frame's (a plain run's, where each raises as Python)
                blame = _blame(list(s.forces) + list(events), s.params, t, yi, dt,
                               list(s.labels) + [f"events[{k}]" for k in range(len(events))],
                               function_roles(s.frame, s.origin, [], [], []))[0]
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
                               trajectory_of(times, OUT, state, events, method, good, hfix)) from None


def trajectory_of(times, OUT, state, events, method, n_kept, step=0.0):
    """The `Trajectory` of the first ``n_kept`` samples; ``step``: a fixed-step method's (``extras["step"]``)."""
    n_kept = max(int(n_kept), 1)
    r = OUT[:n_kept, :, :3].copy()
    v = OUT[:n_kept, :, 3:6].copy()
    steps = int(state["NSTEP"].max()) if state["NSTEP"].size else 0
    nfev = int(state["NFEV"].max()) if state["NFEV"].size else 0
    complete = n_kept == times.size
    traj = Trajectory(times[:n_kept].copy(), r, v, method, steps, nfev, complete,
                      float(times[n_kept - 1]))
    N = OUT.shape[1]
    if events:
        kept = np.arange(state["EVT"].shape[1])[None, :] < np.minimum(state["EVN"], state["EVT"].shape[1])[:, None]
    for k, name in enumerate(uf.event_names(events)):
        # each particle's crossings of event k in time order (ties in the order located), split per particle
        i, j = np.nonzero(kept & (state["EVK"] == k))
        order = np.lexsort((state["EVT"][i, j], i))
        i, j = i[order], j[order]
        counts = np.bincount(i, minlength=N)
        traj.event_times[name] = per_particle(state["EVT"][i, j], counts)
        traj.event_states[name] = per_particle(state["EVY"][i, j, :6], counts)
    traj.extras["status"] = state["ST"].copy()
    if step:
        traj.extras["step"] = step
    return traj


def exact_model(terms, frame, origin, events, frame_terms):
    """The linear problem (`rotframe.problem.exact.LinearProblem`) the exact flow runs, its terms named by their
    place in ``forces``; a ScenarioError naming what has no exact flow."""
    from rotframe.problem.exact import linear_problem

    return linear_problem(terms, [f"forces[{k}]" for k in range(len(terms))], frame, origin, events, frame_terms)


def _exact_run(terms, frame, origin, events, frame_terms, r, v, duration, samples, progress, energy=True) -> ProblemRun:
    """``method="exact"``: the exact flow of the run's linear problem (`rotframe.problem.exact`), the scenes' own
    (`rotframe.particles.integrators.integrate_exact`); the energy diagnostic from the forces' potentials."""
    from rotframe.particles.integrators import integrate_exact
    from rotframe.problem.exact import event_row

    model = exact_model(terms, frame, origin, events, frame_terms)
    rows = [event_row(g, name) for g, name in zip(events, uf.event_names(events))]  # built-in crossings: the flow's own
    traj = integrate_exact(model, r, v, duration, samples, rows, progress, ordered=True)  # per particle, as the engine
    traj.extras["compile_s"] = 0.0
    forces = [f for f in terms if isinstance(f, Force)]
    diagnostics = {}
    notes = list(frame.notes) + ["method exact: the flow of r'' = K r + C v + b (the terms' linear forms and the "
                                 "frame's), to round-off" if model.is_linear else
                                 "method exact: the inertial straight line turned into the frame by the exact "
                                 "integral of its piecewise-linear rate, to round-off"]

    if energy:
        _energy_diagnostics(lambda rotating: array_energies(traj, forces, frame, rotating), traj, frame, origin,
                            forces, diagnostics, notes, frame_terms)
    return ProblemRun(traj, diagnostics, [], notes, frame, 0.0, frame_terms)


def _steady_run(s, atol, progress, energy=True) -> ProblemRun:
    """DOP853 on the steady loop (`rotframe.problem.steady`: `rotframe.particles.dop853_steady`, run in calls by
    `rotframe.particles.chunked`) for the set-up ``s``: the engine's loop's steps, numbers and event records, each
    particle's own tolerances where ``atol`` is None; the energy diagnostic numpy's. The trajectory's ``steps`` and
    ``nfev`` are the most any particle took, as the engine's loop counts them.

    A run that fails (a state not finite, the step collapsed, a speed that grew without a force) raises
    `SteadyLoopFailed`: `simulate_particles` runs it again on the engine's loop, which meets the failure at the same
    step and names its cause and the term to blame. So does a run longer than one call of the calls' driver (a tenth
    of a second of work: `rotframe.particles.chunked.RunNeedsCuts`, seen by its probe before the run): a call ends
    with a step cut to land on its last sample, which the engine's loop never cuts, so the steps would differ."""
    from rotframe.particles.chunked import KernelSetup, RunNeedsCuts, run_chunked
    from rotframe.particles.integrators import METHODS, check_work

    model, q, rows = s.steady.model, s.steady.q, s.steady.rows
    info, samples = METHODS["dop853"], s.times.size - 1
    check_work(info, s.duration, None, samples, s.r.shape[0], model)
    setup = KernelSetup(model, info, s.duration, samples, rtol=s.rtol,
                        atol="own" if atol is None else tuple(atol.tolist()), events=rows, steady=q)
    try:
        traj = run_chunked(setup, model, s.r.copy(), s.v.copy(), progress, s.slots, records=True, owned=True)
    except (IntegrationError, RunNeedsCuts):
        raise SteadyLoopFailed from None
    warnings, _ = _records_of(traj, rows)
    notes = list(s.frame.notes) + ["method dop853: the engine's steady loop (what it takes: a constant rotation "
                                   "rate, uniform gravity, a string, one built-in crossing; rotframe.problem.steady), "
                                   "compiled once for every such problem"]
    return _steady_result(s, traj, warnings, notes, energy)


def _steady_fixed_run(s, progress, energy=True) -> ProblemRun:
    """A fixed-step method on a steady problem (`rotframe.problem.steady`): the scenes' fixed-step drivers
    (`rotframe.particles.drivers`, run in calls by `rotframe.particles.chunked`), which take the engine's loop's
    steps, samples and event times to the bit, its one event a row of theirs. The counts are the engine's: each
    particle's steps up to the end or to the step of its terminal event, the most any took; the force evaluations
    are the drivers' own (``evals_per_step`` a step). A run that fails raises `SteadyLoopFailed`, as `_steady_run`."""
    from rotframe.numerics.step_control import steps_to_event
    from rotframe.particles.chunked import KernelSetup, run_chunked
    from rotframe.particles.integrators import METHODS

    model, rows = s.steady.model, s.steady.rows
    info = METHODS[s.method]
    samples, N = s.times.size - 1, s.r.shape[0]
    try:
        setup = KernelSetup(model, info, s.duration, samples, step=s.hfix, events=rows)
        traj = run_chunked(setup, model, s.r.copy(), s.v.copy(), progress, s.slots, records=True, owned=True)
    except (IntegrationError, ScenarioError):
        raise SteadyLoopFailed from None
    warnings, t_stop = _records_of(traj, rows)
    steps = np.full(N, samples * setup.sps, dtype=np.int64)
    stopped = np.isfinite(t_stop)
    steps[stopped] = steps_to_event(t_stop[stopped], s.times, setup.sps, setup.h)
    traj.steps = int(steps.max()) if N else 0
    traj.nfev = traj.steps * setup.evals_per_step
    notes = list(s.frame.notes) + [f"method {s.method}: the scenes' fixed-step drivers (a constant rotation rate, "
                                   "uniform gravity, air drag, a string, the frame's terms, one built-in crossing: "
                                   "rotframe.problem.steady), the engine's steps to the bit"]
    return _steady_result(s, traj, warnings, notes, energy)


def _records_of(traj, rows):
    """The event records a steady run left (``traj.extras["event_records"]``, of its drivers' ``rows``) attached to
    ``traj`` as the engine's lists, and the engine's status of each particle (``traj.extras["status"]``: 2 where a
    terminal event stopped it, else 1). Returns the warnings of records not kept (`_dropped_records`) and each
    particle's stop time (NaN where none stopped it)."""
    N = traj.r.shape[1]
    evb = traj.extras.pop("event_records", None)
    status, t_stop, warnings = np.ones(N, dtype=np.int64), np.full(N, math.nan), []
    if rows:
        evb.attach(traj, rows)
        warnings += _dropped_records(evb.count, evb.max_events)
        if rows[0].terminal:
            stopped = evb.count > 0
            status[stopped] = 2
            t_stop[stopped] = evb.t[stopped, 0]
    traj.extras["status"] = status
    return warnings, t_stop


def _steady_result(s, traj, warnings, notes, energy):
    """The `ProblemRun` of a steady run (`_steady_run`, `_steady_fixed_run`) of the set-up ``s``: its trajectory,
    warnings and notes, and the energy diagnostic (numpy's) where ``energy``."""
    diagnostics = {}
    if energy:
        _energy_diagnostics(lambda rotating: array_energies(traj, s.forces, s.frame, rotating), traj, s.frame,
                            s.origin, s.forces, diagnostics, notes, s.frame_terms)
    return ProblemRun(traj, diagnostics, warnings, notes, s.frame, traj.extras.get("compile_s", 0.0), s.frame_terms)


def _dropped_records(counts, kept) -> list:
    """The warning of a run whose particles located more event crossings (``counts``, (N,)) than the ``kept`` records
    each (`rotframe.problem.particle_setup.event_slots`) hold; none where every crossing was kept."""
    dropped = int(np.sum(np.maximum(counts - kept, 0)))
    return [f"{dropped} event crossings beyond {kept} per particle were located but not kept"] if dropped else []


def steady_omega(frame):
    """The rate (rad/s, (3,)) of a frame that turns steadily (`_energy_diagnostics` asks for no other)."""
    return frame.data[0] if frame.kind == "constant" else frame.vector_at([0.0])[0][0]


def array_energies(traj, forces, frame, rotating):
    """The energy per unit mass (or the Jacobi integral, ``rotating``) at each sample of ``traj``, (n, N), by numpy:
    ``v^2/2 + sum U`` (less ``|omega x r|^2 / 2``) with each potential called once on every sample's ``r`` (3, n N).
    ``omega`` is the steady frame's (`steady_omega`)."""
    n, N = traj.r.shape[:2]
    pos = traj.r.reshape(-1, 3).T
    t = np.repeat(traj.times, N)
    E = 0.5 * np.sum(traj.v.reshape(-1, 3) ** 2, axis=1)
    for f in forces:
        E = E + np.asarray(f.potential(t, pos), dtype=float)
    if rotating:
        w = steady_omega(frame)
        E = E - 0.5 * np.sum(np.cross(w, pos.T) ** 2, axis=1)
    return E.reshape(n, N)


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
    w = steady_omega(frame)
    rotating = bool(np.any(w != 0.0)) and "centrifugal" in frame_terms
    with np.errstate(over="ignore", invalid="ignore"):
        E = energies(rotating)
    traj.extras["energy"] = E
    name = "jacobi" if rotating else "energy"
    if not np.all(np.isfinite(E)):  # |v|^2 or the potential past float64's range: no drift to measure, said so
        diagnostics[f"{name}_rel_drift"] = math.nan
        notes.append(f"{name}_rel_drift: not measured; the {'Jacobi integral' if rotating else 'energy'} overflows "
                     "float64 at some sample (a speed or distance near 1e154 in SI, whose square is out of range)")
        return
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
