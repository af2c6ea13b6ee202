"""A ball inside a tumbling body: a free particle seen from the axes of a body doing the flip.

The body is a torque-free rigid body (principal moments ``i1, i2, i3``) started near a spin
about its intermediate axis; its exact motion is rotframe's closed form
(`rotframe.problem.body.simulate_rigid_body` with ``method="exact"``, Jacobi elliptic
functions). Its solution is the frame (``omega=`` a rigid-body solution: omega = I^-1 L and
omega' from Euler's equations at each sample, quintic Hermite between them;
`rotframe.problem.frame`) in which a free ball is integrated by
`rotframe.problem.particles.simulate_particles`: built only on the public API.

Oracle: the body's centre of mass is at rest, so in space the ball moves on the straight line
r_s(t) = R0 r0 + t R0 (v0 + w0 x r0), and in body axes r(t) = R(t)^T r_s(t) with R(t) the
body's attitude (its quaternion samples). ``position_error_m`` is the largest distance between
the two over the run; it falls with the frame's interpolation (body samples) and the
integrator's tolerance to the rigid solution's own accuracy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotframe.problem.body import simulate_rigid_body
from rotframe.rigid.observables import body_to_space
from rotframe.problem.particles import simulate_particles
from rotframe.scenes.base import SceneResult, guarded, run_setting, with_parameters

__all__ = ["TumblingBallParameters", "PARAMETERS", "METHODS", "simulate", "analyse", "record", "BODY_SAMPLES_PER_S"]

METHODS = ("dop853", "rk4")
DEFAULT_METHOD = "dop853"
#: samples per second of the body's exact solution, the frame's knots (its interpolation error ~ (h w)^6)
BODY_SAMPLES_PER_S = 200


@dataclass(frozen=True, kw_only=True)
class TumblingBallParameters:
    """Parameters of the tumbling-ball scene, SI."""

    i1: float
    i2: float
    i3: float
    omega: tuple[float, ...]
    position: tuple[float, ...]
    velocity: tuple[float, ...]
    duration: float


PARAMETERS = TumblingBallParameters


#: the conjugate of a scalar-last quaternion, as a factor
_CONJUGATE = np.array([-1.0, -1.0, -1.0, 1.0])


@with_parameters(TumblingBallParameters)
def simulate(p, terms, method, run, progress):
    inertia = np.array([p.i1, p.i2, p.i3], dtype=float)
    w0 = np.asarray(p.omega, dtype=float)
    L0 = inertia * w0
    q0 = np.array([0.0, 0.0, 0.0, 1.0])
    duration = float(p.duration)
    samples = int(run_setting(run, "samples"))
    # the body's samples: at least BODY_SAMPLES_PER_S a second, a whole number of them between two of the
    # ball's, so that every sample of the ball is one of the body's (the oracle reads the attitude there)
    n_body = max(int(math.ceil(BODY_SAMPLES_PER_S * duration)), 16)
    n_body = samples * max(1, math.ceil(n_body / samples))
    body = simulate_rigid_body(inertia=inertia, L0=L0, q0=q0, duration=duration, method="exact", samples=n_body)
    r0 = np.asarray(p.position, dtype=float)
    v0 = np.asarray(p.velocity, dtype=float)

    def finish(ball):  # a ProblemRun, or the trajectory up to an early stop
        traj = getattr(ball, "trajectory", ball)
        return SceneResult(traj, list(terms), traj.method, traj.steps, traj.nfev,
                           extras={"body": body, "w0": w0, "r0": r0, "v0": v0, "notes": getattr(ball, "notes", []),
                                   "rtol": run_setting(run, "rtol") if traj.method == "dop853" else 1e-6,
                                   "warnings": getattr(ball, "warnings", [])})

    return guarded(finish, simulate_particles, omega=body, r0=r0, v0=v0, duration=duration,
                   method=method or DEFAULT_METHOD, rtol=run_setting(run, "rtol"), step=run.get("step"),
                   samples=samples, progress=progress)


def oracle(body, times, r0, v0, w0):
    """The ball's exact path in body axes: the inertial straight line turned by the body's attitude."""
    q_at = _attitude_at(body, times)
    R0 = np.repeat(body.q[:1], 1, axis=0)
    start = body_to_space(R0, r0[None, :])[0]
    vel = body_to_space(R0, (v0 + np.cross(w0, r0))[None, :])[0]
    line = start[None, :] + times[:, None] * vel[None, :]
    return body_to_space(q_at * _CONJUGATE, line), line  # R(q)^T = R(q*): space -> body


def _attitude_at(body, times):
    """The body's quaternion at ``times`` (each a sample time of the body's solution)."""
    idx = np.clip(np.rint(times / (body.times[1] - body.times[0])).astype(int), 0, len(body.times) - 1)
    if not np.allclose(body.times[idx], times, rtol=0, atol=1e-9 * max(1.0, times[-1])):
        raise ValueError("the ball's samples must be among the body's sample times")
    return body.q[idx]


@with_parameters(TumblingBallParameters)
def analyse(p, result):
    traj = result.trajectory
    ex = result.extras
    exact, _ = oracle(ex["body"], traj.times, ex["r0"], ex["v0"], ex["w0"])
    err = float(np.max(np.linalg.norm(traj.r[:, 0] - exact, axis=1)))
    path = float(np.max(np.linalg.norm(exact - exact[0], axis=1)))
    w2 = ex["body"].L[:, 1] / p.i2
    flips = int(np.sum(np.signbit(w2[1:]) != np.signbit(w2[:-1])))
    scale = max(path, float(np.linalg.norm(ex["r0"])), 1e-300)
    tol = 10.0 * float(run_tolerance(result)) * scale  # the global error of the run's steps at rtol
    return {"metrics": {"position_error_m": err, "flips": flips, "curl_m": path},
            "theory": {"position_error_m": 0.0},
            "theory_notes": {"position_error_m": "exact: the inertial straight line in body axes (error 0)"},
            "tolerance": {"position_error_m": tol},
            "diagnostics": {"body_energy_rel_drift": ex["body"].diagnostics.get("energy_rel_drift", 0.0)},
            "notes": list(ex.get("notes", [])), "warnings": list(ex.get("warnings", []))}


def run_tolerance(result):
    """The relative accuracy the run was asked for (DOP853's rtol, else 1e-6 for RK4's default step)."""
    return result.extras.get("rtol", 1e-9)


@with_parameters(TumblingBallParameters, position=1)
def record(rec, p, result):
    traj = result.trajectory
    ex = result.extras
    exact, line = oracle(ex["body"], traj.times, ex["r0"], ex["v0"], ex["w0"])
    size = max(float(np.max(np.abs(traj.r[:, 0]))), float(np.max(np.abs(line))), 1.0)
    # everything sized to the path (tens of metres): the balls, the body's axes, and a label on each path
    # that says what it is, so the curl is read as the straight line seen from the tumbling body
    rec.points("world/body_frame/ball", traj.times, traj.r[:, 0], radius=0.012 * size, color=[230, 90, 40])
    rec.line("world/body_frame/path", traj.r[:, 0], color=[230, 90, 40])
    far = int(np.argmax(np.linalg.norm(traj.r[:, 0], axis=1)))  # labels where the two paths are apart
    rec.static("world/body_frame/path_label", "Points3D", positions=[traj.r[far, 0]], radii=[0.004 * size],
               labels=["the ball seen from the tumbling body's axes: it curls (Coriolis, centrifugal, Euler)"],
               show_labels=True)
    rec.line("world/space/straight_line", line, color=[60, 140, 230])
    rec.points("world/space/ball", traj.times, line, radius=0.012 * size, color=[60, 140, 230])
    rec.static("world/space/line_label", "Points3D", positions=[line[len(line) // 2]], radii=[0.004 * size],
               labels=["the same ball in space: a straight line"], show_labels=True)
    body = ex["body"]
    rec.body("world/space/body", body.times, body.q, axis_length=0.25 * size)
    rec.scalars("diagnostics/position_error_m", traj.times, np.linalg.norm(traj.r[:, 0] - exact, axis=1))
    rec.scalars("diagnostics/omega_body/2", body.times, body.L[:, 1] / p.i2)
    rec.view(eye=(1.2 * size, -1.6 * size, 1.0 * size), look_at=(0.0, 0.0, 0.0))
