"""What the rigid-body scenes share: a trajectory type and a chunked, interruptible run."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from rotframe.errors import IntegrationError, ScenarioError
from rotframe.particles.integrators import RunInterrupted
from rotframe.method_registry import names
from rotframe.scenes.base import guarded

#: Methods of the free body; ``exact`` is the elliptic-function flow, ``lie-poisson[4|6|8]`` the
#: Lie-Poisson splitting of orders 2, 4, 6, 8, ``dop853`` the compiled adaptive Dormand-Prince 8(5,3)
#: (`rotframe.rigid.adaptive.rigid_dop853`, relative tolerance ``rtol`` of the run).
FREE_METHODS = names("free body")
#: Methods of the heavy top: ``top-splitting[4|6|8]`` (exact free symmetric-top flow and gravity kick,
#: orders 2, 4, 6, 8), ``rk4`` and the adaptive ``dop853``; the old names ``splitting``, ``splitting4``,
#: ``splitting6`` are still accepted.
HEAVY_METHODS = names("heavy top")

#: Relative tolerance of ``dop853`` when the run names none (the scenario default of ``rtol``).
DEFAULT_RTOL = 1e-10
#: Samples per compiled call of the adaptive and exact runs: between calls progress shows and Ctrl-C is seen.
SAMPLES_PER_CALL = 4096
#: Steps per compiled call of the adaptive run, at most (about 0.1 s): the bound on how long a signal waits.
STEPS_PER_CALL = 1e5


def adaptive_rel_error(traj):
    """A bound on the relative global error of a ``dop853`` trajectory, from its ``rtol`` and accepted steps.

    The step-size control keeps each step's local error below ``rtol`` (relative,
    per component); summed over ``n`` steps without growth that is ``n rtol``,
    and a factor 10 covers its propagation along the run. Measured: the heavy
    top over 2 s (1125 steps at rtol 1e-10) is off the scipy DOP853 reference by
    2e-8 rad in attitude, 0.02 of ``n rtol``; the Dzhanibekov flip over 100 s
    some 100 ``rtol`` (tests/test_rigid_adaptive.py). Never below 1e-9, the
    round-off floor of the scenes' metrics.
    """
    rtol = traj.extras.get("rtol") or DEFAULT_RTOL
    return max(1e-9, 10.0 * float(rtol) * max(int(traj.steps), 1))


@dataclass
class BodyTrajectory:
    """Samples of a rigid body: angular momentum in body axes and attitude.

    ``L`` (n, 3) kg m^2/s in body axes; ``q`` (n, 4) scalar-last quaternions,
    body -> space; ``times`` (n,) s.
    """

    times: np.ndarray
    L: np.ndarray
    q: np.ndarray
    method: str
    steps: int = 0
    complete: bool = True
    t_reached: float = math.nan
    extras: dict = field(default_factory=dict)


def integrate_body(method, inertia, L0, q0, duration, run, progress, top=None):
    """Integrate a free body, or a heavy symmetric top (``top = (mass, length, g)``), by a named method.

    ``method`` is a name of `FREE_METHODS`, or of `HEAVY_METHODS`
    (an old name too, run and reported under its canonical name) with ``top``.
    Fixed-step methods use ``run["step"]`` and keep ``run["samples"]`` samples;
    the work is done in chunks so that progress shows, Ctrl-C interrupts and a
    non-finite state stops the run with everything before it kept.
    """
    from rotframe.rigid import dynamics as rigid
    from rotframe import limits

    method = method.lower() if isinstance(method, str) else method  # any case: "DOP853" is dop853
    if top is not None:
        method = HEAVY_METHODS.canonical(method)
    duration = float(duration)
    if not (math.isfinite(duration) and duration > 0):
        raise ScenarioError(f"duration: {duration:g} s; must be finite and > 0 (a parameter too large or too small?)")
    samples = max(1, int(run.get("samples") or 2000))
    if method == "exact":
        steps = 0.0
    elif method == "dop853":
        rtol = float(run.get("rtol") or DEFAULT_RTOL)
        _check_adaptive(inertia, rtol)
        from rotframe.rigid.adaptive import steps_estimate  # numba: imported where a run needs it

        steps = steps_estimate(inertia, L0, duration, rtol, 0.0 if top is None else top[0] * top[1] * top[2])
    else:
        per = (duration / samples) / float(run.get("step") or duration / samples / 20)
        # in floats: a step far below the sample interval gives a count beyond any integer a float holds
        steps = float(samples) * max(1.0, math.ceil(per - 1e-9)) if per < 1e300 else math.inf
    limits.check_run(steps=steps, samples=samples + 1, what=f"method {method}")
    times = np.linspace(0.0, duration, samples + 1)
    if method == "dop853":
        return _integrate_adaptive(inertia, L0, q0, times, rtol, 0.0 if top is None else top[0] * top[1] * top[2],
                                   progress, steps)
    if method == "exact":
        if top is not None:
            raise ScenarioError("method 'exact' is the free body's flow; the heavy top has gravity")
        # the elliptic-function flow of rigid.free_body (not the compiled rigid.exact_flow, which agrees to
        # round-off only: the scenes' numbers stay those of the reference implementation)
        t0 = time.perf_counter()
        rigid.free_body_closed_form(inertia, L0, q0, times[:1])  # check every input once; load the kernels
        compile_s = time.perf_counter() - t0
        out_L = np.empty((samples + 1, 3))
        out_q = np.empty((samples + 1, 4))
        done = 0
        try:
            for start in range(0, samples + 1, SAMPLES_PER_CALL):
                stop = min(samples + 1, start + SAMPLES_PER_CALL)
                chunk = times[start:stop]
                out_L[start:stop], out_q[start:stop] = rigid.free_body_closed_form(inertia, L0, q0, chunk)
                done = stop
                if progress:
                    progress(stop / (samples + 1))
        except KeyboardInterrupt:
            raise RunInterrupted(_truncate(BodyTrajectory(times, out_L, out_q, method, 1), done)) from None
        traj = BodyTrajectory(times, out_L, out_q, method, 1, True, duration)
        traj.extras["compile_s"] = compile_s
        return _check_finite(traj)
    step = float(run.get("step") or duration / samples / 20)
    dt_sample = duration / samples
    sps = max(1, math.ceil(dt_sample / step - 1e-9))
    h = dt_sample / sps
    checked, stepper = _stepper(method, inertia, top)
    t0 = time.perf_counter()
    try:
        checked(L0, q0, h, 1, 1)  # check every input once; load or compile the kernel
    except IntegrationError as exc:  # the first step already fails: nothing but the start to keep
        raise IntegrationError(str(exc), t_reached=0.0, partial=None) from None
    compile_s = time.perf_counter() - t0
    out_L = np.empty((samples + 1, 3))
    out_q = np.empty((samples + 1, 4))
    out_L[0], out_q[0] = L0, q0
    chunk = max(1, int(2e6 // sps))
    done = 0
    L, q = np.asarray(L0, float), np.asarray(q0, float)
    try:
        while done < samples:
            m = min(chunk, samples - done)
            try:
                if sps > 2e6:  # a sample interval longer than a chunk: in pieces, so that signals are seen
                    L, q = _advance_in_pieces(stepper, L, q, h, sps - 1)
                Ls, qs, _ = stepper(L, q, h, m * sps if sps <= 2e6 else 1, sps if sps <= 2e6 else 1)
            except IntegrationError as exc:
                # the kernel keeps the finite samples of this chunk in exc.partial = (L, q, times)
                Ls, qs = exc.partial[0], exc.partial[1]
                k = len(Ls) - 1
                out_L[done + 1:done + 1 + k] = Ls[1:]
                out_q[done + 1:done + 1 + k] = qs[1:]
                good = done + 1 + k
                partial = _truncate(BodyTrajectory(times, out_L, out_q, method, (done + k) * sps), good)
                raise IntegrationError(f"non-finite state after t = {times[good - 1]:.6g} s (method {method}); "
                                       "reduce the step", t_reached=float(times[good - 1]), partial=partial) from None
            out_L[done + 1:done + 1 + m] = Ls[1:]
            out_q[done + 1:done + 1 + m] = qs[1:]
            L, q = Ls[-1], qs[-1]
            done += m
            if progress:
                progress(done / samples)
    except KeyboardInterrupt:
        raise RunInterrupted(_truncate(BodyTrajectory(times, out_L, out_q, method, done * sps), done + 1)) from None
    traj = BodyTrajectory(times, out_L, out_q, method, samples * sps, True, duration)
    traj.extras.update(compile_s=compile_s, step=h)
    return traj


def _integrate_adaptive(inertia, L0, q0, times, rtol, mgl, progress, steps_estimate=0.0):
    """The ``dop853`` run at ``times`` (``rtol`` and moments checked by `_check_adaptive`): compiled
    adaptive DOP853, at most `SAMPLES_PER_CALL` samples and about `STEPS_PER_CALL` steps a call
    (from ``steps_estimate``, the run's estimated steps), so that a signal is answered within a fraction
    of a second however long a sample interval is: one that needs more is advanced in pieces.

    Each call starts from the last sample of the one before (its state at a step's end, the
    quaternion normalised) and chooses its first step afresh. ``steps`` counts accepted steps;
    ``extras`` holds ``rtol``, ``nfev`` and ``compile_s`` (the first call, which loads the kernel).
    """
    from rotframe.rigid.adaptive import rigid_dop853

    n = len(times)
    out_L = np.empty((n, 3))
    out_q = np.empty((n, 4))
    out_L[0], out_q[0] = L0, q0
    steps = nfev = 0
    t0 = time.perf_counter()
    rigid_dop853(inertia, L0, q0, times[:1], rtol=rtol, mgl=mgl)  # load or compile the kernel (no step taken)
    compile_s = time.perf_counter() - t0
    done = 1  # samples filled
    L, q = L0, q0
    per_sample = float(steps_estimate) / max(n - 1, 1)
    per_call = int(min(SAMPLES_PER_CALL, max(1.0, STEPS_PER_CALL / max(per_sample, 1e-300))))
    pieces = int(min(1e6, math.ceil(per_sample / STEPS_PER_CALL))) if per_sample > STEPS_PER_CALL else 1
    try:
        while done < n:
            stop = min(n, done + per_call)
            try:
                if pieces > 1:  # one sample interval in pieces: Python regains control between them
                    res = _one_sample_in_pieces(rigid_dop853, inertia, L, q, times[done - 1], times[done], pieces,
                                                rtol, mgl)
                    stop = done + 1
                else:
                    res = rigid_dop853(inertia, L, q, times[done - 1:stop], rtol=rtol, mgl=mgl)
            except IntegrationError as exc:
                k = 1 if pieces > 1 else len(exc.partial.times)  # pieces: the sample was not reached
                out_L[done:done + k - 1], out_q[done:done + k - 1] = exc.partial.L[1:], exc.partial.q[1:]
                good = done + k - 1
                partial = _truncate(BodyTrajectory(times, out_L, out_q, "dop853", steps + exc.partial.steps), good)
                raise IntegrationError(f"non-finite state or step-size collapse after t = {times[good - 1]:.6g} s "
                                       f"(method dop853, rtol {rtol:g})", t_reached=float(times[good - 1]),
                                       partial=partial) from None
            out_L[done:stop], out_q[done:stop] = res.L[1:], res.q[1:]
            L, q = res.L[-1], res.q[-1]
            steps += res.steps
            nfev += res.nfev
            done = stop
            if progress:
                progress(done / n)
    except KeyboardInterrupt:
        raise RunInterrupted(_truncate(BodyTrajectory(times, out_L, out_q, "dop853", steps), done)) from None
    traj = BodyTrajectory(times, out_L, out_q, "dop853", steps, True, float(times[-1]))
    traj.extras.update(compile_s=compile_s, rtol=rtol, nfev=nfev)
    return traj


def _one_sample_in_pieces(rigid_dop853, inertia, L, q, t0, t1, pieces, rtol, mgl):
    """One sample interval [t0, t1] as ``pieces`` calls; a result with the two samples' L, q and the cost."""
    grid = np.linspace(t0, t1, pieces + 1)
    L_out, q_out = [np.asarray(L, float)], [np.asarray(q, float)]
    steps = nfev = 0
    for k in range(pieces):
        res = rigid_dop853(inertia, L, q, grid[k:k + 2], rtol=rtol, mgl=mgl)
        L, q = res.L[-1], res.q[-1]
        steps += res.steps
        nfev += res.nfev
    L_out.append(L)
    q_out.append(q)
    return _Pieces(np.array(L_out), np.array(q_out), steps, nfev)


@dataclass
class _Pieces:
    L: np.ndarray
    q: np.ndarray
    steps: int
    nfev: int


def _check_adaptive(inertia, rtol):
    """ScenarioError unless ``dop853`` can run: 1e-15 <= rtol < 1 and every principal moment > 0."""
    if not (math.isfinite(rtol) and 1e-15 <= rtol < 1.0):
        raise ScenarioError(f"rtol = {rtol:g}: method dop853 needs 1e-15 <= rtol < 1")
    if not all(float(x) > 0 for x in inertia):
        raise ScenarioError(f"method dop853: principal moments {', '.join(f'{x:g}' for x in inertia)} kg m2; "
                            "it needs all > 0 (a thin rod has a zero moment: use exact or lie-poisson)")


def _advance_in_pieces(stepper, L, q, h, steps, piece=1_000_000):
    """The state after ``steps`` steps, taken in kernel calls of ``piece`` steps (Python runs between)."""
    done = 0
    while done < steps:
        k = min(piece, steps - done)
        try:
            Ls, qs, _ = stepper(L, q, h, k, k)
        except IntegrationError as exc:  # no sample was completed in this interval
            exc.partial = (np.asarray([L]), np.asarray([q]), None)
            raise
        L, q = Ls[-1], qs[-1]
        done += k
    return L, q


def free_body_state(inertia, omega_body):
    """``(inertia, L0, q0)`` of a free body: principal moments (checked), L = I omega in body axes, q0 identity.

    Raises ScenarioError for moments that no body has (see
    [`rotframe.rigid.mass_properties.check_moments`][rotframe.rigid.mass_properties.check_moments]).
    """
    from rotframe.rigid import mass_properties

    inertia = np.asarray(inertia, dtype=float)
    mass_properties.check_moments(inertia)
    omega = np.asarray(omega_body, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        # what the numbers become: L, |L| and the energy L . omega / 2, from which every metric is measured
        L = inertia * omega
        energy = 0.5 * float(np.sum(np.abs(L) * np.abs(omega)))
        size = float(np.sqrt(np.sum(L * L)))
    if not (math.isfinite(energy) and math.isfinite(size)):
        bound = math.sqrt(1e308 / max(float(np.max(inertia)), 1e-300))
        raise ScenarioError(f"omega = {omega.tolist()} rad/s: the body's angular momentum or kinetic energy overflows "
                            f"a float64, so no metric can be measured; allowed: |omega| below about {bound:.3g} rad/s "
                            "for these moments")
    return inertia, L, np.array([0.0, 0.0, 0.0, 1.0])


def simulate_free_body(body, duration, method, run, progress):
    """Run a free body ``body = (inertia, L0, q0)`` on the engine (`run_body`); the default method is the exact flow."""
    from rotframe.scenes.base import SceneResult

    inertia, L0, q0 = body
    method = method or run.get("method") or "exact"

    def finish(traj, remarks):
        return SceneResult(traj, ["free-rigid-body"], traj.method, traj.steps, extras={"inertia": inertia, **remarks})

    return run_body(method, inertia, L0, q0, duration, run, progress, finish)


def run_body(method, inertia, L0, q0, duration, run, progress, finish, torque=None):
    """Integrate a rigid scene's body on the engine (`rotframe.problem.body.simulate_rigid_body`) with the run
    settings (``step``, ``rtol``, ``samples``): principal moments ``inertia``, the start ``L0``, ``q0``, the
    ``torque`` (`rotframe.torques`; None: a free body) and a method of the registry.

    ``finish(traj, remarks)`` builds the scene's result from the run's `BodyTrajectory` (or the one up to an early
    stop: `rotframe.scenes.base.guarded`) and the engine's notes and warnings (``remarks``, for the result's
    extras). The trajectory's ``extras`` hold the run's ``rtol`` or ``step`` and ``nfev``; ``steps`` counts the
    steps taken, and one for the exact flow (its one evaluation, as the scenes count it).
    """
    from rotframe.problem.body import simulate_rigid_body  # the engine's front door: imported by a run

    samples = max(1, int(run.get("samples") or 2000))
    rtol = float(run.get("rtol") or DEFAULT_RTOL)

    def done(body_run):
        steps = 1 if body_run.method == "exact" else body_run.steps
        traj = BodyTrajectory(body_run.times, body_run.L, body_run.q, body_run.method, steps, body_run.complete,
                              body_run.t_reached, dict(body_run.extras))
        # the engine's notes on the run (its tier, its caches); not its own account of the invariants, which the
        # scene reports itself
        notes = [n for n in getattr(body_run, "notes", []) if not n.startswith("a torque acts")]
        return finish(traj, {"notes": notes, "warnings": list(getattr(body_run, "warnings", []))})

    return guarded(done, simulate_rigid_body, inertia=inertia, L0=L0, q0=q0, duration=duration, torque=torque,
                   method=method, rtol=rtol if method == "dop853" else None, step=run.get("step"), samples=samples,
                   progress=progress)


def _stepper(method, inertia, top):
    """``(checked, fast)`` steppers ``(L, q, h, n, every) -> (L, q, times)`` of a fixed-step method.

    ``checked`` is the public function (every input checked); ``fast`` runs the
    same compiled driver with the body's constants checked once
    (`rotframe.rigid.drivers.splitting_stepper`), for the chunks after a
    first checked call. Both give the same numbers.
    """
    from rotframe.rigid import dynamics as rigid
    from rotframe.rigid.checks import check_inertia, heavy_top_mgl, symmetry_axis
    from rotframe.rigid.drivers import SPLITTING_ORDERS, splitting_stepper

    i1, i2, i3 = inertia
    mgl = 0.0 if top is None else top[0] * top[1] * top[2]
    if method == "rk4":
        rk4 = lambda L, q, h, n, every: rigid.rigid_rk4(inertia, L, q, h, n, mgl=mgl, sample_every=every)  # noqa: E731
        return rk4, rk4
    zero = np.zeros(3)
    for prefix in ("lie-poisson", "top-splitting"):
        if method.startswith(prefix) and method[len(prefix):] in SPLITTING_ORDERS:
            k = SPLITTING_ORDERS[method[len(prefix):]]
            if top is not None:
                mass, length, g = top

                def checked(L, q, h, n, every):
                    return rigid.heavy_top_splitting(i1, i3, mass, length, g, L, q, h, n, order=k, sample_every=every)

                # the constants exactly as heavy_top_splitting computes them
                fast = splitting_stepper(check_inertia((i1, i1, i3))[1], 2, heavy_top_mgl(mass, length, g),
                                         zero, zero, k)
                return checked, fast

            def checked(L, q, h, n, every):
                return rigid.lie_poisson(inertia, L, q, h, n, order=k, sample_every=every)

            # the constants exactly as lie_poisson computes them (no torque)
            moments, inv_i = check_inertia(inertia)
            sym = symmetry_axis(moments)
            fast = splitting_stepper(inv_i, -1 if sym is None else sym, 0.0, zero, zero, k)
            return checked, fast
    raise ScenarioError(f"method {method!r} unknown for a rigid body")


def _truncate(traj, n):
    n = max(1, n)
    return BodyTrajectory(traj.times[:n], traj.L[:n], traj.q[:n], traj.method, traj.steps, False,
                          float(traj.times[n - 1]), traj.extras)


def _check_finite(traj):
    ok = np.all(np.isfinite(traj.L), axis=1) & np.all(np.isfinite(traj.q), axis=1)
    if not ok.all():
        bad = int(np.argmin(ok))
        raise IntegrationError(f"non-finite state after t = {traj.times[max(bad - 1, 0)]:.6g} s",
                               t_reached=float(traj.times[max(bad - 1, 0)]), partial=_truncate(traj, bad))
    return traj


def initial_attitude_zxz(phi, theta, psi):
    """Quaternion (x, y, z, w), body -> space, of ZXZ Euler angles (Goldstein's convention, rad)."""
    from scipy.spatial.transform import Rotation

    from rotframe import frames

    A = frames.euler_to_dcm([phi, theta, psi], seq="ZXZ")  # space -> body
    return Rotation.from_matrix(A.T).as_quat()


def invariant_drifts(inertia, traj):
    """Relative drifts of the energy and |L| along a free-body trajectory."""
    from rotframe.rigid import dynamics as rigid
    from rotframe.scenes.base import rel_drift

    E = rigid.energy(inertia, traj.L)
    M = np.linalg.norm(traj.L, axis=1)
    return rel_drift(E), rel_drift(M), E, M


def record_body(rec, traj, inertia, name="body", axis_length=1.0, mass=1.0,
                L_label="L in space (fixed: no torque acts)"):
    """Body transform, its axes, a box of the same principal moments, L in space per sample, the polhode.

    Logged to ``rec``, the [`rotframe.app.record.Recording`][rotframe.app.record.Recording] passed in.

    ``world/angular_momentum`` is an arrow along L (space frame) at each
    sample, scaled to 2 ``axis_length``: fixed for a free body, turning for
    a torqued one (``L_label`` says which).
    """
    from rotframe.numerics.sampling import decimate
    from rotframe.rigid import dynamics as rigid

    idx = decimate(len(traj.times), 5000)
    t = traj.times[idx]
    rec.body(f"world/{name}", t, traj.q[idx], axis_length=axis_length)
    I = np.asarray(inertia, float)
    # a box with these principal moments: I1 = m (b^2 + c^2) / 12, ...
    s = 6.0 / mass * (np.array([I[1] + I[2] - I[0], I[0] + I[2] - I[1], I[0] + I[1] - I[2]]))
    half = 0.5 * np.sqrt(np.clip(s, 1e-12 * s.max(), None))
    half *= axis_length * 0.6 / half.max()
    rec.static(f"world/{name}/shape", "Boxes3D", half_sizes=[half], colors=[[200, 170, 90, 160]])
    Ls = rigid.angular_momentum_space(traj.q[idx], traj.L[idx])
    # twice the body axes: its label (at the arrow's middle) clears theirs where L lies along an axis (dzhanibekov)
    scale = 2.0 * axis_length / max(float(np.linalg.norm(Ls[0])), 1e-300)
    rec.segments("world/angular_momentum", t, np.zeros_like(Ls), scale * Ls, color=[250, 250, 250])
    rec.static("world/angular_momentum", "Arrows3D", labels=[L_label], show_labels=True)
    Lb = traj.L[idx] / np.maximum(np.linalg.norm(traj.L[idx], axis=1), 1e-300)[:, None]
    rec.line(f"world/{name}/polhode", 1.2 * axis_length * Lb, color=[250, 200, 60])
    rec.scalars("diagnostics/omega_body/1", t, traj.L[idx, 0] / I[0] if I[0] else 0 * t)
    rec.scalars("diagnostics/omega_body/2", t, traj.L[idx, 1] / I[1] if I[1] else 0 * t)
    rec.scalars("diagnostics/omega_body/3", t, traj.L[idx, 2] / I[2] if I[2] else 0 * t)
    return idx
