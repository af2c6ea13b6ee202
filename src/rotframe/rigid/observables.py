"""Quantities of a rigid-body state: energy, angular velocity, body -> space rotation.

Conventions as in [`rotframe.rigid.free_body`][rotframe.rigid.free_body]: principal body axes,
quaternions scalar-last ``(x, y, z, w)``, active rotation body -> space.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from rotframe.rigid.checks import InvalidStateError, check_axis_momentum, check_inertia
from rotframe.validation import guard_public

__all__ = ["energy", "omega_body", "body_to_space", "angular_momentum_space"]


def energy(inertia: ArrayLike, L_body: ArrayLike) -> np.ndarray:
    """Kinetic energy ``sum L_i^2 / (2 I_i)`` (J) from body angular momentum.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments (kg m^2).
    L_body : array_like, shape (..., 3)
        Angular momentum (kg m^2/s), body axes.

    Returns
    -------
    ndarray, shape (...)
        Energy (J).
    """
    L = np.asarray(L_body, dtype=np.float64)
    return 0.5 * np.sum(L * omega_body(inertia, L), axis=-1)


def omega_body(inertia: ArrayLike, L: ArrayLike) -> np.ndarray:
    """Body angular velocity ``omega = L / I`` (rad/s).

    A zero moment gives a zero component (its ``L`` component must be zero).

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments (kg m^2).
    L : array_like, shape (..., 3)
        Angular momentum (kg m^2/s), body axes.

    Returns
    -------
    ndarray, shape (..., 3)
        Angular velocity (rad/s), body axes.
    """
    inertia, inv_i = check_inertia(inertia)
    L = np.asarray(L, dtype=np.float64)
    check_axis_momentum(inertia, L)
    return L * inv_i[:3]


def body_to_space(q: ArrayLike, vec: ArrayLike) -> np.ndarray:
    """Rotate body components to space components: ``R(q) @ vec``.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Orientations, scalar-last, body -> space (normalised here).
    vec : array_like, shape (..., 3)
        Vectors in body axes; broadcasts against ``q``.

    Returns
    -------
    ndarray, shape (..., 3)
        The vectors in space axes.
    """
    q = np.asarray(q, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    v = np.asarray(vec, dtype=np.float64)
    u, w = q[..., :3], q[..., 3:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def angular_momentum_space(q: ArrayLike, L_body: ArrayLike) -> np.ndarray:
    """Angular momentum in space axes, ``R(q) @ L_body`` (kg m^2/s).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Orientations, scalar-last, body -> space.
    L_body : array_like, shape (..., 3)
        Angular momentum, body axes.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    return body_to_space(q, L_body)




# text, complex and object input to the public functions: a InvalidStateError, not a numpy TypeError
guard_public(globals(), __all__, InvalidStateError)
