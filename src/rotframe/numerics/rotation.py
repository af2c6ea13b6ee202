"""Rotation primitives, one source each: the skew (hat) matrix, Rodrigues' rotation, quaternions.

Conventions
-----------
* ``skew(w) @ v == np.cross(w, v)`` (the hat map of ``so(3)``).
* Rodrigues' formula for the ACTIVE rotation of ``v`` by ``angle`` about the unit
  axis ``a`` (right-hand rule): ``v c + (a x v) s + a (a . v)(1 - c)`` with
  ``c = cos(angle)``, ``s = sin(angle)``; it is ``exp(angle skew(a)) @ v``.
* Quaternions are SCALAR-LAST ``(x, y, z, w)``, as in scipy's ``Rotation``;
  `quat_mul` is Hamilton's product, so ``R(a * b) = R(a) @ R(b)``, and
  `quat_about_axis` is the quaternion of Rodrigues' rotation,
  ``(sin(angle/2) a, cos(angle/2))``.

The compiled kernels (`rodrigues_rotate`, `quat_mul`) take scalar
components so that numba callers pay no array allocation; the array forms
(`rotate_about`, `quat_mul_arrays`) evaluate the same kernels, so
every caller gets the same formula in the same operation order: up to
`NUMPY_ROWS` rows the kernel's Python source on numpy arrays (elementwise
IEEE operations, the same numbers to the last bit, and nothing to compile on a
first run), above it a compiled loop over the kernel. The
formulas are in ``docs/physics/rigid-bodies.md`` (quaternion kinematics) and
``docs/physics/splitting.md`` (exact Coriolis rotation).
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.numerics.compiled import jit_kernel
from rotframe.numerics.hat import skew  # numba-free, for callers that need only the matrix

__all__ = [
    "skew",
    "rodrigues_rotate",
    "rotate_about",
    "quat_mul",
    "quat_mul_arrays",
    "quat_about_axis",
    "NUMPY_ROWS",
]

#: Rows up to which the array forms run the kernels' Python source on numpy arrays instead of a
#: compiled loop: a few microseconds a call more, where the compiled loop would cost a first run
#: 0.2-0.3 s to compile (the rigid scenes pass at most 4097 rows a call).
NUMPY_ROWS = 65536



@jit_kernel
def rodrigues_rotate(vx, vy, vz, ax, ay, az, c, s):
    """``v`` rotated about the unit axis ``(ax, ay, az)`` by the angle with cosine ``c``, sine ``s``.

    Rodrigues: ``v c + (a x v) s + a (a . v)(1 - c)``; returns the three components.
    """
    d = ax * vx + ay * vy + az * vz
    cx = ay * vz - az * vy
    cy = az * vx - ax * vz
    cz = ax * vy - ay * vx
    one_c = 1.0 - c
    return (vx * c + cx * s + ax * d * one_c, vy * c + cy * s + ay * d * one_c,
            vz * c + cz * s + az * d * one_c)


@jit_kernel
def _rotate_rows(axis, c, s, v, out):
    for i in range(c.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = rodrigues_rotate(v[0], v[1], v[2], axis[0], axis[1], axis[2],
                                                           c[i], s[i])


def rotate_about(axis, angle, v) -> np.ndarray:
    """Rotate ``v`` (3,) by each of ``angle`` (n,) about the unit ``axis`` (3,) (Rodrigues).

    Returns
    -------
    ndarray, shape (n, 3)
    """
    angle = np.asarray(angle, dtype=np.float64)
    axis, v = np.asarray(axis, dtype=np.float64), np.asarray(v, dtype=np.float64)
    if angle.shape[0] <= NUMPY_ROWS:
        return np.stack(rodrigues_rotate.py_func(v[0], v[1], v[2], axis[0], axis[1], axis[2], np.cos(angle),
                                                 np.sin(angle)), axis=-1)
    out = np.empty((angle.shape[0], 3))
    _rotate_rows(axis, np.cos(angle), np.sin(angle), v, out)
    return out


@jit_kernel
def quat_mul(a0, a1, a2, a3, b0, b1, b2, b3):
    """Hamilton product ``a * b`` of scalar-last quaternions given as components; a 4-tuple."""
    return (a3 * b0 + b3 * a0 + a1 * b2 - a2 * b1, a3 * b1 + b3 * a1 + a2 * b0 - a0 * b2,
            a3 * b2 + b3 * a2 + a0 * b1 - a1 * b0, a3 * b3 - a0 * b0 - a1 * b1 - a2 * b2)


@jit_kernel
def _quat_mul_rows(a, b, out):
    for i in range(out.shape[0]):
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = quat_mul(a[i, 0], a[i, 1], a[i, 2], a[i, 3],
                                                              b[i, 0], b[i, 1], b[i, 2], b[i, 3])


def quat_mul_arrays(a, b) -> np.ndarray:
    """Hamilton product of scalar-last quaternions ``(..., 4)``, broadcasting over leading axes."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    shape = np.broadcast_shapes(a.shape, b.shape)
    if math.prod(shape[:-1]) <= NUMPY_ROWS:
        return np.stack(quat_mul.py_func(a[..., 0], a[..., 1], a[..., 2], a[..., 3],
                                         b[..., 0], b[..., 1], b[..., 2], b[..., 3]), axis=-1)
    # writeable C-ordered copies: the compiled loop has one signature (a broadcast or Fortran-ordered
    # input would otherwise compile a version of its own)
    rows = [np.array(np.broadcast_to(x, shape).reshape(-1, 4), order="C") for x in (a, b)]
    out = np.empty_like(rows[0])
    _quat_mul_rows(rows[0], rows[1], out)
    return out.reshape(shape)


def quat_about_axis(axis, angle) -> np.ndarray:
    """Quaternions ``(..., 4)`` of rotations by ``angle`` (...) about the unit ``axis`` (3,)."""
    half = 0.5 * np.asarray(angle, dtype=np.float64)[..., None]
    return np.concatenate([np.sin(half) * axis, np.cos(half)], axis=-1)
