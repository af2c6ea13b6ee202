"""Turntable: a puck sliding without friction, seen from the spinning turntable.

The turntable spins about the vertical z axis at w(t) = omega0 + alpha t. The
puck starts at (start_radius, 0, 0) on the turntable, shoved towards the centre
at ``speed`` relative to the turntable. In inertial space it moves on a straight
line; seen from the turntable it feels Coriolis, centrifugal and (while the
turntable spins up) Euler forces. Oracle (docs/physics/rotating-frames.md,
`rotframe.analytic.turntable_inertial_line`): the inertial
line mapped into the rotating frame, r_rot(t) = R_z(-theta(t)) (r0 + v_in t),
theta(t) = integral of w.

Built on the engine of your own problems (`rotframe.problem.particles.simulate_particles`), as
``inertial-oscillation``, ``cr3bp`` and ``tumbling-ball`` are: the scene chooses its frame (a
constant spin, or the rate's two knots joined linearly, which is the spin-up exactly), its terms
(the frame's, by name: ``frame_terms``) and its theory; the engine runs the method (the exact
flow of a force-free particle by default: the inertial line turned by the rate's exact integral).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotframe import analytic, method_registry
from rotframe.errors import IntegrationError, ScenarioError
from rotframe.numerics.vectors import norm3
from rotframe.particles.model import OmegaSchedule
from rotframe.scenes.base import (SceneResult, engine_remarks, guarded, method_rel_error, particle_methods,
                                  reject_subnormal, rel_drift, run_setting, with_parameters)


@dataclass(frozen=True, kw_only=True)
class TurntableParameters:
    """Parameters of the turntable scene, in the units of its scenario file."""

    omega0: float  # rad/s, spin rate at t = 0
    alpha: float  # rad/s^2, spin-up rate
    speed: float  # m/s, shove towards the centre
    duration: float  # s
    start_radius: float  # m
    table_radius: float  # m, drawn only


#: The scene's parameters (the scene protocol's optional ``PARAMETERS``).
PARAMETERS = TurntableParameters


#: Every particle integrator (the registry's names; its old names accepted too).
METHODS = particle_methods()
#: What runs when ``--method`` names none (``rotframe show`` prints it).
DEFAULT_METHOD = "exact (the puck is force-free: a straight line in inertial space)"

Z = np.array([0.0, 0.0, 1.0])


def _setup(p, terms):
    """``(omega, frame, frame_terms, r0, v0, T)``: the spin as a schedule (the oracle's exact angle) and as the
    engine's frame (a constant vector, or the rate's two knots joined linearly), the frame's terms that act (the
    frame's alone: nothing else acts on a frictionless puck)."""
    from rotframe.problem.terms import FRAME_TERMS  # imported by a run, not by listing or describing the scene

    others = [t for t in terms if t not in FRAME_TERMS]
    if others:
        raise ScenarioError(f"model: {others[0]!r} is not a term of this scene; the puck feels the frame's terms "
                            f"alone ({', '.join(FRAME_TERMS)})")
    w0, alpha, T = p.omega0, p.alpha, p.duration
    omega = OmegaSchedule.ramp(Z, w0, alpha, T)
    frame_terms = tuple(t for t in terms if not (t == "euler" and alpha == 0.0))
    # a steady spin is a constant omega; a spin-up is w(t) = w0 + alpha t, exactly the line through its two knots
    frame = w0 * Z if alpha == 0.0 else (np.array([0.0, T]), np.array([w0 * Z, (w0 + alpha * T) * Z]), "linear")
    r0 = np.array([p.start_radius, 0.0, 0.0])
    v0 = np.array([-p.speed, 0.0, 0.0])
    return omega, frame, frame_terms, r0, v0, T


#: A run whose distance from the exact line exceeds this fraction of the motion's size has diverged.
DIVERGED = 0.1


def left_out(frame_terms, alpha) -> list:
    """The frame's terms that act on the puck but the model leaves out (Coriolis, centrifugal, and Euler's while the
    table spins up). With none the puck moves on the inertial straight line, the scene's oracle; a model that
    leaves one out is the motion without it, which leaves the line."""
    acting = {"coriolis", "centrifugal"} | ({"euler"} if alpha != 0.0 else set())
    return sorted(acting - set(frame_terms))


def _default_method(frame_terms, alpha):
    """The exact flow where it exists: the puck under every term of the frame moves on the inertial straight line
    (exact for any spin-up), and a steady frame's terms are linear with constant coefficients; with a term of a
    spinning-up frame left out there is none, and the fourth-order splitting at the scenario's step runs instead."""
    return "exact" if alpha == 0.0 or not left_out(frame_terms, alpha) else "rotation-splitting4"


@with_parameters(TurntableParameters)
def simulate(p, terms, method, run, progress):
    from rotframe.particles.advice import remedy
    from rotframe.problem.particles import simulate_particles  # the engine's front door: imported by a run

    reject_subnormal(p)
    omega, frame, frame_terms, r0, v0, T = _setup(p, terms)
    method = particle_methods().canonical(method) if method else _default_method(frame_terms, p.alpha)

    def finish(res):  # a ProblemRun, or the trajectory up to an early stop
        traj = getattr(res, "trajectory", res)
        oracle = inertial_line(omega, r0, v0, traj.times)
        return SceneResult(traj, list(frame_terms), traj.method, traj.steps, traj.nfev,
                           extras={"oracle": oracle, "omega": omega,
                                   **engine_remarks(res)})  # the engine's notes and warnings, passed on

    result = guarded(finish, simulate_particles, omega=frame, r0=r0, v0=v0, duration=T, method=method,
                     frame_terms=frame_terms, rtol=run_setting(run, "rtol"), step=run.get("step"),
                     samples=int(run_setting(run, "samples")), progress=progress)
    if left_out(frame_terms, p.alpha):  # the line is not this model's motion: leaving it is no failure
        return result
    # a numerical instability that stays finite is still a failure: stop where the path left the exact line
    traj = result.trajectory
    err = _oracle_error(result)
    size = motion_size(p, traj.times)
    bad = np.nonzero(~(err <= DIVERGED * size))[0]
    if len(bad):
        good = max(int(bad[0]), 1)
        partial = finish(traj.truncated(good))
        raise IntegrationError(f"the {traj.method} run diverged: {err[bad[0]]:.3g} m from the exact inertial line "
                               f"at t = {traj.times[bad[0]]:.6g} s, more than {DIVERGED:g} of the motion's size "
                               f"{size[bad[0]]:.3g} m; "
                               + remedy(method_registry.get(traj.method).step, step=traj.extras.get("step"),
                                        rtol=run_setting(run, "rtol")),
                               t_reached=float(traj.times[good - 1]), partial=partial)
    return result


@with_parameters(TurntableParameters)
def motion_size(p, times):
    """Size of the motion (m) up to each time: start radius plus the inertial distance travelled."""
    v_in = math.hypot(p.speed, p.omega0 * p.start_radius)
    return p.start_radius + v_in * np.asarray(times) + 1e-300


def inertial_line(omega, r0, v0, times):
    """Rotating-frame positions (n, 3) of the inertial straight line (the oracle), for the schedule ``omega``.

    ``r0``, ``v0`` are the puck's position and velocity in the turntable's frame
    at t = 0; its inertial velocity is ``v0 + w(0) x r0``, and the line is
    `rotframe.analytic.turntable_inertial_line` turned by the schedule's
    exact angle.
    """
    times = np.asarray(times, dtype=float)
    v_in = v0 + np.cross(omega.vector(0.0), r0)
    return analytic.turntable_inertial_line(r0, v_in, omega.angle(times), times)


def _oracle_error(result):
    """|r - r_exact| (m) at every sample: the distance of the run from the exact inertial line."""
    return norm3(result.trajectory.r[:, 0] - result.extras["oracle"])


def _inertial_speed(result):
    traj, omega = result.trajectory, result.extras["omega"]
    r, v = traj.r[:, 0], traj.v[:, 0]
    w = np.array([omega.vector(t) for t in traj.times])
    return norm3(v + np.cross(w, r))


@with_parameters(TurntableParameters)
def analyse(p, result):
    traj = result.trajectory
    err = _oracle_error(result)
    turns = float(result.extras["omega"].angle(traj.times[-1])[0] / (2 * math.pi))
    T = float(traj.times[-1])
    w_max = max(abs(p.omega0), abs(p.omega0 + p.alpha * T))
    # the method's error over the path: relative to the motion's size, on the spin's time scale 1 / w_max
    size = float(motion_size(p, [T])[0])
    tol = method_rel_error(traj, 1.0 / w_max if w_max > 0 else T) * size
    notes = []
    if p.alpha != 0 and p.omega0 * (p.omega0 + p.alpha * T) < 0:
        notes.append("the spin reverses during the run: turns counts the net angle (the two senses cancel)")
    theory = {"position_error_m": 0.0, "turns": (p.omega0 * T + 0.5 * p.alpha * T**2) / (2 * math.pi)}
    theory_notes = {"position_error_m": "exact: the inertial straight line seen from the turntable",
                    "turns": "exact: (omega0 T + alpha T^2 / 2) / 2 pi"}
    tolerance = {"position_error_m": tol, "turns": 1e-12 * max(abs(turns), 1.0)}
    missing = left_out(result.terms, p.alpha)
    if missing:  # the model is not the whole motion: the line is no theory of it
        for table in (theory, theory_notes, tolerance):
            del table["position_error_m"]
        notes.append(f"position_error_m: the model leaves out the frame's {', '.join(missing)}, so the puck does "
                     "not move on the inertial straight line; it measures how far the model's motion leaves it "
                     "(no theory)")
    return {
        "metrics": {"position_error_m": float(err[-1]), "turns": turns},
        "theory": theory,
        "theory_notes": theory_notes,
        "tolerance": tolerance,
        "diagnostics": {"max_position_error_m": float(np.max(err)),
                        "inertial_speed_rel_drift": rel_drift(_inertial_speed(result))},
        "notes": notes + result.extras.get("notes", []),
        "warnings": result.extras.get("warnings", []),
    }


@with_parameters(TurntableParameters, position=1)
def record(rec, p, result):
    traj = result.trajectory
    rec.points("world/puck", traj.times, traj.r[:, 0], radius=0.03, color=[240, 120, 40])
    rec.points("world/oracle", traj.times, result.extras["oracle"], radius=0.015, color=[80, 80, 80], trail=False)
    # the whole curl from the first frame, faint (the trail above grows with time over it)
    rec.line("world/path_on_the_table", traj.r[:, 0], color=[240, 120, 40, 90])
    phi = np.linspace(0, 2 * np.pi, 181)
    R = p.table_radius
    rec.line("world/turntable", np.stack([R * np.cos(phi), R * np.sin(phi), 0 * phi], axis=1), color=[120, 120, 200])
    rec.frame_axes("world/frame", 0.6 * R, labels=("x (turntable)", "y (turntable)", "z (spin axis)"))
    _record_inertial_axes(rec, traj.times, result.extras["omega"], 1.1 * R)
    # the straight line the puck runs along in inertial space, drawn in the inertial axes (which turn
    # backwards under the table): the curl on the table is this line seen from the turning table
    theta = np.asarray(result.extras["omega"].angle(traj.times[[0, -1]]), dtype=float).reshape(-1)
    ends = np.array([_turn_z(traj.r[k, 0], theta[j]) for j, k in enumerate((0, -1))])
    rec.static("world/inertial_axes/straight_line", "LineStrips3D", strips=[ends], colors=[[200, 200, 200]],
               radii=[0.008], labels=["the puck's straight path in inertial space"])
    size = max(R, float(np.nanmax(np.abs(traj.r[:, 0, :2]))))
    rec.view(eye=(0.8 * size, -1.2 * size, 1.5 * size), look_at=(0.0, 0.0, 0.0))  # from above and aside: the whole curl
    err = _oracle_error(result)
    rec.scalars("diagnostics/position_error_m", traj.times, err)
    speed = _inertial_speed(result)
    rec.scalars("diagnostics/inertial_speed_rel_error", traj.times, speed / speed[0] - 1)


def _turn_z(r, angle):
    """``r`` turned by ``angle`` about z: turntable components into inertial ones (the table has turned by angle)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * r[0] - s * r[1], s * r[0] + c * r[1], r[2]])


def _record_inertial_axes(rec, times, omega, length):
    """The inertial (lab) axes as seen from the turntable: they turn by -theta(t) about z."""
    from rotframe.numerics.sampling import decimate

    idx = decimate(len(times), 2000)
    half = -0.5 * np.asarray(omega.angle(times[idx]), dtype=float).reshape(-1)
    quat = np.stack([0 * half, 0 * half, np.sin(half), np.cos(half)], axis=1)
    rec.body("world/inertial_axes", times[idx], quat, axis_length=None)
    rec.static("world/inertial_axes/arrows", "Arrows3D", vectors=[[length, 0, 0], [0, length, 0]],
               colors=[[120, 120, 120], [120, 120, 120]], labels=["X (inertial)", "Y (inertial)"])
