"""The circular restricted three-body problem (CR3BP) in the co-rotating frame.

Units: the primaries' distance, their mean motion and G (m1 + m2) are 1; a synodic period is
2 pi. The primaries stand at (-mu, 0, 0) and (1 - mu, 0, 0) in the frame turning at
omega = (0, 0, 1). The small body obeys (Szebehely, *Theory of Orbits*, 1967, ch. 1)::

    r'' = -(1 - mu) (r - r1) / |r - r1|^3 - mu (r - r2) / |r - r2|^3 - 2 w x v - w x (w x r)

The gravity is an ordinary user force with its potential U = -(1 - mu)/r1 - mu/r2; the frame's
terms are rotframe's (`rotframe.problem.particles.simulate_particles`): this scene is
built only on the public API for your own problems. The Jacobi constant is
C = 2 Omega - v^2 with Omega = (x^2 + y^2)/2 + (1 - mu)/r1 + mu/r2 (C = -2 J, J the Jacobi
integral rotframe reports as ``jacobi_rel_drift``).

Theory: the five Lagrange points, the collinear ones from the quintics of Szebehely
(section 4.5), L4 and L5 at the apexes of the equilateral triangles; Routh's criterion
mu < mu_R = (1 - sqrt(23/27)) / 2 = 0.03852 for the linear stability of L4. The metrics are
the collinear points found by Brent's method on the force the run integrates (an independent
route to the same numbers), and the largest distance from L4 along the orbit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotframe.problem.particles import Force, simulate_particles
from rotframe.scenes.base import SceneResult, guarded, run_setting, with_parameters

__all__ = ["Cr3bpParameters", "PARAMETERS", "METHODS", "simulate", "analyse", "record", "lagrange_points",
           "ROUTH_MU", "zero_velocity_curve", "jacobi_constant"]

#: Routh's critical mass ratio for the linear stability of L4 and L5
ROUTH_MU = 0.5 * (1.0 - math.sqrt(23.0 / 27.0))

METHODS = ("dop853", "rk4")
DEFAULT_METHOD = "dop853"
#: an orbit that goes farther than this from L4 (primaries' distances) has left it
LEFT_L4 = 0.5


@dataclass(frozen=True, kw_only=True)
class Cr3bpParameters:
    """Parameters of the CR3BP scene (dimensionless: the primaries' distance and mean motion are 1)."""

    mu: float
    offset: tuple[float, ...]
    velocity: tuple[float, ...]
    periods: float


PARAMETERS = Cr3bpParameters


def gravity(t, r, v, mu):
    """Gravity of the two primaries (dimensionless), frame axes."""
    x, y, z = r[0], r[1], r[2]
    d1x = x + mu
    d2x = x - 1.0 + mu
    r1 = math.sqrt(d1x * d1x + y * y + z * z)
    r2 = math.sqrt(d2x * d2x + y * y + z * z)
    k1 = (1.0 - mu) / (r1 * r1 * r1)
    k2 = mu / (r2 * r2 * r2)
    return -k1 * d1x - k2 * d2x, -(k1 + k2) * y, -(k1 + k2) * z


def gravity_potential(t, r, mu):
    """U = -(1 - mu)/r1 - mu/r2 (dimensionless)."""
    x, y, z = r[0], r[1], r[2]
    r1 = math.sqrt((x + mu) ** 2 + y * y + z * z)
    r2 = math.sqrt((x - 1.0 + mu) ** 2 + y * y + z * z)
    return -(1.0 - mu) / r1 - mu / r2


def lagrange_points(mu):
    """The five Lagrange points, (5, 3): L1, L2, L3 from Szebehely's quintics, L4, L5 closed form."""
    quintics = {  # gamma: L1, L2 distance from m2; L3 distance from m1
        1: [1.0, -(3.0 - mu), 3.0 - 2.0 * mu, -mu, 2.0 * mu, -mu],
        2: [1.0, 3.0 - mu, 3.0 - 2.0 * mu, -mu, -2.0 * mu, -mu],
        3: [1.0, 2.0 + mu, 1.0 + 2.0 * mu, -(1.0 - mu), -2.0 * (1.0 - mu), -(1.0 - mu)],
    }
    gam = {}
    for k, coeffs in quintics.items():
        roots = np.roots(coeffs)
        real = roots[(np.abs(roots.imag) < 1e-9) & (roots.real > 0)].real
        g = float(real[0])
        # one Newton step on the polynomial itself polishes numpy's companion-matrix root
        p, dp = np.polyval(coeffs, g), np.polyval(np.polyder(coeffs), g)
        gam[k] = g - p / dp
    return np.array([[1.0 - mu - gam[1], 0, 0], [1.0 - mu + gam[2], 0, 0], [-mu - gam[3], 0, 0],
                     [0.5 - mu, math.sqrt(3) / 2, 0], [0.5 - mu, -math.sqrt(3) / 2, 0]])


def jacobi_constant(r, v, mu):
    """C = 2 Omega - v^2 at positions ``r`` (..., 3) and velocities ``v`` (..., 3)."""
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    r1 = np.sqrt((x + mu) ** 2 + y * y + z * z)
    r2 = np.sqrt((x - 1 + mu) ** 2 + y * y + z * z)
    omega = 0.5 * (x * x + y * y) + (1 - mu) / r1 + mu / r2
    return 2 * omega - np.sum(v * v, axis=-1)


def zero_velocity_curve(mu, C, extent=1.6, n=401):
    """Segments (k, 2, 3) of the curve 2 Omega(x, y) = C in the plane z = 0 (marching squares)."""
    xs = np.linspace(-extent, extent, n)
    X, Y = np.meshgrid(xs, xs, indexing="xy")
    with np.errstate(divide="ignore"):
        F = jacobi_constant(np.stack([X, Y, np.zeros_like(X)], -1), np.zeros(X.shape + (3,)), mu) - C
    F = np.where(np.isfinite(F), F, 1e6)
    segs = []
    f = [F[:-1, :-1], F[:-1, 1:], F[1:, 1:], F[1:, :-1]]
    px = [X[:-1, :-1], X[:-1, 1:], X[1:, 1:], X[1:, :-1]]
    py = [Y[:-1, :-1], Y[:-1, 1:], Y[1:, 1:], Y[1:, :-1]]
    points = []
    for a in range(4):
        b = (a + 1) % 4
        cross = (f[a] > 0) != (f[b] > 0)
        s = np.where(cross, f[a] / np.where(f[a] - f[b] == 0, 1, f[a] - f[b]), np.nan)
        points.append((cross, px[a] + s * (px[b] - px[a]), py[a] + s * (py[b] - py[a])))
    count = sum(p[0].astype(int) for p in points)
    for i, j in zip(*np.nonzero(count >= 2)):
        pts = [(p[1][i, j], p[2][i, j]) for p in points if p[0][i, j]]
        for k in range(0, len(pts) - 1, 2):
            segs.append([[pts[k][0], pts[k][1], 0.0], [pts[k + 1][0], pts[k + 1][1], 0.0]])
    return np.array(segs).reshape(-1, 2, 3)


@with_parameters(Cr3bpParameters)
def simulate(p, terms, method, run, progress):
    mu = float(p.mu)
    L4 = lagrange_points(mu)[3]
    r0 = L4 + np.asarray(p.offset, dtype=float)
    v0 = np.asarray(p.velocity, dtype=float)
    duration = 2 * math.pi * float(p.periods)
    method = method or DEFAULT_METHOD

    def finish(run_out):  # a ProblemRun, or the trajectory up to an early stop
        traj = getattr(run_out, "trajectory", run_out)
        extras = {"diagnostics": getattr(run_out, "diagnostics", {}), "notes": getattr(run_out, "notes", []),
                  "L4": L4, "warnings": getattr(run_out, "warnings", [])}
        return SceneResult(traj, list(terms), traj.method, traj.steps, traj.nfev, extras=extras)

    return guarded(finish, simulate_particles, omega=[0.0, 0.0, 1.0], r0=r0, v0=v0, duration=duration,
                   forces=[Force(gravity, potential=gravity_potential, name="two primaries")], params=(mu,),
                   method=method, rtol=run_setting(run, "rtol"), step=run.get("step"),
                   samples=int(run_setting(run, "samples")), progress=progress)


def _collinear_by_brent(mu):
    """L1, L2, L3 as zeros of the effective acceleration on the x axis, by Brent's method on ``gravity``."""
    from scipy.optimize import brentq

    def ax(x):
        return gravity(0.0, (x, 0.0, 0.0), None, mu)[0] + x  # + centrifugal x (omega = 1)

    eps = 1e-9
    return (brentq(ax, -mu + eps, 1 - mu - eps, xtol=1e-15, rtol=1e-15),
            brentq(ax, 1 - mu + eps, 2.0, xtol=1e-15, rtol=1e-15),
            brentq(ax, -2.0, -mu - eps, xtol=1e-15, rtol=1e-15))


@with_parameters(Cr3bpParameters)
def analyse(p, result):
    traj = result.trajectory
    mu = float(p.mu)
    pts = lagrange_points(mu)
    r = traj.r[:, 0]
    v = traj.v[:, 0]
    L4 = result.extras["L4"]
    dist = np.linalg.norm(r - L4, axis=1)
    b1, b2, b3 = _collinear_by_brent(mu)
    metrics = {"L1_x": b1, "L2_x": b2, "L3_x": b3, "max_distance_from_L4": float(np.max(dist)),
               "left_L4": float(np.max(dist) > LEFT_L4)}
    theory = {"L1_x": float(pts[0, 0]), "L2_x": float(pts[1, 0]), "L3_x": float(pts[2, 0]),
              "left_L4": float(mu > ROUTH_MU)}
    notes = {"L1_x": "exact: the root of Szebehely's quintic (numpy.roots, one Newton step)",
             "L2_x": "exact: the root of Szebehely's quintic", "L3_x": "exact: the root of Szebehely's quintic",
             "left_L4": f"1 if the orbit went farther than {LEFT_L4} from L4, else 0; theory by Routh's criterion: L4 is linearly unstable for mu > {ROUTH_MU:.7f}; indicative for a "
                        "finite displacement (a tadpole may also leave through nonlinear effects)"}
    tolerance = {k: 1e-12 * max(1.0, abs(theory[k])) for k in ("L1_x", "L2_x", "L3_x")}
    C = jacobi_constant(r, v, mu)
    diagnostics = dict(result.extras["diagnostics"])
    diagnostics["jacobi_constant"] = float(C[0])
    warnings = list(result.extras.get("warnings", []))
    if metrics["left_L4"] != theory["left_L4"]:
        warnings.append(f"the orbit {'left' if metrics['left_L4'] else 'stayed near'} L4 (largest distance "
                        f"{metrics['max_distance_from_L4']:.3g}) although Routh's criterion says "
                        f"{'unstable' if theory['left_L4'] else 'stable'} for mu = {mu:g}: a large start offset, "
                        "or too short a run")
    return {"metrics": metrics, "theory": theory, "theory_notes": notes, "tolerance": tolerance,
            "diagnostics": diagnostics, "notes": list(result.extras.get("notes", [])), "warnings": warnings}


@with_parameters(Cr3bpParameters, position=1)
def record(rec, p, result):
    traj = result.trajectory
    mu = float(p.mu)
    r = traj.r[:, 0]
    rec.points("world/body", traj.times, r, radius=0.005, color=[230, 90, 40])
    rec.line("world/orbit", r, color=[230, 90, 40])
    pts = lagrange_points(mu)
    rec.static("world/lagrange_points", "Points3D", positions=pts, radii=[0.012], colors=[[250, 250, 250]],
               labels=["L1", "L2", "L3", "L4", "L5"])
    rec.static("world/primaries", "Points3D", positions=[[-mu, 0, 0], [1 - mu, 0, 0]],
               radii=[0.04, 0.02], colors=[[60, 140, 230], [200, 200, 200]], labels=["m1", "m2"])
    C = jacobi_constant(r[0], traj.v[0, 0], mu)
    segs = zero_velocity_curve(mu, float(C))
    if len(segs):
        rec.static("world/zero_velocity_curve", "LineStrips3D", strips=segs, colors=[[120, 200, 120]])
    Cs = jacobi_constant(r, traj.v[:, 0], mu)
    rec.scalars("diagnostics/jacobi_rel_error", traj.times, (Cs - Cs[0]) / abs(Cs[0]))
    rec.scalars("diagnostics/distance_from_L4", traj.times, np.linalg.norm(r - pts[3], axis=1))
    rec.view(eye=(0.0, -0.6, 3.2), look_at=(0.0, 0.0, 0.0))  # from above the plane: all five points and the orbit
