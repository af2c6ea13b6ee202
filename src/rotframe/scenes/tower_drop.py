"""Tower drop: a body dropped from rest on the rotating Earth lands east of the foot.

Local ENU frame at the foot of the tower (x east, y north, z up), omega =
Omega (0, cos lat, sin lat). Gravity is the effective gravity (centrifugal at
the foot included), so the ``centrifugal`` term, when switched on, adds only its
variation along the path. To first order in Omega the body lands
(1/3) Omega g t^3 cos(lat) east of the foot, t = sqrt(2 h / g); the
equatorward (southward in the north) part is second order,
(1/6) Omega^2 g t^4 sin(lat) cos(lat). Default: Reich, Freiberg 1831.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from rotframe import analytic
# astropy's values, read when the scene is imported (before the run's clock starts): every run needs them
from rotframe.earth import GM_EARTH, R_EARTH
from rotframe.events import crossing
from rotframe.particles.integrators import Event, default_method
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.scenes.base import (SceneResult, engine_remarks, earth_model_constants, jacobi_energy, landing,
                                  method_rel_error, particle_methods, reject_subnormal, rel_drift, resolve_terms,
                                  run_on_engine, scene_parameters, UNDERFLOW, until_event, with_parameters)


@dataclass(frozen=True, kw_only=True)
class TowerDropParameters:
    """Parameters of the tower drop scene, in the units of its scenario file."""

    height: float  # m
    latitude: float  # deg
    drag: float  # 1/m, quadratic drag coefficient (0 = vacuum)
    g_model: str = "wgs84"  # "wgs84" or "standard"
    magnify: float = 1000.0  # display factor of the deflection


#: The scene's parameters (the scene protocol's optional ``PARAMETERS``).
PARAMETERS = TowerDropParameters


#: Every particle integrator (the registry's names; its old names accepted too).
METHODS = particle_methods()
#: What runs when neither ``--method`` nor the scenario file names a method (``rotframe show`` prints it).
DEFAULT_METHOD = "exact where the model is linear (the default terms, with or without centrifugal), else rotation-splitting"
GROUND = Event("ground", "r", 2, 0.0, -1, True)


@with_parameters(TowerDropParameters)
def build(p, terms):
    """(model, r0, v0, duration) for the parameters; drag > 0 adds quadratic drag."""
    Omega, w, g = earth_model_constants(p.latitude, p.g_model)
    model = ParticleModel(resolve_terms(terms, p.drag), omega=OmegaSchedule.constant(w), g=np.array([0.0, 0.0, -g]),
                          k_quadratic=p.drag, g0=g, radius=R_EARTH, gm=GM_EARTH)
    h = p.height
    return model, np.array([0.0, 0.0, h]), np.zeros(3), fall_duration(h, p.drag, g), g


def fall_duration(h, drag, g):
    """Simulated time (s) for a drop from ``h`` to land: room from the problem's own time scale.

    (An absolute margin would swamp a short fall.) Broadcasts over ``h``.
    """
    with np.errstate(all="ignore"):  # a height near the float limit gives inf here, refused as a duration later
        t_vac = np.sqrt(2 * np.asarray(h, dtype=float) / g)
        t_drag = np.asarray(h, dtype=float) * math.sqrt(drag / g) if drag > 0 else 0.0
        t = t_vac + t_drag
        out = 1.5 * t + np.minimum(1.0, 1.5 * t)
    return float(out) if np.ndim(out) == 0 else out


#: the ground on the engine: the same crossing as `GROUND`, the scenes' row that the engine's steady loops take it as
GROUND_EVENT = crossing(2, 0.0, direction=-1, terminal=True, name="ground")


@with_parameters(TowerDropParameters)
def simulate(p, terms, method, run, progress):
    reject_subnormal(p)
    model, r0, v0, duration, g = build(p, terms)
    method = particle_methods().canonical(method) if method else default_method(model)

    def finish(res):  # a ProblemRun, or the trajectory up to an early stop
        traj = getattr(res, "trajectory", res)
        return SceneResult(traj, list(model.terms), traj.method, traj.steps, traj.nfev,
                           extras={"model": model, "g": g, **engine_remarks(res)})  # the engine's, passed on

    return run_on_engine(model, r0, v0, duration, method, run, progress, finish, events=[GROUND_EVENT])


@with_parameters(TowerDropParameters)
def theory_and_accuracy(p, model, g, Omega):
    """Closed forms for the drop and the relative accuracy each one claims, for this model.

    East: (1/3) Omega g t^3 cos(lat), first order in Omega (neglected: relative
    (Omega t)^2). North: second order in Omega, -(1/6) Omega^2 g t^4 sin cos from
    Coriolis, plus -(5/24) Omega^2 g t^4 sin cos when the model has the
    centrifugal variation (neglected: relative Omega t). Fall time sqrt(2 h / g)
    (neglected: relative (Omega t)^2). Altitude gravity weakens g by up to 2 h / R
    along the fall, which moves every value by a relative h / R at most. With
    drag the vacuum forms are indicative only (accuracy None).
    """
    h, lat = p.height, math.radians(p.latitude)
    t = math.sqrt(2 * h / g)
    north = analytic.drop_north_deflection_second_order(h, lat, g, Omega)
    label = "second order in Omega, uniform gravity, vacuum"
    if model.has("centrifugal"):
        north += analytic.drop_north_deflection_centrifugal_second_order(h, lat, g, Omega)
        label = "second order in Omega (Coriolis and the centrifugal variation), uniform gravity, vacuum"
    theory = {"east_deflection_m": float(analytic.drop_east_deflection_first_order(h, lat, g, Omega)),
              "north_deflection_m": float(north), "fall_time_s": t}
    wt = Omega * t
    extra = h / R_EARTH if (model.has("altitude-gravity") or model.has("central-gravity")) else 0.0
    accuracy = {"east_deflection_m": 2 * wt**2 + 2 * extra, "north_deflection_m": 2 * wt + 2 * extra,
                "fall_time_s": 2 * wt**2 + 2 * extra}
    labels = {"east_deflection_m": "first order in Omega, uniform gravity, vacuum",
              "north_deflection_m": label, "fall_time_s": "no rotation, uniform gravity, vacuum"}
    if p.drag > 0:
        return theory, {k: None for k in theory}, {k: v + ": indicative only (the model has drag)"
                                                   for k, v in labels.items()}
    notes = {k: f"{labels[k]} (+-{accuracy[k]:.2g} relative)" for k in theory}
    return theory, accuracy, notes


@with_parameters(TowerDropParameters)
def analyse(p, result):
    traj = result.trajectory
    g = result.extras["g"]
    model = result.extras["model"]
    times, r, v, landed = landing(traj)
    Omega = float(np.linalg.norm(model.omega.vector()))
    metrics = {"east_deflection_m": float(r[-1, 0]), "north_deflection_m": float(r[-1, 1]),
               "fall_time_s": float(times[-1]) if landed else math.nan}
    theory, accuracy, theory_notes = theory_and_accuracy(p, model, g, Omega)
    diagnostics = {}
    notes = []
    e = jacobi_energy(model, r, v)
    if e is not None:
        diagnostics["energy_rel_drift"] = rel_drift(e)
    else:
        notes.append("theory is the vacuum closed form, indicative only with drag: the body falls longer, and the "
                     "air both prolongs the Coriolis push and damps the eastward drift (no energy invariant either)")
    if model.has("altitude-gravity") or model.has("central-gravity"):
        notes.append("theory assumes uniform gravity; weaker gravity aloft changes every value by up to a "
                     f"relative h / R = {p.height / R_EARTH:.2g}")
    if not landed:
        notes.append("the body did not reach the ground in the simulated time")
    # a deflection below float64's normal range has no significant digits left: null, not a number
    log_east = math.log10(Omega / 3) + math.log10(g) + 1.5 * math.log10(2 * p.height / g)
    if log_east < math.log10(UNDERFLOW):
        for key in ("east_deflection_m", "north_deflection_m"):
            metrics[key] = theory[key] = math.nan
        notes.append(f"the deflections (about 1e{log_east:.0f} m) are below float64's normal range: not computed")
    # tolerance: the method's error on top of the closed form's stated accuracy, and round-off of positions
    method_rel = method_rel_error(traj, theory["fall_time_s"])
    # (the horizontal motion is fed by the vertical one through Omega: its round-off scales with the east deflection)
    floor = {"fall_time_s": 1e-14 * theory["fall_time_s"]}
    tolerance = {}
    for key, acc in accuracy.items():
        if acc is not None and math.isfinite(theory[key]):
            tolerance[key] = (acc + method_rel) * abs(theory[key]) + floor.get(
                key, 1e-13 * abs(theory["east_deflection_m"]))
    return {"metrics": metrics, "theory": theory, "theory_notes": theory_notes, "tolerance": tolerance,
            "diagnostics": diagnostics, "notes": notes + result.extras.get("notes", []),
            "warnings": result.extras.get("warnings", [])}


@with_parameters(TowerDropParameters, position=1)
def record(rec, p, result):
    traj = result.trajectory
    times, r, v, _ = landing(traj)
    h = p.height
    rec.points("world/body", times, r, radius=0.5, color=[230, 90, 40])
    magnify = float(p.magnify)
    shown = r.copy()
    shown[:, :2] *= magnify
    rec.points("world/deflection_magnified", times, shown, radius=0.5, color=[40, 160, 230])
    rec.line("world/tower", [[0, 0, 0], [0, 0, h]], color=[150, 150, 150])
    model = result.extras["model"]
    w = model.omega.vector()
    rec.frame_axes("world/frame", h / 5, omega=w)
    rec.scalars("diagnostics/east_deflection_mm", times, 1e3 * r[:, 0], label="east (simulated)")
    # first order in Omega: x(t) = (1/3) Omega g t^3 cos(lat), the vertical component of g only
    Omega, g = float(np.linalg.norm(w)), result.extras["g"]
    rec.reference("diagnostics/east_deflection_mm", times,
                  1e3 * Omega * g * times ** 3 * math.cos(math.radians(p.latitude)) / 3,
                  label="(1/3) Omega g t^3 cos(lat)")
    rec.scalars("diagnostics/north_deflection_mm", times, 1e3 * r[:, 1], label="north (simulated)")
    e = jacobi_energy(model, r, v)
    if e is not None:
        rec.scalars("diagnostics/energy_rel_error", times, (e - e[0]) / abs(e[0]))
    rec.exact_values("world/body/landing", state=np.concatenate([r[-1], v[-1]]), time=[times[-1]])
    # the eye to the south of the tower, level with its middle: the tower and the magnified fall east of it
    rec.line("world/deflection_magnified_path", shown, color=[40, 110, 170])  # the whole fall from the first frame
    rec.static("world/deflection_magnified_path", "LineStrips3D",
               labels=[f"east x{magnify:g}: {1e3 * r[-1, 0]:.1f} mm at the foot"])
    east = float(shown[-1, 0])
    rec.view(eye=(east / 2, -1.6 * h, 0.6 * h), look_at=(east / 2, 0.0, 0.45 * h))


def simulate_ensemble(values_list, terms, method, run, tracks=None):
    """Metrics of many drops: one vectorised integration per group of points sharing the model.

    Points that differ only in ``height`` (and ``magnify``, which is for display) share
    latitude, drag and gravity, hence the model; those whose fall needs the same
    simulated time (`ensemble_duration`, from each point alone, never from the
    others in the call) are one run of the engine (`_on_engine`: every point a particle,
    the ground the terminal event of the single run). The metrics are those of
    `analyse`; they agree with single runs to the method's accuracy (to round-off
    for ``exact``).

    Parameters
    ----------
    values_list : list of dict
        Resolved parameter values per point, as `simulate` takes them.
    terms, method, run
        As for `simulate`.
    tracks : dict, optional
        Keys are indices into ``values_list`` whose paths are wanted; on return each maps
        to ``(times, positions (n, 3))`` up to the landing.

    Returns
    -------
    list of dict
        ``analyse(...)["metrics"]`` per point, in order.
    """
    from rotframe.particles.threads import device_in_force

    metrics = [None] * len(values_list)
    on_gpu = device_in_force() == "gpu"
    for members in _duration_groups(values_list, terms):
        heights = np.array([values_list[i]["height"] for i in members], dtype=float)
        model, _, _, duration, _ = build(values_list[members[0]], terms)
        duration = ensemble_duration(duration)
        r0 = np.zeros((len(members), 3))
        r0[:, 2] = heights
        keep = [k for k, i in enumerate(members) if tracks is not None and i in tracks]
        name = METHODS.canonical(method or run.get("method") or default_method(model))
        t_event, state, paths = (_on_gpu if on_gpu else _on_engine)(model, r0, duration, name, run, keep)
        for k, i in enumerate(members):
            metrics[i] = {"east_deflection_m": float(state[k, 0]), "north_deflection_m": float(state[k, 1]),
                          "fall_time_s": float(t_event[k])}
        for k in keep:
            tracks[members[k]] = paths[k]
    return metrics


def _on_engine(model, r0, duration, method, run, keep):
    """``(t_event, state, paths)`` of drops from rest at ``r0`` (N, 3): each one's landing time (NaN where it did not
    land in ``duration``) and state there (else at the end), and the paths of the indices ``keep`` up to the landing.

    The engine runs them as the single run does (`simulate`: `run_on_engine` with the ground event), every drop a
    particle integrated alone, on the samples of a kept path (the run's ``samples``, 16 to
    `rotframe.particles.ensemble.MAX_TRACK_SAMPLES`) whatever the number of drops, in calls of at most
    `rotframe.particles.ensemble.PATH_BUDGET` particle-samples: a drop's numbers never depend on the others.
    """
    from rotframe.particles.ensemble import PATH_BUDGET

    n = len(r0)
    samples = _path_samples(run)
    per_call = max(1, PATH_BUDGET // (samples + 1))
    t_event, state, paths = np.full(n, math.nan), np.empty((n, 6)), {}
    for lo in range(0, n, per_call):
        hi = min(n, lo + per_call)
        traj = run_on_engine(model, r0[lo:hi], np.zeros((hi - lo, 3)), duration, method, dict(run, samples=samples),
                             None, lambda res: getattr(res, "trajectory", res), events=[GROUND_EVENT], energy=False)
        t_event[lo:hi], state[lo:hi] = traj.first_events("ground")
        for k in keep:
            if lo <= k < hi:
                times, r, _ = until_event(traj, "ground", k - lo)
                paths[k] = (times, r)
    return t_event, state, paths


def _on_gpu(model, r0, duration, method, run, keep):
    """`_on_engine` on the GPU: every drop a thread of one run of the engine that keeps each drop's end alone
    (``samples=1``, the ground its terminal event), which the engine gives to the scenes' GPU kernel, chosen from the
    terms (`rotframe.problem.steady`); the paths of the indices ``keep`` on the CPU (`_on_engine`). Its step is
    `_on_engine`'s, which divides the intervals of a kept path's samples, so each drop takes the CPU's steps (to
    round-off: the GPU counts them from the start). The drops are cut in calls that each fit the run limits in force
    (`rotframe.limits`), as `_on_engine`'s calls fit its paths' memory."""
    from rotframe import limits
    from rotframe.problem.arguments import run_grid

    n = len(r0)
    step = run_grid(duration, _path_samples(run), None, run.get("step"), fixed=True, what=f"method {method}")[4]
    lim = limits.current()
    fit = min(lim.max_steps / math.ceil(duration / step), lim.max_samples / 2)  # drops a call within the limits
    per_call = n if fit >= n else max(1, int(fit))
    t_event, state = np.full(n, math.nan), np.empty((n, 6))
    for lo in range(0, n, per_call):
        hi = min(n, lo + per_call)
        traj = run_on_engine(model, r0[lo:hi], np.zeros((hi - lo, 3)), duration, method,
                             dict(run, samples=1, step=step), None, lambda res: getattr(res, "trajectory", res),
                             events=[GROUND_EVENT], energy=False, device="gpu")
        t_event[lo:hi], state[lo:hi] = traj.first_events("ground")
    paths = _on_engine(model, r0[keep], duration, method, run, range(len(keep)))[2] if keep else {}
    return t_event, state, {k: paths[j] for j, k in enumerate(keep)}


def _path_samples(run):
    """The samples of a kept path (the run's ``samples``, 16 to `rotframe.particles.ensemble.MAX_TRACK_SAMPLES`), on
    whose intervals every drop of an ensemble steps, whether or not its path is kept."""
    from rotframe.particles.ensemble import MAX_TRACK_SAMPLES

    return max(16, min(int(run.get("samples") or MAX_TRACK_SAMPLES), MAX_TRACK_SAMPLES))


def ensemble_duration(duration):
    """The simulated time of an ensemble member whose own fall needs ``duration``: the next power of two (s).

    It depends on the point alone, so a point's numbers never depend on the other
    points integrated with it (how a sweep cut its rows); the power of two keeps
    points of similar heights in one vectorised call.
    """
    if not (math.isfinite(duration) and duration > 0):
        return float(duration)
    e = math.ceil(math.log2(duration))
    return math.ldexp(1.0, e) if -1070 < e < 1020 else float(duration)


def _duration_groups(values_list, terms):
    """Indices grouped by model (every value but height and magnify) and by `ensemble_duration`."""
    from rotframe.particles.ensemble import group_points

    out = []
    for members in group_points(values_list, varying=("height", "magnify")):
        first = scene_parameters(TowerDropParameters, values_list[members[0]])
        _, _, g = earth_model_constants(first.latitude, first.g_model)
        heights = np.array([values_list[i]["height"] for i in members], dtype=float)
        durations = np.atleast_1d(fall_duration(heights, first.drag, g))
        by = {}
        for i, d in zip(members, durations):
            by.setdefault(ensemble_duration(d), []).append(i)
        out.extend(by[d] for d in sorted(by))
    return out


def ensemble_theory(values):
    """The closed forms of `analyse`'s theory for one point, for sweep rows run as an ensemble.

    Vacuum, uniform gravity: east (1/3) Omega g t^3 cos(lat) (first order), north
    (1/6) Omega^2 g t^4 sin(lat) cos(lat) towards the equator (second order),
    t = sqrt(2 h / g). ``values`` is the resolved mapping of `simulate` (read
    directly, and the Earth's constants cached per latitude: this runs once per row).
    """
    h, latitude = float(values["height"]), float(values["latitude"])
    Omega, g = _omega_and_g(latitude, str(values.get("g_model", "wgs84")))
    lat = math.radians(latitude)
    return {"east_deflection_m": float(analytic.drop_east_deflection_first_order(h, lat, g, Omega)),
            "north_deflection_m": float(analytic.drop_north_deflection_second_order(h, lat, g, Omega)),
            "fall_time_s": math.sqrt(2 * h / g)}


@functools.lru_cache(maxsize=4096)
def _omega_and_g(latitude, g_model):
    Omega, _, g = earth_model_constants(latitude, g_model)
    return Omega, g
