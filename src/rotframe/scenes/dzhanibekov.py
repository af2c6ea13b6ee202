"""The Dzhanibekov (intermediate-axis, tennis-racket) flip of a free asymmetric body.

A body spun about its intermediate principal axis with a small perturbation
flips over again and again: omega_2 changes sign every half period of the
elliptic motion (Landau & Lifshitz par. 37). The flip interval is measured
from the motion (the sign changes of omega_2, interpolated) and compared with
half the period 4 K(m) / lambda; energy and |L| are conserved.
"""

from __future__ import annotations

import numpy as np

from rotframe.errors import ScenarioError
from rotframe.scenes.rigid_base import FREE_METHODS, invariant_drifts, record_body, simulate_free_body

METHODS = FREE_METHODS


def build(values):
    from rotframe import inertia as mass_properties

    inertia = np.array([values["i1"], values["i2"], values["i3"]], dtype=float)
    mass_properties.check_moments(inertia)
    omega = np.asarray(values["omega"], dtype=float)
    if not np.any(omega):
        raise ScenarioError("omega = 0,0,0: the body must spin (give 3 numbers in rad/s, body axes)")
    return inertia, inertia * omega, np.array([0.0, 0.0, 0.0, 1.0])


def simulate(values, terms, method, run, progress):
    return simulate_free_body(build(values), values["duration"], method, run, progress)


def flip_times(times, w):
    """Times at which w changes sign (linear interpolation between samples)."""
    k = np.nonzero(np.sign(w[:-1]) * np.sign(w[1:]) < 0)[0]
    return times[k] + (times[k + 1] - times[k]) * w[k] / (w[k] - w[k + 1])


def analyse(values, result):
    from rotframe import rigid

    traj, inertia = result.trajectory, result.extras["inertia"]
    mid = int(np.argsort(inertia)[1])
    flips = flip_times(traj.times, traj.L[:, mid])
    interval = float(np.mean(np.diff(flips))) if len(flips) >= 2 else float("nan")
    e_drift, m_drift, _, _ = invariant_drifts(inertia, traj)
    period = rigid.elliptic_period(inertia, traj.L[0])
    notes = [] if len(flips) >= 2 else ["fewer than two flips in the simulated time: lengthen duration"]
    return {"metrics": {"flip_interval_s": interval, "energy_rel_drift": e_drift, "momentum_rel_drift": m_drift},
            "theory": {"flip_interval_s": period / 2, "energy_rel_drift": 0.0, "momentum_rel_drift": 0.0},
            "diagnostics": {"flips": len(flips), "omega_period_s": period}, "notes": notes}


def record(rec, values, result):
    traj, inertia = result.trajectory, result.extras["inertia"]
    idx = record_body(rec, traj, inertia)
    _, _, E, M = invariant_drifts(inertia, traj)
    rec.scalars("diagnostics/energy_rel_error", traj.times[idx], (E[idx] - E[0]) / E[0])
    rec.scalars("diagnostics/momentum_rel_error", traj.times[idx], (M[idx] - M[0]) / M[0])
