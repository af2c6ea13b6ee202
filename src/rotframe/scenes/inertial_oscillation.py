"""Inertial oscillation: a frictionless puck on a level surface circles clockwise (north).

f-plane model in the local ENU frame: only the vertical component of omega
acts on horizontal motion (the horizontal components push vertically, and the
level surface takes that), so x'' = f y', y'' = -f x' with f = 2 Omega sin(lat).
The velocity turns at rate -f: period 2 pi / |f|, radius |v| / |f|, clockwise
in the north, counter-clockwise in the south, a straight line on the equator.
The model is linear, so the exact propagator is the default.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe import analytic, earth  # noqa: F401  (astropy loads with the scene, before timing)
from rotframe.integrators import default_method
from rotframe.model import OmegaSchedule, ParticleModel
from rotframe.scenes.base import SceneResult, earth_model_constants, rel_drift, run_particles

METHODS = ("exact", "splitting", "splitting4", "rk4", "dop853")


def build(values, terms):
    Omega, w, g = earth_model_constants(values["latitude"])
    f_plane = np.array([0.0, 0.0, w[2]])
    model = ParticleModel(tuple(terms), omega=OmegaSchedule.constant(f_plane))
    az = math.radians(values["heading"])
    v0 = values["speed"] * np.array([math.sin(az), math.cos(az), 0.0])
    return model, np.zeros(3), v0, Omega


def simulate(values, terms, method, run, progress):
    model, r0, v0, Omega = build(values, terms)
    method = method or default_method(model)

    def finish(traj):
        return SceneResult(traj, list(model.terms), traj.method, traj.steps, traj.nfev, extras={"Omega": Omega})

    return run_particles(model, r0, v0, values["duration"], method, run, progress, finish)


def measured(times, r, v):
    """(period s, radius m, sense) from the motion: the turning rate of v and a circle fit."""
    heading = np.unwrap(np.arctan2(v[:, 1], v[:, 0]))
    rate = np.polyfit(times, heading, 1)[0]
    if abs(rate) * (times[-1] - times[0]) < 1e-9:
        return math.inf, math.inf, 0.0
    # algebraic circle fit x^2 + y^2 + D x + E y + F = 0
    x, y = r[:, 0], r[:, 1]
    M = np.stack([x, y, np.ones_like(x)], axis=1)
    D, E, F = np.linalg.lstsq(M, -(x * x + y * y), rcond=None)[0]
    radius = math.sqrt(max(D * D / 4 + E * E / 4 - F, 0.0))
    return 2 * math.pi / abs(rate), radius, math.copysign(1.0, rate)


def analyse(values, result):
    traj = result.trajectory
    r, v = traj.r[:, 0], traj.v[:, 0]
    period, radius, sense = measured(traj.times, r, v)
    theory = analytic.inertial_oscillation(math.radians(values["latitude"]), values["speed"], result.extras["Omega"])
    metrics = {"period_s": period, "radius_m": radius}
    diagnostics = {"speed_rel_drift": rel_drift(np.linalg.norm(v, axis=1)),
                   "sense": "clockwise" if sense < 0 else "counter-clockwise" if sense > 0 else "none"}
    return {"metrics": metrics, "theory": {"period_s": float(theory.period), "radius_m": float(theory.radius)},
            "diagnostics": diagnostics}


def record(rec, values, result):
    traj = result.trajectory
    rec.points("world/puck", traj.times, traj.r[:, 0] / 1000.0, radius=0.5, color=[230, 90, 40])
    f = 2 * result.extras["Omega"] * math.sin(math.radians(values["latitude"]))
    omega = np.array([0.0, 0.0, f / 2])  # the f-plane: only the vertical part of Omega acts
    rec.frame_axes("world/frame", max(float(np.max(np.abs(traj.r[:, 0]))) / 1000.0, 1.0) / 2, omega=omega)
    rec.scalars("diagnostics/speed_rel_error", traj.times,
                np.linalg.norm(traj.v[:, 0], axis=1) / values["speed"] - 1 if values["speed"] else 0 * traj.times)
    v = traj.v[:, 0]
    if values["speed"]:
        direction = np.degrees(np.unwrap(np.arctan2(v[:, 1], v[:, 0])))
        rec.scalars("diagnostics/velocity_direction_deg", traj.times, direction, label="direction of v (from east)")
        rec.reference("diagnostics/velocity_direction_deg", traj.times, direction[0] - np.degrees(f * traj.times),
                      label="turns at -2 Omega sin(lat) (clockwise in the north)")
