"""The heavy symmetric top about a fixed point, including the sleeping top.

Goldstein 5.7: with u = cos(theta), the axis nods between the roots of the
cubic f(u) = (1 - u^2)(alpha - beta u) - (b - a u)^2 in [-1, 1]. Started at
theta0 with rates (phidot0, thetadot0 = wobble, psidot0), ZXZ Euler angles
(used only to set up and to report; the body is integrated with a quaternion,
so theta0 = 0, the upright "sleeping" top, is no singularity). The upright top
is stable when I3^2 w3^2 > 4 I1 m g l (I1 about the fixed point).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotframe.scenes.base import SceneResult, reject_subnormal, samples_for, unresolved_note, with_parameters
from rotframe import torques
from rotframe.scenes.rigid_base import HEAVY_METHODS, adaptive_rel_error, initial_attitude_zxz, run_body


@dataclass(frozen=True, kw_only=True)
class HeavyTopParameters:
    """Parameters of the heavy symmetric top scene, in the units of its scenario file."""

    i1: float  # kg m^2, about the fixed point
    i3: float  # kg m^2
    mass: float  # kg
    length: float  # m, pivot to centre of mass
    g: float  # m/s^2
    theta0: float  # deg
    phidot0: float  # rad/s
    psidot0: float  # rad/s
    wobble: float  # rad/s, initial thetadot
    duration: float  # s


#: The scene's parameters (the scene protocol's optional ``PARAMETERS``).
PARAMETERS = HeavyTopParameters


#: ``top-splitting``, ``top-splitting4``, ``top-splitting6``, ``rk4``, ``dop853`` (the old ``splitting[4|6]``
#: accepted).
METHODS = HEAVY_METHODS


@with_parameters(HeavyTopParameters)
def build(p):
    from rotframe import frames
    from rotframe.rigid import mass_properties
    i1, i3 = p.i1, p.i3
    inertia = np.array([i1, i1, i3])
    mass_properties.check_moments(inertia)
    theta0 = math.radians(p.theta0)
    angles = [0.0, theta0, 0.0]
    rates = [p.phidot0, p.wobble, p.psidot0]
    omega = frames.euler_rates_to_omega(angles, rates, seq="ZXZ", frame="body")
    return inertia, inertia * omega, initial_attitude_zxz(*angles)


@with_parameters(HeavyTopParameters)
def turning_points(p):
    """(theta_min, theta_max, nutation period) from Goldstein's cubic, or None where it has no bracket.

    None too for a top started upright without a nod (theta0 = 0, wobble = 0): it has no turning points.
    """
    from rotframe.rigid import dynamics as rigid
    if not (p.theta0 > 0 or p.wobble != 0):
        return None
    try:
        return rigid.heavy_top_turning_points(p.i1, p.i3, p.mass, p.length,
                                              p.g, math.radians(p.theta0), p.wobble,
                                              p.phidot0, p.psidot0)
    except Exception:  # the cubic has no bracket (e.g. exactly steady precession)
        return None


def _nutation_period_estimate(p):
    """A nutation period (s) to size the sampling: the cubic's, else the fast top's 2 pi I1 / (I3 |omega3|)."""
    tp = turning_points(p)
    if tp is not None and len(tp) > 2 and math.isfinite(tp[2]) and tp[2] > 0:
        return float(tp[2])
    w3 = spin_rate(p)
    return 2 * math.pi * p.i1 / (p.i3 * abs(w3)) if w3 else math.inf


def spin_rate(p):
    """omega3 (rad/s), the spin about the symmetry axis at the start: psidot0 + phidot0 cos(theta0) (ZXZ rates)."""
    return p.psidot0 + p.phidot0 * math.cos(math.radians(p.theta0))


@with_parameters(HeavyTopParameters)
def simulate(p, terms, method, run, progress):
    reject_subnormal(p)
    inertia, L0, q0 = build(p)
    method = HEAVY_METHODS.canonical(method or run.get("method") or "top-splitting")
    period = _nutation_period_estimate(p)
    samples, resolved = samples_for(p.duration, period, run.get("samples") or 2000)

    def finish(traj, remarks):
        return SceneResult(traj, ["free-rigid-body", "gravity-torque"], traj.method, traj.steps,
                           extras={"inertia": inertia, "resolved": resolved, "nutation_period": period, **remarks})

    # the engine's heavy top: the free body under the built-in gravity torque, the heavy-top scene's arithmetic
    return run_body(method, inertia, L0, q0, p.duration, dict(run, samples=samples), progress, finish,
                    torque=torques.gravity(p.mass, p.length, p.g), spin="phidot0, psidot0, wobble")


#: Order of each fixed-step method (its global error goes as h^order): what its stated accuracy scales by.
ORDERS = {"top-splitting": 2, "top-splitting4": 4, "top-splitting6": 6, "top-splitting8": 8, "rk4": 4}

#: Theory: turning points closer than this (rad) are steady motion (no nutation).
NUTATION_FLOOR = 1e-12


def tilt(traj):
    """theta(t) (rad): angle between the symmetry axis and the vertical, from the quaternions."""
    from rotframe.rigid import dynamics as rigid
    e3 = rigid.body_to_space(traj.q, np.array([0.0, 0.0, 1.0]))
    return np.arccos(np.clip(e3[:, 2], -1.0, 1.0))


def euler_angles(q, seq="ZXZ"):
    """Euler angles (rad, any of the twelve sequences) of body -> space quaternions, as an output.

    The direction-cosine matrix of [`rotframe.frames`][rotframe.frames] maps space to body, the
    transpose of the quaternion's matrix. Where the angles are not unique (the
    sleeping top at theta = 0) the third angle is set to 0 (``on_gimbal_lock="mask"``).
    """
    from scipy.spatial.transform import Rotation

    from rotframe import frames

    A = np.swapaxes(Rotation.from_quat(q).as_matrix(), -1, -2)
    angles, _ = frames.dcm_to_euler(frames.orthonormalize(A), seq=seq, on_gimbal_lock="mask")
    return np.unwrap(angles, axis=0)


def _maxima(theta):
    """Indices of the strict local maxima of theta (samples)."""
    return np.nonzero((theta[1:-1] > theta[:-2]) & (theta[1:-1] >= theta[2:]))[0] + 1


def _peak_times(times, theta, k):
    """Times of the maxima of theta at sample indices ``k``: the vertex of the parabola through each
    maximum and its two neighbours, kept within half a sample of it (where the true maximum lies).

    At a smooth maximum the vertex is good to O(dt^3); the sampled time alone is off by up to dt / 2,
    which printed a nutation period wrong in its fifth digit at the default sampling.
    """
    i = np.asarray(k)
    i = i[(i > 0) & (i < len(theta) - 1)]
    t0, t1, t2 = times[i - 1], times[i], times[i + 1]
    z0, z1, z2 = theta[i - 1], theta[i], theta[i + 1]
    d1 = (z1 - z0) / (t1 - t0)
    d2 = ((z2 - z1) / (t2 - t1) - d1) / (t2 - t0)
    with np.errstate(divide="ignore", invalid="ignore"):
        tv = np.where(d2 < 0, 0.5 * (t0 + t1) - d1 / (2 * np.where(d2 < 0, d2, -1.0)), t1)
    return np.clip(tv, t1 - 0.5 * (t1 - t0), t1 + 0.5 * (t2 - t1))


@with_parameters(HeavyTopParameters)
def analyse(p, result):
    from rotframe.rigid import dynamics as rigid
    traj = result.trajectory
    theta = tilt(traj)
    args = (p.i1, p.i3, p.mass, p.length, p.g)
    threshold = rigid.sleeping_top_threshold(*args)
    w3 = spin_rate(p)
    dt = float(traj.times[1] - traj.times[0]) if len(traj.times) > 1 else math.inf
    h = traj.extras.get("step") or dt
    amplitude = float(theta.max() - theta.min())
    # round-off of theta after n steps grows like eps sqrt(n) (a random walk); 100 times that is not motion
    floor = NUTATION_FLOOR + 100 * np.finfo(float).eps * math.sqrt(max(traj.steps, 1))
    notes = []
    # nutation period from the maxima of theta, only where theta really nods and the samples resolve it
    period = math.nan
    k = _maxima(theta)
    if amplitude <= floor:
        notes.append(f"no nutation: theta stays at {math.degrees(theta[0]):.6g} deg to {math.degrees(amplitude):.2g} deg "
                     "(round-off), so there is no nutation period")
    elif not result.extras.get("resolved", True):
        notes.append(unresolved_note("nutation (theta_min_deg, theta_max_deg, nutation_period_s)", "nutation",
                                     result.extras["nutation_period"], float(traj.times[-1])))
    elif len(k) >= 2:
        tk = _peak_times(traj.times, theta, k)
        period = float((tk[-1] - tk[0]) / (len(tk) - 1))
    else:
        notes.append("fewer than two maxima of theta in the simulated time: no nutation period")
    metrics = {"theta_min_deg": math.degrees(theta.min()), "theta_max_deg": math.degrees(theta.max()),
               "nutation_period_s": period}
    if not result.extras.get("resolved", True):  # extremes of unresolved samples are not the motion's
        metrics.update(theta_min_deg=math.nan, theta_max_deg=math.nan)
    T_nut = result.extras.get("nutation_period", math.inf)
    if amplitude > floor and math.isfinite(T_nut) and float(traj.times[-1]) < T_nut:
        metrics.update(theta_min_deg=math.nan, theta_max_deg=math.nan)
        notes.append(f"the run is shorter than one nutation period ({T_nut:.4g} s): theta has not reached both "
                     "turning points, so theta_min_deg and theta_max_deg are null")
    theory, tolerance = {}, {}
    exact = "exact: roots of Goldstein's cubic f(u) of the same top"
    theory_notes = {"theta_min_deg": exact, "theta_max_deg": exact,
                    "nutation_period_s": "exact: 2 int du / sqrt(f(u)) between the roots (elliptic integral)"}
    tp = turning_points(p)
    if p.theta0 > 0 or p.wobble != 0:
        if tp is None:
            notes.append("no turning-point theory: the cubic f(u) has no bracketing roots (steady precession)")
        else:
            theory = {"theta_min_deg": math.degrees(tp[0]), "theta_max_deg": math.degrees(tp[1]),
                      "nutation_period_s": float(tp[2]) if len(tp) > 2 else math.nan}
            if tp[1] - tp[0] <= NUTATION_FLOOR:
                theory["nutation_period_s"] = math.nan
                notes.append(f"theory: theta stays at {math.degrees(tp[0]):.6g} deg (steady to the resolution of the cubic; the period of "
                             f"small nods about it would be {tp[2]:.6g} s)")
            # method error of an order-p fixed-step method, (w h)^p relative with w the fastest rate, factor 10
            # margin (dop853: its bound from the tolerance, rigid_base.adaptive_rel_error);
            # a sampled extreme misses the true one by up to amplitude (pi dt / T)^2 / 2
            T = float(tp[2]) if len(tp) > 2 and math.isfinite(tp[2]) and tp[2] > 0 else math.inf
            w_fast = max(abs(w3), abs(p.phidot0), 2 * math.pi / T)
            with np.errstate(over="ignore"):  # a rate of 1e150 rad/s: an infinite bound, not an OverflowError
                fixed_rel = 10 * float(np.float64(w_fast * h) ** ORDERS.get(traj.method, 2)) + 1e-9
            method_rel = (adaptive_rel_error(traj) if traj.method == "dop853"
                          else fixed_rel if traj.method != "exact" else 1e-9)
            amp_deg = math.degrees(tp[1] - tp[0])
            for key, i in (("theta_min_deg", int(np.argmin(theta))), ("theta_max_deg", int(np.argmax(theta)))):
                # the true extreme lies within a sample of the sampled one, so it differs from it by at most
                # the larger change to a neighbouring sample (whether the extreme is smooth or a kink at 180 deg)
                near = theta[max(i - 1, 0):i + 2]
                sampled = math.degrees(float(np.max(np.abs(near - theta[i]))))
                tolerance[key] = sampled + method_rel * max(amp_deg, 1e-300) + 1e-9 * abs(theory[key])
            if math.isfinite(period) and math.isfinite(theory["nutation_period_s"]):
                # each maximum is placed within the half sample each side of the sampled one, where the true
                # one lies, so within dt of it: the mean is good to 2 dt / (n - 1) (O(dt^3) where it is smooth)
                tolerance["nutation_period_s"] = 2 * dt / (len(k) - 1) + method_rel * T
    diagnostics = {"sleeping_threshold_omega3_rad_s": threshold, "omega3_rad_s": w3,
                   "sleeping_top_stable": bool(abs(w3) > threshold)}
    if p.theta0 == 0:
        notes.append(f"sleeping top: stable above omega3 = {threshold:.4g} rad/s; this one spins at {w3:.4g}"
                     + (" (stays up)" if abs(w3) > threshold else " (falls)"))
    return {"metrics": metrics, "theory": theory, "theory_notes": theory_notes, "tolerance": tolerance,
            "diagnostics": diagnostics, "notes": notes}


@with_parameters(HeavyTopParameters, position=1)
def record(rec, p, result):
    """The top, L in space per sample (its horizontal part turns under the gravity torque), theta and its
    turning-angle theory, the Euler angles, the energy error; each kind in its own time-series view."""
    from rotframe.rigid import dynamics as rigid
    from rotframe.scenes.rigid_base import record_body

    traj = result.trajectory
    idx = record_body(rec, traj, result.extras["inertia"], axis_length=p.length * 1.5, mass=p.mass,
                      L_label="L in space (its vertical part is conserved; the horizontal part turns "
                              "with the gravity torque)")
    t = traj.times[idx]
    theta = tilt(traj)
    rec.scalars("diagnostics/theta_deg", t, np.degrees(theta[idx]), kind="tilt theta (deg)", label="theta (simulated)")
    theory = turning_points(p)
    if theory is not None:
        rec.reference("diagnostics/theta_deg", t, math.degrees(theory[0]), label="theta_min (Goldstein cubic)",
                      name="theory_min")
        rec.reference("diagnostics/theta_deg", t, math.degrees(theory[1]), label="theta_max (Goldstein cubic)",
                      name="theory_max")
    angles = euler_angles(traj.q[idx], "ZXZ")
    for k, name in enumerate(("phi", "theta", "psi")):
        kind = "Euler angle theta (deg)" if name == "theta" else f"Euler angle {name} (deg, unwrapped)"
        rec.scalars(f"diagnostics/euler_zxz/{name}_deg", t, np.degrees(angles[:, k]), kind=kind)
    tip = rigid.body_to_space(traj.q[idx], np.array([0.0, 0.0, 1.5 * p.length]))
    rec.trail("world/tip_path", t, tip, color=[60, 200, 120])
    rec.frame_axes("world/frame", p.length, labels=("x", "y", "z (up)"))
    E = rigid.energy(result.extras["inertia"], traj.L) + p.mass * p.g * p.length * np.cos(theta)
    rec.scalars("diagnostics/energy_rel_error", t, (E[idx] - E[0]) / abs(E[0]))
    # slow motion: the spin (tens of turns a second) plays at about 2 turns a second, which the eye follows
    rec.view(playback_speed=min(1.0, 2.0 * 2.0 * math.pi / max(abs(spin_rate(p)), 1e-12)))


@with_parameters(HeavyTopParameters)
def analyse_theory(p):
    """(theta_min, theta_max, period) from Goldstein's cubic, or None where it has no bracket."""
    from rotframe.rigid import dynamics as rigid
    if not (p.theta0 > 0 or p.wobble != 0):
        return None
    args = (p.i1, p.i3, p.mass, p.length, p.g)
    try:
        return rigid.heavy_top_turning_points(*args, math.radians(p.theta0), p.wobble,
                                              p.phidot0, p.psidot0)
    except Exception:  # the cubic has no bracket (e.g. exactly steady precession)
        return None
