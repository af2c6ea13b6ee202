"""What the rigid-body scenes share: a trajectory type, their run on the engine (`run_body`), their recording."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rotframe.errors import ScenarioError
from rotframe.method_registry import names
from rotframe.scenes.base import guarded

#: Methods of the free body; ``exact`` is the elliptic-function flow, ``lie-poisson[4|6|8]`` the
#: Lie-Poisson splitting of orders 2, 4, 6, 8, ``dop853`` the engine's adaptive Dormand-Prince 8(5,3)
#: (relative tolerance ``rtol`` of the run), ``rk4``.
FREE_METHODS = names("free body")
#: Methods of the heavy top: ``top-splitting[4|6|8]`` (exact free symmetric-top flow and gravity kick,
#: orders 2, 4, 6, 8), ``rk4`` and the adaptive ``dop853``; the old names ``splitting``, ``splitting4``,
#: ``splitting6`` are still accepted.
HEAVY_METHODS = names("heavy top")

#: Relative tolerance of ``dop853`` when the run names none (the scenario default of ``rtol``).
DEFAULT_RTOL = 1e-10


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


def simulate_free_body(body, duration, method, run, progress, spin="omega"):
    """Run a free body ``body = (inertia, L0, q0)`` on the engine (`run_body`); the default method is the exact flow.

    ``spin`` names the scene's keys that make ``L0``, for a refusal of it (`run_body`)."""
    from rotframe.scenes.base import SceneResult

    inertia, L0, q0 = body
    method = method or run.get("method") or "exact"

    def finish(traj, remarks):
        return SceneResult(traj, ["free-rigid-body"], traj.method, traj.steps, extras={"inertia": inertia, **remarks})

    return run_body(method, inertia, L0, q0, duration, run, progress, finish, spin=spin)


def run_body(method, inertia, L0, q0, duration, run, progress, finish, torque=None, spin="the spin"):
    """Integrate a rigid scene's body on the engine (`rotframe.problem.body.simulate_rigid_body`) with the run
    settings (``step``, ``rtol``, ``samples``): principal moments ``inertia``, the start ``L0``, ``q0``, the
    ``torque`` (`rotframe.torques`; None: a free body) and a method of the registry.

    ``finish(traj, remarks)`` builds the scene's result from the run's `BodyTrajectory` (or the one up to an early
    stop: `rotframe.scenes.base.guarded`) and the engine's notes and warnings (``remarks``, for the result's
    extras). The trajectory's ``extras`` hold the run's ``rtol`` or ``step`` and ``nfev``; ``steps`` counts the
    steps taken, and one for the exact flow (its one evaluation, as the scenes count it). A start the engine refuses
    by its ``L0`` (out of float64's range for the method: `rotframe.problem.body_checks`) is said of the scene's keys
    that make it, ``spin``.
    """
    from rotframe.problem.body import simulate_rigid_body  # the engine's front door: imported by a run

    samples = max(1, int(run.get("samples") or 2000))
    rtol = float(run.get("rtol") or DEFAULT_RTOL)

    def done(body_run):
        steps = 1 if body_run.method == "exact" else body_run.steps
        traj = BodyTrajectory(body_run.times, body_run.L, body_run.q, body_run.method, steps, body_run.complete,
                              body_run.t_reached, dict(body_run.extras))
        # the engine's notes on the run (its tier, its caches)
        return finish(traj, {"notes": list(getattr(body_run, "notes", [])),
                             "warnings": list(getattr(body_run, "warnings", []))})

    try:
        return guarded(done, simulate_rigid_body, inertia=inertia, L0=L0, q0=q0, duration=duration, torque=torque,
                       method=method, rtol=rtol if method == "dop853" else None, step=run.get("step"),
                       samples=samples, progress=progress)
    except ScenarioError as exc:
        if not str(exc).startswith("L0: "):
            raise
        raise ScenarioError(f"{spin}: the body's angular momentum {str(exc)[len('L0: '):]}") from None


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
