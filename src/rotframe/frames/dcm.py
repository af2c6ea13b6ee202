"""Direction-cosine matrices: direction cosines, elemental rotations, the rotation check, orthonormalization, scipy conversion.

``A`` is passive: ``x_body = A @ x_space`` (conventions in [`rotframe.frames`][rotframe.frames]).
scipy's ``Rotation.as_matrix()`` is the active matrix ``A.T``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from rotframe.errors import NotARotationError
from rotframe.frames.arguments import FrameInputError, where_text
from rotframe.validation import check_vector3, guard_public

__all__ = [
    "direction_cosines",
    "elemental",
    "check_rotation",
    "orthonormalize",
    "from_scipy",
    "to_scipy",
    "passive_matrix",
]

#: The public functions of this module (wrapped by `guard_public`).
_GUARDED = ("direction_cosines", "elemental", "check_rotation", "orthonormalize", "from_scipy", "to_scipy")


def direction_cosines(v: ArrayLike) -> np.ndarray:
    """Direction cosines ``(alpha, beta, gamma)`` of a vector.

    Parameters
    ----------
    v : array_like, shape (..., 3)
        Vector components in any set of axes.

    Returns
    -------
    ndarray, shape (..., 3)
        Cosines of the angles between ``v`` and the three axes of the same set,
        ``v / |v|``; ``alpha**2 + beta**2 + gamma**2 = 1``.

    Raises
    ------
    ValueError (RotframeError)
        For a zero or non-finite vector (no direction) or a last axis not of length 3.
    """
    v = check_vector3(v, "v", FrameInputError, stack=True, finite=False, caller="direction_cosines")
    scale = np.abs(v).max(axis=-1, keepdims=True)  # scaled first: no overflow for huge |v|
    bad = ~(np.isfinite(scale[..., 0]) & (scale[..., 0] > 0))
    if bad.any():
        raise FrameInputError(
            f"direction_cosines: a zero-length or non-finite vector has no direction{where_text(bad)};"
            " give vectors with finite, nonzero length"
        )
    u = v / scale
    return u / np.linalg.norm(u, axis=-1, keepdims=True)


def elemental(axis: int | str, angle: ArrayLike, degrees: bool = False) -> np.ndarray:
    """Passive rotation matrix about one coordinate axis (the lecture's ``D``, ``C``, ``B``; docs/physics/seed-errata.md).

    Parameters
    ----------
    axis : {"x", "y", "z", "X", "Y", "Z", 0, 1, 2}
        Axis about which the coordinate axes are turned.
    angle : array_like, shape (...)
        Angle by which the axes are turned (right-handed about ``axis``).
    degrees : bool, optional
        ``angle`` is in degrees.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Matrix taking components in the old axes to components in the turned axes;
        about x: ``[[1, 0, 0], [0, cos, sin], [0, -sin, cos]]``.
    """
    angle = np.asarray(angle, dtype=np.float64)
    if degrees:
        angle = np.radians(angle)
    return passive_matrix(_axis_index(axis), angle)


def check_rotation(A: ArrayLike, atol: float = 1e-9) -> np.ndarray:
    """Check that ``A`` is a proper rotation matrix and return it as float64.

    Parameters
    ----------
    A : array_like, shape (..., 3, 3), or scipy Rotation
        Matrix to check (a ``Rotation`` is converted with ``as_matrix().T``).
    atol : float, optional
        Largest allowed ``max |A^T A - I|`` (entrywise).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``A`` itself (as a float64 array).

    Raises
    ------
    NotARotationError
        Naming the defect: wrong shape, non-finite entries, not orthogonal
        (``max |A^T A - I|`` and ``det A`` are reported), or a reflection (det = -1).
    Examples
    --------
    >>> import numpy as np
    >>> check_rotation(np.diag([1.0, 1.0, -1.0]))
    Traceback (most recent call last):
    ...
    rotframe.errors.NotARotationError: ...
    """
    A = _matrices(A, "check_rotation")
    finite = np.isfinite(A).all(axis=(-1, -2))
    if not finite.all():
        raise NotARotationError(
            f"check_rotation: A has NaN or infinite entries{where_text(~finite)};"
            " a rotation matrix has finite entries"
        )
    err = np.abs(np.swapaxes(A, -1, -2) @ A - np.eye(3)).max(axis=(-1, -2))
    det = np.linalg.det(A)
    bad = err > atol
    if bad.any():
        raise NotARotationError(
            f"check_rotation: A is not orthogonal{where_text(bad)}: max|A^T A - I| ="
            f" {err[bad].flat[0]:.3g} > atol = {atol:.3g} (det A = {det[bad].flat[0]:.6g});"
            " a rotation matrix has orthonormal rows and columns and det +1;"
            " orthonormalize(A) gives the nearest rotation"
        )
    reflection = det < 0
    if reflection.any():
        raise NotARotationError(
            f"check_rotation: A is a reflection, not a rotation{where_text(reflection)}:"
            f" det A = {det[reflection].flat[0]:.6g}; a proper rotation has det +1"
            " (is one axis of the frame left-handed?)"
        )
    return A


def orthonormalize(A: ArrayLike) -> np.ndarray:
    """Nearest proper rotation matrix to ``A`` (in the Frobenius norm).

    Polar decomposition by SVD: with ``A = U S V^T``, the result is
    ``U diag(1, 1, det(U V^T)) V^T``, so its determinant is +1 even when ``A`` is
    closer to a reflection. Use it to remove the drift of an integrated matrix.

    Parameters
    ----------
    A : array_like, shape (..., 3, 3), or scipy Rotation
        Approximate direction-cosine matrix (any frames; the result maps the same ones).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Proper rotation matrix.

    Raises
    ------
    NotARotationError
        Wrong shape, non-finite entries, or rank below 2 (no unique nearest rotation).
    """
    A = _matrices(A, "orthonormalize")
    if not np.isfinite(A).all():
        raise NotARotationError(
            "orthonormalize: A has NaN or infinite entries; give a finite matrix"
        )
    U, s, Vt = np.linalg.svd(A)
    degenerate = s[..., 1] <= 1e-12 * s[..., 0]
    if degenerate.any():
        raise NotARotationError(
            f"orthonormalize: A has rank below 2{where_text(degenerate)}, so no unique nearest"
            " rotation exists; give a matrix close to a rotation"
        )
    d = np.linalg.det(U @ Vt)
    U = U.copy()
    U[..., :, 2] *= d[..., None]  # flip the axis of the smallest singular value if needed
    return U @ Vt


def from_scipy(rotation: Rotation) -> np.ndarray:
    """Direction-cosine matrix ``A`` (space -> body) of a scipy ``Rotation``.

    scipy's ``as_matrix()`` is active (body -> space components), so ``A`` is its
    transpose.

    Parameters
    ----------
    rotation : scipy.spatial.transform.Rotation
        Single or stacked rotation that carries space axes onto body axes.

    Returns
    -------
    ndarray, shape (rotation.shape + (3, 3))
        ``A`` with ``x_body = A @ x_space``.
    """
    if not isinstance(rotation, Rotation):
        raise FrameInputError(
            "from_scipy: expected a scipy.spatial.transform.Rotation,"
            f" got {type(rotation).__name__}"
        )
    return np.swapaxes(rotation.as_matrix(), -1, -2)


def to_scipy(A: ArrayLike, atol: float = 1e-9) -> Rotation:
    """scipy ``Rotation`` of a direction-cosine matrix ``A`` (space -> body).

    Parameters
    ----------
    A : array_like, shape (..., 3, 3), or scipy Rotation
        Checked with [`check_rotation`][rotframe.frames.check_rotation] (``atol``); a ``Rotation`` is returned as is.

    Returns
    -------
    scipy.spatial.transform.Rotation
        ``Rotation.from_matrix(A.T)``, whose ``apply`` maps body components to space.
    """
    if isinstance(A, Rotation):
        return A
    return Rotation.from_matrix(np.swapaxes(check_rotation(A, atol=atol), -1, -2))


def _axis_index(axis):
    if isinstance(axis, str) and axis.lower() in ("x", "y", "z"):
        return "xyz".index(axis.lower())
    if isinstance(axis, (int, np.integer)) and not isinstance(axis, bool) and 0 <= axis <= 2:
        return int(axis)
    raise FrameInputError(f"unknown axis {axis!r}: use 'x', 'y', 'z' (either case) or 0, 1, 2")


def passive_matrix(axis, angle):
    """Passive elemental matrix about axis index ``axis`` (0, 1, 2); angle is a float64 array, rad.

    The unchecked kernel of [`elemental`][rotframe.frames.elemental], shape ``angle.shape + (3, 3)``.
    """
    c, s = np.cos(angle), np.sin(angle)
    p, q = (axis + 1) % 3, (axis + 2) % 3
    out = np.zeros(np.shape(angle) + (3, 3))
    out[..., axis, axis] = 1.0
    out[..., p, p] = c
    out[..., q, q] = c
    out[..., p, q] = s
    out[..., q, p] = -s
    return out


def _matrices(A, caller):
    if isinstance(A, Rotation):
        return from_scipy(A)
    try:
        A = np.asarray(A, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise NotARotationError(
            f"{caller}: A is not a numeric array ({exc}); give a (..., 3, 3) matrix"
        ) from None
    if A.ndim < 2 or A.shape[-2:] != (3, 3):
        raise NotARotationError(
            f"{caller}: A has shape {A.shape}; a rotation matrix has shape (..., 3, 3)"
            " (or pass a scipy Rotation)"
        )
    return A


# text, complex and object input to the public functions: a FrameInputError, not a numpy TypeError
guard_public(globals(), _GUARDED, FrameInputError,
             error_for={n: NotARotationError for n in ("check_rotation", "orthonormalize", "from_scipy", "to_scipy")})
