"""Euler-angle sequences: the 24 sequence strings, angles -> matrix, matrix -> angles, gimbal lock.

Sequences and ranges as in scipy (conventions in [`rotframe.frames`][rotframe.frames]): UPPER case
intrinsic, lower case extrinsic; angles in the order the rotations are applied.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from rotframe.errors import GimbalLockError, NotARotationError
from rotframe.frames.arguments import FrameInputError, where_text
from rotframe.frames.dcm import check_rotation, passive_matrix
from rotframe.validation import check_vector3, guard_public

__all__ = [
    "SEQUENCES",
    "GIMBAL_ATOL",
    "euler_to_dcm",
    "dcm_to_euler",
    "parse_sequence",
    "checked_angles",
    "is_proper",
    "gimbal_measure_name",
    "angle_text",
]

_PROPER = ("ZXZ", "XYX", "YZY", "ZYZ", "XZX", "YXY")
_TAIT_BRYAN = ("XYZ", "YZX", "ZXY", "XZY", "ZYX", "YXZ")

#: The 24 accepted sequence strings: 12 intrinsic (upper case), then 12 extrinsic.
SEQUENCES = _PROPER + _TAIT_BRYAN + tuple(s.lower() for s in _PROPER + _TAIT_BRYAN)

#: Default gimbal-lock tolerance on |sin(middle)| (proper) or |cos(middle)| (Tait-Bryan).
GIMBAL_ATOL = 1e-7


def euler_to_dcm(angles: ArrayLike, seq: str = "ZXZ", degrees: bool = False) -> np.ndarray:
    """Direction-cosine matrix ``A`` (space -> body components) from Euler angles.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        Angles ``(a1, a2, a3)`` in the order the rotations are applied
        (``(phi, theta, psi)`` for ``"ZXZ"``).
    seq : str, optional
        One of `SEQUENCES`; upper case intrinsic, lower case extrinsic.
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
    axes, extrinsic = parse_sequence(seq)
    a = checked_angles(angles, "euler_to_dcm", "angles", degrees)
    p1, p2, p3 = (passive_matrix(ax, a[..., n]) for n, ax in enumerate(axes))
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
        converted with ``as_matrix().T``. Checked with [`check_rotation`][rotframe.frames.check_rotation].
    seq : str, optional
        One of `SEQUENCES`; upper case intrinsic, lower case extrinsic.
    degrees : bool, optional
        Return angles in degrees.
    on_gimbal_lock : {"raise", "mask"}, optional
        ``"raise"``: raise [`GimbalLockError`][rotframe.errors.GimbalLockError] if any entry is locked.
        ``"mask"``: return ``(angles, mask)``; at locked entries the third angle is
        set to 0 and the first angle carries the whole turn about the (coinciding)
        first/third axis, so ``euler_to_dcm(angles, seq)`` reproduces ``A`` to within
        about ``gimbal_atol`` (scipy's choice too).
    gimbal_atol : float, optional
        Locked where ``|sin(middle)|`` (proper Euler) or ``|cos(middle)|`` (Tait-Bryan)
        is below this. Above it, the first and third angles carry an error of about
        ``1e-16 / |sin(middle)|`` (resp. ``|cos|``) each, while their matrix stays exact.
    atol : float, optional
        Orthogonality tolerance passed to [`check_rotation`][rotframe.frames.check_rotation].

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
    axes, extrinsic = parse_sequence(seq)
    if on_gimbal_lock not in ("raise", "mask"):
        raise FrameInputError(f"dcm_to_euler: on_gimbal_lock={on_gimbal_lock!r}; use 'raise' or 'mask'")
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
            f"dcm_to_euler: gimbal lock in sequence {seq!r}{where_text(locked)}: the middle angle"
            f" is {angle_text(ang[..., 1][locked].flat[0])}"
            f" ({gimbal_measure_name(seq)} = {g[locked].flat[0]:.3g} < gimbal_atol = {gimbal_atol:.3g}),"
            " so only the sum or difference of the first and third angles is determined;"
            " pass on_gimbal_lock='mask' to get one valid set (third angle = 0),"
            " or use a sequence whose singularity is elsewhere"
        )
    if degrees:
        ang = np.degrees(ang)
    return (ang, locked) if on_gimbal_lock == "mask" else ang


def parse_sequence(seq):
    """Axis indices (i, j, k) and extrinsic flag of a sequence string; FrameInputError if not one of `SEQUENCES`."""
    if not isinstance(seq, str) or seq not in SEQUENCES:
        raise FrameInputError(
            f"unknown sequence {seq!r}: use three axes from x, y, z with no two consecutive"
            " equal, all upper (intrinsic) or all lower (extrinsic) case,"
            " e.g. 'ZXZ', 'XYZ', 'zyx'"
        )
    return tuple("xyz".index(c) for c in seq.lower()), seq.islower()


def _parity(i, j):
    """Sign of the permutation (i, j, m), m the remaining axis: e_i x e_j = parity * e_m."""
    return 1.0 if (j - i) % 3 == 1 else -1.0


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
    Pj = passive_matrix(j, a2)  # = R_j(a2)^T
    a3 = _angle_about(k, Pj @ passive_matrix(i, a1) @ M)
    if not zero_first and locked.any():
        # locked: M = R_i(a1) R_j(a2)  =>  R_i(a1) = M R_j(a2)^T
        a1 = np.where(locked, _angle_about(i, M @ Pj), a1)
        a3 = np.where(locked, 0.0, a3)
    return np.stack([a1, a2, a3], axis=-1), locked, g


def checked_angles(angles, caller, name, degrees):
    """``angles`` as a float64 (..., 3) array in radians; FrameInputError naming ``caller`` if not 3-vectors."""
    a = check_vector3(angles, name, FrameInputError, stack=True, finite=False, caller=caller)
    return np.radians(a) if degrees else a


def is_proper(seq):
    """Proper Euler sequence (first axis = third axis), as opposed to Tait-Bryan."""
    return seq[0].lower() == seq[2].lower()


def gimbal_measure_name(seq):
    """The quantity whose smallness means gimbal lock in ``seq``: |sin(middle)| or |cos(middle)|."""
    return "|sin(middle)|" if is_proper(seq) else "|cos(middle)|"


def angle_text(angle):
    """An angle for an error message: radians and degrees."""
    return f"{float(angle):.9g} rad ({np.degrees(float(angle)):.6g} deg)"


# text, complex and object input to the public functions: a FrameInputError, not a numpy TypeError
guard_public(globals(), ("euler_to_dcm", "dcm_to_euler"), FrameInputError, error_for={"dcm_to_euler": NotARotationError})
