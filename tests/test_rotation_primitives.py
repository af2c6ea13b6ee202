"""Tests of rotframe.numerics.rotation, rotframe.rigid.kernels.euler_rates and validation.check_vector3.

Oracles are independent of the code under test: scipy's ``Rotation`` (its own
quaternion and rotation-vector code), ``numpy.cross``, and Euler's equations
written out here with scipy's rotation matrix. Inputs are O(1), so the float64
round-off of a few operations is a few 1e-16; the tolerance 1e-13 leaves room
for that and nothing else (a wrong sign or a swapped index errs by O(1)).
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rotframe.errors import RotframeError
from rotframe.numerics.rotation import (
    quat_about_axis,
    quat_mul,
    quat_mul_arrays,
    rodrigues_rotate,
    rotate_about,
    skew,
)
from rotframe.rigid.kernels import euler_rates
from rotframe.validation import check_vector3

RNG = np.random.default_rng(20261123)
TOL = 1e-13


def _unit(v):
    return v / np.linalg.norm(v)


def test_skew_is_the_cross_product():
    for _ in range(20):
        w, v = RNG.normal(size=3), RNG.normal(size=3)
        assert np.allclose(skew(w) @ v, np.cross(w, v), rtol=0, atol=TOL)


def test_rodrigues_matches_scipy_rotation_vector():
    for _ in range(50):
        axis, v = _unit(RNG.normal(size=3)), RNG.normal(size=3)
        angle = RNG.uniform(-10.0, 10.0)
        expected = Rotation.from_rotvec(angle * axis).apply(v)
        got = rodrigues_rotate(*v, *axis, np.cos(angle), np.sin(angle))
        assert np.allclose(got, expected, rtol=0, atol=TOL)
        rows = rotate_about(axis, np.array([angle, -angle]), v)
        assert np.allclose(rows[0], expected, rtol=0, atol=TOL)
        assert np.allclose(rows[1], Rotation.from_rotvec(-angle * axis).apply(v), rtol=0, atol=TOL)


def test_quaternion_product_is_scipy_composition_scalar_last():
    a = Rotation.random(30, random_state=1)
    b = Rotation.random(30, random_state=2)
    qa, qb = a.as_quat(), b.as_quat()  # scalar-last, as rotframe
    expected = (a * b).as_matrix()  # R(a * b) = R(a) @ R(b)
    prod = quat_mul_arrays(qa, qb)
    assert np.allclose(Rotation.from_quat(prod).as_matrix(), expected, rtol=0, atol=TOL)
    for i in range(3):
        assert np.array_equal(np.array(quat_mul(*qa[i], *qb[i])), prod[i])
    # broadcasting one quaternion against many
    assert np.array_equal(quat_mul_arrays(qa[0], qb), quat_mul_arrays(np.tile(qa[0], (30, 1)), qb))


def test_quat_about_axis_is_the_rodrigues_rotation():
    axis = _unit(np.array([1.0, -2.0, 0.5]))
    angles = np.linspace(-4.0, 4.0, 9)
    q = quat_about_axis(axis, angles)
    ref = Rotation.from_rotvec(angles[:, None] * axis).as_quat()  # scipy picks w >= 0; q and -q agree
    ref *= np.sign(np.sum(ref * q, axis=1))[:, None]
    assert np.allclose(q, ref, rtol=0, atol=TOL)


def _euler_reference(L, q, inertia, mgl, nb, ns):
    """Euler's equations and dq/dt = q (omega, 0) / 2, written out with scipy's matrix."""
    omega = L / inertia
    R = Rotation.from_quat(q).as_matrix()  # normalises q
    z_body = R.T @ np.array([0.0, 0.0, 1.0])
    torque = nb + R.T @ ns + mgl * np.array([z_body[1], -z_body[0], 0.0])
    dL = np.cross(L, omega) + torque
    x, y, z, w = q
    ox, oy, oz = omega
    dq = 0.5 * np.array([w * ox + y * oz - z * oy, w * oy + z * ox - x * oz,
                         w * oz + x * oy - y * ox, -(x * ox + y * oy + z * oz)])
    return np.concatenate([dL, dq])


@pytest.mark.parametrize("mgl", [0.0, 0.7])
def test_euler_rates_against_written_out_equations(mgl):
    for _ in range(20):
        inertia = RNG.uniform(0.5, 2.0, size=3)
        L, q = RNG.normal(size=3), _unit(RNG.normal(size=4))
        nb, ns = RNG.normal(size=3), RNG.normal(size=3)
        got = np.array(euler_rates(*L, *q, *(1.0 / inertia), mgl, *nb, *ns))
        assert np.allclose(got, _euler_reference(L, q, inertia, mgl, nb, ns), rtol=0, atol=TOL)


class _Err(RotframeError, ValueError):
    pass


def test_check_vector3_accepts_and_refuses():
    assert check_vector3([1, 2, 3], "r0").dtype == np.float64
    with pytest.raises(_Err, match=r"^w = '\[1, \[2, 3\]\]' is not numbers; it must be 3 numbers$"):
        check_vector3([1, [2, 3]], "w", _Err)  # ragged: numpy's own test of complexity cannot read it
    assert check_vector3(np.zeros((4, 2, 3)), "r", stack=True).shape == (4, 2, 3)
    assert np.isnan(check_vector3([np.nan, 0, 0], "r", finite=False)[0])
    with pytest.raises(_Err, match=r"^f: omega = \[1\.0, 2\.0\] has shape \(2,\); it must be \(\.\.\., 3\)$"):
        check_vector3([1.0, 2.0], "omega", _Err, stack=True, finite=False, caller="f")
    with pytest.raises(_Err, match=r"^com = \[1\.0, nan, 0\.0\] has shape \(3,\); it must be 3 finite numbers \(m\)$"):
        check_vector3([1.0, np.nan, 0.0], "com", _Err, unit="m")
    with pytest.raises(ValueError, match=r"^v0 = .* has shape \(4, 3\); it must be 3 finite numbers$"):
        check_vector3(np.zeros((4, 3)), "v0")


def test_array_forms_give_the_same_bits_compiled_or_not(monkeypatch):
    # up to NUMPY_ROWS rows the array forms run the kernels' source on numpy arrays, above it a compiled
    # loop: both evaluate one formula in one operation order (IEEE elementwise), so the bits agree
    from rotframe.numerics import rotation

    qa, qb = Rotation.random(40, random_state=3).as_quat(), Rotation.random(40, random_state=4).as_quat()
    axis, angles, v = _unit(RNG.normal(size=3)), RNG.uniform(-10.0, 10.0, 40), RNG.normal(size=3)
    small = quat_mul_arrays(qa, qb), quat_mul_arrays(qa[0], qb), rotate_about(axis, angles, v)
    monkeypatch.setattr(rotation, "NUMPY_ROWS", 0)
    big = quat_mul_arrays(qa, qb), quat_mul_arrays(qa[0], qb), rotate_about(axis, angles, v)
    for x, y in zip(small, big):
        assert x.shape == y.shape and np.array_equal(x, y)
