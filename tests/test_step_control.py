"""One DOP853 step controller, starting step and dense output for every loop (rotframe.numerics).

The oracles are written here, apart from the code they check: Hairer's rules (dop853.f's defaults,
docs/physics/dop853.md) as formulas, his starting step (II.4) in numpy with RMS norms (and scipy's
own ``select_initial_step`` where it is importable), and a plain-Python DOP853 loop over the
tableau with that control. The loops of rotframe (the particle scenes, the engine of your own
problems, the rigid body, the bench's hand-written ceiling) must take exactly the steps of that
loop on the same problem, and give its samples, which are Hairer's dense output (``contd8``
written here in dop853.f's own form).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, strategies as st

from rotframe.numerics import step_control as sc
from rotframe.numerics.dop853 import coefficients
from rotframe.numerics.dop853_dense import dense_tables

from rotframe.numerics.plain import plain  # noqa: E402

next_step = plain(sc.next_step)
first_step_trial = plain(sc.first_step_trial)
first_step = plain(sc.first_step)

errs = st.floats(min_value=0.0, max_value=1e12, allow_nan=False)
steps = st.floats(min_value=1e-6, max_value=1e6)


# ---------------------------------------------------------------- the rules


@given(h=steps, err=errs)
def test_an_error_at_most_one_is_accepted_and_the_step_scaled_within_a_sixth_and_three(h, err):
    accepted, h_next = next_step(h, h, err, False)
    assert accepted == (err <= 1.0)
    ratio = 0.9 * err ** (-1.0 / 8.0) if err > 0.0 else math.inf
    if accepted:
        expected = min(6.0, max(0.333, ratio))
    else:
        expected = max(0.333, ratio)
    assert h_next == pytest.approx(h * expected, rel=1e-12)


def test_the_bounds_themselves():
    assert next_step(1.0, 1.0, 0.0, False) == (True, pytest.approx(6.0, rel=1e-15))  # growth at most 6
    assert next_step(1.0, 1.0, 1e30, False) == (False, pytest.approx(0.333, rel=1e-15))  # shrink at most 3.003
    assert next_step(1.0, 1.0, 1.0, False) == (True, pytest.approx(0.9, rel=1e-15))  # the safety factor
    assert next_step(2.0, 2.0, 2.0 ** 8, False) == (False, pytest.approx(2.0 * 0.9 / 2.0, rel=1e-14))


@given(h=steps, err=st.floats(min_value=0.0, max_value=1.0))
def test_no_growth_right_after_a_rejection(h, err):
    accepted, h_next = next_step(h, h, err, True)
    assert accepted
    assert h_next <= h
    assert h_next == pytest.approx(h * min(1.0, 0.9 * err ** (-1.0 / 8.0)) if err > 0 else h, rel=1e-12)


@given(h=steps, cut=st.floats(min_value=1e-6, max_value=0.999), err=st.floats(min_value=0.0, max_value=1.0))
def test_a_step_cut_to_land_hands_on_the_controllers_step(h, cut, err):
    accepted, h_next = next_step(h * cut, h, err, False)
    assert accepted
    own = h * cut * min(6.0, max(0.333, 0.9 * err ** (-1.0 / 8.0) if err > 0 else 6.0))
    assert h_next == pytest.approx(max(h, own), rel=1e-12)


@pytest.mark.parametrize("err", [math.nan, math.inf, -math.inf])
def test_a_non_finite_error_is_a_rejection_ten_times_shorter(err):
    assert next_step(0.5, 0.5, err, False) == (False, pytest.approx(0.05, rel=1e-15))


def test_a_collapsed_step_is_under_ten_ulp_of_t():
    t = 1e6
    ulp = math.ulp(t)
    assert plain(sc.step_collapsed)(9.0 * ulp, t)
    assert not plain(sc.step_collapsed)(11.0 * ulp, t)
    assert plain(sc.step_collapsed)(9.0 * ulp, -t)  # the same below zero


# ---------------------------------------------------------------- the starting step


def hinit(f, t, y, rtol, atol, bound):
    """Hairer's starting step of order 8 (II.4), in numpy with RMS norms: the test's own."""
    scale = atol + rtol * np.abs(y)
    rms = lambda x: float(np.sqrt(np.mean(np.square(x))))  # noqa: E731
    f0 = f(t, y)
    d0, d1 = rms(y / scale), rms(f0 / scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, bound)
    f1 = f(t + h0, y + h0 * f0)
    d2 = rms((f1 - f0) / scale) / h0
    h1 = max(1e-6, 1e-3 * h0) if max(d1, d2) <= 1e-15 else (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, bound)


def ours(f, t, y, rtol, atol, bound):
    f0 = f(t, y)
    h0 = first_step_trial(y, f0, rtol, atol, bound)
    return first_step(y, f0, f(t + h0, y + h0 * f0), h0, rtol, atol, bound)


def _problems():
    rng = np.random.default_rng(3)
    for _ in range(20):
        M = rng.normal(size=(5, 5)) * 10.0 ** rng.uniform(-3, 3)
        y = rng.normal(size=5) * 10.0 ** rng.uniform(-2, 4)
        yield (lambda t, y, M=M: M @ y + np.sin(t) * y ** 2 * 1e-3), y
    yield (lambda t, y: np.zeros_like(y)), np.ones(5)  # no motion: the 1e-6 branches
    yield (lambda t, y: np.full_like(y, 1e-20)), np.zeros(5)


@pytest.mark.parametrize("k", range(22))
def test_the_starting_step_is_hairers(k):
    f, y = list(_problems())[k]
    for rtol, bound in ((1e-6, 1e3), (1e-10, 1e3), (1e-8, 1e-4)):
        atol = np.full(5, rtol * 1e-2)
        assert ours(f, 0.3, y, rtol, atol, bound) == pytest.approx(hinit(f, 0.3, y, rtol, atol, bound), rel=1e-12)


def test_the_starting_step_agrees_with_scipys():
    common = pytest.importorskip("scipy.integrate._ivp.common")
    select = getattr(common, "select_initial_step", None)
    if select is None:
        pytest.skip("scipy has no select_initial_step here")
    for f, y in list(_problems())[:20]:
        try:  # scipy >= 1.12: (fun, t0, y0, t_bound, max_step, f0, direction, order, rtol, atol)
            theirs = select(f, 0.3, y, 0.3 + 50.0, np.inf, f(0.3, y), 1.0, 7, 1e-8, 1e-10)
        except TypeError:
            pytest.skip("scipy's select_initial_step has another signature")
        assert ours(f, 0.3, y, 1e-8, np.full(5, 1e-10), 50.0) == pytest.approx(theirs, rel=1e-12)


@pytest.mark.parametrize("f, y", [
    (lambda t, y: np.full(4, 1.0), np.full(4, 1.5e-5)),  # |y| just above the 1e-5 of the trial step's rule
    (lambda t, y: np.full(4, 1.0), np.full(4, 1e-7)),  # |y| below it, |f| above
    (lambda t, y: np.full(4, 1.5e-5), np.ones(4)),  # |f| just above it
    (lambda t, y: np.full(4, 1.5e-15 * t), np.ones(4)),  # f = 0 at the start, |f'| just above 1e-15
])
def test_the_starting_steps_thresholds(f, y):
    """The branches of hinit at their edges, with unit scales (atol 1, rtol 0): the norms are the values.

    (Where ``max(d1, d2) <= 1e-15``, ``h0`` is at most 1e-6, so ``max(1e-6, 1e-3 h0)`` is always
    1e-6: its second term cannot be reached, in Hairer's code as here.)"""
    atol = np.ones(4)
    assert ours(f, 0.0, y, 0.0, atol, 1e9) == pytest.approx(hinit(f, 0.0, y, 0.0, atol, 1e9), rel=1e-12)


def test_a_run_of_no_length_starts_with_no_step():
    y = np.ones(3)
    assert first_step(y, y, y, 0.0, 1e-8, np.ones(3), 0.0) == 0.0


# ---------------------------------------------------------------- the loops take the oracle's steps


def contd8(y, y_new, K, h, s):
    """Hairer's dense output at t + s h in dop853.f's own form (contd8): K (16, n) the step's and dense stages."""
    _, D = dense_tables()
    ydiff = y_new - y
    bspl = h * K[0] - ydiff
    c3 = ydiff - h * K[12] - bspl
    d = [h * (D[r] @ K) for r in range(4)]
    s1 = 1.0 - s
    conpar = d[0] + s * (d[1] + s1 * (d[2] + s * d[3]))
    return y + s * (ydiff + s1 * (bspl + s * (c3 + s1 * conpar)))


def dense_stages_of(f, t, y, h, K):
    """The three dense-output stages of a step, K[13..15] (the test's own stage loop)."""
    A_extra, _ = dense_tables()
    for i, c in enumerate((0.1, 0.2, 7.0 / 9.0)):
        K[13 + i] = f(t + c * h, y + h * (A_extra[i, :13 + i] @ K[:13 + i]))


def reference_dop853(f, t0, y0, T, rtol, atol, samples=()):
    """A plain-Python DOP853 to T with Hairer's control, its own code.

    Returns (accepted steps, final state, the states at ``samples`` by the dense output).
    """
    A, B, C, E3, E5 = coefficients()
    atol = np.broadcast_to(np.asarray(atol, dtype=float), y0.shape)
    h = hinit(f, t0, y0, rtol, atol, T - t0)
    t, y, k0 = t0, y0.copy(), f(t0, y0)
    accepted_steps, last_rejected = 0, False
    out, pending = [], list(samples)
    while t < T:
        cut = t + h > T
        hh = T - t if cut else h
        K = np.zeros((16, y.size))
        K[0] = k0
        for s in range(1, 12):
            K[s] = f(t + C[s] * hh, y + hh * (A[s, :s] @ K[:s]))
        y_new = y + hh * (B @ K[:12])
        K[12] = f(t + hh, y_new)
        scale = atol + rtol * np.maximum(np.abs(y), np.abs(y_new))
        e5 = np.sum(((E5 @ K[:13]) / scale) ** 2)
        e3 = np.sum(((E3 @ K[:13]) / scale) ** 2)
        err = 0.0 if e5 == 0.0 and e3 == 0.0 else hh * e5 / math.sqrt((e5 + 0.01 * e3) * y.size)
        fac11 = err ** 0.125
        if err <= 1.0:
            h_new = hh / max(1.0 / 6.0, min(1.0 / 0.333, fac11 / 0.9))
            if last_rejected:
                h_new = min(h_new, hh)
            if hh < h:
                h_new = max(h_new, h)
            t_new = T if cut else t + hh
            if pending and pending[0] < t_new:
                dense_stages_of(f, t, y, hh, K)
            while pending and pending[0] <= t_new:
                ts = pending.pop(0)
                out.append(y_new.copy() if ts == t_new else contd8(y, y_new, K, hh, (ts - t) / hh))
            t, y, k0 = t_new, y_new, K[12]
            accepted_steps += 1
            last_rejected = False
        else:
            h_new = hh / min(1.0 / 0.333, fac11 / 0.9)
            last_rejected = True
        h = h_new
    return accepted_steps, y, np.array(out)


W = np.array([0.0, 0.3, 0.4])
G = np.array([0.0, 0.0, -9.81])
R0 = np.array([1.0, 2.0, 1e4])
V0 = np.array([0.5, 0.1, 0.2])


def particle_rhs(t, y):
    """Gravity, Coriolis and the centrifugal term in a frame turning at W (the test's own)."""
    r, v = y[:3], y[3:]
    a = G - 2.0 * np.cross(W, v) - np.cross(W, np.cross(W, r))
    return np.concatenate([v, a])


SAMPLES = 7  # samples of the run: all but the last inside steps, from the dense output


@pytest.fixture(scope="module")
def reference():
    times = np.linspace(0.0, 20.0, SAMPLES + 1)[1:]
    return reference_dop853(particle_rhs, 0.0, np.concatenate([R0, V0]), 20.0, 1e-10, 1e-6, samples=times)


def test_the_particle_scenes_take_the_oracles_steps_and_samples(reference):
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    model = ParticleModel(("gravity", "coriolis", "centrifugal"), omega=OmegaSchedule.constant(W), g=G)
    n, y, samples = reference
    traj = integrate_particles(model, R0[None], V0[None], 20.0, method="dop853", rtol=1e-10, atol=1e-6,
                               samples=SAMPLES)
    assert traj.steps == n
    got = np.concatenate([traj.r[1:, 0], traj.v[1:, 0]], axis=1)
    np.testing.assert_allclose(got, samples, rtol=1e-11, atol=1e-9)


def test_a_problem_of_your_own_takes_the_oracles_steps_and_samples(reference):
    from rotframe import forces
    from rotframe.problem.particles import simulate_particles

    n, y, samples = reference
    # the steady loop (rotframe.problem.steady, chosen for this problem) and the engine's own (inline=False)
    for inline in (None, False):
        run = simulate_particles(omega=W, r0=R0, v0=V0, duration=20.0, forces=[forces.gravity(G)], method="dop853",
                                 rtol=1e-10, atol=1e-6, samples=SAMPLES, inline=inline)
        assert any("steady loop" in note for note in run.notes) == (inline is None)
        assert run.trajectory.steps == n
        got = np.concatenate([run.trajectory.r[1:, 0], run.trajectory.v[1:, 0]], axis=1)
        np.testing.assert_allclose(got, samples, rtol=1e-11, atol=1e-9)


def test_the_bench_ceiling_takes_the_oracles_steps(reference):
    from rotframe.app.bench import ceiling

    A, B, C, E3, E5 = coefficients()
    tab = np.zeros((16, 13))
    tab[:12, :12], tab[12, :12], tab[13, :12], tab[14], tab[15] = A, B, C, E3, E5
    r, v, counted = R0[None].copy(), V0[None].copy(), np.zeros(1, dtype=np.int64)
    # the ceiling's loop has no centrifugal term: its own oracle run
    n, y, _ = reference_dop853(lambda t, y: np.concatenate([y[3:], G - 2.0 * np.cross(W, y[3:])]), 0.0,
                            np.concatenate([R0, V0]), 20.0, 1e-10, 1e-6)
    ceiling.dop853_serial(r, v, G, W, tab, 1e-10, 1e-6, 20.0, False, counted)
    assert counted[0] == n
    np.testing.assert_allclose(np.concatenate([r[0], v[0]]), y, rtol=1e-11)


def test_the_rigid_body_takes_the_oracles_steps_and_samples():
    from rotframe.rigid.adaptive import rigid_dop853

    inertia = np.array([1.0, 2.0, 3.0])
    L0 = np.array([0.1, 2.0, 0.05])
    q0 = np.array([0.0, 0.0, 0.0, 1.0])

    def rhs(t, y):  # Euler's equations and dq/dt = q (omega, 0) / 2, scalar-last (the test's own)
        L, q = y[:3], y[3:]
        w = L / inertia
        x, yy, z, s = q
        dq = 0.5 * np.array([s * w[0] + yy * w[2] - z * w[1], s * w[1] + z * w[0] - x * w[2],
                             s * w[2] + x * w[1] - yy * w[0], -(x * w[0] + yy * w[1] + z * w[2])])
        return np.concatenate([np.cross(L, w), dq])

    atol = np.array([1e-9 * np.linalg.norm(L0)] * 3 + [1e-9] * 4)
    times = np.linspace(0.0, 30.0, 8)
    n, y, samples = reference_dop853(rhs, 0.0, np.concatenate([L0, q0]), 30.0, 1e-9, atol, samples=times[1:])
    run = rigid_dop853(inertia, L0, q0, times, rtol=1e-9)
    assert run.steps == n
    np.testing.assert_allclose(run.L[1:], samples[:, :3], rtol=1e-9, atol=1e-12)
    q = samples[:, 3:] / np.linalg.norm(samples[:, 3:], axis=1, keepdims=True)  # rigid_dop853 normalises q
    np.testing.assert_allclose(run.q[1:], q, rtol=1e-9, atol=1e-12)


# ---------------------------------------------------------------- the dense output itself


def test_the_dense_stages_nodes_are_their_row_sums():
    from rotframe.numerics.dop853_dense import C_EXTRA

    A_extra, _ = dense_tables()
    np.testing.assert_allclose(A_extra.sum(axis=1), C_EXTRA, rtol=0, atol=1e-14)


def _one_step_interpolant(h, x):
    """y'' = -y from (1, 0): one DOP853 step of length h and its dense output at x h (rotframe's F and value)."""
    from rotframe.numerics.dop853_dense import dense_coefficients, dense_value

    A, B, C, _, _ = coefficients()
    f = lambda t, y: np.array([y[1], -y[0]])  # noqa: E731
    y = np.array([1.0, 0.0])
    K = np.zeros((16, 2))
    K[0] = f(0.0, y)
    for s in range(1, 12):
        K[s] = f(C[s] * h, y + h * (A[s, :s] @ K[:s]))
    y_new = y + h * (B @ K[:12])
    K[12] = f(h, y_new)
    dense_stages_of(f, 0.0, y, h, K)
    F = np.empty((7, 2))
    _, D = dense_tables()
    plain(dense_coefficients)(y, y_new, K, h, D, F)
    got = np.array([plain(dense_value)(F, y, x, j) for j in range(2)])
    return got, y, y_new, K


def test_the_dense_output_is_of_order_seven():
    x = 0.37
    errors = []
    for h in (0.4, 0.2, 0.1):
        got, *_ = _one_step_interpolant(h, x)
        errors.append(abs(got[0] - math.cos(x * h)))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 7.5) & (orders < 8.6))  # local error O(h^8) of an order-7 interpolant


@pytest.mark.parametrize("x", [0.0, 0.2, 0.5, 0.9, 1.0])
def test_the_dense_output_is_hairers_contd8(x):
    got, y, y_new, K = _one_step_interpolant(0.3, x)
    np.testing.assert_allclose(got, contd8(y, y_new, K, 0.3, x), rtol=1e-14, atol=1e-15)
    if x == 0.0:
        np.testing.assert_array_equal(got, y)
    if x == 1.0:
        np.testing.assert_allclose(got, y_new, rtol=1e-15)


def test_samples_inside_steps_cut_to_a_knot_are_the_solution():
    """rotframe.simulate's steps end on the knots of an omega table; samples inside such a cut step are
    interpolated on the step actually taken (a spring in a frame whose table holds zero rotation:
    the closed form x = x0 cos(w t) + v0 / w sin(w t))."""
    from rotframe.problem.particles import simulate_particles

    k = 4.0

    def spring(t, r, v):
        return -k * r[0], -k * r[1], -k * r[2]

    knots = np.linspace(0.0, 10.0, 14)  # steps of about 0.3 s are cut at every 0.77 s
    table = (knots, np.zeros((knots.size, 3)))
    r0, v0 = np.array([1.0, -0.5, 0.2]), np.array([0.3, 0.7, -0.1])
    run = simulate_particles(omega=table, r0=r0, v0=v0, duration=10.0, forces=[spring], method="dop853",
                             rtol=1e-12, samples=400)
    t = run.trajectory.times[:, None]
    w = math.sqrt(k)
    exact = r0 * np.cos(w * t) + v0 / w * np.sin(w * t)
    np.testing.assert_allclose(run.trajectory.r[:, 0], exact, rtol=0, atol=1e-9)


def test_every_kernel_is_cached_under_the_whole_packages_sources():
    """numba stamps a disk cache with the kernel's own file; rotframe's kernels carry the package's
    fingerprint, so that a change to a callee in another file (models.py under engine.py) recompiles."""
    from numba import njit

    from rotframe.numerics.compiled import source_fingerprint
    from rotframe.problem import engine
    from rotframe.rigid import adaptive

    from rotframe.problem.signatures import PARTICLE

    for kernel in (engine.variant(PARTICLE, "dop853", False), engine.start_events, adaptive._trajectory):
        assert kernel._cache._impl._locator.get_source_stamp() == source_fingerprint()

    def outside(x):  # a kernel of another package (this test file): numba's own stamp, its file alone
        return x + 1.0

    stamp = njit(cache=True)(outside)._cache._impl._locator.get_source_stamp()
    assert stamp != source_fingerprint()
