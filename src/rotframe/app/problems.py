"""``rotframe.simulate`` and ``rotframe.simulate_body``: your own problem, as a `Result`.

The numerical work is `rotframe.problem` (the numerical core's layer); this edge wraps
what it returns in the same [`rotframe.app.api.Result`][rotframe.app.api.Result] as ``rotframe.run``: arrays,
diagnostics, warnings, ``record()``, ``export()``, ``to_dataframe()``, ``to_json()``.
Arguments are keyword-only, SI units, vectors in the frame's axes (DESIGN, "Python: your own
problem").

Examples
--------
>>> import numpy as np, rotframe
>>> def spring(t, r, v, k):
...     return -k * r[0], -k * r[1], -k * r[2]
>>> res = rotframe.simulate(omega=[0, 0, 0], r0=[1, 0, 0], v0=[0, 1, 0], duration=2 * np.pi,
...                         forces=[spring], params=(1.0,), samples=4)
>>> bool(np.allclose(res.trajectory.r[-1, 0], [1, 0, 0], atol=1e-8))    # one full turn
True
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from rotframe import method_registry as registry

__all__ = ["simulate", "simulate_body", "ProblemScenario"]


@dataclass
class ProblemScenario:
    """What a `Result` needs of a scenario, for a problem posed in Python."""

    name: str
    scene: str
    title: str
    description: str
    parameters: dict = field(default_factory=dict)
    run: dict = field(default_factory=dict)
    model: list = field(default_factory=list)


def _summary(name, params, terms, method, steps, diagnostics, warnings, notes, timing, complete, t_reached):
    summary = {"scenario": name, "params": params, "model": terms, "method": method, "steps": int(steps),
               "metrics": {}, "theory": {}, "theory_notes": {}, "diagnostics": dict(diagnostics),
               "warnings": list(warnings), "timing": timing, "recording": None, "units": {}}
    if notes:
        summary["notes"] = list(notes)
    if not complete:
        summary["complete"] = False
        summary["t_reached_s"] = float(t_reached)
    return summary


def _atol_si(atol):
    """``atol`` in SI: 6 values, 3 in m (r) then 3 in m/s (v); a single Quantity is ambiguous and refused."""
    from rotframe.app.quantities import holds_quantity, is_quantity, to_si
    from rotframe.errors import ScenarioError

    if not holds_quantity(atol):
        return atol
    if is_quantity(atol) and getattr(atol, "ndim", 0) == 0:
        raise ScenarioError(f"atol={atol}: one Quantity cannot be both a length and a speed; give 6 values, "
                            "3 in m (r) then 3 in m/s (v), or plain SI numbers")
    values = list(atol)
    if len(values) != 6:
        raise ScenarioError(f"atol: {len(values)} values; 6 are expected, 3 in m (r) then 3 in m/s (v)")
    return [to_si(a, "m" if k < 3 else "m/s", f"atol[{k}]") for k, a in enumerate(values)]


def _progress(progress, label):
    from rotframe.app.progress import progress_callback

    return progress_callback(progress, label)


def _describe(f):
    from rotframe.problem.callables import display_name

    name = getattr(f, "name", "")  # a built-in term (rotframe.forces, rotframe.torques) or a named Force or Torque
    return name if isinstance(name, str) and name else display_name(getattr(f, "accel", getattr(f, "func", f)))


def _result(scn, scene, scene_result, summary):
    """The same `Result` as `rotframe.run`'s, recording through the problem's own ``scene``."""
    from rotframe.app.api import Result

    return Result(scn, {"run": {}}, scene_result, summary, scene=scene)


def simulate(*, omega, r0, v0, duration, forces=(), params=(), origin_acceleration=None, events=(), method=None,
             rtol=None, step=None, samples=None, omega_dot=None, atol=None, frame_attitude=None, jit=True,
             progress=None, threads=None, device=None, max_events=256, frame_terms=None, inline=None):
    """Particles under your forces in any rotating frame; returns a [`rotframe.Result`][rotframe.app.api.Result].

    Solves ``r'' = sum f(t, r, v) - 2 w x v - w x (w x r) - w' x r - a0(t)`` in the frame's
    axes (the fictitious forces are rotframe's; never add them yourself: ``frame_terms`` chooses
    which of them act).

    Parameters
    ----------
    omega : 3-vector, (times, vectors), callable or rigid-body Result
        The frame's angular velocity relative to inertial space, rad/s, in its own axes: a
        constant; a table (a C2 cubic spline through it; ``(times, vectors, "linear")``: the
        straight lines between its knots, a ramp kept as a ramp); a function ``t -> (3,)`` (with
        ``omega_dot`` or derived); or a rigid-body ``Result`` (the frame of that tumbling body).
    r0, v0 : (3,) or (N, 3)
        Initial positions (m) and velocities (m/s) in the frame; N particles at once (one of
        them may be (3,), shared by all).
    duration : float
        Seconds. Every input with a unit may also be an astropy Quantity, converted to SI:
        vectors, lists of Quantities, the tables' times and vectors, ``atol`` (3 values in m,
        then 3 in m/s) and ``params`` (each in SI base units, angles in radians). A function's
        return must be plain numbers in SI.
    forces : sequence of callables or `rotframe.problem.particles.Force`
        ``f(t, r, v, *params) -> (ax, ay, az)``, m/s^2, frame axes (``Force(f, axes="inertial")``
        for inertial axes; ``potential=U`` for the energy or Jacobi diagnostic).
    params : tuple
        Numbers or float arrays passed to every force and event after ``(t, r, v)``.
    origin_acceleration : None, 3-vector, table or callable
        a0(t), m/s^2, frame axes.
    events : sequence of callables
        ``g(t, r, v, *params) -> float`` with optional ``terminal`` and ``direction``
        attributes, as in ``scipy.integrate.solve_ivp``; times in ``trajectory.event_times``.
    method : {"dop853", "rk4", "rotation-splitting", "rotation-splitting4", "exact"}, optional
        Any case; default DOP853 at ``rtol`` (default 1e-10). ``"exact"``: the exact flow of a
        linear problem (the built-in linear terms in a steady frame, `rotframe.problem.exact`;
        anything else refused by name), no step and no tolerance.
    rtol, step, samples : optional
        DOP853's tolerance; RK4's step (s); samples kept (default 1000 intervals).
    max_events : int
        Event crossings kept per particle (default 256; more are located, counted and dropped,
        with a warning). Each slot holds a time and a state for every particle: a large ensemble
        with a terminal event needs one.
    jit : bool
        False runs the forces and the integrator in plain Python (slow; for what numba cannot compile).
    progress : bool or callable, optional
        True draws a bar (a widget in Jupyter with tqdm); a callable gets the fraction done.
    threads : int, optional
        Threads for many particles during this call (default every core); the numbers do not
        depend on it.
    device : {"cpu", "gpu"}, optional
        ``"gpu"`` runs every particle at once on a CUDA GPU: the same loop, equations and forces
        compiled for it (`rotframe.problem.gpu`), the fixed-step methods (``rk4``,
        ``rotation-splitting``, ``rotation-splitting4``; name one), numbers that agree with the
        CPU's to round-off. Your functions must compile for the GPU too: arithmetic returning a
        tuple, no array made.
    frame_terms : sequence of str, optional
        Which of the frame's terms act: names from ``"coriolis"`` (``-2 w x v``),
        ``"centrifugal"`` (``-w x (w x r)``) and ``"euler"`` (``-w' x r``); default all three.
        Leave one out only where your forces already hold it, as the scenes do: on the Earth the
        centrifugal term is inside the local (effective) gravity, so a problem with
        ``rotframe.forces.gravity`` of the local g takes ``frame_terms=("coriolis",)`` (the
        Foucault pendulum, a dropped body). The energy diagnostic follows: the Jacobi integral
        where the centrifugal term acts in a rotating frame, ``v^2/2 + U`` where it does not.
    inline : bool, optional
        Whether the run goes on in a loop compiled with your functions in it
        (`rotframe.problem.inlined`): the same steps and numbers to the bit, in some 0.8 to 0.97 of
        the time, for a compile of a few seconds (cached on disk for the same functions). Default:
        decided by the run once it has measured its pace (a run with over 80 s of work left
        compiles it; one with half a second left loads it where it is cached); True: from the
        start; False: never. It needs ``jit=True``; on the GPU the kernel holds your functions
        already.

    Raises
    ------
    rotframe.errors.ScenarioError
        Bad input, or a user function that raises, returns the wrong shape or NaN at the start,
        or cannot be compiled (the message names it and numba's reason).
    rotframe.errors.IntegrationError
        A non-finite state during the run (``exc.partial``: a ``Result`` of what was computed; so
        too for a user function that raises mid-run, a ``ScenarioError``).
    rotframe.particles.trajectory.RunInterrupted
        Ctrl-C or SIGTERM during the run (``exc.partial``: a ``Result`` of what was computed).
    """
    from rotframe.errors import IntegrationError, ScenarioError
    from rotframe.particles.trajectory import RunInterrupted
    from rotframe.problem.particles import ProblemRun, simulate_particles
    from rotframe.app.quantities import params_si, to_si, vector_or_table_si
    from rotframe.app.signals import InterruptScope

    t0 = time.perf_counter()
    from rotframe.problem.arguments import sequence_of_callables

    forces = sequence_of_callables(forces, "forces")
    events = sequence_of_callables(events, "events")
    from rotframe.particles.ensemble import threads_scope

    bar = _progress(progress, "simulate")
    try:
        omega = vector_or_table_si(omega, "rad/s", "omega")
        r0, v0 = to_si(r0, "m", "r0"), to_si(v0, "m/s", "v0")
        duration, step = to_si(duration, "s", "duration"), to_si(step, "s", "step")
        rtol, atol = to_si(rtol, "", "rtol"), _atol_si(atol)
        origin_acceleration = vector_or_table_si(origin_acceleration, "m/s2", "origin_acceleration")
        frame_attitude, params = to_si(frame_attitude, "", "frame_attitude"), params_si(params)
        with threads_scope(threads), InterruptScope():  # SIGTERM stops the run as Ctrl-C does
            run = simulate_particles(omega=omega, r0=r0, v0=v0, duration=duration, forces=forces, params=params,
                                     origin_acceleration=origin_acceleration, events=events, method=method,
                                     rtol=rtol, step=step, samples=samples, omega_dot=omega_dot, atol=atol,
                                     frame_attitude=frame_attitude, jit=jit, progress=bar, device=device,
                                     max_events=max_events, frame_terms=frame_terms, inline=inline)
    except (IntegrationError, RunInterrupted, ScenarioError) as exc:  # what was computed, as rotframe.run's Result
        partial = getattr(exc, "partial", None)
        if partial is not None and hasattr(partial, "r"):
            from rotframe.problem.frame import frame_spec
            from rotframe.problem.terms import check_frame_terms

            stopped = ProblemRun(partial, {}, ["the run stopped early: " + str(exc)], [], frame_spec(omega, omega_dot),
                                 frame_terms=check_frame_terms(frame_terms))
            exc.partial = _particle_result(stopped, forces, origin_acceleration, duration,
                                           time.perf_counter() - t0)
        raise
    finally:
        if progress is True:  # the bar is ours to end
            bar.close()
    # a setting the caller gave that the method does not read is flagged, as in the scenes' runs (the registry's rule)
    given = {key: value for key, value in (("step", step), ("rtol", rtol), ("atol", atol)) if value is not None}
    run.warnings[:0] = registry.unread_settings(run.trajectory.method, given) + _unread_params(
        params, events or any(_takes_params(f) for f in forces), "force or event")
    if frame_attitude is not None and "frame_q" not in run.trajectory.extras:  # read only with an inertial force
        run.warnings.insert(0, "frame_attitude is not used: no force acts in inertial axes "
                               "(rotframe.Force(..., axes='inertial')), so nothing reads the frame's attitude")
    return _particle_result(run, forces, origin_acceleration, duration, time.perf_counter() - t0)


def _takes_params(f) -> bool:
    """Whether the entry ``f`` of ``forces`` is called with the run's ``params``: a function of yours or a
    `rotframe.Force` that takes them (the built-in terms and the pendulum's string do not)."""
    from rotframe.problem.terms import Force, StringConstraint

    return f.takes_params if isinstance(f, Force) else not isinstance(f, StringConstraint)


def _unread_params(params, read: bool, what: str) -> list:
    """The warning for ``params`` given where no function reads them (``read`` False): none where they are read."""
    if read or params is None or len(params) == 0:
        return []
    return [f"params = {tuple(params)!r} is not used: no {what} of yours takes them (the built-in terms' constants "
            "are their own)"]


def _particle_result(run, forces, origin_acceleration, duration, simulate_s):
    from rotframe.scenes.user_problem import ParticleProblemScene

    traj = run.trajectory
    terms = [_describe(f) for f in forces] + list(run.frame_terms)
    if origin_acceleration is not None:
        terms.append("origin acceleration")
    params_out = {"duration": float(duration), "particles": int(traj.r.shape[1]), "frame": run.frame.kind}
    timing = {"compile_s": run.compile_s, "simulate_s": simulate_s, "record_s": 0.0, "total_s": simulate_s}
    summary = _summary("simulate", params_out, terms, traj.method, traj.steps, run.diagnostics, run.warnings,
                       run.notes, timing, traj.complete, traj.t_reached)
    summary["units"] = {"duration": "s"}
    scn = ProblemScenario("simulate", "simulate", "Your own problem (rotframe.simulate)",
                          f"{traj.r.shape[1]} particle(s) in a frame given as {run.frame.kind}; forces: "
                          + (", ".join(terms[:len(forces)]) or "none"))
    from rotframe.scenes.base import SceneResult

    scene_result = SceneResult(traj, terms, traj.method, traj.steps, traj.nfev,
                                extras={"diagnostics": run.diagnostics, "frame": run.frame})
    result = _result(scn, ParticleProblemScene(), scene_result, summary)
    result.trajectory.frame = "the frame given by omega (its own axes)"
    return result


def simulate_body(*, inertia, L0, q0, duration, torque=None, params=(), method=None, rtol=None, step=None,
                  samples=None, jit=True, progress=None, inline=None):
    """A rigid body under your torque; returns a [`rotframe.Result`][rotframe.app.api.Result] (``trajectory.L``, ``.q``).

    Parameters
    ----------
    inertia : (3,) principal moments or (3, 3) tensor, kg m^2
        In the body axes that ``L0`` and the torque use.
    L0 : (3,)
        Angular momentum in body axes, kg m^2/s.
    q0 : (4,)
        Attitude, a scalar-last unit quaternion rotating body components into space components.
    torque : callable, Torque, or a list of them, optional
        ``tau(t, L, q, *params) -> (3,)``, N m, body axes, compiled with numba as the forces are; a
        list is summed in order, so the built-in torques of `rotframe.torques` (gravity on a heavy
        top, a torque fixed in the body or in space) compose with your own.
    method : {"dop853", "rk4", "lie-poisson", "lie-poisson4", "lie-poisson6", "lie-poisson8", "top-splitting", "top-splitting4", "top-splitting6", "top-splitting8", "exact"}, optional
        Any case. The splittings (principal axes, ``step``; the rigid scenes' own step, a symmetric
        body's free flow exactly; ``top-splitting`` a symmetric body only) take torques of ``(t, q)``
        alone, marked ``rotframe.Torque(f, attitude_only=True)`` (the built-in ones are), as a kick;
        ``exact`` takes none. Other torques with a splitting are refused by name.
    inline : bool, optional
        Whether the run goes on in a loop compiled with the torque in it, as `rotframe.simulate`'s
        ``inline`` (the same numbers to the bit; by default decided by the run's pace).

    Returns
    -------
    Result
        ``trajectory.L`` (n, 3), ``trajectory.q`` (n, 4); it also carries ``inertia`` (3, 3), so
        that it can be the frame of ``rotframe.simulate`` (``omega=result``: the body's axes).
    """
    import numpy as np

    from rotframe.problem.body import simulate_rigid_body
    from rotframe.scenes.user_problem import BodyProblemScene

    t0 = time.perf_counter()
    from rotframe.app.quantities import params_si, to_si

    inertia, L0, q0 = to_si(inertia, "kg m2", "inertia"), to_si(L0, "kg m2/s", "L0"), to_si(q0, "", "q0")
    duration, step, rtol = to_si(duration, "s", "duration"), to_si(step, "s", "step"), to_si(rtol, "", "rtol")
    params = params_si(params)
    bar = _progress(progress, "simulate_body")
    from rotframe.app.signals import InterruptScope

    try:
        with InterruptScope():  # SIGTERM stops the run as Ctrl-C does
            run = simulate_rigid_body(inertia=inertia, L0=L0, q0=q0, duration=duration, torque=torque,
                                      params=params, method=method, rtol=rtol, step=step, samples=samples, jit=jit,
                                      progress=bar, inline=inline)
    finally:
        if progress is True:
            bar.close()
    simulate_s = time.perf_counter() - t0
    from rotframe.problem.body import torque_terms

    torques = [term for _, term in torque_terms(torque)]
    # a setting or params the caller gave that nothing reads is flagged, as in `simulate` and the scenes' runs
    given = {key: value for key, value in (("step", step), ("rtol", rtol)) if value is not None}
    run.warnings[:0] = registry.unread_settings(run.method, given) + _unread_params(
        params, any(term.takes_params for term in torques), "torque")
    terms = ["euler equations"] + [f"torque {_describe(term)}" for term in torques]
    timing = {"compile_s": run.compile_s, "simulate_s": simulate_s, "record_s": 0.0, "total_s": simulate_s}
    # the diagnostics a torque leaves out, said where they are reported (a scene reports its own)
    notes = (["a torque acts: energy and |L| are not conserved, and not reported"] if torques else []) + run.notes
    summary = _summary("simulate_body", {"duration": float(duration)}, terms, run.method, run.steps,
                       run.diagnostics, run.warnings, notes, timing, run.complete, run.t_reached)
    scn = ProblemScenario("simulate_body", "simulate_body", "Your own rigid body (rotframe.simulate_body)",
                          "Euler's equations" + (" with a torque" if torques else ", torque-free"))
    from rotframe.scenes.base import SceneResult

    scene_result = SceneResult(run, terms, run.method, run.steps, run.nfev,
                                extras={"diagnostics": run.diagnostics, "inertia": np.diag(run.inertia).copy()
                                        if np.all(run.inertia == np.diag(np.diag(run.inertia))) else run.inertia})
    result = _result(scn, BodyProblemScene(), scene_result, summary)
    result.inertia = run.inertia
    result.torque_samples = run.torque_samples
    return result
