"""The rigid-body scenarios end to end: metrics against theory, recordings, degenerate bodies."""

import math
import subprocess
import sys

import numpy as np
import pytest

from rotframe.app import runner
def run(name, method=None, **sets):
    return runner.run(name, {k: str(v) for k, v in sets.items()}, method=method)


@pytest.mark.parametrize("eps,period", [(1e-2, 39.1), (1e-4, 71.0), (1e-6, 102.9)])
def test_flip_interval_follows_the_ln_one_over_eps_law(eps, period):
    # docs/physics/rigid-bodies.md: for I = (1, 2, 3), w0 = (eps, 1, eps) the period of w is 39.1, 71.0, 102.9 s
    s, _ = run("dzhanibekov", omega=f"{eps},1,{eps}", duration=4 * period)
    assert s["metrics"]["flip_interval_s"] == pytest.approx(period / 2, abs=0.06)
    assert s["metrics"]["flip_interval_s"] == pytest.approx(s["theory"]["flip_interval_s"], rel=1e-6)


@pytest.mark.parametrize("method,step,tol", [("exact", None, 1e-14), ("lie-poisson", 1e-2, 1e-13),
                                             ("lie-poisson4", 1e-2, 1e-13), ("rk4", 1e-2, 1e-6)])
def test_every_free_body_method_flips_at_the_elliptic_interval(method, step, tol):
    sets = {"step": step} if step else {}
    s, _ = run("dzhanibekov", method=method, **sets)
    assert s["metrics"]["flip_interval_s"] == pytest.approx(s["theory"]["flip_interval_s"], rel=1e-4)
    assert s["metrics"]["momentum_rel_drift"] < tol


def test_dzhanibekov_recording_shows_the_flips(tmp_path):
    from rerun.chunk import RrdReader

    out = tmp_path / "dz.rrd"
    res = subprocess.run([sys.executable, "-m", "rotframe", "run", "dzhanibekov", "--out", str(out)],
                         capture_output=True, text=True, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    omega2, transforms = [], 0
    for chunk in RrdReader(str(out)).stream():
        rb = chunk.to_record_batch()
        if chunk.entity_path == "/diagnostics/omega_body/2":
            col = rb.column("Scalars:scalars").to_pylist()
            omega2.extend(v[0] for v in col)
        if chunk.entity_path == "/world/body" and not chunk.is_static:
            transforms += chunk.num_rows
    signs = np.sign(np.array(omega2))
    assert np.count_nonzero(signs[1:] != signs[:-1]) >= 8  # 200 s at a 19.6 s flip interval
    assert transforms > 100


def test_earth_free_top_gives_the_euler_period():
    s, _ = run("free-top")
    assert s["diagnostics"]["body_precession_period_sidereal_days"] == pytest.approx(304.5, abs=0.5)
    assert s["metrics"]["space_precession_rate_rad_s"] == pytest.approx(s["theory"]["space_precession_rate_rad_s"],
                                                                        rel=1e-9)


def test_free_top_symmetric_precession_rate():
    s, _ = run("free-top", i1=2.0, i3=3.0, omega3=5.0, omega_perp=0.5, duration=20)
    k = 5.0 * (3.0 - 2.0) / 2.0
    assert s["metrics"]["body_precession_period_s"] == pytest.approx(2 * math.pi / k, rel=1e-9)


def test_heavy_top_turning_angles_match_the_cubic():
    for method in ("splitting", "splitting4"):
        s, _ = run("heavy-top", method=method, duration=2)
        assert s["metrics"]["theta_max_deg"] == pytest.approx(s["theory"]["theta_max_deg"], abs=1e-3)
        assert s["metrics"]["theta_min_deg"] == pytest.approx(s["theory"]["theta_min_deg"], abs=1e-3)
        assert s["metrics"]["nutation_period_s"] == pytest.approx(s["theory"]["nutation_period_s"], rel=1e-3)


@pytest.mark.parametrize("factor,stays_up", [(1.2, True), (0.8, False)])
def test_sleeping_top_threshold_from_both_sides(factor, stays_up):
    i1, i3, m, l, g = 1.9e-4, 2.5e-5, 0.1, 0.04, 9.81
    critical = math.sqrt(4 * m * g * l * i1) / i3  # I3^2 w3^2 = 4 I1 m g l
    s, _ = run("heavy-top", theta0=0, wobble=1e-4, psidot0=factor * critical, duration=3)
    assert s["diagnostics"]["sleeping_top_stable"] is stays_up
    if stays_up:
        assert s["metrics"]["theta_max_deg"] < 0.01
    else:
        assert s["metrics"]["theta_max_deg"] > 30


@pytest.mark.parametrize("sets", [{"i1": 2, "i2": 2, "i3": 2},           # sphere
                                  {"i1": 1, "i2": 1, "i3": 2},           # symmetric
                                  {"i1": 1, "i2": 1, "i3": 0, "omega": "0.3,1,0"}])  # thin rod
def test_degenerate_bodies_run_without_nan(sets):
    for method in ("exact", "lie-poisson"):
        s, result = run("dzhanibekov", method=method, **sets, duration=20)
        assert np.all(np.isfinite(result.trajectory.L)) and np.all(np.isfinite(result.trajectory.q))


@pytest.mark.parametrize("args", [["dzhanibekov", "--set", "i3=5"],        # triangle inequality
                                  ["dzhanibekov", "--set", "omega=1,2"],    # not three numbers
                                  ["dzhanibekov", "--set", "i1=-1"],
                                  ["heavy-top", "--method", "lie-poisson"]])
def test_impossible_bodies_exit_2(tmp_path, args):
    res = subprocess.run([sys.executable, "-m", "rotframe", "run", *args, "--no-record"], cwd=tmp_path,
                         capture_output=True, text=True)
    assert res.returncode == 2, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1


def test_kinetic_energy_equals_the_seed_euler_angle_formula_along_a_heavy_top_run():
    # T = I1/2 (phidot^2 sin^2 theta + thetadot^2) + I3/2 (phidot cos theta + psidot)^2 (the lecture),
    # with the angles read from the quaternions and the rates from omega via rotframe.frames
    from rotframe import frames
    from rotframe.rigid import dynamics as rigid
    from rotframe.scenes.heavy_top import euler_angles

    s, result = run("heavy-top", duration=0.5)
    traj = result.trajectory
    inertia = result.extras["inertia"]
    angles = euler_angles(traj.q[::50], "ZXZ")
    omega = traj.L[::50] / inertia
    rates = frames.omega_to_euler_rates(angles, omega, seq="ZXZ", frame="body")
    T_seed = rigid.symmetric_top_euler_energy(inertia[0], inertia[2], *angles.T, *rates.T)
    T_body = rigid.energy(inertia, traj.L[::50])
    assert np.allclose(T_seed, T_body, rtol=1e-12)


def test_torque_depending_on_time_and_state_matches_solve_ivp():
    # body torque: a time-varying push about axis 1 plus damping of the spin (depends on L)
    from scipy.integrate import solve_ivp

    from rotframe.rigid import dynamics as rigid
    inertia = np.array([1.0, 2.0, 3.0])
    L0 = np.array([0.2, 1.0, 0.3])
    q0 = np.array([0.0, 0.0, 0.0, 1.0])

    def torque(t, L, q):
        return np.array([0.1 * np.sin(2.0 * t), 0.0, 0.0]) - 0.05 * L

    def rhs(t, y):
        L, q = y[:3], y[3:]
        w = L / inertia
        x, yq, z, s = q
        dq = 0.5 * np.array([s * w[0] + yq * w[2] - z * w[1], s * w[1] + z * w[0] - x * w[2],
                             s * w[2] + x * w[1] - yq * w[0], -x * w[0] - yq * w[1] - z * w[2]])
        return np.concatenate([np.cross(L, w) + torque(t, L, q), dq])

    T = 10.0
    ref = solve_ivp(rhs, (0, T), np.concatenate([L0, q0]), method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]
    errors = []
    for h in (1e-2, 5e-3):
        L, q, _ = rigid.torqued_splitting(inertia, L0, q0, h, int(round(T / h)), torque, order=2)
        errors.append(np.linalg.norm(L[-1] - ref[:3]))
    assert errors[0] < 1e-3
    assert 3.5 < errors[0] / errors[1] < 4.5  # second order
    # a constant torque through the callable equals the compiled constant-torque path
    Lc, qc, _ = rigid.torqued_splitting(inertia, L0, q0, 1e-2, 500, lambda t, L, q: np.array([0.1, 0.0, 0.2]))
    Lk, qk, _ = rigid.lie_poisson(inertia, L0, q0, 1e-2, 500, torque=[0.1, 0.0, 0.2])
    assert np.allclose(Lc[-1], Lk[-1], atol=1e-12)
