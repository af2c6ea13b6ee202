"""Frames: direction cosines, rotation matrices, Euler angles, the transport theorem.

Conventions
-----------
Direction-cosine matrix ``A`` (passive)
    ``A`` maps SPACE components of a vector to BODY components,
    ``x_body = A @ x_space``; its rows are the body unit vectors written in space
    axes (the rigid-body lecture's ``A = B C D``, docs/physics/seed-errata.md). ``A.T`` maps body components to space
    components. scipy's ``Rotation.as_matrix()`` is the active matrix, i.e. ``A.T``:
    ``A = Rotation.from_euler(seq, angles).as_matrix().T``. Wherever a matrix ``A``
    is accepted, a ``scipy.spatial.transform.Rotation`` is accepted too and is
    converted with ``as_matrix().T``.
Elemental rotations
    ``elemental(axis, t)`` is passive, like the lecture's ``D``, ``C`` and ``B``: the
    components of a fixed vector in axes turned by ``t`` about ``axis``. About x it
    is ``[[1, 0, 0], [0, cos t, sin t], [0, -sin t, cos t]]``.
Euler-angle sequences
    ``seq`` is one of the twelve axis sequences (six proper Euler: ``ZXZ``, ``XYX``,
    ``YZY``, ``ZYZ``, ``XZX``, ``YXY``; six Tait-Bryan: ``XYZ``, ``YZX``, ``ZXY``,
    ``XZY``, ``ZYX``, ``YXZ``), exactly as in scipy: UPPER case is intrinsic (each
    rotation about an axis of the frame already turned), lower case is extrinsic
    (each rotation about a fixed space axis). The angles ``(a1, a2, a3)`` are given
    in the order the rotations are applied, so for intrinsic ``"IJK"``
    ``A = elemental(K, a3) @ elemental(J, a2) @ elemental(I, a1)`` (for ``ZXZ``
    with ``(phi, theta, psi)`` that is ``A = B C D``), and for extrinsic ``"ijk"``
    ``A = elemental(i, a1) @ elemental(j, a2) @ elemental(k, a3)``.
    Angles returned by :func:`dcm_to_euler` lie in ``[-pi, pi]`` for the first and
    third angle, in ``[0, pi]`` for the middle angle of a proper Euler sequence and in
    ``[-pi/2, pi/2]`` for a Tait-Bryan sequence (scipy's ranges).
Gimbal lock
    The first and third angles are not unique, and the Euler-rate map is singular,
    where ``g = |sin(middle)|`` (proper Euler) or ``g = |cos(middle)|`` (Tait-Bryan)
    vanishes. Both :func:`dcm_to_euler` and :func:`omega_to_euler_rates` treat
    ``g < gimbal_atol`` (default ``1e-7``) as locked.
Angular velocity
    ``omega`` in the ``"body"`` frame has body-axis components,
    ``skew(omega_body) = A @ dA/dt.T``; in the ``"space"`` frame it has space-axis
    components, ``skew(omega_space) = dA/dt.T @ A``; ``omega_space = A.T @ omega_body``.
Transport theorem
    ``(dX/dt)_space = (dX/dt)_rot + omega x X`` for any vector ``X``; all three
    vectors must be given in one set of axes.

Angles are in radians unless ``degrees=True``; every function broadcasts over
leading axes and computes in float64.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from rotframe.errors import GimbalLockError, NotARotationError, RotframeError

__all__ = [
    "SEQUENCES",
    "GIMBAL_ATOL",
    "direction_cosines",
    "elemental",
    "euler_to_dcm",
    "dcm_to_euler",
    "check_rotation",
    "orthonormalize",
    "euler_rates_to_omega",
    "omega_to_euler_rates",
    "space_derivative",
    "fictitious_accelerations",
    "from_scipy",
    "to_scipy",
]

_PROPER = ("ZXZ", "XYX", "YZY", "ZYZ", "XZX", "YXY")
_TAIT_BRYAN = ("XYZ", "YZX", "ZXY", "XZY", "ZYX", "YXZ")

#: The 24 accepted sequence strings: 12 intrinsic (upper case), then 12 extrinsic.
SEQUENCES = _PROPER + _TAIT_BRYAN + tuple(s.lower() for s in _PROPER + _TAIT_BRYAN)

#: Default gimbal-lock tolerance on |sin(middle)| (proper) or |cos(middle)| (Tait-Bryan).
GIMBAL_ATOL = 1e-7


class _InputError(RotframeError, ValueError):
    """Bad argument (sequence, frame, axis or array shape) to a frames function."""


# --------------------------------------------------------------------------- public


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
    v = check_vector3(v, "v", _InputError, stack=True, finite=False, caller="direction_cosines")
    scale = np.abs(v).max(axis=-1, keepdims=True)  # scaled first: no overflow for huge |v|
    bad = ~(np.isfinite(scale[..., 0]) & (scale[..., 0] > 0))
    if bad.any():
        raise _InputError(
            f"direction_cosines: a zero-length or non-finite vector has no direction{_where(bad)};"
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
    return _passive(_axis_index(axis), angle)


def euler_to_dcm(angles: ArrayLike, seq: str = "ZXZ", degrees: bool = False) -> np.ndarray:
    """Direction-cosine matrix ``A`` (space -> body components) from Euler angles.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        Angles ``(a1, a2, a3)`` in the order the rotations are applied
        (``(phi, theta, psi)`` for ``"ZXZ"``).
    seq : str, optional
        One of :data:`SEQUENCES`; upper case intrinsic, lower case extrinsic.
    degrees : bool, optional
        ``angles`` are in degrees.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``A`` with ``x_body = A @ x_space``. For ``"ZXZ"`` this is the lecture's
        ``A = B C D``. Equals ``Rotation.from_euler(seq, angles).as_matrix().T``.
    Examples
    --------
    A rotation of the axes by 90 deg about z: the space x axis has body components (0, -1, 0).

    >>> import numpy as np
    >>> A = euler_to_dcm([90, 0, 0], seq="ZXZ", degrees=True)
    >>> np.round(A @ [1.0, 0.0, 0.0], 12) + 0.0
    array([ 0., -1.,  0.])
    """
    axes, extrinsic = _parse_sequence(seq)
    a = _angles(angles, "euler_to_dcm", "angles", degrees)
    p1, p2, p3 = (_passive(ax, a[..., n]) for n, ax in enumerate(axes))
    # intrinsic: later rotations act on already-turned axes, so they multiply on the left
    return p1 @ p2 @ p3 if extrinsic else p3 @ p2 @ p1


def dcm_to_euler(
    A: ArrayLike,
    seq: str = "ZXZ",
    degrees: bool = False,
    *,
    on_gimbal_lock: str = "raise",
    gimbal_atol: float = GIMBAL_ATOL,
    atol: float = 1e-9,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Euler angles of a direction-cosine matrix ``A`` (space -> body components).

    Parameters
    ----------
    A : array_like, shape (..., 3, 3), or scipy Rotation
        Direction-cosine matrix, ``x_body = A @ x_space``. A ``Rotation`` is
        converted with ``as_matrix().T``. Checked with :func:`check_rotation`.
    seq : str, optional
        One of :data:`SEQUENCES`; upper case intrinsic, lower case extrinsic.
    degrees : bool, optional
        Return angles in degrees.
    on_gimbal_lock : {"raise", "mask"}, optional
        ``"raise"``: raise :class:`GimbalLockError` if any entry is locked.
        ``"mask"``: return ``(angles, mask)``; at locked entries the third angle is
        set to 0 and the first angle carries the whole turn about the (coinciding)
        first/third axis, so ``euler_to_dcm(angles, seq)`` reproduces ``A`` to within
        about ``gimbal_atol`` (scipy's choice too).
    gimbal_atol : float, optional
        Locked where ``|sin(middle)|`` (proper Euler) or ``|cos(middle)|`` (Tait-Bryan)
        is below this. Above it, the first and third angles carry an error of about
        ``1e-16 / |sin(middle)|`` (resp. ``|cos|``) each, while their matrix stays exact.
    atol : float, optional
        Orthogonality tolerance passed to :func:`check_rotation`.

    Returns
    -------
    angles : ndarray, shape (..., 3)
        ``(a1, a2, a3)`` in the order of ``seq``; ``a1, a3`` in ``[-pi, pi]``, ``a2`` in
        ``[0, pi]`` (proper Euler) or ``[-pi/2, pi/2]`` (Tait-Bryan).
    mask : ndarray of bool, shape (...)
        Only with ``on_gimbal_lock="mask"``: True where gimbal-locked.

    Raises
    ------
    NotARotationError
        ``A`` is not a proper rotation within ``atol``.
    GimbalLockError
        With ``on_gimbal_lock="raise"``, where the angles are not unique.
    Examples
    --------
    >>> import numpy as np
    >>> A = euler_to_dcm([0.3, 1.1, -0.4], seq="ZXZ")
    >>> np.round(dcm_to_euler(A, seq="ZXZ"), 12)
    array([ 0.3,  1.1, -0.4])
    """
    axes, extrinsic = _parse_sequence(seq)
    if on_gimbal_lock not in ("raise", "mask"):
        raise _InputError(f"dcm_to_euler: on_gimbal_lock={on_gimbal_lock!r}; use 'raise' or 'mask'")
    M = np.swapaxes(check_rotation(A, atol=atol), -1, -2)  # active, body -> space
    if extrinsic:
        # extrinsic (a, b, c) with (t1, t2, t3) is intrinsic (c, b, a) with (t3, t2, t1);
        # "third angle = 0" is then the first angle of the intrinsic form
        ang, locked, g = _intrinsic_angles(M, axes[::-1], True, gimbal_atol)
        ang = ang[..., ::-1]
    else:
        ang, locked, g = _intrinsic_angles(M, axes, False, gimbal_atol)
    if on_gimbal_lock == "raise" and locked.any():
        raise GimbalLockError(
            f"dcm_to_euler: gimbal lock in sequence {seq!r}{_where(locked)}: the middle angle"
            f" is {_angle_text(ang[..., 1][locked].flat[0])}"
            f" ({_g_name(seq)} = {g[locked].flat[0]:.3g} < gimbal_atol = {gimbal_atol:.3g}),"
            " so only the sum or difference of the first and third angles is determined;"
            " pass on_gimbal_lock='mask' to get one valid set (third angle = 0),"
            " or use a sequence whose singularity is elsewhere"
        )
    if degrees:
        ang = np.degrees(ang)
    return (ang, locked) if on_gimbal_lock == "mask" else ang


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
            f"check_rotation: A has NaN or infinite entries{_where(~finite)};"
            " a rotation matrix has finite entries"
        )
    err = np.abs(np.swapaxes(A, -1, -2) @ A - np.eye(3)).max(axis=(-1, -2))
    det = np.linalg.det(A)
    bad = err > atol
    if bad.any():
        raise NotARotationError(
            f"check_rotation: A is not orthogonal{_where(bad)}: max|A^T A - I| ="
            f" {err[bad].flat[0]:.3g} > atol = {atol:.3g} (det A = {det[bad].flat[0]:.6g});"
            " a rotation matrix has orthonormal rows and columns and det +1;"
            " orthonormalize(A) gives the nearest rotation"
        )
    reflection = det < 0
    if reflection.any():
        raise NotARotationError(
            f"check_rotation: A is a reflection, not a rotation{_where(reflection)}:"
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
            f"orthonormalize: A has rank below 2{_where(degenerate)}, so no unique nearest"
            " rotation exists; give a matrix close to a rotation"
        )
    d = np.linalg.det(U @ Vt)
    U = U.copy()
    U[..., :, 2] *= d[..., None]  # flip the axis of the smallest singular value if needed
    return U @ Vt


def euler_rates_to_omega(
    angles: ArrayLike,
    rates: ArrayLike,
    seq: str = "ZXZ",
    frame: str = "body",
    degrees: bool = False,
) -> np.ndarray:
    """Angular velocity from Euler angles and their time derivatives.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        Euler angles ``(a1, a2, a3)`` in the order of ``seq``.
    rates : array_like, shape (..., 3)
        Their time derivatives ``(a1', a2', a3')``.
    seq : str, optional
        One of :data:`SEQUENCES`.
    frame : {"body", "space"}, optional
        Axes of the returned components: ``"body"`` gives
        ``skew(omega) = A dA/dt^T``, ``"space"`` gives ``skew(omega) = dA/dt^T A``.
    degrees : bool, optional
        ``angles`` are in degrees. The map is linear with dimensionless
        coefficients, so ``omega`` comes out in the unit of ``rates`` (rad/s in,
        rad/s out; deg/s in, deg/s out).

    Returns
    -------
    ndarray, shape (..., 3)
        ``omega`` in the axes named by ``frame``. For ``"ZXZ"``, body frame:
        ``w1 = phi' sin(theta) sin(psi) + theta' cos(psi)``,
        ``w2 = phi' sin(theta) cos(psi) - theta' sin(psi)``,
        ``w3 = phi' cos(theta) + psi'``.
    Examples
    --------
    Aerospace yaw-pitch-roll (intrinsic ZYX): body rates (p, q, r) from the Euler rates.

    >>> import numpy as np
    >>> w = euler_rates_to_omega([30, 10, 5], [2, 0, 1], seq="ZYX", frame="body", degrees=True)
    >>> np.round(w, 6)                           # deg/s, since degrees=True
    array([0.652704, 0.171663, 1.962121])
    """
    J, _ = _rate_matrix(angles, seq, frame, degrees, "euler_rates_to_omega")
    rates = check_vector3(rates, "rates", _InputError, stack=True, finite=False, caller="euler_rates_to_omega")
    _common_shape("euler_rates_to_omega", angles=J[..., 0], rates=rates)
    return (J @ rates[..., None])[..., 0]


def omega_to_euler_rates(
    angles: ArrayLike,
    omega: ArrayLike,
    seq: str = "ZXZ",
    frame: str = "body",
    degrees: bool = False,
    *,
    gimbal_atol: float = GIMBAL_ATOL,
) -> np.ndarray:
    """Euler-angle rates from an angular velocity (inverse of :func:`euler_rates_to_omega`).

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        Euler angles ``(a1, a2, a3)`` in the order of ``seq``.
    omega : array_like, shape (..., 3)
        Angular velocity, components in the axes named by ``frame``.
    seq : str, optional
        One of :data:`SEQUENCES`.
    frame : {"body", "space"}, optional
        Axes of the components of ``omega``.
    degrees : bool, optional
        ``angles`` are in degrees; the rates come out in the unit of ``omega``.
    gimbal_atol : float, optional
        Singular where ``|sin(middle)|`` (proper Euler) or ``|cos(middle)|``
        (Tait-Bryan), the determinant of the rate map up to sign, is below this.

    Returns
    -------
    ndarray, shape (..., 3)
        ``(a1', a2', a3')``.

    Raises
    ------
    GimbalLockError
        At the singularity (the first and third axes coincide), naming the sequence
        and the middle angle; rates there are not finite, and none are returned.
    """
    J, middle = _rate_matrix(angles, seq, frame, degrees, "omega_to_euler_rates")
    omega = check_vector3(omega, "omega", _InputError, stack=True, finite=False, caller="omega_to_euler_rates")
    _common_shape("omega_to_euler_rates", angles=J[..., 0], omega=omega)
    g = np.abs(np.sin(middle)) if _is_proper(seq) else np.abs(np.cos(middle))
    locked = g < gimbal_atol
    if locked.any():
        raise GimbalLockError(
            f"omega_to_euler_rates: sequence {seq!r} is singular{_where(locked)}: the middle"
            f" angle is {_angle_text(middle[locked].flat[0])}"
            f" ({_g_name(seq)} = {g[locked].flat[0]:.3g} < gimbal_atol = {gimbal_atol:.3g});"
            " the first and third axes coincide, so their rates are not determined;"
            " use another sequence there, or carry the orientation as a matrix or quaternion"
        )
    J, omega = np.broadcast_arrays(J, omega[..., None])
    return np.linalg.solve(J, omega)[..., 0]


def space_derivative(d_body: ArrayLike, omega: ArrayLike, vec: ArrayLike) -> np.ndarray:
    """Transport theorem: rate of change of a vector seen from space.

    ``(d vec/dt)_space = (d vec/dt)_rot + omega x vec``.

    Parameters
    ----------
    d_body : array_like, shape (..., 3)
        Rate of change of ``vec`` seen in the rotating (body) frame.
    omega : array_like, shape (..., 3)
        Angular velocity of the rotating frame relative to space.
    vec : array_like, shape (..., 3)
        The vector. All three must have components in the same axes (usually the
        body axes); the result has components in those axes too.

    Returns
    -------
    ndarray, shape (..., 3)
        ``d_body + omega x vec``.
    """
    d_body = check_vector3(d_body, "d_body", _InputError, stack=True, finite=False, caller="space_derivative")
    omega = check_vector3(omega, "omega", _InputError, stack=True, finite=False, caller="space_derivative")
    vec = check_vector3(vec, "vec", _InputError, stack=True, finite=False, caller="space_derivative")
    _common_shape("space_derivative", d_body=d_body, omega=omega, vec=vec)
    return d_body + np.cross(omega, vec)


def fictitious_accelerations(
    r: ArrayLike,
    v: ArrayLike,
    omega: ArrayLike,
    omega_dot: ArrayLike | None = None,
) -> dict[str, np.ndarray]:
    """Coriolis, centrifugal and Euler accelerations in a rotating frame.

    In the rotating frame ``a_rot = F/m + coriolis + centrifugal + euler``.

    Parameters
    ----------
    r, v : array_like, shape (..., 3)
        Position and velocity relative to the rotating frame (``v`` is ``dr/dt``
        seen in that frame).
    omega : array_like, shape (..., 3)
        Angular velocity of the frame relative to inertial space.
    omega_dot : array_like, shape (..., 3), optional
        Its time derivative (the same seen from either frame); None means constant.
        All components in the same axes (usually the rotating axes); so are the results.

    Returns
    -------
    dict of ndarray, shape (..., 3)
        ``"coriolis"``: ``-2 omega x v``; ``"centrifugal"``: ``-omega x (omega x r)``;
        ``"euler"``: ``-omega_dot x r`` (zeros when ``omega_dot`` is None).
    Examples
    --------
    A puck moving north at 10 m/s at latitude 45 deg (ENU axes):

    >>> import numpy as np
    >>> omega = 7.292115e-5 * np.array([0.0, np.cos(np.pi / 4), np.sin(np.pi / 4)])
    >>> a = fictitious_accelerations(r=[0, 0, 0], v=[0, 10, 0], omega=omega)
    >>> np.round(a["coriolis"] * 1e3, 4) + 0.0  # mm/s^2: 2 Omega sin(45 deg) 10 m/s, east (to the right)
    array([1.0313, 0.    , 0.    ])
    """
    r = check_vector3(r, "r", _InputError, stack=True, finite=False, caller="fictitious_accelerations")
    v = check_vector3(v, "v", _InputError, stack=True, finite=False, caller="fictitious_accelerations")
    omega = check_vector3(omega, "omega", _InputError, stack=True, finite=False, caller="fictitious_accelerations")
    if omega_dot is None:
        omega_dot = np.zeros(3)
    omega_dot = check_vector3(omega_dot, "omega_dot", _InputError, stack=True, finite=False, caller="fictitious_accelerations")
    shape = _common_shape("fictitious_accelerations", r=r, v=v, omega=omega, omega_dot=omega_dot)
    coriolis = -2.0 * np.cross(omega, v)
    centrifugal = -np.cross(omega, np.cross(omega, r))
    euler = -np.cross(omega_dot, r)
    return {
        "coriolis": np.broadcast_to(coriolis, shape).copy(),
        "centrifugal": np.broadcast_to(centrifugal, shape).copy(),
        "euler": np.broadcast_to(euler, shape).copy(),
    }


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
        raise _InputError(
            "from_scipy: expected a scipy.spatial.transform.Rotation,"
            f" got {type(rotation).__name__}"
        )
    return np.swapaxes(rotation.as_matrix(), -1, -2)


def to_scipy(A: ArrayLike, atol: float = 1e-9) -> Rotation:
    """scipy ``Rotation`` of a direction-cosine matrix ``A`` (space -> body).

    Parameters
    ----------
    A : array_like, shape (..., 3, 3), or scipy Rotation
        Checked with :func:`check_rotation` (``atol``); a ``Rotation`` is returned as is.

    Returns
    -------
    scipy.spatial.transform.Rotation
        ``Rotation.from_matrix(A.T)``, whose ``apply`` maps body components to space.
    """
    if isinstance(A, Rotation):
        return A
    return Rotation.from_matrix(np.swapaxes(check_rotation(A, atol=atol), -1, -2))


# --------------------------------------------------------------------------- helpers


def _parse_sequence(seq):
    """Axis indices (i, j, k) and extrinsic flag of a sequence string."""
    if not isinstance(seq, str) or seq not in SEQUENCES:
        raise _InputError(
            f"unknown sequence {seq!r}: use three axes from x, y, z with no two consecutive"
            " equal, all upper (intrinsic) or all lower (extrinsic) case,"
            " e.g. 'ZXZ', 'XYZ', 'zyx'"
        )
    return tuple("xyz".index(c) for c in seq.lower()), seq.islower()


def _axis_index(axis):
    if isinstance(axis, str) and axis.lower() in ("x", "y", "z"):
        return "xyz".index(axis.lower())
    if isinstance(axis, (int, np.integer)) and not isinstance(axis, bool) and 0 <= axis <= 2:
        return int(axis)
    raise _InputError(f"unknown axis {axis!r}: use 'x', 'y', 'z' (either case) or 0, 1, 2")


def _parity(i, j):
    """Sign of the permutation (i, j, m), m the remaining axis: e_i x e_j = parity * e_m."""
    return 1.0 if (j - i) % 3 == 1 else -1.0


def _passive(axis, angle):
    """Passive elemental matrix about axis index ``axis``; angle is a float64 array."""
    c, s = np.cos(angle), np.sin(angle)
    p, q = (axis + 1) % 3, (axis + 2) % 3
    out = np.zeros(np.shape(angle) + (3, 3))
    out[..., axis, axis] = 1.0
    out[..., p, p] = c
    out[..., q, q] = c
    out[..., p, q] = s
    out[..., q, p] = -s
    return out


def _angle_about(axis, N):
    """Angle of an active rotation N (..., 3, 3) known to be about axis index ``axis``."""
    p, q = (axis + 1) % 3, (axis + 2) % 3
    return np.arctan2(N[..., q, p] - N[..., p, q], N[..., p, p] + N[..., q, q])


def _intrinsic_angles(M, axes, zero_first, gimbal_atol):
    """Angles of M = R_i(a1) R_j(a2) R_k(a3) (active elementals about axes (i, j, k)).

    Returns the angles (..., 3), the locked mask and g = |sin a2| (proper Euler) or
    |cos a2| (Tait-Bryan). a2 and a1 come from column i (proper) or column k (Tait-Bryan)
    of M, written out with e_i x e_j = eps e_m (m the remaining axis). a3 is then read
    from the rotation left over, R_k(a3) = R_j(a2)^T R_i(a1)^T M, so that the three angles
    reproduce M to round-off even where a1 alone is ill-conditioned (small g).
    Where g < gimbal_atol only a1 +- a3 is determined: the angle that the caller calls
    "third" (a1 if ``zero_first``, else a3) is set to 0 and the other one is read from the
    rotation left over.
    """
    i, j, k = axes
    m = 3 - i - j
    eps = _parity(i, j)
    if k == i:
        # proper Euler: column i = cos a2 e_i + sin a2 sin a1 e_j - eps sin a2 cos a1 e_m
        g = np.hypot(M[..., j, i], M[..., m, i])
        a2 = np.arctan2(g, M[..., i, i])
        a1 = np.arctan2(M[..., j, i], -eps * M[..., m, i])
    else:
        # Tait-Bryan: column k = eps sin a2 e_i - eps cos a2 sin a1 e_j + cos a2 cos a1 e_k
        g = np.hypot(M[..., j, k], M[..., k, k])
        a2 = np.arctan2(eps * M[..., i, k], g)
        a1 = np.arctan2(-eps * M[..., j, k], M[..., k, k])
    locked = g < gimbal_atol
    if zero_first:  # locked: M = R_j(a2) R_k(a3)
        a1 = np.where(locked, 0.0, a1)
    Pj = _passive(j, a2)  # = R_j(a2)^T
    a3 = _angle_about(k, Pj @ _passive(i, a1) @ M)
    if not zero_first and locked.any():
        # locked: M = R_i(a1) R_j(a2)  =>  R_i(a1) = M R_j(a2)^T
        a1 = np.where(locked, _angle_about(i, M @ Pj), a1)
        a3 = np.where(locked, 0.0, a3)
    return np.stack([a1, a2, a3], axis=-1), locked, g


def _rate_matrix(angles, seq, frame, degrees, caller):
    """Matrix J (..., 3, 3) with omega = J @ rates, and the middle angle in radians.

    For intrinsic (i, j, k) with angles (a1, a2, a3), R = R_i(a1) R_j(a2) R_k(a3) (body ->
    space), each rate turns about its own axis as it stands at that moment:
    space: omega = a1' e_i + a2' R_i(a1) e_j + a3' R_i(a1) R_j(a2) e_k,
    body:  omega = R^T omega_space = a1' P_k(a3) P_j(a2) e_i + a2' P_k(a3) e_j + a3' e_k,
    with P = R^T the passive elementals. Extrinsic (a, b, c) is intrinsic (c, b, a) with the
    angles and columns reversed. det J = +-sin(a2) (proper Euler) or +-cos(a2) (Tait-Bryan).
    """
    axes, extrinsic = _parse_sequence(seq)
    if frame not in ("body", "space"):
        raise _InputError(
            f"{caller}: frame={frame!r}; use 'body' (omega in body axes)"
            " or 'space' (omega in space axes)"
        )
    a = _angles(angles, caller, "angles", degrees)
    if extrinsic:
        axes, a = axes[::-1], a[..., ::-1]
    i, j, k = axes
    a1, a2, a3 = a[..., 0], a[..., 1], a[..., 2]
    e = np.eye(3)
    if frame == "body":
        Pk = _passive(k, a3)
        PkPj = Pk @ _passive(j, a2)
        cols = [PkPj[..., :, i], Pk[..., :, j], np.broadcast_to(e[k], Pk.shape[:-1])]
    else:
        Ri = np.swapaxes(_passive(i, a1), -1, -2)
        RiRj = Ri @ np.swapaxes(_passive(j, a2), -1, -2)
        cols = [np.broadcast_to(e[i], Ri.shape[:-1]), Ri[..., :, j], RiRj[..., :, k]]
    J = np.stack(cols, axis=-1)
    if extrinsic:
        J = J[..., ::-1]
    return J, np.broadcast_to(a2, J.shape[:-2])


def _angles(angles, caller, name, degrees):
    a = check_vector3(angles, name, _InputError, stack=True, finite=False, caller=caller)
    return np.radians(a) if degrees else a


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


def _where(mask):
    """' at index (..) (n of N entries)' for a boolean array of bad entries, '' for a scalar."""
    mask = np.asarray(mask)
    if mask.ndim == 0:
        return ""
    first = tuple(int(n) for n in np.argwhere(mask)[0])
    return f" at index {first} ({int(mask.sum())} of {mask.size} entries)"


def _common_shape(caller, **arrays):
    """Broadcast shape of the named arrays, or an error naming their shapes."""
    try:
        return np.broadcast_shapes(*(a.shape for a in arrays.values()))
    except ValueError:
        shapes = ", ".join(f"{name} {a.shape}" for name, a in arrays.items())
        raise _InputError(
            f"{caller}: shapes do not broadcast: {shapes}; leading axes must match or be 1"
        ) from None


def _is_proper(seq):
    """Proper Euler sequence (first axis = third axis), as opposed to Tait-Bryan."""
    return seq[0].lower() == seq[2].lower()


def _g_name(seq):
    return "|sin(middle)|" if _is_proper(seq) else "|cos(middle)|"


def _angle_text(angle):
    return f"{float(angle):.9g} rad ({np.degrees(float(angle)):.6g} deg)"


# text, complex and object input to the public functions: a _InputError, not a numpy TypeError
from rotframe.validation import check_vector3, guard_public  # noqa: E402

guard_public(globals(), __all__, _InputError, error_for={n: NotARotationError for n in ("check_rotation", "orthonormalize", "dcm_to_euler", "from_scipy", "to_scipy")})
