"""The free symmetric top, by default the Earth: the Euler (Chandler-free) wobble.

For I1 = I2 the body-frame angular velocity (w1, w2) turns about the symmetry
axis at k = w3 (I3 - I1) / I1 while w3 stays constant, and in space the
symmetry axis turns about the fixed L at |L| / I1 (docs/physics/rigid-bodies.md). With
Earth's principal moments, (C - A) / A = 0.0032845, the body precession
period is A / (C - A) sidereal days, about 304.5 (Euler's period; the observed
Chandler wobble is longer, 433 days, because the Earth is not rigid). Both
rates are measured from the motion.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.scenes.rigid_base import FREE_METHODS, invariant_drifts, record_body, simulate_free_body

METHODS = FREE_METHODS


def build(values):
    from rotframe import inertia as mass_properties

    inertia = np.array([values["i1"], values["i1"], values["i3"]], dtype=float)
    mass_properties.check_moments(inertia)
    omega = np.array([values["omega_perp"], 0.0, values["omega3"]])
    return inertia, inertia * omega, np.array([0.0, 0.0, 0.0, 1.0])


def simulate(values, terms, method, run, progress):
    return simulate_free_body(build(values), values["duration"], method, run, progress)


def measured_rates(traj, inertia):
    """(body precession rate of (w1, w2), space precession rate of e3 about L), rad/s, signed."""
    from rotframe import rigid

    w = traj.L / inertia
    body_angle = np.unwrap(np.arctan2(w[:, 1], w[:, 0]))
    body_rate = np.polyfit(traj.times, body_angle, 1)[0]
    Ls = rigid.angular_momentum_space(traj.q[0], traj.L[0])
    n = Ls / np.linalg.norm(Ls)
    e3 = rigid.body_to_space(traj.q, np.array([0.0, 0.0, 1.0]))
    # angle of e3 about n in a fixed basis of the plane normal to n
    a = np.cross(n, [1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.cross(n, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    space_angle = np.unwrap(np.arctan2(e3 @ b, e3 @ a))
    space_rate = np.polyfit(traj.times, space_angle, 1)[0]
    return body_rate, space_rate


def analyse(values, result):
    from rotframe import rigid

    traj, inertia = result.trajectory, result.extras["inertia"]
    body_rate, space_rate = measured_rates(traj, inertia)
    k = rigid.free_symmetric_precession(inertia[0], inertia[2], values["omega3"])
    Lmag = float(np.linalg.norm(traj.L[0]))
    e_drift, m_drift, _, _ = invariant_drifts(inertia, traj)
    sidereal_day = 2 * math.pi / values["omega3"]
    period = 2 * math.pi / abs(body_rate) if body_rate else math.inf
    return {"metrics": {"body_precession_period_s": period, "space_precession_rate_rad_s": abs(space_rate)},
            "theory": {"body_precession_period_s": 2 * math.pi / abs(k), "space_precession_rate_rad_s": Lmag / inertia[0]},
            "diagnostics": {"body_precession_period_sidereal_days": period / sidereal_day,
                            "energy_rel_drift": e_drift, "momentum_rel_drift": m_drift}}


def record(rec, values, result):
    traj, inertia = result.trajectory, result.extras["inertia"]
    idx = record_body(rec, traj, inertia)
    w = traj.L[idx] / inertia
    rec.scalars("diagnostics/pole_offset_urad", traj.times[idx], 1e6 * np.hypot(w[:, 0], w[:, 1]) / w[:, 2])
