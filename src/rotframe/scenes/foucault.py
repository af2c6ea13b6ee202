"""Foucault's pendulum: the swing plane turns at Omega sin(latitude), clockwise in the north.

Local ENU frame with the origin below the pivot at the bob's rest position,
pivot at (0, 0, L). The full model is the spherical pendulum on the rotating
Earth: effective gravity, Coriolis, the string kept exactly (the splitting on
the sphere in `rotframe.particles.kernels.step_sphere`). The bob is released from
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
from dataclasses import dataclass

import numpy as np

from rotframe import analytic
from rotframe.numerics.linefit import line_fit
from rotframe.particles.integrators import default_method
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.scenes.base import (SceneResult, earth_model_constants, engine_remarks, jacobi_energy,
                                  method_rel_error, particle_methods, potential_energy, reject_subnormal,
                                  run_on_engine, run_setting, unresolved_note, with_parameters)


@dataclass(frozen=True, kw_only=True)
class FoucaultParameters:
    """Parameters of the foucault pendulum scene, in the units of its scenario file."""

    length: float  # m
    latitude: float  # deg
    amplitude: float  # m
    duration: float  # s
    small_angle: bool  # the linearised model
    g_model: str = "wgs84"  # "wgs84" or "standard"
    record_samples: int = 20000  # samples kept in the recording


#: The scene's parameters (the scene protocol's optional ``PARAMETERS``).
PARAMETERS = FoucaultParameters


#: Every particle integrator (the registry's names; its old names accepted too).
METHODS = particle_methods()
#: What runs when ``--method`` names none (``rotframe show`` prints it).
DEFAULT_METHOD = "dop853 for the full pendulum; exact for the linearised one (small_angle)"
SAMPLES_PER_PERIOD = 32
#: Samples kept at most (memory: 48 bytes each); beyond, the period is not measured.
MAX_SAMPLES = 2_000_000


@with_parameters(FoucaultParameters)
def build(p, terms):
    Omega, w, g = earth_model_constants(p.latitude, p.g_model)
    L, a = p.length, p.amplitude
    if a >= L:
        from rotframe.errors import ScenarioError

        raise ScenarioError(f"amplitude = {a:g} m: must be smaller than length = {L:g} m")
    if p.small_angle:
        w_vertical = np.array([0.0, 0.0, w[2]])
        model = ParticleModel(("spring", "coriolis"), omega=OmegaSchedule.constant(w_vertical), spring=g / L)
        r0 = np.array([a, 0.0, 0.0])
    else:
        model = ParticleModel(tuple(t for t in terms if t != "spring") + (() if "pendulum" in terms else ("pendulum",)),
                              omega=OmegaSchedule.constant(w), g=np.array([0.0, 0.0, -g]),
                              pendulum_length=L, pivot=np.array([0.0, 0.0, L]))
        r0 = np.array([a, 0.0, L - math.sqrt(L * L - a * a)])
    return model, r0, np.zeros(3), g, Omega


@with_parameters(FoucaultParameters)
def simulate(p, terms, method, run, progress):
    reject_subnormal(p)
    model, r0, v0, g, Omega = build(p, terms)
    T = p.duration
    period = 2 * math.pi * math.sqrt(p.length / g)
    need = SAMPLES_PER_PERIOD * T / period  # a float: a huge duration makes it inf, not an int's overflow
    resolved = need <= MAX_SAMPLES
    samples = max(int(run.get("samples") or 0), int(min(need, MAX_SAMPLES)))
    run = dict(run, samples=samples)
    # unless a method is named: the linearised (small-angle) model by its exact propagator, the full
    # pendulum by dop853, the cheapest for its stated accuracy in `rotframe bench foucault`
    method = method or ("dop853" if model.has("pendulum") else default_method(model))

    def finish(res):  # a ProblemRun, or the trajectory up to an early stop
        traj = getattr(res, "trajectory", res)
        return SceneResult(traj, list(model.terms), traj.method, traj.steps, traj.nfev,
                           extras={"model": model, "g": g, "Omega": Omega, "resolved": resolved,
                                   **engine_remarks(res)})

    return run_on_engine(model, r0, v0, T, method, run, progress, finish,
                         atol=run_setting(run, "rtol") * swing_scale(r0, v0))


def swing_scale(r0, v0):
    """The scale of DOP853's absolute tolerance for the swing from ``r0``, ``v0``: max(1 m, |r0|, |v0|), for r and
    v alike (DOP853's ``atol`` is ``rtol`` times it). Not the engine's default, which scales v by |r0| / duration:
    over an hour, a thousandth of the swing's speed, and some 1.5 times the steps for nothing the metrics resolve.
    The scenes' ensembles' scale (`rotframe.numerics.step_control.ensemble_scale`)."""
    from rotframe.numerics.step_control import ensemble_scale

    return ensemble_scale(r0, v0)


def swing_angle(r, v, w0):
    """Angle (rad, from east towards north) of the swing direction, unwrapped, per sample.

    Major axis of A = v v^T + w0^2 x x^T in the horizontal plane; defined
    modulo pi, unwrapped by doubling.
    """
    # in units of the swing's size (the angle does not depend on them): squares of a tiny swing do not underflow
    scale = max(float(np.max(np.abs(r[:, :2]))), float(np.max(np.abs(v[:, :2]))) / w0) or 1.0
    x, y, vx, vy = r[:, 0] / scale, r[:, 1] / scale, v[:, 0] / scale, v[:, 1] / scale
    axx = vx * vx + w0 * w0 * x * x
    ayy = vy * vy + w0 * w0 * y * y
    axy = vx * vy + w0 * w0 * x * y
    return 0.5 * np.unwrap(np.arctan2(2 * axy, axx - ayy))


def measured_rates(times, r, v, length, g, with_error=False):
    """(precession rate in rad/s, clockwise positive; period in s) from the motion.

    With ``with_error`` a third value is the standard error (rad/s) of the fitted
    rate, from the scatter of the swing angle about the fitted line.
    """
    w0 = math.sqrt(g / length)
    angle = swing_angle(r, v, w0)
    slope, _, slope_error = line_fit(times, angle)
    # period from the maxima of the horizontal distance: x.v changes sign from + to -
    scale = max(float(np.max(np.abs(r[:, :2]))), float(np.max(np.abs(v[:, :2]))) / w0) or 1.0
    rho = (r[:, 0] / scale) * (v[:, 0] / scale) + (r[:, 1] / scale) * (v[:, 1] / scale)
    k = np.nonzero((rho[:-1] > 0) & (rho[1:] <= 0))[0]
    if len(k) >= 3:
        tc = times[k] + (times[k + 1] - times[k]) * rho[k] / (rho[k] - rho[k + 1])
        half_period = line_fit(np.arange(len(tc), dtype=np.float64), tc)[0]
        period = 2 * half_period
    else:
        period = math.nan
    return (-slope, period, slope_error) if with_error else (-slope, period)


@with_parameters(FoucaultParameters)
def analyse(p, result):
    traj = result.trajectory
    g = result.extras["g"]
    model = result.extras["model"]
    r, v = traj.r[:, 0], traj.v[:, 0]
    L, a = p.length, p.amplitude
    rate, period, rate_error = measured_rates(traj.times, r, v, L, g, with_error=True)
    Omega = result.extras["Omega"]
    lat = math.radians(p.latitude)
    foucault_rate = analytic.foucault_precession_rate(lat, Omega)
    w0 = math.sqrt(g / L)
    T_swing = 2 * math.pi / w0
    duration = float(traj.times[-1])
    notes, warnings = [], []
    per_hour = math.degrees(1.0) * 3600
    if p.small_angle:
        theory_rate, airy = foucault_rate, 0.0
        rate_label = "exact for the linearised model: Omega sin(latitude)"
        period_theory = float(analytic.pendulum_period(L, g, 0.0))
        period_label = "small amplitude 2 pi sqrt(L / g) (+-(Omega / w0)^2 relative)"
    else:
        # released from rest in the rotating frame the swing is an ellipse of minor axis
        # b = a Omega sin(lat) / w0, whose Airy precession runs against the Foucault turn
        b = a * foucault_rate / w0
        airy = analytic.airy_precession(L, g, a, b)
        theory_rate = foucault_rate - airy
        rate_label = (f"Omega sin(latitude) minus Airy's finite-amplitude precession (3/8) w0 a b / L^2, leading "
                      f"order in a / L (+-{2 * (a / L) ** 2:.2g} of the Airy part)")
        period_theory = float(analytic.pendulum_period(L, g, a))
        period_label = "exact plane pendulum of amplitude a, 4 sqrt(L / g) K(sin^2(theta0 / 2)) (+-(Omega / w0)^2)"
    metrics = {"precession_rate_deg_per_hour": rate * per_hour, "period_s": period}
    theory = {"precession_rate_deg_per_hour": theory_rate * per_hour, "period_s": period_theory}
    theory_notes = {"precession_rate_deg_per_hour": rate_label, "period_s": period_label}
    diagnostics = {"simulated_hours": duration / 3600,
                   "omega_sin_latitude_deg_per_hour": foucault_rate * per_hour}
    if not p.small_angle:
        diagnostics["airy_precession_deg_per_hour"] = -airy * per_hour
    if not result.extras.get("resolved", True):
        metrics["period_s"] = math.nan
        notes.append(unresolved_note("period_s", "swing", T_swing, duration, per_period=SAMPLES_PER_PERIOD,
                                     bound=MAX_SAMPLES) + " (the precession rate needs no such resolution)")
    if not p.small_angle and a < 1e4 * np.finfo(float).eps * L:
        # the string is kept to round-off of its length, eps L: a swing not far above that is noise
        metrics = {"precession_rate_deg_per_hour": math.nan, "period_s": math.nan}
        notes.append(f"amplitude {a:.3g} m is within 1e4 round-offs of the string length ({L:g} m): the full "
                     "pendulum cannot resolve the swing; use small_angle = true")
    if duration < 2 * T_swing:
        metrics["precession_rate_deg_per_hour"] = math.nan
        notes.append(f"precession not measured: the run is shorter than two swings ({2 * T_swing:.4g} s)")
    if model.has("pendulum"):
        diagnostics["constraint_drift_m"] = float(np.max(np.abs(np.linalg.norm(r - model.pivot, axis=1) - L)))
    e = jacobi_energy(model, r, v)
    if e is not None:
        # relative to the swing's energy (the potential at the release point), not to an arbitrary zero
        diagnostics["energy_rel_drift"] = float(np.max(np.abs(e - e[0])) / max(abs(float(
            potential_energy(model, r[:1])[0])), 1e-300))
    # tolerances: the method's error, the fit's own scatter (5 standard errors) and the theory's accuracy
    method_rel = method_rel_error(traj, T_swing)
    tolerance = {
        "precession_rate_deg_per_hour": (5 * rate_error + method_rel * abs(foucault_rate)
                                         + 2 * (a / L) ** 2 * abs(airy) + (Omega / w0) ** 2 * abs(foucault_rate)
                                         + 1e-12 * Omega) * per_hour,
        "period_s": (method_rel + (Omega / w0) ** 2 + 2 * (a * foucault_rate / w0 / L) ** 2) * period_theory
                    + T_swing * (w0 * (traj.times[1] - traj.times[0])) ** 3 / max(duration / T_swing, 1.0),
    }
    rate = metrics["precession_rate_deg_per_hour"] / per_hour
    if math.isfinite(rate) and abs(rate) > 5 * rate_error and rate != 0:
        diagnostics["hours_per_turn"] = float(2 * math.pi / abs(rate) / 3600)
    elif math.isfinite(rate):
        notes.append("the swing plane does not turn measurably (no hours per turn)")
    notes.append(f"simulated {duration / 3600:.3g} h of motion ({len(traj.times) - 1} samples)")
    return {"metrics": metrics, "theory": theory, "theory_notes": theory_notes, "tolerance": tolerance,
            "diagnostics": diagnostics, "notes": notes + result.extras.get("notes", []),
            "warnings": warnings + result.extras.get("warnings", [])}


@with_parameters(FoucaultParameters, position=1)
def record(rec, p, result):
    """The bob with a trail that grows with time, the swing plane and its angle beside Omega sin(lat) t,
    the local frame with Earth's rotation vector, the string's length error."""
    from rotframe.numerics.sampling import decimate

    traj = result.trajectory
    idx = decimate(len(traj.times), int(p.record_samples))
    t, r = traj.times[idx], traj.r[idx, 0]
    L = p.length
    rec.points("world/bob", t, r, radius=0.15, color=[230, 90, 40])
    g = result.extras["g"]
    angle = swing_angle(traj.r[:, 0], traj.v[:, 0], math.sqrt(g / L))[idx]
    a = p.amplitude
    d = np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], axis=1) * a
    rec.segments("world/swing_plane", t, -d, d, color=[40, 160, 230])
    rec.line("world/string_at_rest", [[0, 0, 0], [0, 0, L]], color=[150, 150, 150])
    model = result.extras["model"]
    rec.frame_axes("world/frame", a, omega=model.omega.vector() if not p.small_angle else None)
    rec.scalars("diagnostics/swing_angle_deg", t, np.degrees(angle), label="swing plane (measured)")
    rate = analytic.foucault_precession_rate(math.radians(p.latitude), result.extras["Omega"])
    rec.reference("diagnostics/swing_angle_deg", t, np.degrees(angle[0] - rate * t),
                  label="-Omega sin(lat) t (clockwise in the north)")
    if model.has("pendulum"):
        rec.scalars("diagnostics/constraint_error_m", t, np.linalg.norm(r - [0, 0, L], axis=1) - L)
    # the swing plane at the start and at the end, static: the first frame already shows the turn
    turned = float(np.degrees(angle[-1] - angle[0]))
    for name, k, color, text in (("start", 0, [60, 200, 90], "t = 0"),
                                 ("end", -1, [230, 60, 60], f"t = {t[-1] / 3600:.3g} h: turned {abs(turned):.3g} deg "
                                  + ("clockwise" if turned < 0 else "anticlockwise"))):
        rec.static(f"world/swing_plane_{name}", "LineStrips3D", strips=[np.stack([-d[k], d[k]]).astype(np.float32)],
                   colors=[color], radii=[0.02])
        # the label at the line's end (a strip's label sits at its middle, where the two would overlap)
        rec.static(f"world/swing_plane_{name}/label", "Points3D", positions=[(1.08 * d[k]).astype(np.float32)],
                   colors=[color], labels=[text], radii=[0.04])
    # the eye above the bob, tilted a little to the south: the swing and its turning plane fill the
    # view (the string, L up, is out of it); the hour plays in half a minute
    rec.view(eye=(0.0, -0.9 * a, 2.6 * a), look_at=(0.0, 0.0, 0.0),
             contents=["+ /world/**", "- /world/string_at_rest"])
