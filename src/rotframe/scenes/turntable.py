"""Turntable: a puck sliding without friction, seen from the spinning turntable.

The turntable spins about the vertical z axis at w(t) = omega0 + alpha t. The
puck starts at (start_radius, 0, 0) on the turntable, shoved towards the centre
at ``speed`` relative to the turntable. In inertial space it moves on a straight
line; seen from the turntable it feels Coriolis, centrifugal and (while the
turntable spins up) Euler forces. Oracle (docs/physics/rotating-frames.md): the inertial
line mapped into the rotating frame, r_rot(t) = R_z(-theta(t)) (r0 + v_in t),
theta(t) = integral of w.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.model import OmegaSchedule, ParticleModel
from rotframe.scenes.base import SceneResult, rel_drift, run_particles

Z = np.array([0.0, 0.0, 1.0])


def _setup(values, terms):
    w0, alpha, T = values["omega0"], values["alpha"], values["duration"]
    omega = OmegaSchedule.ramp(Z, w0, alpha, T)
    terms = [t for t in terms if not (t == "euler" and alpha == 0.0)]
    model = ParticleModel(tuple(terms), omega=omega)
    r0 = np.array([values["start_radius"], 0.0, 0.0])
    v0 = np.array([-values["speed"], 0.0, 0.0])
    return model, omega, r0, v0, T


def simulate(values, terms, method, run, progress):
    model, omega, r0, v0, T = _setup(values, terms)

    def finish(traj):
        oracle = inertial_line(omega, r0, v0, traj.times)
        return SceneResult(traj, list(model.terms), traj.method, traj.steps, traj.nfev,
                           extras={"oracle": oracle, "omega": omega})

    return run_particles(model, r0, v0, T, method, run, progress, finish)


def inertial_line(omega, r0, v0, times):
    """Rotating-frame positions of the inertial straight line (the oracle)."""
    v_in = v0 + np.cross(omega.vector(0.0), r0)
    theta = omega.angle(times)
    p = r0[None, :] + v_in[None, :] * np.asarray(times)[:, None]
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * p[:, 0] + s * p[:, 1], -s * p[:, 0] + c * p[:, 1], p[:, 2]], axis=1)


def _inertial_speed(result):
    traj, omega = result.trajectory, result.extras["omega"]
    r, v = traj.r[:, 0], traj.v[:, 0]
    w = np.array([omega.vector(t) for t in traj.times])
    return np.linalg.norm(v + np.cross(w, r), axis=1)


def analyse(values, result):
    traj = result.trajectory
    err = np.linalg.norm(traj.r[:, 0] - result.extras["oracle"], axis=1)
    turns = float(result.extras["omega"].angle(traj.times[-1])[0] / (2 * math.pi))
    return {
        "metrics": {"position_error_m": float(err[-1]), "turns": turns},
        "theory": {"position_error_m": 0.0,
                   "turns": (values["omega0"] * values["duration"]
                             + 0.5 * values["alpha"] * values["duration"] ** 2) / (2 * math.pi)},
        "diagnostics": {"max_position_error_m": float(np.max(err)),
                        "inertial_speed_rel_drift": rel_drift(_inertial_speed(result))},
    }


def record(rec, values, result):
    traj = result.trajectory
    rec.points("world/puck", traj.times, traj.r[:, 0], radius=0.03, color=[240, 120, 40])
    rec.points("world/oracle", traj.times, result.extras["oracle"], radius=0.015, color=[80, 80, 80], trail=False)
    phi = np.linspace(0, 2 * np.pi, 181)
    R = values["table_radius"]
    rec.line("world/turntable", np.stack([R * np.cos(phi), R * np.sin(phi), 0 * phi], axis=1), color=[120, 120, 200])
    err = np.linalg.norm(traj.r[:, 0] - result.extras["oracle"], axis=1)
    rec.scalars("diagnostics/position_error_m", traj.times, err)
    rec.scalars("diagnostics/inertial_speed_rel_error", traj.times, _inertial_speed(result) / _inertial_speed(result)[0] - 1)
