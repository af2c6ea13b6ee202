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

import numpy as np

from rotframe.scenes.base import SceneResult
from rotframe.scenes.rigid_base import HEAVY_METHODS, guarded, initial_attitude_zxz, integrate_body

METHODS = HEAVY_METHODS


def build(values):
    from rotframe import frames
    from rotframe import inertia as mass_properties

    i1, i3 = values["i1"], values["i3"]
    inertia = np.array([i1, i1, i3])
    mass_properties.check_moments(inertia)
    theta0 = math.radians(values["theta0"])
    angles = [0.0, theta0, 0.0]
    rates = [values["phidot0"], values["wobble"], values["psidot0"]]
    omega = frames.euler_rates_to_omega(angles, rates, seq="ZXZ", frame="body")
    return inertia, inertia * omega, initial_attitude_zxz(*angles)


def simulate(values, terms, method, run, progress):
    inertia, L0, q0 = build(values)
    method = method or run.get("method") or "splitting"
    top = (values["mass"], values["length"], values["g"])

    def finish(traj):
        return SceneResult(traj, ["free-rigid-body", "gravity-torque"], traj.method, traj.steps,
                           extras={"inertia": inertia})

    return guarded(finish, integrate_body, method, inertia, L0, q0, values["duration"], run, progress, top=top)


def tilt(traj):
    """theta(t) (rad): angle between the symmetry axis and the vertical, from the quaternions."""
    from rotframe import rigid

    e3 = rigid.body_to_space(traj.q, np.array([0.0, 0.0, 1.0]))
    return np.arccos(np.clip(e3[:, 2], -1.0, 1.0))


def euler_angles(q, seq="ZXZ"):
    """Euler angles (rad, any of the twelve sequences) of body -> space quaternions, as an output.

    The direction-cosine matrix of :mod:`rotframe.frames` maps space to body, the
    transpose of the quaternion's matrix. Where the angles are not unique (the
    sleeping top at theta = 0) the third angle is set to 0 (``on_gimbal_lock="mask"``).
    """
    from scipy.spatial.transform import Rotation

    from rotframe import frames

    A = np.swapaxes(Rotation.from_quat(q).as_matrix(), -1, -2)
    angles, _ = frames.dcm_to_euler(frames.orthonormalize(A), seq=seq, on_gimbal_lock="mask")
    return np.unwrap(angles, axis=0)


def analyse(values, result):
    from rotframe import rigid

    traj = result.trajectory
    theta = tilt(traj)
    args = (values["i1"], values["i3"], values["mass"], values["length"], values["g"])
    threshold = rigid.sleeping_top_threshold(*args)
    w3 = values["psidot0"] + values["phidot0"] * math.cos(math.radians(values["theta0"]))
    # nutation period from the maxima of theta
    k = np.nonzero((theta[1:-1] > theta[:-2]) & (theta[1:-1] >= theta[2:]))[0] + 1
    period = float(np.mean(np.diff(traj.times[k]))) if len(k) >= 2 else math.nan
    metrics = {"theta_min_deg": math.degrees(theta.min()), "theta_max_deg": math.degrees(theta.max()),
               "nutation_period_s": period}
    theory = {}
    notes = []
    if values["theta0"] > 0 or values["wobble"] != 0:
        try:
            tp = rigid.heavy_top_turning_points(*args, math.radians(values["theta0"]), values["wobble"],
                                                values["phidot0"], values["psidot0"])
            theory = {"theta_min_deg": math.degrees(tp[0]), "theta_max_deg": math.degrees(tp[1]),
                      "nutation_period_s": float(tp[2]) if len(tp) > 2 else math.nan}
        except Exception as exc:  # the cubic has no bracket (e.g. exactly steady precession)
            notes.append(f"no turning-point theory: {exc}")
    diagnostics = {"sleeping_threshold_omega3_rad_s": threshold, "omega3_rad_s": w3,
                   "sleeping_top_stable": bool(abs(w3) > threshold)}
    if values["theta0"] == 0:
        notes.append(f"sleeping top: stable above omega3 = {threshold:.4g} rad/s; this one spins at {w3:.4g}"
                     + (" (stays up)" if abs(w3) > threshold else " (falls)"))
    return {"metrics": metrics, "theory": theory, "diagnostics": diagnostics, "notes": notes}


def record(rec, values, result):
    """The top, L in space per sample (its horizontal part turns under the gravity torque), theta and its
    turning-angle theory, the Euler angles, the energy error; each kind in its own time-series view."""
    from rotframe import rigid
    from rotframe.scenes.rigid_base import record_body

    traj = result.trajectory
    idx = record_body(rec, traj, result.extras["inertia"], axis_length=values["length"] * 1.5, mass=values["mass"],
                      L_label="L in space (its vertical part is conserved; the horizontal part turns "
                              "with the gravity torque)")
    t = traj.times[idx]
    theta = tilt(traj)
    rec.scalars("diagnostics/theta_deg", t, np.degrees(theta[idx]), kind="tilt theta (deg)", label="theta (simulated)")
    theory = analyse_theory(values)
    if theory is not None:
        rec.reference("diagnostics/theta_deg", t, math.degrees(theory[0]), label="theta_min (Goldstein cubic)",
                      name="theory_min")
        rec.reference("diagnostics/theta_deg", t, math.degrees(theory[1]), label="theta_max (Goldstein cubic)",
                      name="theory_max")
    angles = euler_angles(traj.q[idx], "ZXZ")
    for k, name in enumerate(("phi", "theta", "psi")):
        kind = "Euler angle theta (deg)" if name == "theta" else f"Euler angle {name} (deg, unwrapped)"
        rec.scalars(f"diagnostics/euler_zxz/{name}_deg", t, np.degrees(angles[:, k]), kind=kind)
    tip = rigid.body_to_space(traj.q[idx], np.array([0.0, 0.0, 1.5 * values["length"]]))
    rec.trail("world/tip_path", t, tip, color=[60, 200, 120])
    rec.frame_axes("world/frame", values["length"], labels=("x", "y", "z (up)"))
    E = rigid.energy(result.extras["inertia"], traj.L) + values["mass"] * values["g"] * values["length"] * np.cos(theta)
    rec.scalars("diagnostics/energy_rel_error", t, (E[idx] - E[0]) / abs(E[0]))


def analyse_theory(values):
    """(theta_min, theta_max, period) from Goldstein's cubic, or None where it has no bracket."""
    from rotframe import rigid

    if not (values["theta0"] > 0 or values["wobble"] != 0):
        return None
    args = (values["i1"], values["i3"], values["mass"], values["length"], values["g"])
    try:
        return rigid.heavy_top_turning_points(*args, math.radians(values["theta0"]), values["wobble"],
                                              values["phidot0"], values["psidot0"])
    except Exception:  # the cubic has no bracket (e.g. exactly steady precession)
        return None
