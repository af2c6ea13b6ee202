"""Bench rows for your own problem: a user force beside the built-in term, and cr3bp beside scipy.

``user-force``: gravity plus a spring written as a user force (``rotframe.simulate``) against
the same physics as built-in terms (``integrate_particles`` with ``gravity`` and ``spring``),
both DOP853 at the same tolerance in the same rotating frame. The row compares the cost of
one right-hand-side evaluation (wall time over evaluations, drivers warmed and compiled), the
issue's goal being at most 1.5 times the built-in's; the two final states must agree to the
tolerance (``same_answer_rel``).

``cr3bp``: the scene's orbit (100 synodic periods near L4) by ``rotframe.problem`` against
scipy's ``solve_ivp`` (DOP853) with a numba-compiled right-hand side, at the same rtol; each
row gives the wall time and the error against a tighter rotframe run, and, where jax and
diffrax are installed (the ``bench`` extra), diffrax's jit-compiled Dopri8 at the same rtol.
"""

from __future__ import annotations

import math
import time

import numpy as np

__all__ = ["user_force_rows"]


def _best(fn, repeats):
    best = math.inf
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _gravity_spring(t, r, v, gz, k):
    return -k * r[0], -k * r[1], gz  # the built-in spring is horizontal (the linearised pendulum)


def user_force_rows(quick=False):
    """The ``user-force`` and ``cr3bp`` rows (see the module docstring)."""
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel
    from rotframe.problem.particles import simulate_particles

    w = np.array([0.0, 4.6e-5, 5.7e-5])
    k, gz = 0.3, -9.81
    T = 200.0 if quick else 2000.0
    rtol = 1e-10
    r0, v0 = np.array([1.0, 2.0, 3.0]), np.array([0.5, 0.0, 0.0])
    repeats = 3 if quick else 7
    model = ParticleModel(("gravity", "spring", "coriolis", "centrifugal"), omega=OmegaSchedule.constant(w),
                          g=np.array([0.0, 0.0, gz]), spring=k)

    def builtin():
        return integrate_particles(model, r0, v0, T, method="dop853", rtol=rtol, samples=10)

    def user(inline):
        return simulate_particles(omega=w, r0=r0, v0=v0, duration=T, forces=[_gravity_spring], params=(gz, k),
                                  rtol=rtol, samples=10, inline=inline).trajectory

    builtin(), user(False), user(True)  # compile (or load) each
    tb, a = _best(builtin, repeats)
    per_b = tb / max(a.nfev, 1)
    scale = float(np.max(np.abs(a.r[-1])))
    rows = []
    for inline, method, note in (
            (False, "dop853", "gravity + spring as a user force vs the built-in terms, cost per evaluation (includes "
                              "each driver's per-step work); the engine calls the force by address"),
            (True, "dop853 inlined", "the same, in the loop compiled with the force in it (inline=True, "
                                     "rotframe.problem.inlined): what a long run switches to")):
        tu, b = _best(lambda: user(inline), repeats)
        per_u = tu / max(b.nfev, 1)
        rows.append({"scenario": "user-force", "kind": "user-force", "method": method, "setting": rtol,
                     "wall_s": tu, "builtin_wall_s": tb, "nfev": int(b.nfev), "builtin_nfev": int(a.nfev),
                     "per_eval_s": per_u, "builtin_per_eval_s": per_b, "ratio": per_u / per_b, "goal": 1.5,
                     "met": bool(per_u / per_b <= 1.5), "error": math.nan, "error_kind": "none",
                     "same_answer_rel": float(np.max(np.abs(a.r[-1] - b.r[-1]))) / scale, "note": note})
    rows.append(_prepared_row(model, w, r0, v0, rtol, repeats))
    rows.extend(_cr3bp_rows(quick, repeats))
    return rows


def _prepared_row(model, w, r0, v0, rtol, repeats):
    """A short run (1 s of the same problem, DOP853) set up once and run again: what a run costs beyond its
    integration, the user's problem (`rotframe.problem.prepared.PreparedProblem`) against the built-in terms (the
    scenes' `rotframe.particles.prepared.PreparedRun`), with ``simulate``'s whole call beside them."""
    from rotframe.particles.prepared import PreparedRun
    from rotframe.problem.particles import simulate_particles
    from rotframe.problem.prepared import PreparedProblem

    kw = dict(omega=w, duration=1.0, forces=[_gravity_spring], params=(model.g[2], model.spring), rtol=rtol,
              samples=10)
    prepared = PreparedProblem(r0=r0, v0=v0, **kw)
    builtin = PreparedRun(model, "dop853", 1.0, rtol=rtol, samples=10)
    mine, theirs = prepared.run(r0, v0), builtin(r0, v0)
    t_sim, _ = _best(lambda: simulate_particles(r0=r0, v0=v0, inline=True, **kw), repeats)
    t_mine, _ = _best(lambda: prepared.run(r0, v0), repeats * 10)
    t_theirs, _ = _best(lambda: builtin(r0, v0), repeats * 10)
    scale = float(np.max(np.abs(theirs[0][-1])))
    return {"scenario": "user-force", "kind": "user-force", "method": "dop853 prepared, 1 s", "setting": rtol,
            "wall_s": t_mine, "builtin_wall_s": t_theirs, "simulate_wall_s": t_sim, "nfev": int(mine.nfev),
            "builtin_nfev": int(builtin.nfev), "ratio": t_mine / t_theirs, "error": math.nan, "error_kind": "none",
            "same_answer_rel": float(np.max(np.abs(mine.r[-1] - theirs[0][-1]))) / scale,
            "note": "a 1 s run set up once and run again: the user's problem (PreparedProblem, inlined) against the "
                    "built-in terms (the scenes' PreparedRun), the whole run each; simulate_wall_s is a whole "
                    "rotframe.simulate call of it (checks, glue lookup, energy diagnostic)"}


def _cr3bp_rows(quick, repeats):
    import numba
    from scipy.integrate import solve_ivp

    from rotframe.problem.particles import Force, simulate_particles
    from rotframe.scenes.cr3bp import gravity, gravity_potential, lagrange_points

    mu = 0.01215058560962404
    r0 = lagrange_points(mu)[3] + [0.01, 0.0, 0.0]
    T = 2 * math.pi * (10 if quick else 100)

    @numba.njit(cache=True)
    def rhs(t, y):
        x, yy, z, vx, vy, vz = y[0], y[1], y[2], y[3], y[4], y[5]
        d1 = x + mu
        d2 = x - 1 + mu
        r1 = math.sqrt(d1 * d1 + yy * yy + z * z)
        r2 = math.sqrt(d2 * d2 + yy * yy + z * z)
        k1 = (1 - mu) / r1 ** 3
        k2 = mu / r2 ** 3
        out = np.empty(6)
        out[0], out[1], out[2] = vx, vy, vz
        out[3] = x + 2 * vy - k1 * d1 - k2 * d2
        out[4] = yy - 2 * vx - (k1 + k2) * yy
        out[5] = -(k1 + k2) * z
        return out

    def ours(rtol):
        return simulate_particles(omega=[0, 0, 1.0], r0=r0, v0=np.zeros(3), duration=T,
                                  forces=[Force(gravity, potential=gravity_potential)], params=(mu,), rtol=rtol,
                                  samples=1).trajectory.r[-1, 0]

    y0 = np.concatenate([r0, np.zeros(3)])

    def scipy_run(rtol):
        return solve_ivp(rhs, (0, T), y0, method="DOP853", rtol=rtol, atol=rtol * 1e-3).y[:3, -1]

    ref = ours(1e-14)
    jax_run = _diffrax_cr3bp(mu, y0, T)
    rows = []
    for rtol in (1e-6, 1e-9, 1e-12):
        scipy_run(rtol)
        t_o, a = _best(lambda: ours(rtol), repeats)
        t_s, b = _best(lambda: scipy_run(rtol), max(1, repeats // 2))
        row = {"scenario": "cr3bp", "kind": "cr3bp", "method": "dop853 (rotframe.problem)", "setting": rtol,
               "wall_s": t_o, "error": float(np.linalg.norm(a - ref)), "error_kind": "position vs rtol 1e-14",
               "peer": "scipy DOP853 + numba rhs", "peer_wall_s": t_s,
               "peer_error": float(np.linalg.norm(b - ref)), "speedup": t_s / t_o, "nfev": 0}
        if jax_run is not None:
            t_d, c = _best(lambda: jax_run(rtol), repeats)
            row.update({"diffrax_wall_s": t_d, "diffrax_error": float(np.linalg.norm(c - ref)),
                        "speedup_vs_diffrax": t_d / t_o})
        else:
            row["diffrax"] = "not installed (pip install 'rotframe[bench]')"
        rows.append(row)
    return rows


def _diffrax_cr3bp(mu, y0, T):
    """diffrax's Dopri8 on the CR3BP (jax.jit-compiled once, rtol traced), or None without jax/diffrax."""
    try:
        import diffrax
        import jax
    except Exception:  # noqa: BLE001 (any import failure: no diffrax row)
        return None
    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp

    def field(t, y, args):
        x, yy, z, vx, vy, vz = y[0], y[1], y[2], y[3], y[4], y[5]
        d1 = x + mu
        d2 = x - 1 + mu
        r1 = jnp.sqrt(d1 * d1 + yy * yy + z * z)
        r2 = jnp.sqrt(d2 * d2 + yy * yy + z * z)
        k1 = (1 - mu) / r1 ** 3
        k2 = mu / r2 ** 3
        return jnp.stack([vx, vy, vz, x + 2 * vy - k1 * d1 - k2 * d2, yy - 2 * vx - (k1 + k2) * yy, -(k1 + k2) * z])

    term = diffrax.ODETerm(field)
    y0j = jnp.asarray(y0, dtype=jnp.float64)

    @jax.jit
    def solve(rtol):
        sol = diffrax.diffeqsolve(term, diffrax.Dopri8(), t0=0.0, t1=float(T), dt0=None, y0=y0j,
                                  stepsize_controller=diffrax.PIDController(rtol=rtol, atol=rtol),
                                  saveat=diffrax.SaveAt(t1=True), max_steps=4_000_000)
        return sol.ys[-1]

    def run(rtol):
        return np.asarray(solve(float(rtol)).block_until_ready())[:3]

    run(1e-6)  # compile
    return run
