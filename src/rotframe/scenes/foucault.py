"""Foucault's pendulum: the swing plane turns at Omega sin(latitude), clockwise in the north.

Local ENU frame with the origin below the pivot at the bob's rest position,
pivot at (0, 0, L). The full model is the spherical pendulum on the rotating
Earth: effective gravity, Coriolis, the string kept exactly (the splitting on
the sphere in :func:`rotframe.kernels.step_sphere`). The bob is released from
rest in the rotating frame at ``amplitude`` east of the rest position, which
gives a swing of tiny ellipticity and so negligible Airy precession
(docs/physics/earth.md). ``small_angle = true`` uses instead the linearised
model x'' = -w0^2 x - 2 Omega_z z_hat x x' (w0^2 = g / L; the horizontal
components of omega act only on the vertical, which the string takes), solved
exactly by the matrix exponential.

The precession rate is measured from the motion: the major axis of the tensor
A = v v^T + w0^2 x x^T (horizontal components) is the swing direction; its
angle, unwrapped and fitted against time, gives the rate.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe import analytic, earth  # noqa: F401  (astropy loads with the scene, before timing)
from rotframe.integrators import default_method
from rotframe.model import OmegaSchedule, ParticleModel
from rotframe.scenes.base import SceneResult, earth_model_constants, energy_in_rotating_frame, run_particles

METHODS = ("splitting", "splitting4", "rk4", "dop853", "exact")
SAMPLES_PER_PERIOD = 32


def build(values, terms):
    Omega, w, g = earth_model_constants(values["latitude"], values.get("g_model", "wgs84"))
    L, a = values["length"], values["amplitude"]
    if a >= L:
        from rotframe.errors import ScenarioError

        raise ScenarioError(f"amplitude = {a:g} m: must be smaller than length = {L:g} m")
    if values["small_angle"]:
        w_vertical = np.array([0.0, 0.0, w[2]])
        model = ParticleModel(("spring", "coriolis"), omega=OmegaSchedule.constant(w_vertical), spring=g / L)
        r0 = np.array([a, 0.0, 0.0])
    else:
        model = ParticleModel(tuple(t for t in terms if t != "spring") + (() if "pendulum" in terms else ("pendulum",)),
                              omega=OmegaSchedule.constant(w), g=np.array([0.0, 0.0, -g]),
                              pendulum_length=L, pivot=np.array([0.0, 0.0, L]))
        r0 = np.array([a, 0.0, L - math.sqrt(L * L - a * a)])
    return model, r0, np.zeros(3), g, Omega


def simulate(values, terms, method, run, progress):
    model, r0, v0, g, Omega = build(values, terms)
    T = values["duration"]
    period = 2 * math.pi * math.sqrt(values["length"] / g)
    samples = max(int(run.get("samples") or 0), int(SAMPLES_PER_PERIOD * T / period))
    run = dict(run, samples=samples)
    method = method or default_method(model)

    def finish(traj):
        return SceneResult(traj, list(model.terms), traj.method, traj.steps, traj.nfev,
                           extras={"model": model, "g": g, "Omega": Omega})

    return run_particles(model, r0, v0, T, method, run, progress, finish)


def swing_angle(r, v, w0):
    """Angle (rad, from east towards north) of the swing direction, unwrapped, per sample.

    Major axis of A = v v^T + w0^2 x x^T in the horizontal plane; defined
    modulo pi, unwrapped by doubling.
    """
    x, y, vx, vy = r[:, 0], r[:, 1], v[:, 0], v[:, 1]
    axx = vx * vx + w0 * w0 * x * x
    ayy = vy * vy + w0 * w0 * y * y
    axy = vx * vy + w0 * w0 * x * y
    return 0.5 * np.unwrap(np.arctan2(2 * axy, axx - ayy))


def measured_rates(times, r, v, length, g):
    """(precession rate in rad/s, clockwise positive; period in s) from the motion."""
    w0 = math.sqrt(g / length)
    angle = swing_angle(r, v, w0)
    slope = np.polyfit(times, angle, 1)[0]
    # period from the maxima of the horizontal distance: x.v changes sign from + to -
    rho = r[:, 0] * v[:, 0] + r[:, 1] * v[:, 1]
    k = np.nonzero((rho[:-1] > 0) & (rho[1:] <= 0))[0]
    if len(k) >= 3:
        tc = times[k] + (times[k + 1] - times[k]) * rho[k] / (rho[k] - rho[k + 1])
        half_period = np.polyfit(np.arange(len(tc)), tc, 1)[0]
        period = 2 * half_period
    else:
        period = math.nan
    return -slope, period


def analyse(values, result):
    traj = result.trajectory
    g = result.extras["g"]
    model = result.extras["model"]
    r, v = traj.r[:, 0], traj.v[:, 0]
    rate, period = measured_rates(traj.times, r, v, values["length"], g)
    Omega = result.extras["Omega"]
    lat = math.radians(values["latitude"])
    theory_rate = analytic.foucault_precession_rate(lat, Omega)
    amplitude = 0.0 if values["small_angle"] else values["amplitude"]
    metrics = {"precession_rate_deg_per_hour": math.degrees(rate) * 3600, "period_s": period}
    theory = {"precession_rate_deg_per_hour": math.degrees(theory_rate) * 3600,
              "period_s": float(analytic.pendulum_period(values["length"], g, amplitude))}
    diagnostics = {"simulated_hours": float(traj.times[-1] / 3600)}
    if not values["small_angle"]:
        # released from rest in the rotating frame the swing is an ellipse of minor axis
        # b = a Omega sin(lat) / w0, whose Airy precession runs against the Foucault turn
        w0 = math.sqrt(g / values["length"])
        b = values["amplitude"] * theory_rate / w0
        airy = analytic.airy_precession(values["length"], g, values["amplitude"], b)
        diagnostics["airy_corrected_rate_deg_per_hour"] = math.degrees(theory_rate - airy) * 3600
    if model.has("pendulum"):
        diagnostics["constraint_drift_m"] = float(np.max(np.abs(np.linalg.norm(r - model.pivot, axis=1)
                                                                - values["length"])))
        e = energy_in_rotating_frame(r - [0, 0, 0], v, g, model.omega.vector(), model.has("centrifugal"))
        diagnostics["energy_rel_drift"] = float(np.max(np.abs(e - e[0])) / (g * (r[0, 2] + 1e-300)))
    if rate != 0:
        diagnostics["hours_per_turn"] = float(2 * math.pi / abs(rate) / 3600)
    notes = [f"simulated {traj.times[-1] / 3600:.3g} h of motion ({len(traj.times) - 1} samples)"]
    return {"metrics": metrics, "theory": theory, "diagnostics": diagnostics, "notes": notes}


def record(rec, values, result):
    from rotframe.record import decimate

    traj = result.trajectory
    idx = decimate(len(traj.times), int(values.get("record_samples", 20000)))
    t, r = traj.times[idx], traj.r[idx, 0]
    L = values["length"]
    rec.points("world/bob", t, r, radius=0.15, color=[230, 90, 40], trail=False)
    rec.line("world/path", r, color=[230, 90, 40, 80])
    g = result.extras["g"]
    angle = swing_angle(traj.r[:, 0], traj.v[:, 0], math.sqrt(g / L))[idx]
    a = values["amplitude"]
    d = np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], axis=1) * a
    rec.segments("world/swing_plane", t, -d, d, color=[40, 160, 230])
    rec.line("world/string_at_rest", [[0, 0, 0], [0, 0, L]], color=[150, 150, 150])
    rec.scalars("diagnostics/swing_angle_deg", t, np.degrees(angle))
    if result.extras["model"].has("pendulum"):
        rec.scalars("diagnostics/constraint_error_m", t, np.linalg.norm(r - [0, 0, L], axis=1) - L)
