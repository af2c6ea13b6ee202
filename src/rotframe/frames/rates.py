"""Euler-angle rates and angular velocity: the rate map, its inverse, its singularity (gimbal lock).

``omega`` in the ``"body"`` frame has body-axis components, in the ``"space"`` frame
space-axis components (conventions in [`rotframe.frames`][rotframe.frames]).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from rotframe.errors import GimbalLockError
from rotframe.frames.arguments import FrameInputError, common_shape, where_text
from rotframe.frames.dcm import passive_matrix
from rotframe.frames.euler import (
    GIMBAL_ATOL,
    angle_text,
    checked_angles,
    gimbal_measure_name,
    is_proper,
    parse_sequence,
)
from rotframe.validation import check_vector3, guard_public

__all__ = ["euler_rates_to_omega", "omega_to_euler_rates"]


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
        One of `SEQUENCES`.
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
    rates = check_vector3(rates, "rates", FrameInputError, stack=True, finite=False, caller="euler_rates_to_omega")
    common_shape("euler_rates_to_omega", angles=J[..., 0], rates=rates)
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
    """Euler-angle rates from an angular velocity (inverse of [`euler_rates_to_omega`][rotframe.frames.euler_rates_to_omega]).

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        Euler angles ``(a1, a2, a3)`` in the order of ``seq``.
    omega : array_like, shape (..., 3)
        Angular velocity, components in the axes named by ``frame``.
    seq : str, optional
        One of `SEQUENCES`.
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
    omega = check_vector3(omega, "omega", FrameInputError, stack=True, finite=False, caller="omega_to_euler_rates")
    common_shape("omega_to_euler_rates", angles=J[..., 0], omega=omega)
    g = np.abs(np.sin(middle)) if is_proper(seq) else np.abs(np.cos(middle))
    locked = g < gimbal_atol
    if locked.any():
        raise GimbalLockError(
            f"omega_to_euler_rates: sequence {seq!r} is singular{where_text(locked)}: the middle"
            f" angle is {angle_text(middle[locked].flat[0])}"
            f" ({gimbal_measure_name(seq)} = {g[locked].flat[0]:.3g} < gimbal_atol = {gimbal_atol:.3g});"
            " the first and third axes coincide, so their rates are not determined;"
            " use another sequence there, or carry the orientation as a matrix or quaternion"
        )
    J, omega = np.broadcast_arrays(J, omega[..., None])
    return np.linalg.solve(J, omega)[..., 0]


def _rate_matrix(angles, seq, frame, degrees, caller):
    """Matrix J (..., 3, 3) with omega = J @ rates, and the middle angle in radians.

    For intrinsic (i, j, k) with angles (a1, a2, a3), R = R_i(a1) R_j(a2) R_k(a3) (body ->
    space), each rate turns about its own axis as it stands at that moment:
    space: omega = a1' e_i + a2' R_i(a1) e_j + a3' R_i(a1) R_j(a2) e_k,
    body:  omega = R^T omega_space = a1' P_k(a3) P_j(a2) e_i + a2' P_k(a3) e_j + a3' e_k,
    with P = R^T the passive elementals. Extrinsic (a, b, c) is intrinsic (c, b, a) with the
    angles and columns reversed. det J = +-sin(a2) (proper Euler) or +-cos(a2) (Tait-Bryan).
    """
    axes, extrinsic = parse_sequence(seq)
    if frame not in ("body", "space"):
        raise FrameInputError(
            f"{caller}: frame={frame!r}; use 'body' (omega in body axes)"
            " or 'space' (omega in space axes)"
        )
    a = checked_angles(angles, caller, "angles", degrees)
    if extrinsic:
        axes, a = axes[::-1], a[..., ::-1]
    i, j, k = axes
    a1, a2, a3 = a[..., 0], a[..., 1], a[..., 2]
    e = np.eye(3)
    if frame == "body":
        Pk = passive_matrix(k, a3)
        PkPj = Pk @ passive_matrix(j, a2)
        cols = [PkPj[..., :, i], Pk[..., :, j], np.broadcast_to(e[k], Pk.shape[:-1])]
    else:
        Ri = np.swapaxes(passive_matrix(i, a1), -1, -2)
        RiRj = Ri @ np.swapaxes(passive_matrix(j, a2), -1, -2)
        cols = [np.broadcast_to(e[i], Ri.shape[:-1]), Ri[..., :, j], RiRj[..., :, k]]
    J = np.stack(cols, axis=-1)
    if extrinsic:
        J = J[..., ::-1]
    return J, np.broadcast_to(a2, J.shape[:-2])


# text, complex and object input to the public functions: a FrameInputError, not a numpy TypeError
guard_public(globals(), __all__, FrameInputError)
