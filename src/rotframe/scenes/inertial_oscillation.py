"""Inertial oscillation: a frictionless puck on a level surface circles clockwise (north).

f-plane model in the local ENU frame: only the vertical component of omega
acts on horizontal motion (the horizontal components push vertically, and the
level surface takes that), so x'' = f y', y'' = -f x' with f = 2 Omega sin(lat).
The velocity turns at rate -f: period 2 pi / |f|, radius |v| / |f|, clockwise
in the north, counter-clockwise in the south, a straight line on the equator.
The model is linear, so the exact propagator is the default.

Built on the engine of your own problems (`rotframe.problem.particles.simulate_particles`), as
``cr3bp`` and ``tumbling-ball`` are: the scene chooses its frame (the f-plane's omega), its terms
(the frame's, by name: ``frame_terms``; Coriolis alone by default) and its theory, and the engine
chooses the flow (the exact one of a linear problem, `rotframe.problem.exact`, for ``exact``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotframe import analytic
from rotframe.numerics.linefit import line_fit
from rotframe.numerics.vectors import norm3
from rotframe.errors import ScenarioError
from rotframe.scenes.base import (SceneResult, earth_model_constants, engine_remarks, guarded, method_rel_error,
                                  particle_methods, reject_subnormal, rel_drift, run_setting, samples_for,
                                  unresolved_note, with_parameters)


@dataclass(frozen=True, kw_only=True)
class InertialOscillationParameters:
    """Parameters of the inertial oscillation scene, in the units of its scenario file."""

    latitude: float  # deg
    speed: float  # m/s
    heading: float  # deg from north, clockwise
    duration: float  # s


#: The scene's parameters (the scene protocol's optional ``PARAMETERS``).
PARAMETERS = InertialOscillationParameters


#: Every particle integrator (the registry's names; its old names accepted too).
METHODS = particle_methods()
#: What runs when ``--method`` names none (``rotframe show`` prints it).
DEFAULT_METHOD = "exact (the model is linear: the frame's terms in a steady frame)"


@with_parameters(InertialOscillationParameters)
def build(p, terms):
    """``(omega, frame_terms, r0, v0, Omega)``: the f-plane's omega (its vertical part, rad/s), the frame's terms
    the model names (a term that is not the frame's is refused: nothing else acts on the puck), the start."""
    from rotframe.problem.terms import FRAME_TERMS  # imported by a run, not by listing or describing the scene

    others = [t for t in terms if t not in FRAME_TERMS]
    if others:
        raise ScenarioError(f"model: {others[0]!r} is not a term of this scene; the puck feels the frame's terms "
                            f"alone ({', '.join(FRAME_TERMS)})")
    Omega, w, g = earth_model_constants(p.latitude)
    f_plane = np.array([0.0, 0.0, w[2]])
    az = math.radians(p.heading)
    v0 = p.speed * np.array([math.sin(az), math.cos(az), 0.0])
    return f_plane, tuple(terms), np.zeros(3), v0, Omega


@with_parameters(InertialOscillationParameters)
def simulate(p, terms, method, run, progress):
    from rotframe.problem.particles import simulate_particles  # the engine's front door: imported by a run

    reject_subnormal(p)
    f_plane, frame_terms, r0, v0, Omega = build(p, terms)
    method = particle_methods().canonical(method) if method else "exact"  # the model is linear
    f = abs(2 * Omega * math.sin(math.radians(p.latitude)))
    period = 2 * math.pi / f if f > 0 else math.inf
    samples, resolved = samples_for(p.duration, period, run_setting(run, "samples"))

    def finish(res):  # a ProblemRun, or the trajectory up to an early stop
        traj = getattr(res, "trajectory", res)
        return SceneResult(traj, list(frame_terms), traj.method, traj.steps, traj.nfev,
                           extras={"Omega": Omega, "resolved": resolved, "period": period,
                                   **engine_remarks(res)})  # the engine's notes and warnings, passed on

    return guarded(finish, simulate_particles, omega=f_plane, r0=r0, v0=v0, duration=p.duration, method=method,
                   frame_terms=frame_terms, rtol=run_setting(run, "rtol"), step=run.get("step"), samples=samples,
                   progress=progress)


#: A heading that turns by less than this (rad) over the run is round-off, not rotation.
TURN_FLOOR = 1e-12


def measured(times, r, v):
    """(period s, radius m, sense) from the motion: the turning rate of v and a circle fit.

    When the run covers less than a quarter turn the circle fit is ill-conditioned
    and the radius is the curvature radius |v| / |turning rate| instead.
    """
    heading = np.unwrap(np.arctan2(v[:, 1], v[:, 0]))
    rate = line_fit(times, heading)[0]
    turned = abs(rate) * (times[-1] - times[0])
    if turned < TURN_FLOOR:
        return math.inf, math.inf, 0.0
    if turned < 0.5 * math.pi:
        radius = float(np.mean(norm3(v))) / abs(rate)
    else:
        # algebraic circle fit x^2 + y^2 + D x + E y + F = 0, in units of the path's extent so that
        # squares neither underflow nor overflow whatever the speed
        scale = float(np.max(np.abs(r[:, :2]))) or 1.0
        x, y = r[:, 0] / scale, r[:, 1] / scale
        M = np.stack([x, y, np.ones_like(x)], axis=1)
        D, E, F = np.linalg.lstsq(M, -(x * x + y * y), rcond=None)[0]
        radius = scale * math.sqrt(max(D * D / 4 + E * E / 4 - F, 0.0))
    return 2 * math.pi / abs(rate), radius, math.copysign(1.0, rate)


@with_parameters(InertialOscillationParameters)
def analyse(p, result):
    traj = result.trajectory
    r, v = traj.r[:, 0], traj.v[:, 0]
    lat = math.radians(p.latitude)
    theory = analytic.inertial_oscillation(lat, p.speed, result.extras["Omega"])
    notes = []
    metrics = {"period_s": math.nan, "radius_m": math.nan}
    sense = 0.0
    if p.speed == 0:
        metrics["radius_m"] = float(np.max(norm3(r)))
        notes.append("speed = 0: the puck stays at rest; nothing circles, so there is no period")
    elif not result.extras.get("resolved", True):
        notes.append(unresolved_note("period_s and radius_m", "inertial", result.extras["period"],
                                     float(traj.times[-1])))
    else:
        period, radius, sense = measured(traj.times, r, v)
        metrics = {"period_s": period, "radius_m": radius}
        if not math.isfinite(period):
            notes.append("on the equator f = 2 Omega sin(latitude) = 0: the puck goes straight, period and radius "
                         "are infinite (null)" if lat == 0 else
                         f"the velocity turns by less than {TURN_FLOOR:g} rad in the run, below round-off: period "
                         "and radius not measured (lengthen duration)")
            if lat != 0:  # on the equator infinity is the answer; elsewhere the run could not tell
                metrics = {"period_s": math.nan, "radius_m": math.nan}
    theory_vals = {"period_s": float(theory.period), "radius_m": float(theory.radius)}
    exact = "exact: 2 pi / |f| and speed / |f|, f = 2 Omega sin(latitude), of the same f-plane model"
    theory_notes = {"period_s": exact, "radius_m": exact}
    # the method's error, and the heading's round-off (1e-15 rad) over the angle turned in the run
    turned = 2 * math.pi * float(traj.times[-1]) / metrics["period_s"] if math.isfinite(metrics["period_s"]) else 0
    method_rel = method_rel_error(traj, result.extras["period"]) + (1e-15 / turned if turned else 0.0)
    tolerance = {k: method_rel * abs(t) for k, t in theory_vals.items()
                 if math.isfinite(t) and (k != "period_s" or p.speed > 0)}
    expected = -math.copysign(1.0, lat) if lat != 0 and p.speed > 0 else 0.0
    diagnostics = {"speed_rel_drift": rel_drift(norm3(v)) if p.speed > 0 else 0.0,
                   "sense": "clockwise" if sense < 0 else "counter-clockwise" if sense > 0 else "none"}
    warnings = []
    if math.isfinite(metrics["period_s"]) and sense != expected:
        warnings.append(f"sense of rotation: measured {diagnostics['sense']}, but f = 2 Omega sin(latitude) says "
                        + ("clockwise" if expected < 0 else "counter-clockwise"))
    return {"metrics": metrics, "theory": theory_vals, "theory_notes": theory_notes, "tolerance": tolerance,
            "diagnostics": diagnostics, "notes": notes + result.extras.get("notes", []),
            "warnings": warnings + result.extras.get("warnings", [])}


@with_parameters(InertialOscillationParameters, position=1)
def record(rec, p, result):
    traj = result.trajectory
    rec.points("world/puck", traj.times, traj.r[:, 0] / 1000.0, radius=0.5, color=[230, 90, 40])
    f = 2 * result.extras["Omega"] * math.sin(math.radians(p.latitude))
    omega = np.array([0.0, 0.0, f / 2])  # the f-plane: only the vertical part of Omega acts
    rec.frame_axes("world/frame", max(float(np.max(np.abs(traj.r[:, 0]))) / 1000.0, 1.0) / 2, omega=omega)
    rec.scalars("diagnostics/speed_rel_error", traj.times,
                norm3(traj.v[:, 0]) / p.speed - 1 if p.speed else 0 * traj.times)
    v = traj.v[:, 0]
    if p.speed:
        direction = np.degrees(np.unwrap(np.arctan2(v[:, 1], v[:, 0])))
        rec.scalars("diagnostics/velocity_direction_deg", traj.times, direction, label="direction of v (from east)")
        rec.reference("diagnostics/velocity_direction_deg", traj.times, direction[0] - np.degrees(f * traj.times),
                      label="turns at -2 Omega sin(lat) (clockwise in the north)")
    # the eye above the middle of the circle (km), tilted a little to the south: the whole loop in view
    rec.line("world/path", traj.r[:, 0] / 1000.0, color=[110, 110, 110])  # the whole loop from the first frame
    xy = traj.r[:, 0, :2] / 1000.0
    centre = np.append((xy.min(axis=0) + xy.max(axis=0)) / 2, 0.0)
    size = max(float(np.max(xy.max(axis=0) - xy.min(axis=0))), 1e-3)
    rec.view(eye=centre + np.array([0.0, -0.5 * size, 1.4 * size]), look_at=centre)
