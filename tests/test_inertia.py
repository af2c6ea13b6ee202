"""Inertia tensors: textbook closed forms, quadrature of the point-mass formula, refusals.

The independent reference for every solid is the point-mass definition
I = sum m (|r|^2 E - r r^T) applied to a dense Gauss-Legendre sampling of the
solid (written out here with its own masses and positions), which integrates the
quadratic moments exactly, so agreement is expected to round-off.
"""

import numpy as np
import pytest
from numpy.polynomial.legendre import leggauss
from scipy.spatial.transform import Rotation

from rotframe.rigid import mass_properties as inertia
from rotframe.errors import RotframeError
from rotframe.rigid.mass_properties import InvalidBodyError

RTOL = 1e-12


# --- samplings of solids (mass elements with positions), independent of inertia.py ---


def _gauss(a, b, n):
    """Gauss-Legendre nodes and weights on [a, b]."""
    x, w = leggauss(n)
    return 0.5 * (b - a) * x + 0.5 * (b + a), 0.5 * (b - a) * w


def _periodic(n):
    """Equally spaced angles and weights on [0, 2 pi) (exact for trigonometric polynomials)."""
    return np.arange(n) * 2 * np.pi / n, np.full(n, 2 * np.pi / n)


def _grid(*axes):
    """Outer product of (nodes, weights) pairs -> (flattened nodes..., product weights)."""
    nodes = np.meshgrid(*[a[0] for a in axes], indexing="ij")
    weights = np.prod(np.meshgrid(*[a[1] for a in axes], indexing="ij"), axis=0)
    return [n.ravel() for n in nodes], weights.ravel()


def sample_box(mass, a, b, c, n=6):
    (x, y, z), w = _grid(_gauss(-a / 2, a / 2, n), _gauss(-b / 2, b / 2, n), _gauss(-c / 2, c / 2, n))
    return mass * w / (a * b * c), np.column_stack([x, y, z])


def sample_solid_sphere(mass, radius, n=8):
    (r, mu, ph), w = _grid(_gauss(0, radius, n), _gauss(-1, 1, n), _periodic(2 * n))
    s = np.sqrt(1 - mu**2)
    dm = mass / (4 / 3 * np.pi * radius**3) * r**2 * w
    return dm, np.column_stack([r * s * np.cos(ph), r * s * np.sin(ph), r * mu])


def sample_shell(mass, radius, n=8):
    (mu, ph), w = _grid(_gauss(-1, 1, n), _periodic(2 * n))
    s = np.sqrt(1 - mu**2)
    dm = mass / (4 * np.pi) * w
    return dm, radius * np.column_stack([s * np.cos(ph), s * np.sin(ph), mu])


def sample_cylinder(mass, radius, height, n=8):
    (r, ph, z), w = _grid(_gauss(0, radius, n), _periodic(2 * n), _gauss(-height / 2, height / 2, n))
    dm = mass / (np.pi * radius**2 * height) * r * w
    return dm, np.column_stack([r * np.cos(ph), r * np.sin(ph), z])


def sample_rod(mass, length, n=8):
    z, w = _gauss(-length / 2, length / 2, n)
    return mass / length * w, np.column_stack([np.zeros(n), np.zeros(n), z])


# --- standard solids ---


def test_standard_solids_equal_textbook_closed_forms():
    m = 2.5
    np.testing.assert_allclose(inertia.solid_sphere(m, 0.3), np.diag([0.4 * m * 0.09] * 3), rtol=RTOL)
    np.testing.assert_allclose(inertia.spherical_shell(m, 0.3), np.diag([2 / 3 * m * 0.09] * 3), rtol=RTOL)
    np.testing.assert_allclose(
        inertia.box(m, 1.0, 2.0, 3.0), np.diag([m * 13 / 12, m * 10 / 12, m * 5 / 12]), rtol=RTOL
    )
    np.testing.assert_allclose(
        inertia.solid_cylinder(m, 0.5, 2.0),
        np.diag([m * (0.75 + 4) / 12, m * (0.75 + 4) / 12, m * 0.25 / 2]),
        rtol=RTOL,
    )
    np.testing.assert_allclose(inertia.thin_rod(m, 3.0), np.diag([m * 9 / 12, m * 9 / 12, 0.0]), rtol=RTOL)


@pytest.mark.parametrize(
    "solid, args, sampler",
    [
        (inertia.solid_sphere, (1.7, 0.4), sample_solid_sphere),
        (inertia.spherical_shell, (1.7, 0.4), sample_shell),
        (inertia.box, (1.7, 0.3, 0.5, 1.1), sample_box),
        (inertia.solid_cylinder, (1.7, 0.4, 1.3), sample_cylinder),
        (inertia.thin_rod, (1.7, 2.0), sample_rod),
    ],
)
def test_standard_solids_equal_point_mass_formula_on_dense_sampling(solid, args, sampler):
    dm, pos = sampler(*args)
    assert dm.sum() == pytest.approx(args[0], rel=RTOL)
    np.testing.assert_allclose(pos.T @ dm, 0.0, atol=1e-14)  # sampled about its centre of mass
    scale = np.trace(solid(*args))
    np.testing.assert_allclose(inertia.point_masses(dm, pos), solid(*args), rtol=0, atol=RTOL * scale)


def test_point_mass_formula_components():
    # one mass at (1, 2, 3): I_xx = m (y^2 + z^2), I_xy = -m x y, ... (Goldstein 5.3)
    m = 2.0
    t = inertia.point_masses([m], [[1.0, 2.0, 3.0]])
    expected = m * np.array([[13.0, -2.0, -3.0], [-2.0, 10.0, -6.0], [-3.0, -6.0, 5.0]])
    np.testing.assert_allclose(t, expected, rtol=RTOL)
    # about the point itself it vanishes
    np.testing.assert_allclose(inertia.point_masses([m], [[1.0, 2.0, 3.0]], about=[1, 2, 3]), 0.0)


# --- parallel axes and composition ---


def test_parallel_axis_shift_equals_direct_sum_and_round_trips():
    rng = np.random.default_rng(7)
    dm = rng.uniform(0.1, 2.0, 20)
    pos = rng.normal(size=(20, 3))
    mass, com = dm.sum(), pos.T @ dm / dm.sum()
    t_com = inertia.point_masses(dm, pos, about=com)
    point = np.array([0.3, -1.2, 2.0])
    t_point = inertia.shift_from_com(t_com, mass, com, point)
    np.testing.assert_allclose(t_point, inertia.point_masses(dm, pos, about=point), rtol=RTOL)
    np.testing.assert_allclose(inertia.shift_to_com(t_point, mass, com, point), t_com, rtol=1e-11)


def test_sampled_displaced_box_equals_parallel_axis_shift():
    dm, pos = sample_box(3.0, 0.2, 0.7, 1.5)
    offset = np.array([1.0, -0.5, 0.25])
    direct = inertia.point_masses(dm, pos + offset)  # about the origin
    shifted = inertia.shift_from_com(inertia.box(3.0, 0.2, 0.7, 1.5), 3.0, offset, np.zeros(3))
    np.testing.assert_allclose(direct, shifted, rtol=RTOL)


def test_two_half_boxes_combine_into_one_box():
    m, a, b, c = 1.3, 0.4, 0.9, 1.7
    half = inertia.box(m, a, b, c)
    parts = [(m, [-a / 2 + 1.0, 2.0, 3.0], half), (m, [a / 2 + 1.0, 2.0, 3.0], half)]
    mass, com, tensor = inertia.combine(parts)
    assert mass == pytest.approx(2 * m)
    np.testing.assert_allclose(com, [1.0, 2.0, 3.0], rtol=RTOL)
    np.testing.assert_allclose(tensor, inertia.box(2 * m, 2 * a, b, c), rtol=RTOL)


def test_dumbbell_combination_equals_point_mass_sum():
    # rod of two sampled spheres: combine() against the point-mass formula on all samples
    s1, p1 = sample_solid_sphere(2.0, 0.1)
    s2, p2 = sample_solid_sphere(1.0, 0.2)
    c1, c2 = np.array([-0.5, 0.0, 0.1]), np.array([0.7, 0.2, -0.3])
    mass, com, tensor = inertia.combine(
        [(2.0, c1, inertia.solid_sphere(2.0, 0.1)), (1.0, c2, inertia.solid_sphere(1.0, 0.2))]
    )
    dm = np.concatenate([s1, s2])
    pos = np.concatenate([p1 + c1, p2 + c2])
    np.testing.assert_allclose(com, pos.T @ dm / dm.sum(), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(tensor, inertia.point_masses(dm, pos, about=com), rtol=1e-12, atol=1e-14)


# --- principal axes ---


@pytest.mark.parametrize("seed", range(5))
def test_principal_axes_of_rotated_box_are_the_rotation(seed):
    rot = Rotation.random(random_state=seed).as_matrix()
    body = inertia.box(2.0, 0.3, 0.8, 1.5)  # distinct moments: I_x > I_y > I_z
    tensor = rot @ body @ rot.T
    moments, axes = inertia.principal_moments(tensor)
    order = np.argsort(np.diag(body))
    np.testing.assert_allclose(moments, np.diag(body)[order], rtol=1e-12)
    # each principal axis is the rotated box axis with the same moment (up to sign)
    np.testing.assert_allclose(np.abs(axes.T @ rot[:, order]), np.eye(3), atol=1e-12)
    assert np.linalg.det(axes) == pytest.approx(1.0)
    np.testing.assert_allclose(axes @ np.diag(moments) @ axes.T, tensor, atol=1e-13)


def test_thin_rod_is_a_valid_limit():
    moments, _ = inertia.principal_moments(inertia.thin_rod(1.0, 2.0))
    np.testing.assert_allclose(moments, [0.0, 1 / 3, 1 / 3], atol=1e-15)


# --- refusals ---


@pytest.mark.parametrize("mass", [-1.0, 0.0, np.nan, np.inf])
def test_refuses_non_physical_mass(mass):
    with pytest.raises(InvalidBodyError, match="mass"):
        inertia.solid_sphere(mass, 1.0)
    with pytest.raises(InvalidBodyError, match=r"masses\[1\]"):
        inertia.point_masses([1.0, mass], [[0, 0, 1], [1, 0, 0]])


def test_refuses_asymmetric_tensor():
    t = np.diag([1.0, 2.0, 2.5])
    t[0, 1] = 0.1
    with pytest.raises(InvalidBodyError, match="not symmetric"):
        inertia.principal_moments(t)


def test_refuses_tensor_that_is_not_positive_semidefinite():
    # symmetric, trace positive, but one principal moment negative
    t = np.array([[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 2.5]])
    with pytest.raises(InvalidBodyError, match="positive semi-definite"):
        inertia.check_tensor(t)


def test_refuses_moments_violating_triangle_inequality():
    with pytest.raises(InvalidBodyError, match="triangle inequality") as info:
        inertia.check_tensor(np.diag([1.0, 1.0, 2.5]))
    assert "2.5" in str(info.value)
    # at equality (a plane lamina) it is accepted, and round-off below it too
    inertia.check_moments([1.0, 2.0, 3.0 * (1 + 1e-14)])


def test_refuses_non_finite_tensor_and_impossible_shift():
    with pytest.raises(InvalidBodyError, match="non-finite"):
        inertia.check_tensor(np.full((3, 3), np.nan))
    # a tensor about a point smaller than the point-mass term of the whole mass
    with pytest.raises(InvalidBodyError):
        inertia.shift_to_com(np.eye(3) * 0.1, 1.0, [0.0, 0.0, 1.0], [0.0, 0.0, 0.0])


def test_invalid_body_error_is_a_value_error_and_rotframe_error():
    assert issubclass(InvalidBodyError, ValueError)
    assert issubclass(InvalidBodyError, RotframeError)
