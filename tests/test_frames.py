"""Tests of rotframe.frames against independent references.

References: scipy's ``Rotation`` (matrices, Euler angles), central finite differences of
scipy's matrices (angular velocity), matrices and formulas written out by hand from the
seed lecture, numpy cross products, and exact motions (a vector fixed in a turning body, a
free particle seen from a turning frame). The module is never compared with itself.
"""

import itertools

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.linalg import polar
from scipy.spatial.transform import Rotation

from rotframe import frames
from rotframe.errors import GimbalLockError, NotARotationError, RotframeError

PROPER = ["".join((a, b, a)) for a in "XYZ" for b in "XYZ" if a != b]
TAIT_BRYAN = ["".join(p) for p in itertools.permutations("XYZ")]
INTRINSIC = PROPER + TAIT_BRYAN
ALL_SEQ = INTRINSIC + [s.lower() for s in INTRINSIC]

FAST = settings(max_examples=150, deadline=None)
angle = st.floats(-2 * np.pi, 2 * np.pi, allow_nan=False, allow_infinity=False)
angles3 = st.tuples(angle, angle, angle).map(np.array)
rate3 = st.tuples(*[st.floats(-5, 5, allow_nan=False)] * 3).map(np.array)
quat = st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 4).filter(lambda q: np.linalg.norm(q) > 0.1)
seqs = st.sampled_from(ALL_SEQ)


def scipy_dcm(seq, angles, degrees=False):
    """Independent A (space -> body): transpose of scipy's active matrix."""
    return np.swapaxes(Rotation.from_euler(seq, angles, degrees=degrees).as_matrix(), -1, -2)


def is_proper(seq):
    return seq[0].lower() == seq[2].lower()


def singular_value(seq, middle):
    """|sin| (proper Euler) or |cos| (Tait-Bryan) of the middle angle."""
    return abs(np.sin(middle)) if is_proper(seq) else abs(np.cos(middle))


def wrap(a):
    return np.angle(np.exp(1j * np.asarray(a)))


def vee(W):
    """Vector of a skew matrix, W = skew(w): w = (W32, W13, W21)."""
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


def numerical_omega(seq, angles, rates, frame, h=1e-6):
    """omega from central differences of scipy's A(t): body A dA^T, space dA^T A."""
    A = scipy_dcm(seq, angles)
    dA = (scipy_dcm(seq, angles + h * rates) - scipy_dcm(seq, angles - h * rates)) / (2 * h)
    W = A @ dA.T if frame == "body" else dA.T @ A
    assert np.allclose(W, -W.T, atol=1e-7)  # it is skew, as it must be
    return vee(W)


# ------------------------------------------------------------------- sequences, scipy


def test_sequences_are_the_twelve_axis_orders_in_both_conventions():
    assert len(frames.SEQUENCES) == 24
    assert set(frames.SEQUENCES) == set(ALL_SEQ)


@FAST
@given(seq=seqs, a=angles3)
def test_euler_to_dcm_equals_transpose_of_scipy_matrix(seq, a):
    np.testing.assert_allclose(frames.euler_to_dcm(a, seq), scipy_dcm(seq, a), atol=1e-14)
    np.testing.assert_allclose(
        frames.euler_to_dcm(np.degrees(a), seq, degrees=True), scipy_dcm(seq, a), atol=1e-13
    )


@pytest.mark.parametrize("seq", ALL_SEQ)
def test_euler_to_dcm_broadcasts_over_leading_axes(seq):
    a = np.random.default_rng(1).uniform(-4, 4, (4, 5, 3))
    A = frames.euler_to_dcm(a, seq)
    assert A.shape == (4, 5, 3, 3)
    np.testing.assert_allclose(A, scipy_dcm(seq, a.reshape(-1, 3)).reshape(4, 5, 3, 3), atol=1e-14)


@FAST
@given(seq=seqs, a=angles3)
def test_dcm_to_euler_equals_scipy_angles_away_from_gimbal_lock(seq, a):
    assume(singular_value(seq, a[1]) > 1e-3)
    A = scipy_dcm(seq, a)
    with np.errstate(invalid="raise", divide="raise", over="raise"):
        got = frames.dcm_to_euler(A, seq)
    want = Rotation.from_euler(seq, a).as_euler(seq)
    np.testing.assert_allclose(wrap(got - want), 0, atol=1e-11)
    lo, hi = (0, np.pi) if is_proper(seq) else (-np.pi / 2, np.pi / 2)
    assert lo <= got[1] <= hi
    assert np.all(np.abs(got[[0, 2]]) <= np.pi)
    np.testing.assert_allclose(frames.dcm_to_euler(A, seq, degrees=True), np.degrees(got))


@FAST
@given(seq=seqs, q=quat)
def test_dcm_to_euler_round_trip_reproduces_any_rotation(seq, q):
    r = Rotation.from_quat(q)
    A = r.as_matrix().T
    got, mask = frames.dcm_to_euler(A, seq, on_gimbal_lock="mask")
    assert mask.shape == ()
    # exact to round-off; where locked (third angle forced to 0) to within ~gimbal_atol
    np.testing.assert_allclose(scipy_dcm(seq, got), A, atol=2e-7 if mask else 1e-13)


SINGULAR = [(s, m) for s in PROPER for m in (0.0, np.pi)] + [
    (s, m) for s in TAIT_BRYAN for m in (np.pi / 2, -np.pi / 2)
]
SINGULAR += [(s.lower(), m) for s, m in SINGULAR]


@pytest.mark.parametrize("seq,middle", SINGULAR)
def test_dcm_to_euler_at_singular_middle_angle(seq, middle):
    outer = np.random.default_rng(7).uniform(-3, 3, (6, 2))
    a = np.column_stack([outer[:, 0], np.full(6, middle), outer[:, 1]])
    A = scipy_dcm(seq, a)
    with pytest.raises(GimbalLockError, match=seq) as err:
        frames.dcm_to_euler(A, seq)
    assert "middle angle" in str(err.value) and "mask" in str(err.value)

    got, mask = frames.dcm_to_euler(A, seq, on_gimbal_lock="mask")
    assert mask.shape == (6,) and mask.all()
    assert np.all(got[:, 2] == 0.0)  # the documented convention: third angle = 0
    np.testing.assert_allclose(scipy_dcm(seq, got), A, atol=1e-12)  # matrices, not angles


@pytest.mark.parametrize("seq", ALL_SEQ)
def test_gimbal_mask_marks_only_the_locked_entries(seq):
    singular = 0.0 if is_proper(seq) else np.pi / 2
    inside = singular + 0.2 if is_proper(seq) else singular - 0.2  # within scipy's range
    a = np.array([[0.3, singular, -1.1], [0.3, inside, -1.1], [2.0, singular + 1e-9, 0.5]])
    A = scipy_dcm(seq, a)
    got, mask = frames.dcm_to_euler(A, seq, on_gimbal_lock="mask")
    assert mask.tolist() == [True, False, True]
    np.testing.assert_allclose(scipy_dcm(seq, got), A, atol=1e-8)  # within ~gimbal_atol
    np.testing.assert_allclose(got[1], wrap(a[1]), atol=1e-12)


@pytest.mark.parametrize("seq", ALL_SEQ)
def test_dcm_to_euler_near_gimbal_lock_still_reproduces_the_matrix(seq):
    """1e-7 < |sin| or |cos| of the middle angle < 1e-2: outer angles ill-conditioned, A not."""
    rng = np.random.default_rng(19)
    singular = 0.0 if is_proper(seq) else np.pi / 2
    offsets = np.repeat(np.array([1e-2, 1e-4, 1e-6, 5e-7]) * [[1], [-1]], 5)
    a = np.column_stack([rng.uniform(-3, 3, 40), singular + offsets, rng.uniform(-3, 3, 40)])
    # through quaternions, so that the entries carry ordinary absolute round-off
    A = np.swapaxes(Rotation.from_quat(Rotation.from_euler(seq, a).as_quat()).as_matrix(), -1, -2)
    got = frames.dcm_to_euler(A, seq)
    np.testing.assert_allclose(scipy_dcm(seq, got), A, atol=2e-15)


# ------------------------------------------------------------------- the seed's statements


def seed_D(phi):
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])


def seed_C(theta):  # with the erratum: -sin theta in row 3
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[1, 0, 0], [0, c, s], [0, -s, c]])


def seed_B(psi):
    return seed_D(psi)


def test_elemental_rotations_are_the_seeds_D_C_B():
    t = 0.83
    for axis in ("z", "Z", 2):
        np.testing.assert_allclose(frames.elemental(axis, t), seed_D(t), atol=1e-15)
    for axis in ("x", "X", 0):
        np.testing.assert_allclose(frames.elemental(axis, t), seed_C(t), atol=1e-15)
    c, s = np.cos(t), np.sin(t)
    # about y: i' = i cos - k sin, k' = i sin + k cos (right-handed turn of the axes)
    np.testing.assert_allclose(
        frames.elemental("y", t), [[c, 0, -s], [0, 1, 0], [s, 0, c]], atol=1e-15
    )
    np.testing.assert_allclose(
        frames.elemental(1, np.degrees(t), degrees=True), frames.elemental("y", t)
    )
    stack = frames.elemental("x", np.array([[0.1, 0.2], [0.3, 0.4]]))
    assert stack.shape == (2, 2, 3, 3)
    np.testing.assert_allclose(stack[1, 0], seed_C(0.3), atol=1e-15)


@FAST
@given(a=angles3)
def test_zxz_direction_cosine_matrix_is_B_C_D(a):
    phi, theta, psi = a
    np.testing.assert_allclose(
        frames.euler_to_dcm(a, "ZXZ"), seed_B(psi) @ seed_C(theta) @ seed_D(phi), atol=1e-14
    )


@FAST
@given(seq=seqs, a=angles3)
def test_dcm_is_orthogonal_with_determinant_plus_one(seq, a):
    A = frames.euler_to_dcm(a, seq)
    # sum_i a_ij a_ik = delta_jk
    np.testing.assert_allclose(np.einsum("ij,ik->jk", A, A), np.eye(3), atol=1e-14)
    assert np.linalg.det(A) == pytest.approx(1.0, abs=1e-14)
    assert frames.check_rotation(A) is not None


def test_seed_k2_row_of_C_gives_the_body_z_axis():
    # the seed's own k2 = -j1 sin(theta) + k1 cos(theta): row 3 of C
    theta = 0.4
    np.testing.assert_allclose(frames.elemental("x", theta)[2], [0, -np.sin(theta), np.cos(theta)])


def test_determinant_is_invariant_under_similarity_transform():
    rng = np.random.default_rng(3)
    A = frames.euler_to_dcm(rng.uniform(-3, 3, 3), "ZXZ")
    P = rng.normal(size=(3, 3)) + 3 * np.eye(3)  # invertible
    Ap = np.linalg.inv(P) @ A @ P
    assert np.linalg.det(Ap) == pytest.approx(np.linalg.det(A), rel=1e-12)
    # similarity by a rotation keeps a rotation (the operator seen in other axes)
    B = frames.euler_to_dcm(rng.uniform(-3, 3, 3), "xyz")
    np.testing.assert_array_equal(frames.check_rotation(B @ A @ B.T), B @ A @ B.T)


@FAST
@given(v=st.tuples(*[st.floats(-1e3, 1e3, allow_nan=False)] * 3).map(np.array))
def test_direction_cosines_are_unit_and_rebuild_the_vector(v):
    n = np.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    assume(n > 1e-6)
    alpha, beta, gamma = frames.direction_cosines(v)
    assert alpha**2 + beta**2 + gamma**2 == pytest.approx(1.0, abs=1e-14)
    # A = |A| (cos a i + cos b j + cos c k), with cos a = A.i / |A|
    np.testing.assert_allclose(n * np.array([alpha, beta, gamma]), v, atol=1e-12 * n)
    np.testing.assert_allclose(alpha, v @ [1, 0, 0] / n, atol=1e-15)


def test_direction_cosines_broadcast_and_survive_huge_and_tiny_vectors():
    v = np.array([[[3.0, 0, 4]], [[0, -2, 0]], [[3e300, 0, -4e300]], [[3e-310, 4e-310, 0]]])
    want = [[[0.6, 0, 0.8]], [[0, -1, 0]], [[0.6, 0, -0.8]], [[0.6, 0.8, 0]]]
    np.testing.assert_allclose(frames.direction_cosines(v), want, rtol=1e-15)


# ------------------------------------------------------------------- Euler rates


@FAST
@given(a=angles3, r=rate3)
def test_zxz_body_omega_is_the_seeds_formula(a, r):
    phi, theta, psi = a
    dphi, dtheta, dpsi = r
    want = [
        dphi * np.sin(theta) * np.sin(psi) + dtheta * np.cos(psi),
        dphi * np.sin(theta) * np.cos(psi) - dtheta * np.sin(psi),
        dphi * np.cos(theta) + dpsi,
    ]
    np.testing.assert_allclose(frames.euler_rates_to_omega(a, r), want, atol=1e-13)
    np.testing.assert_allclose(frames.euler_rates_to_omega(a, r, "ZXZ", "body"), want, atol=1e-13)


@FAST
@given(seq=seqs, a=angles3, r=rate3, frame=st.sampled_from(["body", "space"]))
def test_euler_rates_to_omega_matches_finite_differences_of_the_dcm(seq, a, r, frame):
    got = frames.euler_rates_to_omega(a, r, seq, frame)
    np.testing.assert_allclose(got, numerical_omega(seq, a, r, frame), atol=1e-7)


@pytest.mark.parametrize("frame", ["body", "space"])
def test_euler_rates_with_degrees_use_the_rates_unit(frame):
    a, r = np.array([0.3, 1.1, -0.4]), np.array([0.2, -0.7, 1.3])
    rad = frames.euler_rates_to_omega(a, r, "zyx", frame)
    deg = frames.euler_rates_to_omega(np.degrees(a), np.degrees(r), "zyx", frame, degrees=True)
    np.testing.assert_allclose(deg, np.degrees(rad), rtol=1e-13)


def test_euler_rate_maps_broadcast_angles_against_rates():
    rng = np.random.default_rng(5)
    a, r = rng.uniform(0.2, 1.2, (4, 1, 3)), rng.normal(size=(1, 6, 3))
    w = frames.euler_rates_to_omega(a, r, "XYZ", "space")
    assert w.shape == (4, 6, 3)
    for m, n in [(0, 0), (3, 5)]:
        want = numerical_omega("XYZ", a[m, 0], r[0, n], "space")
        np.testing.assert_allclose(w[m, n], want, atol=1e-7)
    back = frames.omega_to_euler_rates(a, w, "XYZ", "space")
    np.testing.assert_allclose(back, np.broadcast_to(r, w.shape))


@FAST
@given(seq=seqs, a=angles3, w=rate3, frame=st.sampled_from(["body", "space"]))
def test_omega_to_euler_rates_undoes_euler_rates_to_omega(seq, a, w, frame):
    assume(singular_value(seq, a[1]) > 1e-2)
    rates = frames.omega_to_euler_rates(a, w, seq, frame)
    # check against the finite-difference omega: independent of the forward map
    np.testing.assert_allclose(numerical_omega(seq, a, rates, frame), w, atol=1e-5)
    np.testing.assert_allclose(frames.euler_rates_to_omega(a, rates, seq, frame), w, atol=1e-10)


@pytest.mark.parametrize("seq,middle", SINGULAR)
@pytest.mark.parametrize("frame", ["body", "space"])
def test_omega_to_euler_rates_raises_at_the_singularity(seq, middle, frame):
    a = np.array([0.4, middle, -1.3])
    with pytest.raises(GimbalLockError) as err:
        frames.omega_to_euler_rates(a, [0.1, 0.2, 0.3], seq, frame)
    msg = str(err.value)
    assert repr(seq) in msg and "middle angle" in msg
    # and a stack with one singular entry raises too (never 1e16 rates)
    stack = np.array([[0.4, middle + 0.5, -1.3], a])
    with pytest.raises(GimbalLockError, match=r"index \(1,\)"):
        frames.omega_to_euler_rates(stack, [0.1, 0.2, 0.3], seq, frame)


def test_omega_to_euler_rates_near_singularity_stays_bounded_by_tolerance():
    a = np.array([0.4, 1e-6, -1.3])  # |sin| = 1e-6 > 1e-7: allowed, rates ~ 1e6
    rates = frames.omega_to_euler_rates(a, [0.1, 0.2, 0.3], "ZXZ")
    assert np.all(np.isfinite(rates)) and np.abs(rates).max() < 1e7
    with pytest.raises(GimbalLockError, match="ZXZ"):
        frames.omega_to_euler_rates(a, [0.1, 0.2, 0.3], "ZXZ", gimbal_atol=1e-5)


# ------------------------------------------------------------------- transport theorem


def test_space_derivative_is_d_body_plus_omega_cross_vec():
    rng = np.random.default_rng(11)
    d, w, x = rng.normal(size=(3, 8, 3))
    (w1, w2, w3), (x1, x2, x3) = w.T, x.T
    want = d + np.stack([w2 * x3 - w3 * x2, w3 * x1 - w1 * x3, w1 * x2 - w2 * x1], axis=-1)
    np.testing.assert_allclose(frames.space_derivative(d, w, x), want, atol=1e-14)
    assert frames.space_derivative(d[0], w[0], x).shape == (8, 3)


@pytest.mark.parametrize("u", [np.zeros(3), np.array([0.5, -0.2, 0.9])])
def test_transport_theorem_against_finite_differences_in_space(u):
    """A vector fixed in (u = 0) or moving in a body that turns at constant omega."""
    omega_space = np.array([0.3, -0.5, 0.8])
    R0 = Rotation.from_euler("ZYX", [0.1, 0.2, 0.3])
    c0 = np.array([1.0, 2.0, -0.5])

    def turn(t):  # active, body -> space components
        return Rotation.from_rotvec(omega_space * t) * R0

    def x_space(t):
        return turn(t).apply(c0 + u * t)

    t, h = 0.7, 1e-5
    fd = (x_space(t + h) - x_space(t - h)) / (2 * h)
    if not u.any():
        np.testing.assert_allclose(fd, np.cross(omega_space, x_space(t)), atol=1e-9)
    Rt = turn(t)
    omega_body = Rt.inv().apply(omega_space)
    got_body = frames.space_derivative(u, omega_body, c0 + u * t)
    np.testing.assert_allclose(Rt.apply(got_body), fd, atol=1e-9)
    # the same in space axes: A turns body components into space components and back
    A = frames.from_scipy(Rt)
    np.testing.assert_allclose(
        frames.space_derivative(A.T @ u, omega_space, x_space(t)), fd, atol=1e-9
    )


def test_fictitious_accelerations_are_the_three_cross_products():
    rng = np.random.default_rng(13)
    r, v, w, wd = rng.normal(size=(4, 5, 3))
    got = frames.fictitious_accelerations(r, v, w, wd)
    assert set(got) == {"coriolis", "centrifugal", "euler"}
    np.testing.assert_allclose(got["coriolis"], -2 * np.cross(w, v), atol=1e-14)
    np.testing.assert_allclose(got["centrifugal"], -np.cross(w, np.cross(w, r)), atol=1e-14)
    np.testing.assert_allclose(got["euler"], -np.cross(wd, r), atol=1e-14)
    still = frames.fictitious_accelerations(r, v, w)
    np.testing.assert_array_equal(still["euler"], np.zeros((5, 3)))
    # centrifugal points away from the axis: for omega = z, r = x it is +omega^2 x
    c = frames.fictitious_accelerations([2.0, 0, 0], [0, 0, 0], [0, 0, 3.0])["centrifugal"]
    np.testing.assert_allclose(c, [18.0, 0, 0])


def test_free_particle_seen_from_a_turning_frame_feels_only_fictitious_forces():
    """Straight line in space, mapped by R(theta(t))^T with a fixed axis (docs/physics/rotating-frames.md)."""
    n = np.array([1.0, 2.0, 2.0]) / 3.0
    x0, u = np.array([1.0, -0.5, 2.0]), np.array([0.3, 0.8, -0.2])
    a0, a1 = 0.4, 0.15  # theta = a0 t + a1 t^2: omega = (a0 + 2 a1 t) n, omega_dot = 2 a1 n

    def r_rot(t):
        return Rotation.from_rotvec((a0 * t + a1 * t**2) * n).inv().apply(x0 + u * t)

    t, h = 1.3, 1e-4
    v = (r_rot(t + h) - r_rot(t - h)) / (2 * h)
    acc = (r_rot(t + h) - 2 * r_rot(t) + r_rot(t - h)) / h**2
    omega = (a0 + 2 * a1 * t) * n  # the axis is fixed, so these are also rotating-frame components
    f = frames.fictitious_accelerations(r_rot(t), v, omega, 2 * a1 * n)
    np.testing.assert_allclose(f["coriolis"] + f["centrifugal"] + f["euler"], acc, atol=1e-6)


# ------------------------------------------------------------------- check, orthonormalize


def test_check_rotation_names_the_defect():
    A = frames.euler_to_dcm([0.1, 0.2, 0.3])
    assert frames.check_rotation(A) is not None
    bent = A.copy()
    bent[0, 1] += 1e-3
    with pytest.raises(NotARotationError, match=r"not orthogonal.*A\^T A - I") as err:
        frames.check_rotation(bent)
    assert "orthonormalize" in str(err.value)
    frames.check_rotation(bent, atol=1e-2)  # within a looser tolerance it passes

    with pytest.raises(NotARotationError, match=r"reflection.*det A = -1.*det \+1"):
        frames.check_rotation(A @ np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(NotARotationError, match="det"):
        frames.check_rotation(-np.eye(3))
    with pytest.raises(NotARotationError, match="NaN"):
        frames.check_rotation(np.full((3, 3), np.nan))
    stack = np.stack([A, A, 2 * A])
    with pytest.raises(NotARotationError, match=r"index \(2,\)"):
        frames.check_rotation(stack)


@FAST
@given(q=quat, noise=st.floats(0, 0.1), seed=st.integers(0, 2**16))
def test_orthonormalize_gives_the_polar_factor(q, noise, seed):
    A = Rotation.from_quat(q).as_matrix().T
    M = A + noise * np.random.default_rng(seed).normal(size=(3, 3))
    assume(np.linalg.det(M) > 0.1)
    got = frames.orthonormalize(M)
    np.testing.assert_allclose(got.T @ got, np.eye(3), atol=1e-13)
    assert np.linalg.det(got) == pytest.approx(1.0, abs=1e-13)
    np.testing.assert_allclose(got, polar(M)[0], atol=1e-12)  # nearest orthogonal matrix


def test_orthonormalize_fixes_the_determinant_of_a_near_reflection():
    M = np.diag([3.0, 2.0, -0.01])
    got = frames.orthonormalize(M)
    np.testing.assert_allclose(got, np.eye(3), atol=1e-15)  # flip the weakest axis
    stack = frames.orthonormalize(np.stack([M, 1.001 * np.eye(3)]))
    assert stack.shape == (2, 3, 3)
    with pytest.raises(NotARotationError, match="rank"):
        frames.orthonormalize(np.outer([1, 0, 0], [0, 1, 0]))


# ------------------------------------------------------------------- interop with scipy


def test_from_scipy_maps_space_components_to_body_components():
    rng = np.random.default_rng(17)
    r = Rotation.from_quat(rng.normal(size=(4, 4)))
    v_body = rng.normal(size=(4, 3))
    v_space = r.apply(v_body)  # scipy's rotation takes body components to space
    A = frames.from_scipy(r)
    assert A.shape == (4, 3, 3)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", A, v_space), v_body, atol=1e-14)
    back = frames.to_scipy(A)
    assert np.all(back.approx_equal(r, atol=1e-12))
    np.testing.assert_allclose(frames.from_scipy(frames.to_scipy(A)), A, atol=1e-15)


def test_a_scipy_rotation_is_accepted_wherever_a_matrix_is():
    r = Rotation.from_euler("ZXZ", [0.5, 1.0, -0.7])
    A = r.as_matrix().T
    np.testing.assert_allclose(frames.check_rotation(r), A)
    np.testing.assert_allclose(frames.orthonormalize(r), A, atol=1e-15)
    np.testing.assert_allclose(frames.dcm_to_euler(r, "ZXZ"), [0.5, 1.0, -0.7], atol=1e-14)
    assert frames.to_scipy(r) is r
    stack = Rotation.from_euler("xyz", [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]])
    np.testing.assert_allclose(
        frames.dcm_to_euler(stack, "xyz"), [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]], atol=1e-14
    )


# ------------------------------------------------------------------- bad input


def raises_input_error(match):
    return pytest.raises(ValueError, match=match)


def test_zero_vector_has_no_direction():
    with raises_input_error("zero-length.*nonzero") as err:
        frames.direction_cosines([0.0, 0.0, 0.0])
    assert isinstance(err.value, RotframeError)
    with raises_input_error(r"index \(1,\)"):
        frames.direction_cosines([[1.0, 0, 0], [0, 0, 0]])


@pytest.mark.parametrize(
    "call",
    [
        lambda: frames.direction_cosines([1.0, 2.0]),
        lambda: frames.euler_to_dcm([0.1, 0.2, 0.3, 0.4]),
        lambda: frames.euler_to_dcm(0.1),
        lambda: frames.euler_rates_to_omega([0.1, 0.2, 0.3], [1.0, 2.0]),
        lambda: frames.omega_to_euler_rates([0.1, 0.2], [1.0, 2.0, 3.0]),
        lambda: frames.space_derivative([1.0, 2.0, 3.0], [1.0, 2.0], [1.0, 2.0, 3.0]),
        lambda: frames.fictitious_accelerations([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [[1.0, 2.0]]),
    ],
)
def test_wrong_vector_shape_is_refused(call):
    with raises_input_error(r"must be \(\.\.\., 3\)") as err:
        call()
    assert isinstance(err.value, RotframeError)


@pytest.mark.parametrize("bad", [np.eye(2), np.ones(3), np.zeros((3, 4))])
def test_wrong_matrix_shape_is_not_a_rotation(bad):
    for fn in (frames.check_rotation, frames.orthonormalize, frames.dcm_to_euler, frames.to_scipy):
        with pytest.raises(NotARotationError, match=r"\(\.\.\., 3, 3\)"):
            fn(bad)


@pytest.mark.parametrize(
    "call",
    [
        lambda: frames.euler_rates_to_omega(np.zeros((4, 3)), np.ones((5, 3))),
        lambda: frames.omega_to_euler_rates(np.ones((4, 3)), np.ones((2, 3))),
        lambda: frames.space_derivative(np.ones((2, 3)), np.ones((3, 3)), np.ones(3)),
        lambda: frames.fictitious_accelerations(np.ones((2, 3)), 0 * np.ones(3), [1, 0, 0], np.ones((4, 3))),
    ],
)
def test_leading_axes_that_do_not_broadcast_are_refused(call):
    with raises_input_error("do not broadcast.*must match or be 1") as err:
        call()
    assert isinstance(err.value, RotframeError)


def test_dcm_to_euler_refuses_non_rotations():
    with pytest.raises(NotARotationError, match="reflection"):
        frames.dcm_to_euler(np.diag([1.0, -1.0, 1.0]))
    with pytest.raises(NotARotationError, match="not orthogonal"):
        frames.dcm_to_euler(2 * np.eye(3))


@pytest.mark.parametrize("seq", ["ZZX", "XYz", "xYz", "XY", "ABC", "XYZX", 3])
def test_unknown_sequence_says_what_is_allowed(seq):
    calls = [
        lambda: frames.euler_to_dcm([0.1, 0.2, 0.3], seq),
        lambda: frames.dcm_to_euler(np.eye(3), seq),
        lambda: frames.euler_rates_to_omega([0.1, 0.2, 0.3], [1, 2, 3], seq),
        lambda: frames.omega_to_euler_rates([0.1, 0.2, 0.3], [1, 2, 3], seq),
    ]
    for call in calls:
        with raises_input_error("unknown sequence") as err:
            call()
        msg = str(err.value)
        assert repr(seq) in msg
        assert "x, y, z" in msg and "upper (intrinsic)" in msg and "lower (extrinsic)" in msg
        assert isinstance(err.value, RotframeError)


@pytest.mark.parametrize("fn", [frames.euler_rates_to_omega, frames.omega_to_euler_rates])
def test_bad_frame_name_says_body_or_space(fn):
    with raises_input_error(r"frame='world'.*'body'.*'space'") as err:
        fn([0.1, 0.2, 0.3], [1.0, 2.0, 3.0], "ZXZ", "world")
    assert isinstance(err.value, RotframeError)


def test_bad_axis_and_bad_gimbal_option_are_refused():
    for axis in ("w", 3, -1, True, None):
        with raises_input_error("'x', 'y', 'z'.*0, 1, 2"):
            frames.elemental(axis, 0.1)
    with raises_input_error("'raise' or 'mask'"):
        frames.dcm_to_euler(np.eye(3), "XYZ", on_gimbal_lock="ignore")
