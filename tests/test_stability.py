"""Stability suite: the hard cases, and what each method is expected to do on them.

Each test names the methods it expects to hold and the ones it expects to fail,
so this file documents where each method stops being trustworthy. Marked slow;
CI runs it (about a minute on two cores).
"""

import math

import numpy as np
import pytest

from rotframe.rigid import dynamics as rigid
from rotframe.errors import IntegrationError
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel

pytestmark = pytest.mark.slow
EPS = np.finfo(float).eps


# --- Dzhanibekov near the separatrix -------------------------------------------------


@pytest.mark.parametrize("eps", [1e-2, 1e-4, 1e-6])
def test_separatrix_exact_flow_and_splitting_hold_rk4_drifts(eps):
    inertia = np.array([1.0, 2.0, 3.0])
    L0 = inertia * np.array([eps, 1.0, eps])
    q0 = np.array([0.0, 0.0, 0.0, 1.0])
    period = rigid.elliptic_period(inertia, L0)
    T = 3 * period
    # exact: the state after three periods returns to the start (omega is periodic)
    L_exact, _ = rigid.free_body_exact(inertia, L0, q0, np.array([T]))
    assert np.linalg.norm(L_exact[0] - L0) / np.linalg.norm(L0) < 1e-9
    # splitting: |L| to round-off whatever the phase error; energy bounded
    h = 1e-2
    n = int(T / h)
    L, q, _ = rigid.lie_poisson(inertia, L0, q0, h, n, order=4, sample_every=50)
    M = np.linalg.norm(L, axis=1)
    turns = n * 3 * 5  # order 4: three order-2 steps of five exact turns each
    assert np.max(np.abs(M / M[0] - 1)) < 10 * EPS * math.sqrt(turns)  # round-off only
    E = rigid.energy(inertia, L)
    assert np.max(np.abs(E / E[0] - 1)) < 1e-8
    # RK4 at the same step keeps neither invariant to round-off (expected to drift)
    Lr, qr, _ = rigid.rigid_rk4(inertia, L0, q0, h, n, sample_every=50)
    Mr = np.linalg.norm(Lr, axis=1)
    assert np.max(np.abs(Mr / Mr[0] - 1)) > 1e-12


def test_nearly_equal_moments_and_the_sphere_are_exact_and_finite():
    q0 = np.array([0.0, 0.0, 0.0, 1.0])
    times = np.linspace(0, 50, 501)
    for inertia in ([1.0, 1.0 + 1e-12, 2.0], [1.0, 2.0 - 1e-12, 2.0], [2.0, 2.0, 2.0], [1.0, 1.0 + 1e-7, 1.0 + 2e-7]):
        inertia = np.array(inertia)
        L0 = inertia * np.array([0.3, 0.5, 1.0])
        L, q = rigid.free_body_exact(inertia, L0, q0, times)
        assert np.all(np.isfinite(L)) and np.all(np.isfinite(q))
        Ls, qs, _ = rigid.lie_poisson(inertia, L0, q0, 1e-3, 50000, order=4, sample_every=5000)
        assert np.linalg.norm(Ls[-1] - L[-1]) / np.linalg.norm(L0) < 1e-9
        # L is fixed in space for every method
        Lspace = rigid.angular_momentum_space(q, L)
        assert np.max(np.abs(Lspace - Lspace[0])) < 1e-10 * np.linalg.norm(L0)


# --- heavy tops ---------------------------------------------------------------------


def _top_state(theta0, psidot, i1=1.9e-4, i3=2.5e-5, phidot=0.0):
    from rotframe.scenes.heavy_top import build

    return build({"i1": i1, "i3": i3, "theta0": theta0, "phidot0": phidot, "psidot0": psidot, "wobble": 1e-4,
                  "mass": 0.1, "length": 0.04, "g": 9.81, "duration": 1.0})


@pytest.mark.parametrize("factor", [1.02, 0.98])
def test_sleeping_top_just_above_and_below_the_threshold(factor):
    m, l, g, i1, i3 = 0.1, 0.04, 9.81, 1.9e-4, 2.5e-5
    critical = rigid.sleeping_top_threshold(i1, i3, m, l, g)
    inertia, L0, q0 = _top_state(0.0, factor * critical)
    L, q, _ = rigid.heavy_top_splitting(i1, i3, m, l, g, L0, q0, 1e-4, 100000, order=2, sample_every=100)
    tilt = np.degrees(np.arccos(np.clip(rigid.body_to_space(q, [0, 0, 1.0])[:, 2], -1, 1)))
    if factor > 1:
        assert tilt.max() < 0.1  # stays up: the tilt stays of the order of the initial wobble
    else:
        assert tilt.max() > 10  # falls


def test_fast_heavy_top_splitting_is_stable_where_rk4_blows_up():
    # spin 1000 times the slow precession: the splitting's step is set by the precession,
    # RK4 needs to resolve the spin and diverges at the same step
    m, l, g, i1, i3 = 0.1, 0.04, 9.81, 1.9e-4, 2.5e-5
    psidot = 3000.0
    precession = m * g * l / (i3 * psidot)
    assert psidot / precession > 1000
    inertia, L0, q0 = _top_state(20.0, psidot)
    h = 2 * math.pi / psidot * 2.5  # 2.5 spin periods per step
    n = 4000
    L, q, _ = rigid.heavy_top_splitting(i1, i3, m, l, g, L0, q0, h, n, order=2, sample_every=40)
    assert np.all(np.isfinite(L))
    assert np.max(np.abs(L[:, 2] / L0[2] - 1)) < 1e-12  # p_psi = I3 w3 is kept exactly
    with pytest.raises(IntegrationError):
        Lr, qr, _ = rigid.rigid_rk4(inertia, L0, q0, h, n, mgl=m * g * l, sample_every=40)
        if np.all(np.isfinite(Lr)) and np.max(np.abs(np.linalg.norm(Lr, axis=1) / np.linalg.norm(L0) - 1)) > 1:
            raise IntegrationError("RK4 diverged")


# --- Foucault over a week --------------------------------------------------------------


def _foucault_model(lat_deg=48.846, L=67.0):
    from rotframe import earth

    lat = math.radians(lat_deg)
    g = float(earth.normal_gravity(lat))
    model = ParticleModel(("gravity", "coriolis", "pendulum"), omega=OmegaSchedule.constant(earth.omega_enu(lat)),
                          g=np.array([0, 0, -g]), pendulum_length=L, pivot=np.array([0.0, 0.0, L]))
    a = 3.0
    return model, np.array([a, 0, L - math.sqrt(L * L - a * a)]), g


def test_foucault_over_a_week_splitting_keeps_string_and_rate():
    from rotframe.scenes.foucault import measured_rates

    model, r0, g = _foucault_model()
    week = 7 * 86400.0
    traj = integrate_particles(model, r0, np.zeros(3), week, method="splitting", step=0.02, samples=40000)
    r = traj.r[:, 0]
    assert np.max(np.abs(np.linalg.norm(r - model.pivot, axis=1) - 67.0)) < 1e-11
    rate, period = measured_rates(traj.times, r, traj.v[:, 0], 67.0, g)
    omega_sin = float(np.linalg.norm(model.omega.vector())) * math.sin(math.radians(48.846))
    assert rate == pytest.approx(omega_sin * (1 - 3 / 8 * (3 / 67) ** 2), rel=1e-4)


def test_foucault_rk4_lets_the_string_stretch_splitting_does_not():
    model, r0, g = _foucault_model()
    day = 86400.0
    drift = {}
    for method in ("rk4", "splitting"):
        traj = integrate_particles(model, r0, np.zeros(3), day, method=method, step=0.05, samples=200)
        drift[method] = np.max(np.abs(np.linalg.norm(traj.r[:, 0] - model.pivot, axis=1) - 67.0))
    assert drift["splitting"] < 1e-11
    assert drift["rk4"] > 1e3 * drift["splitting"]  # RK4's constraint error grows secularly


# --- turntable near RK4's stability limit ------------------------------------------------


@pytest.mark.parametrize("wh,rk4_stable", [(2.6, True), (3.0, False)])
def test_turntable_near_rk4_stability_limit(wh, rk4_stable):
    # pure Coriolis rotates v at rate 2|omega|: RK4 is stable for 2|omega| h < 2 sqrt(2) = 2.83
    omega = 1.0
    h = wh / (2 * omega)
    model = ParticleModel(("coriolis",), omega=OmegaSchedule.constant([0, 0, omega]))
    v0 = np.array([1.0, 0.0, 0.0])
    n = 2000
    speeds = {}
    for method in ("splitting", "rk4"):
        try:
            traj = integrate_particles(model, np.zeros(3), v0, n * h, method=method, step=h, samples=100)
            speeds[method] = float(np.linalg.norm(traj.v[-1, 0]))
        except IntegrationError:
            speeds[method] = math.inf
    assert speeds["splitting"] == pytest.approx(1.0, abs=1e-12)  # exact rotation: any step
    if rk4_stable:
        assert speeds["rk4"] < 1.0  # damped, not exploding
    else:
        assert speeds["rk4"] > 1e10  # beyond the limit RK4 explodes


# --- round-off over 10^7 steps -------------------------------------------------------------


def test_ten_million_steps_round_off_grows_like_sqrt_n():
    # A symmetric body under the Lie-Poisson splitting: every sub-flow is exact, so the energy
    # error is pure round-off. Brouwer's law: it grows like eps sqrt(N); a biased rounding
    # (e.g. a rotation whose cos^2 + sin^2 != 1 applied N times) would grow like eps N.
    inertia = np.array([1.0, 1.0, 2.0])
    L0 = np.array([0.3, 0.1, 1.0])
    q0 = np.array([0.0, 0.0, 0.0, 1.0])
    E0 = rigid.energy(inertia, L0)
    for n in (10**5, 10**6, 10**7):
        L, q, _ = rigid.lie_poisson(inertia, L0, q0, 0.05, n, sample_every=n // 100)
        err = np.max(np.abs(rigid.energy(inertia, L) / E0 - 1))
        assert err < 10 * EPS * math.sqrt(n), (n, err)
        assert err < 1e-3 * EPS * n or n < 10**6  # far below the linear law
