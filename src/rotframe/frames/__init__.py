"""Frames: direction cosines, rotation matrices, Euler angles, the transport theorem.

A package of one concept per module, every public name re-exported here
(``from rotframe.frames import X``): `rotframe.frames.dcm` (direction cosines,
elemental rotations, [`check_rotation`][rotframe.frames.check_rotation], [`orthonormalize`][rotframe.frames.orthonormalize],
[`from_scipy`][rotframe.frames.from_scipy], [`to_scipy`][rotframe.frames.to_scipy]), `rotframe.frames.euler` (``SEQUENCES``,
``GIMBAL_ATOL``, [`euler_to_dcm`][rotframe.frames.euler_to_dcm], [`dcm_to_euler`][rotframe.frames.dcm_to_euler]),
`rotframe.frames.rates` ([`euler_rates_to_omega`][rotframe.frames.euler_rates_to_omega],
[`omega_to_euler_rates`][rotframe.frames.omega_to_euler_rates]), `rotframe.frames.transport`
([`space_derivative`][rotframe.frames.space_derivative], [`fictitious_accelerations`][rotframe.frames.fictitious_accelerations]); argument checks in
`rotframe.frames.arguments`. numpy and scipy only (no numba, no astropy).

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
    Angles returned by [`dcm_to_euler`][rotframe.frames.dcm_to_euler] lie in ``[-pi, pi]`` for the first and
    third angle, in ``[0, pi]`` for the middle angle of a proper Euler sequence and in
    ``[-pi/2, pi/2]`` for a Tait-Bryan sequence (scipy's ranges).
Gimbal lock
    The first and third angles are not unique, and the Euler-rate map is singular,
    where ``g = |sin(middle)|`` (proper Euler) or ``g = |cos(middle)|`` (Tait-Bryan)
    vanishes. Both [`dcm_to_euler`][rotframe.frames.dcm_to_euler] and [`omega_to_euler_rates`][rotframe.frames.omega_to_euler_rates] treat
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

from rotframe.frames.dcm import (
    check_rotation,
    direction_cosines,
    elemental,
    from_scipy,
    orthonormalize,
    to_scipy,
)
from rotframe.frames.euler import GIMBAL_ATOL, SEQUENCES, dcm_to_euler, euler_to_dcm
from rotframe.frames.rates import euler_rates_to_omega, omega_to_euler_rates
from rotframe.frames.transport import fictitious_accelerations, space_derivative

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
