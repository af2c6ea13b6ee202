"""The transport theorem and the fictitious accelerations of a rotating frame.

``(dX/dt)_space = (dX/dt)_rot + omega x X``; all vectors in one set of axes.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from rotframe.frames.arguments import FrameInputError, common_shape
from rotframe.validation import check_vector3, guard_public

__all__ = ["space_derivative", "fictitious_accelerations"]


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
    d_body = check_vector3(d_body, "d_body", FrameInputError, stack=True, finite=False, caller="space_derivative")
    omega = check_vector3(omega, "omega", FrameInputError, stack=True, finite=False, caller="space_derivative")
    vec = check_vector3(vec, "vec", FrameInputError, stack=True, finite=False, caller="space_derivative")
    common_shape("space_derivative", d_body=d_body, omega=omega, vec=vec)
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
    r = check_vector3(r, "r", FrameInputError, stack=True, finite=False, caller="fictitious_accelerations")
    v = check_vector3(v, "v", FrameInputError, stack=True, finite=False, caller="fictitious_accelerations")
    omega = check_vector3(omega, "omega", FrameInputError, stack=True, finite=False, caller="fictitious_accelerations")
    if omega_dot is None:
        omega_dot = np.zeros(3)
    omega_dot = check_vector3(omega_dot, "omega_dot", FrameInputError, stack=True, finite=False, caller="fictitious_accelerations")
    shape = common_shape("fictitious_accelerations", r=r, v=v, omega=omega, omega_dot=omega_dot)
    coriolis = -2.0 * np.cross(omega, v)
    centrifugal = -np.cross(omega, np.cross(omega, r))
    euler = -np.cross(omega_dot, r)
    return {
        "coriolis": np.broadcast_to(coriolis, shape).copy(),
        "centrifugal": np.broadcast_to(centrifugal, shape).copy(),
        "euler": np.broadcast_to(euler, shape).copy(),
    }


# text, complex and object input to the public functions: a FrameInputError, not a numpy TypeError
guard_public(globals(), __all__, FrameInputError)
