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
from dataclasses import dataclass

import numpy as np

from rotframe.numerics.linefit import line_fit
from rotframe.scenes.base import reject_subnormal, samples_for, unresolved_note, with_parameters
from rotframe.scenes.rigid_base import (FREE_METHODS, adaptive_rel_error, free_body_state,
                                       invariant_drifts, record_body, simulate_free_body)


@dataclass(frozen=True, kw_only=True)
class FreeTopParameters:
    """Parameters of the free symmetric top scene, in the units of its scenario file."""

    i1: float  # kg m^2
    i3: float  # kg m^2
    omega3: float  # rad/s
    omega_perp: float  # rad/s
    duration: float  # s


#: The scene's parameters (the scene protocol's optional ``PARAMETERS``).
PARAMETERS = FreeTopParameters


METHODS = FREE_METHODS


@with_parameters(FreeTopParameters)
def build(p):
    """``(inertia, L0, q0)``: the symmetric top spinning at (omega_perp, 0, omega3) in body axes."""
    return free_body_state([p.i1, p.i1, p.i3], [p.omega_perp, 0.0, p.omega3])


@with_parameters(FreeTopParameters)
def time_scales(p):
    """(body precession rate k, space precession rate |L| / I1), rad/s, from the parameters.

    k = omega3 (I3 - I1) / I1 (signed, about +e3); the symmetry axis circles L at |L| / I1.
    """
    i1, i3 = p.i1, p.i3
    k = p.omega3 * (i3 - i1) / i1
    space = math.hypot(i1 * p.omega_perp, i3 * p.omega3) / i1
    return k, space


def _periods(p):
    """The periods (s) the metrics must resolve: of the rates that are not zero."""
    k, space = time_scales(p)
    return [2 * math.pi / abs(r) for r in (k, space) if r != 0.0 and math.isfinite(2 * math.pi / abs(r))]


@with_parameters(FreeTopParameters)
def simulate(p, terms, method, run, progress):
    reject_subnormal(p)
    periods = _periods(p)
    shortest = min(periods) if periods else math.inf
    samples, resolved = samples_for(p.duration, shortest, run.get("samples") or 2000)
    result = simulate_free_body(build(p), p.duration, method, dict(run, samples=samples), progress,
                                spin="omega3, omega_perp")
    result.extras["resolved"] = resolved
    result.extras["shortest_period"] = shortest
    return result


def measured_rates(traj, inertia):
    """(body precession rate of (w1, w2), space precession rate of e3 about L, their standard errors), rad/s.

    The rates are signed; the errors come from the scatter of the angles about their fitted lines.
    """
    from rotframe.rigid import dynamics as rigid
    w = traj.L / inertia
    body_angle = np.unwrap(np.arctan2(w[:, 1], w[:, 0]))
    body_rate, _, body_error = line_fit(traj.times, body_angle)
    Ls = rigid.angular_momentum_space(traj.q[0], traj.L[0])
    n = Ls / np.linalg.norm(Ls)
    e3 = rigid.body_to_space(traj.q, np.array([0.0, 0.0, 1.0]))
    # angle of e3 about n in a fixed basis of the plane normal to n
    a = np.cross(n, [1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.cross(n, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    space_angle = np.unwrap(np.arctan2(e3 @ b, e3 @ a))
    space_rate, _, space_error = line_fit(traj.times, space_angle)
    return body_rate, space_rate, body_error, space_error


def _unresolved(name, error, tol, duration):
    """A note when a fitted metric's standard error ``error`` exceeds its tolerance ``tol`` (else None)."""
    if error <= tol:
        return None
    unit = "s" if name.endswith("_s") else "rad/s"
    return (f"{name} not measured: over {duration:.4g} s the angle it fits turns too little to tell its rate "
            f"from round-off (standard error {error:.3g} {unit}, over the tolerance {tol:.3g} {unit}); "
            "lengthen duration")


def _tolerance(method, rate, traj):
    """Largest |measured - exact| rate (rad/s) the method allows: round-off for the exact flow.

    The exact flow and the Lie-Poisson splittings (whose free symmetric sub-flows
    are exact) measure a uniform rotation, fitted over many samples: a relative
    1e-9 covers the round-off of angles of up to 1e7 rad. RK4 adds its truncation
    error, (rate h)^4 per unit time in relative terms, with a factor 100 of margin. The adaptive
    ``dop853`` is good to `rotframe.scenes.rigid_base.adaptive_rel_error` of its ``rtol`` and steps.
    """
    tol = 1e-9 * abs(rate)
    h = traj.extras.get("step")
    if method == "dop853":
        tol = adaptive_rel_error(traj) * abs(rate)
    if method == "rk4" and h:
        tol += 100.0 * abs(rate) * (abs(rate) * h) ** 4 * max(1.0, abs(rate) * traj.times[-1])
    return tol


@with_parameters(FreeTopParameters)
def analyse(p, result):
    traj, inertia = result.trajectory, result.extras["inertia"]
    omega3, omega_perp = p.omega3, p.omega_perp
    k, space_theory = time_scales(p)
    duration = float(traj.times[-1])
    e_drift, m_drift, _, _ = invariant_drifts(inertia, traj)
    notes, theory, tolerance = [], {}, {}
    exact = "exact (closed form of the free symmetric top)"
    theory_notes = {"body_precession_period_s": exact + ": 2 pi I1 / |omega3 (I3 - I1)|",
                    "space_precession_rate_rad_s": exact + ": |L| / I1"}
    metrics = {"body_precession_period_s": math.nan, "space_precession_rate_rad_s": math.nan}
    diagnostics = {}
    body_rate = space_rate = math.nan
    body_error = space_error = 0.0
    if omega3 == 0.0 and omega_perp == 0.0:
        notes.append("omega3 = omega_perp = 0: the body does not turn; nothing precesses")
    elif not result.extras.get("resolved", True):
        notes.append(unresolved_note("precession", "precession", result.extras["shortest_period"], duration))
    else:
        body_rate, space_rate, body_error, space_error = measured_rates(traj, inertia)
    if omega_perp == 0.0 and omega3 != 0.0:
        notes.append("omega_perp = 0: the body spins about its symmetry axis, so omega, L and the axis stay "
                     "aligned and nothing precesses (both precession metrics are null)")
    elif k == 0.0 and omega_perp != 0.0:
        why = ("omega3 = 0: the body spins about an equatorial axis, where omega is fixed in the body"
               if omega3 == 0.0 else "i1 = i3: every axis is principal, so omega is fixed in the body")
        notes.append(f"{why}; there is no body precession (period null); the symmetry axis still circles L "
                     "in space")
        theory["space_precession_rate_rad_s"] = space_theory
        metrics["space_precession_rate_rad_s"] = abs(space_rate)
        tolerance["space_precession_rate_rad_s"] = _tolerance(traj.method, space_theory, traj)
    elif omega_perp != 0.0:
        theory = {"body_precession_period_s": 2 * math.pi / abs(k), "space_precession_rate_rad_s": space_theory}
        if math.isfinite(body_rate):
            period = 2 * math.pi / abs(body_rate) if body_rate else math.inf
            metrics = {"body_precession_period_s": period, "space_precession_rate_rad_s": abs(space_rate)}
            tolerance = {"body_precession_period_s": _tolerance(traj.method, k, traj) / abs(k) * theory[
                "body_precession_period_s"], "space_precession_rate_rad_s": _tolerance(traj.method, space_theory, traj)}
            if omega3 != 0.0:
                # a period is positive; its sense is said apart, relative to the spin. The unit is the
                # Earth's sidereal day 2 pi / OMEGA_EARTH whatever the body (not a turn of this body's
                # spin, which would call a top's 1.26 s period "2 days"); for the Earth's spin it is
                # A / (C - A), Euler's 304.5 days
                from rotframe.earth import OMEGA_EARTH

                diagnostics["body_precession_period_sidereal_days"] = period * OMEGA_EARTH / (2 * math.pi)
                diagnostics["body_precession_sense"] = ("with the spin (oblate, I3 > I1)" if body_rate * omega3 > 0
                                                        else "against the spin (prolate, I3 < I1)")
        periods = duration * abs(k) / (2 * math.pi)
        notes.append(f"simulated {periods:.4g} body precession periods" if periods < 1e6 else
                     f"simulated {periods:.4g} body precession periods (the default duration is two Euler periods "
                     "of the Earth; set duration to suit another body)")
    # a rate the samples cannot resolve from round-off is null with a note, never a number
    errors = {"body_precession_period_s": body_error / abs(k) * theory.get("body_precession_period_s", 0.0)
              if k else 0.0, "space_precession_rate_rad_s": space_error}
    for name, tol in tolerance.items():
        note = _unresolved(name, errors[name], tol, duration)
        if note and math.isfinite(metrics.get(name, math.nan)):
            metrics[name] = math.nan
            notes.append(note)
    diagnostics.update(energy_rel_drift=e_drift, momentum_rel_drift=m_drift)
    return {"metrics": metrics, "theory": theory, "theory_notes": theory_notes, "tolerance": tolerance,
            "diagnostics": diagnostics, "notes": notes}


@with_parameters(FreeTopParameters, position=1)
def record(rec, p, result):
    traj, inertia = result.trajectory, result.extras["inertia"]
    idx = record_body(rec, traj, inertia)
    w = traj.L[idx] / inertia
    rec.scalars("diagnostics/pole_offset_urad", traj.times[idx], 1e6 * np.hypot(w[:, 0], w[:, 1]) / w[:, 2])
    _record_wobble_magnified(rec, traj, idx)


def _record_wobble_magnified(rec, traj, idx):
    """The symmetry axis's circle about L, magnified by a power of ten to a third of the axis (labelled with it).

    The wobble of the defaults is a microradian: drawn true to scale, the axis and L coincide. The
    tip of the unit symmetry axis e3 is drawn at ``n + M (e3 - (e3 . n) n)``, n the unit L in space.
    """
    from rotframe.rigid import dynamics as rigid

    t = traj.times[idx]
    e3 = rigid.body_to_space(traj.q[idx], np.array([0.0, 0.0, 1.0]))
    Ls = rigid.angular_momentum_space(traj.q[idx], traj.L[idx])
    n = Ls / np.maximum(np.linalg.norm(Ls, axis=1), 1e-300)[:, None]
    off = e3 - np.sum(e3 * n, axis=1)[:, None] * n
    size = float(np.max(np.linalg.norm(off, axis=1)))
    if not size > 0.0:
        return
    magnify = 10.0 ** round(math.log10(0.3 / size))
    tips = n + magnify * off
    label = f"symmetry axis tip about L, x{magnify:.0e} (a {size:.2g} rad wobble)"
    rec.line("world/wobble_magnified/circle", tips, color=[120, 170, 255, 120])
    rec.points("world/wobble_magnified", t, tips, radius=0.02, color=[120, 170, 255], trail=False)
    rec.static("world/wobble_magnified/label", "Points3D", positions=[tips[0]], radii=[0.001], labels=[label],
               show_labels=True)
