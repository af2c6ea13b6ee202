"""The rigid scenes' ``dop853`` method (rotframe.scenes.rigid_base) against independent references.

References: scipy's solve_ivp DOP853 at rtol 1e-12 with a right-hand side written here
(torque r_cm x F from scipy's Rotation, not rotframe's kernel), the conserved quantities of
the heavy top (energy, the vertical component of L in space, L3 in the body) and of the
free body (energy, |L|), and the elliptic-function theory the scenes report.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from rotframe.app import runner
from rotframe.errors import ScenarioError
from rotframe.scenes import rigid_base

MASS, G, LENGTH = 0.1, 9.81, 0.04  # heavy-top.toml defaults


def run(name, method="dop853", **sets):
    return runner.run(name, {k: str(v) for k, v in sets.items()}, method=method)


def top_rhs(I, m, g, l):
    """Euler's equations in body axes with the torque l e3 x F_body of the weight, and dq/dt = q (w, 0) / 2."""
    def f(t, y):
        L, q = y[:3], y[3:]
        R = Rotation.from_quat(q / np.linalg.norm(q)).as_matrix()  # body -> space
        w = L / I
        N = np.cross([0.0, 0.0, l], R.T @ np.array([0.0, 0.0, -m * g]))
        x, yq, z, s = q
        dq = 0.5 * np.array([s * w[0] + yq * w[2] - z * w[1], s * w[1] + z * w[0] - x * w[2],
                             s * w[2] + x * w[1] - yq * w[0], -(x * w[0] + yq * w[1] + z * w[2])])
        return np.concatenate([np.cross(L, w) + N, dq])
    return f


def angle(q, q_ref):
    """Rotation angle (rad) between unit quaternions, |q - q_ref| = 2 sin(angle / 4) with the closer sign."""
    s = np.where(np.sum(q * q_ref, axis=-1) < 0, -1.0, 1.0)[..., None]
    return 4 * np.arcsin(np.minimum(1.0, 0.5 * np.linalg.norm(q - s * q_ref, axis=-1)))


def test_heavy_top_dop853_matches_an_independent_solve_ivp():
    # 1 s of the default top (4.5 nutations, 300 rad of spin) at rtol 1e-10. The reference's own error at
    # rtol 1e-12 is ~1e-10 (100 times smaller than rotframe's, measured 6e-9 in L and 2e-8 rad in
    # attitude over 2 s); the bound 10 n rtol of rigid_base.adaptive_rel_error is 5.6e-7 for the ~560
    # steps, which the run must honour
    s, res = run("heavy-top", duration=1.0, samples=2000, rtol=1e-10)
    tr = res.trajectory
    assert s["method"] == "dop853" and tr.method == "dop853" and tr.extras["rtol"] == 1e-10
    I = res.extras["inertia"]
    M = np.linalg.norm(tr.L[0])
    every = 40
    ref = solve_ivp(top_rhs(I, MASS, G, LENGTH), (0, tr.times[-1]), np.concatenate([tr.L[0], tr.q[0]]),
                    method="DOP853", rtol=1e-12, atol=np.array([1e-12 * M] * 3 + [1e-12] * 4),
                    t_eval=tr.times[::every])
    qr = ref.y[3:].T / np.linalg.norm(ref.y[3:].T, axis=1)[:, None]
    eL = np.max(np.linalg.norm(tr.L[::every] - ref.y[:3].T, axis=1)) / M
    eq = np.max(angle(tr.q[::every], qr))
    bound = rigid_base.adaptive_rel_error(tr)
    assert bound <= 1e-6
    assert eL < bound and eq < bound, (eL, eq, bound)
    assert eL > 1e-12 or eq > 1e-12  # a real comparison, not the same numbers


def test_heavy_top_dop853_keeps_the_invariants():
    # energy (T + m g l cos theta), L_z in space and L3 in the body are exact invariants of the Lagrange top;
    # the default run (dop853 at rtol 1e-9 over 10 s, 4222 steps) must keep them within 10 n rtol = 4.2e-5
    # (measured: energy 3.5e-9, L_z 7.6e-8; L3 stays exact, the I1 = I2 top has no torque or coupling on it)
    s, res = run("heavy-top")
    tr = res.trajectory
    assert s["method"] == "dop853" and tr.extras["rtol"] == 1e-9  # heavy-top.toml's default
    I = res.extras["inertia"]
    R = Rotation.from_quat(tr.q).as_matrix()
    e3 = R[:, :, 2]
    E = 0.5 * np.sum(tr.L ** 2 / I, axis=1) + MASS * G * LENGTH * e3[:, 2]
    Lz = np.einsum("nij,nj->ni", R, tr.L)[:, 2]
    bound = rigid_base.adaptive_rel_error(tr)
    assert np.max(np.abs(E / E[0] - 1)) < bound
    assert np.max(np.abs(Lz / Lz[0] - 1)) < bound
    assert np.max(np.abs(tr.L[:, 2] / tr.L[0, 2] - 1)) < bound
    # the turning angles agree with Goldstein's cubic within the stated tolerance, and no warning is raised
    assert s["warnings"] == []
    for key in ("theta_min_deg", "theta_max_deg", "nutation_period_s"):
        assert s["metrics"][key] == pytest.approx(s["theory"][key], rel=1e-5)


def test_free_bodies_dop853_keep_energy_and_momentum_and_flip_on_time():
    # the Dzhanibekov flip at rtol 1e-10: flip interval = half the elliptic period (theory of the scene,
    # Jacobi functions) within the flip tolerance; energy and |L| drift below the 10 n rtol bound
    s, res = run("dzhanibekov")
    tr = res.trajectory
    bound = rigid_base.adaptive_rel_error(tr)
    assert s["metrics"]["energy_rel_drift"] < bound and s["metrics"]["momentum_rel_drift"] < bound
    assert s["metrics"]["flip_interval_s"] == pytest.approx(s["theory"]["flip_interval_s"], rel=1e-7)
    assert s["warnings"] == []
    # the free symmetric top: the measured rates agree with the closed forms (|L| / I1 and 2 pi I1 / |k|)
    s, _ = run("free-top", i1=2.0, i3=3.0, omega3=5.0, omega_perp=0.5, duration=20)
    for key in ("body_precession_period_s", "space_precession_rate_rad_s"):
        assert s["metrics"][key] == pytest.approx(s["theory"][key], rel=1e-7)
    assert s["warnings"] == []


def test_dop853_matches_the_exact_free_flow_across_calls():
    # many samples (the engine's dense output between steps, its calls sized in time): the result stays on the
    # elliptic-function flow (an independent algorithm) to the 10 n rtol bound
    n = 2 * 4096 + 7
    _, res = run("dzhanibekov", samples=n, duration=100, rtol=1e-11)
    _, ex = run("dzhanibekov", method="exact", samples=n, duration=100)
    a, b = res.trajectory, ex.trajectory
    assert len(a.times) == len(b.times) == n + 1
    bound = rigid_base.adaptive_rel_error(a)
    M = np.linalg.norm(b.L[0])
    assert np.max(np.linalg.norm(a.L - b.L, axis=1)) / M < bound
    assert np.max(angle(a.q, b.q)) < bound
    assert a.extras["nfev"] > a.steps > 0


@pytest.mark.parametrize("sets,match", [({"rtol": 2.0}, "rtol"), ({"i1": 1.0, "i2": 1.0, "i3": 0.0}, "moments")])
def test_dop853_refuses_what_it_cannot_do(sets, match):
    with pytest.raises(ScenarioError, match=match):
        run("dzhanibekov", **sets)


def test_dop853_is_listed_for_the_rigid_scenes():
    from rotframe.app.scenario import methods_for

    for name in ("heavy-top", "free-top", "dzhanibekov"):
        assert "dop853" in methods_for(name)
