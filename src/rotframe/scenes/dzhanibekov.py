"""The Dzhanibekov (intermediate-axis, tennis-racket) flip of a free asymmetric body.

A body spun about its intermediate principal axis with a small perturbation
flips over again and again: omega_2 changes sign every half period of the
elliptic motion (Landau & Lifshitz par. 37). The flip interval is measured
from the motion (the sign changes of omega_2, interpolated) and compared with
half the period 4 K(m) / lambda; energy and |L| are conserved.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotframe.errors import ScenarioError
from rotframe.scenes.base import reject_subnormal, samples_for, unresolved_note, with_parameters
from rotframe.scenes.rigid_base import (FREE_METHODS, adaptive_rel_error, free_body_state,
                                       invariant_drifts, record_body, simulate_free_body)


@dataclass(frozen=True, kw_only=True)
class DzhanibekovParameters:
    """Parameters of the dzhanibekov effect scene, in the units of its scenario file."""

    i1: float  # kg m^2
    i2: float  # kg m^2
    i3: float  # kg m^2
    omega: tuple[float, ...]  # rad/s, body frame (3 numbers)
    duration: float  # s


#: The scene's parameters (the scene protocol's optional ``PARAMETERS``).
PARAMETERS = DzhanibekovParameters


METHODS = FREE_METHODS


@with_parameters(DzhanibekovParameters)
def build(p):
    """``(inertia, L0, q0)``: the body in the identity attitude, spinning at ``omega`` (body axes)."""
    body = free_body_state([p.i1, p.i2, p.i3], p.omega)
    if not np.any(p.omega):
        raise ScenarioError("omega = 0,0,0: the body must spin (give 3 numbers in rad/s, body axes)")
    return body


#: Samples per period of omega(t): omega_mid changes sign twice a period, so 32 per flip.
SAMPLES_PER_OMEGA_PERIOD = 64


@with_parameters(DzhanibekovParameters)
def simulate(p, terms, method, run, progress):
    from rotframe.rigid import dynamics as rigid
    reject_subnormal(p)
    body = build(p)
    period = rigid.elliptic_period(body[0], body[1])
    samples, resolved = samples_for(p.duration, period, run.get("samples") or 2000,
                                    per_period=SAMPLES_PER_OMEGA_PERIOD)
    result = simulate_free_body(body, p.duration, method, dict(run, samples=samples), progress)
    result.extras.update(resolved=resolved, omega_period=period)
    return result


def flip_times(times, w):
    """Times at which w changes sign: linear interpolation between samples of opposite signs.

    A flip can land on a sample (by symmetry: a run of 4.5 periods puts the middle flip on the middle
    sample, w = 0 there exactly): a zero between samples of opposite signs is the flip's time
    (the middle of a run of zeros), and zeros at the run's ends are flips at their time (omega_mid
    passes through 0 at a flip, it never touches it and returns: Euler's equations give it a
    non-zero slope there).
    """
    times = np.asarray(times, dtype=float)
    w = np.asarray(w, dtype=float)
    nz = np.flatnonzero(w != 0.0)
    if nz.size == 0:
        return np.array([])
    sign = np.sign(w[nz])
    change = np.flatnonzero(sign[:-1] != sign[1:])
    a, b = nz[change], nz[change + 1]
    adjacent = b == a + 1
    interpolated = times[a] + (times[b] - times[a]) * w[a] / np.where(adjacent, w[a] - w[b], 1.0)
    on_samples = 0.5 * (times[np.minimum(a + 1, b)] + times[np.maximum(b - 1, a)])  # the run of zeros' middle
    inner = np.where(adjacent, interpolated, on_samples)
    first = [0.5 * (times[0] + times[nz[0] - 1])] if nz[0] > 0 else []  # the run starts at a flip
    last = [0.5 * (times[nz[-1] + 1] + times[-1])] if nz[-1] < w.size - 1 else []  # the run ends at one
    return np.concatenate([first, inner, last])


def _flip_tolerance(traj, inertia, mid, n_intervals, interval, method):
    """Largest error (s) of the mean flip interval measured from the samples.

    Each sign change is placed by linear interpolation; omega_mid has an
    inflection there (d^2 omega_mid / dt^2 = 0 where omega_mid = 0, from Euler's
    equations), so the error is O(dt^3 lambda^2) with lambda = max |dL_mid/dt| /
    max |L_mid|, the steepness of the flip; taken at dt^3 lambda^2 per crossing.
    The interval is (last - first) / (n - 1), so two crossing errors count. A
    relative 1e-9 covers round-off of the exact flow; fixed-step methods add
    (lambda h)^2 relative (order 2, factor 10 of margin), the adaptive ``dop853``
    `rotframe.scenes.rigid_base.adaptive_rel_error` of its ``rtol`` and steps.
    """
    dt = float(traj.times[1] - traj.times[0])
    w = traj.L / np.where(inertia > 0, inertia, np.inf)
    dL = np.cross(traj.L, w)[:, mid]
    lam = float(np.max(np.abs(dL)) / max(np.max(np.abs(traj.L[:, mid])), 1e-300))
    tol = 2 * dt**3 * lam**2 / n_intervals + 1e-9 * interval
    h = traj.extras.get("step")
    if method == "dop853":
        tol += adaptive_rel_error(traj) * interval
    elif method != "exact" and h:
        tol += 10.0 * interval * (lam * h) ** 2
    return tol


@with_parameters(DzhanibekovParameters)
def analyse(p, result):
    from rotframe.rigid import dynamics as rigid
    traj, inertia = result.trajectory, result.extras["inertia"]
    mid = int(np.argsort(inertia)[1])
    e_drift, m_drift, _, _ = invariant_drifts(inertia, traj)
    period = rigid.elliptic_period(inertia, traj.L[0])
    notes, tolerance = [], {}
    exact = "exact: conserved by the free body"
    theory_notes = {"flip_interval_s": "exact: half the period 4 K(m) / lambda of omega(t) of the same free body "
                                       "(Jacobi elliptic functions)",
                    "energy_rel_drift": exact, "momentum_rel_drift": exact}
    interval = math.nan
    # omega along one principal axis: a steady rotation (Euler's equations give d omega / dt = 0), so
    # nothing flips however long the run; the elliptic period there is the limit of nearby motions only
    axis = np.nonzero(traj.L[0])[0]
    steady = len(axis) == 1
    if steady:
        which = {0: "smallest", 1: "intermediate", 2: "largest"}[int(np.argsort(np.argsort(inertia))[axis[0]])]
        notes.append(f"omega lies along a principal axis (of the {which} moment): the rotation is steady and never "
                     "flips, so flip_interval_s and its theory are null" + (
                         " (the intermediate axis is an unstable equilibrium: any tilt, however small, "
                         "makes it flip, the more rarely the smaller the tilt)" if which == "intermediate" and
                         len(set(inertia.tolist())) == 3 else ""))
    if not result.extras.get("resolved", True):
        notes.append(unresolved_note("flip_interval_s", "omega", period, float(traj.times[-1]),
                                     per_period=SAMPLES_PER_OMEGA_PERIOD))
        flips = np.array([])
    else:
        flips = flip_times(traj.times, traj.L[:, mid])
        if steady:
            pass
        elif len(flips) >= 2:
            interval = float((flips[-1] - flips[0]) / (len(flips) - 1))
            tolerance["flip_interval_s"] = _flip_tolerance(traj, inertia, mid, len(flips) - 1, interval, traj.method)
        else:
            notes.append("fewer than two flips in the simulated time: lengthen duration")
    if len(set(inertia.tolist())) < 3:
        notes.append("two principal moments are equal: there is no intermediate axis; flip_interval_s is the "
                     "interval between sign changes of omega about the axis of the middle moment as sorted")
    elif abs(traj.L[0, mid]) < 0.5 * np.linalg.norm(traj.L[0]) and not steady:
        notes.append("the body starts far from its intermediate axis: omega changes sign about that axis as the "
                     "body wobbles about a stable one; it does not turn over")
    if steady:
        period = math.nan
    theory = {"flip_interval_s": period / 2 if math.isfinite(period) else math.nan,
              "energy_rel_drift": 0.0, "momentum_rel_drift": 0.0}
    return {"metrics": {"flip_interval_s": interval, "energy_rel_drift": e_drift, "momentum_rel_drift": m_drift},
            "theory": theory, "theory_notes": theory_notes, "tolerance": tolerance,
            "diagnostics": {"flips": len(flips), "omega_period_s": period}, "notes": notes}


@with_parameters(DzhanibekovParameters, position=1)
def record(rec, p, result):
    traj, inertia = result.trajectory, result.extras["inertia"]
    idx = record_body(rec, traj, inertia)
    _, _, E, M = invariant_drifts(inertia, traj)
    rec.scalars("diagnostics/energy_rel_error", traj.times[idx], (E[idx] - E[0]) / E[0])
    rec.scalars("diagnostics/momentum_rel_error", traj.times[idx], (M[idx] - M[0]) / M[0])
