"""Projectile: a shell fired at an azimuth and elevation from the rotating Earth.

Local ENU frame at the gun (x east, y north, z up). The base model is flat
ground, uniform effective gravity and Coriolis. For long range the scene may
switch on ``central-gravity`` (g = -GM (r - c)/|r - c|^3 towards the centre c =
(0, 0, -R), which also turns the vertical along the path), ``curvature`` (the
ground is the sphere |r - c| = R, so the shell flies further before it lands),
``centrifugal`` (its variation along the path) and ``quadratic-drag`` (with an
isothermal atmosphere, density exp(-z / H)). Range is measured along the
ground (the great circle when ``curvature`` is on); the lateral deflection is
positive to the right of the aim. Theory: flat Earth, vacuum, zeroth order in
Omega for range and flight time, first order for the lateral deflection
(`rotframe.analytic.projectile_lateral_deflection_first_order`), each with
its stated accuracy (`theory_and_accuracy`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotframe import analytic
# astropy's values, read when the scene is imported (before the run's clock starts): every run needs them
from rotframe.earth import R_EARTH
from rotframe.particles.integrators import Event, check_exact, default_method
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.scenes.base import (SceneResult, earth_model_constants, engine_remarks, jacobi_energy, landing,
                                  method_rel_error, particle_methods, reject_subnormal, rel_drift, resolve_terms,
                                  run_on_engine, run_setting, samples_for, UNDERFLOW, with_parameters)


@dataclass(frozen=True, kw_only=True)
class ProjectileParameters:
    """Parameters of the projectile scene, in the units of its scenario file."""

    latitude: float  # deg
    azimuth: float  # deg from north, clockwise
    elevation: float  # deg
    speed: float  # m/s
    drag: float  # 1/m, quadratic drag coefficient (0 = vacuum)
    scale_height: float  # m, of the isothermal atmosphere
    magnify: float = 20.0  # display factor of the lateral deflection


#: The scene's parameters (the scene protocol's optional ``PARAMETERS``).
PARAMETERS = ProjectileParameters


#: Every particle integrator (the registry's names; its old names accepted too).
METHODS = particle_methods()
#: What runs when neither ``--method`` nor the scenario file names a method (``rotframe show`` prints it).
DEFAULT_METHOD = "exact where the model is linear (the default terms, with or without centrifugal), else dop853"


def aim_axes(azimuth_deg):
    """Horizontal unit vectors (ENU) along the aim and to its right, for an azimuth in degrees from north."""
    az = math.radians(azimuth_deg)
    return np.array([math.sin(az), math.cos(az), 0.0]), np.array([math.cos(az), -math.sin(az), 0.0])


@with_parameters(ProjectileParameters)
def build(p, terms):
    Omega, w, g = earth_model_constants(p.latitude)
    terms = resolve_terms(terms, p.drag)
    R = R_EARTH
    # GM chosen so that central gravity equals the effective g at the gun (same g at the start)
    model = ParticleModel(terms, omega=OmegaSchedule.constant(w), g=np.array([0.0, 0.0, -g]),
                          k_quadratic=p.drag, scale_height=p.scale_height, radius=R,
                          gm=g * R * R, g0=g)
    el = math.radians(p.elevation)
    aim, _ = aim_axes(p.azimuth)
    v0 = p.speed * (math.cos(el) * aim + math.sin(el) * np.array([0.0, 0.0, 1.0]))
    ground = Event("ground", "altitude" if "curvature" in terms else "r", 2, 0.0, -1, True)
    flight = 2 * p.speed * max(math.sin(el), 1e-3) / g
    # room to land, from the shot's own time scale (an absolute margin would swamp a short flight)
    return model, np.zeros(3), v0, ground, 3.0 * flight + min(10.0, 3.0 * flight), g


def ground_event(ground):
    """The engine's ground of the scene's event row ``ground`` (`build`): the flat ground's crossing of z = 0, or the
    curved Earth's altitude 0 (the ``curvature`` term), falling, terminal (`rotframe.events`)."""
    from rotframe import events

    if ground.kind == "altitude":
        return events.altitude(R_EARTH, ground.value, direction=-1, terminal=True, name="ground")
    return events.crossing(ground.component, ground.value, direction=-1, terminal=True, name="ground")


@with_parameters(ProjectileParameters)
def simulate(p, terms, method, run, progress):
    reject_subnormal(p)
    model, r0, v0, ground, duration, g = build(p, terms)
    # the exact flow where it exists (round-off accurate, nothing to compile); DOP853 at the scenario's rtol once
    # central gravity, curvature or drag make the model nonlinear
    method = particle_methods().canonical(method or run.get("method") or default_method(model, [ground],
                                                                                         otherwise="dop853"))
    if method == "exact":
        check_exact(model)  # the scenes' one-line reason (the curved ground is no term of the engine's)

    # the apex is read from the samples: at least 32 of them per (vacuum) flight, or it is null
    flight = 2 * p.speed * math.sin(math.radians(p.elevation)) / g
    samples, resolved = samples_for(duration, flight, run_setting(run, "samples"))

    def finish(res):  # a ProblemRun, or the trajectory up to an early stop
        traj = getattr(res, "trajectory", res)
        return SceneResult(traj, list(model.terms), traj.method, traj.steps, traj.nfev,
                           extras={"model": model, "g": g, "apex_resolved": resolved, "flight": flight,
                                   **engine_remarks(res)})  # the engine's notes and warnings, passed on

    return run_on_engine(model, r0, v0, duration, method, dict(run, samples=samples), progress, finish,
                         events=[ground_event(ground)])


def apex_height(times, r):
    """Highest altitude (m) of the sampled flight: the vertex of the parabola through the highest sample and its neighbours.

    Between samples the altitude is a parabola to O(dt^3) (gravity dominates the vertical
    acceleration), so the vertex of the three-point fit is good to that order, where the
    highest sample alone misses the apex by up to g dt^2 / 8.
    """
    z = r[:, 2]
    i = int(np.argmax(z))
    if i == 0 or i == len(z) - 1:
        return float(z[i])
    t0, t1, t2 = times[i - 1:i + 2]
    z0, z1, z2 = z[i - 1:i + 2]
    # Newton form of the parabola through the three points; its vertex
    d1 = (z1 - z0) / (t1 - t0)
    d2 = ((z2 - z1) / (t2 - t1) - d1) / (t2 - t0)
    if not d2 < 0:
        return float(z1)
    tv = 0.5 * (t0 + t1) - d1 / (2 * d2)
    return float(max(z1, z0 + d1 * (tv - t0) + d2 * (tv - t0) * (tv - t1)))


@with_parameters(ProjectileParameters)
def ground_track(p, r, model):
    """(range along the ground, lateral deflection right of the aim) of positions r (n, 3)."""
    aim, right = aim_axes(p.azimuth)
    if model.has("curvature"):
        R = model.radius
        c = np.array([0.0, 0.0, -R])
        u = (r - c) / np.linalg.norm(r - c, axis=1)[:, None]
        # angles along and across the aim, measured on the sphere
        along = np.arctan2(u @ aim, u[:, 2])
        across = np.arcsin(np.clip(u @ right, -1, 1))
        return R * along, R * across
    return r @ aim, r @ right


@with_parameters(ProjectileParameters)
def theory_and_accuracy(p, g, Omega, model):
    """Flat-vacuum closed forms, their labels and the absolute accuracy each one claims.

    The expansion parameter is eps = 2 Omega v / g (Omega times the longest time
    scale of the shot, v / g, which exceeds the flight time for a low shot):
    range and flight time are zeroth order in Omega (error 2 eps times the size
    of the trajectory, max(range, apex), or the flight time), the lateral
    deflection first order (error 2 eps^2 times that size). The factor 2 covers
    the largest ratio found over azimuths, latitudes, elevations and speeds
    (tests/test_theory_warnings.py). With any term beyond flat ground, uniform
    gravity and Coriolis (curvature, central gravity, centrifugal, drag) the
    closed forms describe another model: they are shown as indicative only and
    no accuracy is claimed (a difference there is the physics of the extra
    terms, which ``--audit`` measures, not an error of the run).
    """
    el, az, lat = (math.radians(x) for x in (p.elevation, p.azimuth, p.latitude))
    v = p.speed
    flat = analytic.projectile_flat_vacuum(v, el, g)
    theory = {"range_m": float(flat.range), "flight_time_s": float(flat.flight_time),
              "lateral_deflection_m": float(analytic.projectile_lateral_deflection_first_order(v, el, az, lat, g, Omega))}
    eps = 2 * Omega * v / g
    size = max(abs(theory["range_m"]), (v * math.sin(el)) ** 2 / (2 * g))
    accuracy = {"range_m": 2 * eps * size, "flight_time_s": 2 * eps * theory["flight_time_s"],
                "lateral_deflection_m": 2 * eps**2 * size}
    labels = {"range_m": "zeroth order in Omega, flat ground, uniform gravity, vacuum",
              "flight_time_s": "zeroth order in Omega, flat ground, uniform gravity, vacuum",
              "lateral_deflection_m": "first order in Omega, flat ground, uniform gravity, vacuum"}
    extra = [t for t in model.terms if t not in ("gravity", "coriolis")]
    if extra:
        return theory, {k: None for k in theory}, {
            k: f"{lab}: indicative only, the model also has {', '.join(extra)}" for k, lab in labels.items()}
    return theory, accuracy, {k: f"{lab} (+-{accuracy[k]:.2g} {'s' if k == 'flight_time_s' else 'm'})"
                              for k, lab in labels.items()}


@with_parameters(ProjectileParameters)
def analyse(p, result):
    traj = result.trajectory
    model = result.extras["model"]
    g = result.extras["g"]
    times, r, v, landed = landing(traj)
    rng, lateral = ground_track(p, r, model)
    Omega = float(np.linalg.norm(model.omega.vector()))
    theory, accuracy, theory_notes = theory_and_accuracy(p, g, Omega, model)
    metrics = {"range_m": float(rng[-1]), "lateral_deflection_m": float(lateral[-1]),
               "flight_time_s": float(times[-1]) if landed else math.nan}
    diagnostics = {"apex_m": apex_height(times, r)}
    notes = []
    if not result.extras.get("apex_resolved", True):
        diagnostics["apex_m"] = math.nan
        notes.append(f"apex_m not measured: the flight ({result.extras['flight']:.4g} s) is too short for the "
                     "samples the run may keep (32 per flight needed)")
    e = jacobi_energy(model, r, v)
    if e is not None:
        diagnostics["energy_rel_drift"] = rel_drift(e)
    extra = [t for t in model.terms if t not in ("gravity", "coriolis")]
    if extra:
        notes.append(f"theory is flat-Earth vacuum; the scene also has {', '.join(extra)}")
    if not landed:
        notes.append("the shell had not landed at the end of the simulated time")
        metrics.update(range_m=math.nan, lateral_deflection_m=math.nan)
        notes.append("range and lateral deflection are of a landing, so they are null")
    # a shot whose apex is below float64's normal range computes its heights with a few digits or none:
    # the landing it locates, and all that is measured at it, are null (found: speed 1e-160 m/s gave the
    # flight time 0.5 % off, 1e-170 m/s a factor 667)
    vz = p.speed * math.sin(math.radians(p.elevation))
    log_apex = 2 * math.log10(vz) - math.log10(2 * g) if vz > 0 else math.inf  # no apex: nothing to check
    if log_apex < math.log10(UNDERFLOW):
        for key in ("range_m", "lateral_deflection_m", "flight_time_s"):
            metrics[key] = math.nan
        for key in ("range_m", "lateral_deflection_m"):  # of the same size as the apex: subnormal too
            theory[key] = math.nan
        notes.append(f"the shot's apex (about 1e{log_apex:.0f} m) is below float64's normal range: heights "
                     "that small keep too few digits to locate the landing; range, lateral deflection and flight "
                     "time are not computed")
    method_rel = method_rel_error(traj, theory["flight_time_s"])
    size = max(abs(theory["range_m"]), float(np.max(np.abs(r))))
    tolerance = {k: acc + method_rel * (theory[k] if k == "flight_time_s" else size)
                 for k, acc in accuracy.items() if acc is not None}
    return {"metrics": metrics, "theory": theory, "theory_notes": theory_notes, "tolerance": tolerance,
            "diagnostics": diagnostics, "notes": notes + result.extras.get("notes", []),
            "warnings": result.extras.get("warnings", [])}


@with_parameters(ProjectileParameters, position=1)
def record(rec, p, result):
    traj = result.trajectory
    times, r, v, _ = landing(traj)
    rec.points("world/shell", times, r / 1000.0, radius=0.5, color=[230, 90, 40])
    rec.frame_axes("world/frame", 20.0, omega=result.extras["model"].omega.vector())  # km
    rng, lateral = ground_track(p, r, result.extras["model"])
    rec.scalars("diagnostics/altitude_km", times, r[:, 2] / 1000.0)
    rec.scalars("diagnostics/lateral_deflection_m", times, lateral)
    magnify = float(p.magnify)
    aim, right = aim_axes(p.azimuth)
    shown = (np.outer(rng, aim) + magnify * np.outer(lateral, right)) / 1000.0
    shown[:, 2] = r[:, 2] / 1000.0
    rec.points("world/deflection_magnified", times, shown, radius=0.4, color=[40, 160, 230])
    # the whole path and its magnified deflection, static and faint: the first frame shows the flight
    rec.line("world/path", r / 1000.0, color=[120, 120, 120])
    rec.line("world/deflection_magnified_path", shown, color=[40, 110, 170])
    rec.static("world/deflection_magnified_path", "LineStrips3D",
               labels=[f"deflection x{magnify:g}: {lateral[-1]:.0f} m right of the aim at the landing"])
    # the eye beside and above the middle of the path, left of the aim: the whole path in view
    # (not the muzzle among the axis arrows), the deflection to the right seen across it
    span = max(float(rng[-1]), float(np.max(r[:, 2])), 1.0) / 1000.0
    middle = aim * span / 2 + np.array([0.0, 0.0, float(np.max(r[:, 2])) / 2000.0])
    rec.view(eye=middle - 0.9 * span * right + np.array([0.0, 0.0, 0.45 * span]), look_at=middle)
