"""Inertia tensors of rigid bodies: point masses, standard solids, parallel axes, parts.

Conventions
-----------
* SI units: masses in kg, lengths in m, inertia tensors in kg m^2, all float64.
* A tensor is a 3x3 array in some reference axes, taken about a stated point
  (the centre of mass unless a function says otherwise). For a mass element
  ``dm`` at ``r`` relative to that point,
  ``I = integral (|r|^2 E - r r^T) dm``, i.e. ``I_xx = sum m (y^2 + z^2)``,
  ``I_xy = -sum m x y`` and cyclically (Goldstein ch. 5.3; the rigid-body lecture's
  "Angular momentum, moment of inertia" section).
* Principal moments are returned ascending with the principal axes as the
  columns of a proper rotation, by [`rotframe.rigid.principal.principal_axes`][rotframe.rigid.principal.principal_axes].
* What cannot be a body is refused with [`InvalidBodyError`][rotframe.rigid.mass_properties.InvalidBodyError] (a
  ``ValueError``): non-positive or non-finite mass, a tensor that is not
  finite, not symmetric or not positive semi-definite, or principal moments
  that violate the triangle inequality ``I1 + I2 >= I3`` (true of every mass
  distribution, since ``I1 + I2 - I3 = 2 integral z'^2 dm >= 0`` along the third
  principal axis).
"""

from __future__ import annotations

from typing import Iterable

import numpy as np
from numpy.typing import ArrayLike

from rotframe.errors import RotframeError
from rotframe.rigid.principal import principal_axes

__all__ = [
    "InvalidBodyError",
    "point_masses",
    "solid_sphere",
    "spherical_shell",
    "box",
    "solid_cylinder",
    "thin_rod",
    "shift_from_com",
    "shift_to_com",
    "combine",
    "principal_moments",
    "check_mass",
    "check_tensor",
    "check_moments",
]

#: Default relative tolerance (on the trace) for symmetry, semi-definiteness and
#: the triangle inequality: far above the round-off of any tensor built here.
RTOL = 1e-10


class InvalidBodyError(RotframeError, ValueError):
    """A mass, inertia tensor or set of principal moments that no rigid body can have."""


# ---------------------------------------------------------------------------
# Point masses and standard solids
# ---------------------------------------------------------------------------


def point_masses(masses: ArrayLike, positions: ArrayLike, about: ArrayLike = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Inertia tensor of point masses about a point.

    ``I = sum_k m_k (|r_k|^2 E - r_k r_k^T)`` with ``r_k = position_k - about``,
    so ``I_xx = sum m (y^2 + z^2)`` and ``I_xy = -sum m x y`` (Goldstein 5.3).

    Parameters
    ----------
    masses : array_like, shape (n,)
        Masses (kg), each positive and finite.
    positions : array_like, shape (n, 3)
        Positions (m) in the reference axes.
    about : array_like, shape (3,)
        Point (m) about which the tensor is taken; the origin by default.

    Returns
    -------
    ndarray, shape (3, 3)
        Inertia tensor (kg m^2) about ``about`` in the reference axes.
    """
    m = np.atleast_1d(np.asarray(masses, dtype=np.float64))
    r = np.asarray(positions, dtype=np.float64).reshape(-1, 3) - check_vector3(about, "about", InvalidBodyError, unit="m")
    if m.ndim != 1 or m.shape[0] != r.shape[0]:
        raise InvalidBodyError(
            f"masses (shape {m.shape}) and positions (shape {r.shape}) must pair each mass "
            "with one 3-vector"
        )
    for k, mk in enumerate(m):
        check_mass(mk, name=f"masses[{k}]")
    if not np.all(np.isfinite(r)):
        raise InvalidBodyError("positions must be finite")
    second = np.einsum("k,ki,kj->ij", m, r, r)  # sum m r r^T
    return np.trace(second) * np.eye(3) - second


def solid_sphere(mass: float, radius: float) -> np.ndarray:
    """Solid homogeneous sphere about its centre: ``(2/5) m R^2`` on each axis.

    Parameters
    ----------
    mass : float
        Mass (kg).
    radius : float
        Radius (m).

    Returns
    -------
    ndarray, shape (3, 3)
        Inertia tensor (kg m^2) about the centre of mass.
    """
    return _isotropic(mass, radius, 0.4)


def spherical_shell(mass: float, radius: float) -> np.ndarray:
    """Thin spherical shell about its centre: ``(2/3) m R^2`` on each axis.

    Parameters and result as in [`solid_sphere`][rotframe.rigid.mass_properties.solid_sphere].
    """
    return _isotropic(mass, radius, 2.0 / 3.0)


def _isotropic(mass, radius, factor):
    """``factor m R^2`` on each axis (a body with the symmetry of the sphere), after the checks."""
    m = check_mass(mass)
    r = _length(radius, "radius")
    return np.eye(3) * (factor * m * r * r)


def box(mass: float, a: float, b: float, c: float) -> np.ndarray:
    """Homogeneous rectangular box with edges ``a, b, c`` along x, y, z.

    ``I_xx = m (b^2 + c^2) / 12`` and cyclically, about the centre of mass.

    Parameters
    ----------
    mass : float
        Mass (kg).
    a, b, c : float
        Full edge lengths (m) along the x, y and z axes.

    Returns
    -------
    ndarray, shape (3, 3)
        Inertia tensor (kg m^2) about the centre of mass, diagonal.
    Examples
    --------
    >>> float(box(12.0, 1.0, 2.0, 2.0)[0, 0])   # m (b^2 + c^2) / 12
    8.0
    """
    m = check_mass(mass)
    a, b, c = (_length(v, n) for v, n in ((a, "a"), (b, "b"), (c, "c")))
    return np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * (m / 12.0)


def solid_cylinder(mass: float, radius: float, height: float) -> np.ndarray:
    """Homogeneous solid cylinder with its axis along z.

    ``I_zz = m R^2 / 2`` and ``I_xx = I_yy = m (3 R^2 + H^2) / 12`` about the
    centre of mass.

    Parameters
    ----------
    mass : float
        Mass (kg).
    radius : float
        Radius (m).
    height : float
        Length (m) along z.

    Returns
    -------
    ndarray, shape (3, 3)
        Inertia tensor (kg m^2) about the centre of mass, diagonal.
    """
    m = check_mass(mass)
    r = _length(radius, "radius")
    h = _length(height, "height")
    side = m * (3.0 * r * r + h * h) / 12.0
    return np.diag([side, side, 0.5 * m * r * r])


def thin_rod(mass: float, length: float) -> np.ndarray:
    """Thin homogeneous rod along z: ``m L^2 / 12`` about x and y, zero about z.

    Parameters
    ----------
    mass : float
        Mass (kg).
    length : float
        Length (m).

    Returns
    -------
    ndarray, shape (3, 3)
        Inertia tensor (kg m^2) about the centre of mass, diagonal.
    """
    m = check_mass(mass)
    l = _length(length, "length")
    side = m * l * l / 12.0
    return np.diag([side, side, 0.0])


# ---------------------------------------------------------------------------
# Parallel axes and composition
# ---------------------------------------------------------------------------


def shift_from_com(tensor_com: ArrayLike, mass: float, com: ArrayLike, point: ArrayLike) -> np.ndarray:
    """Parallel-axis theorem: tensor about the centre of mass -> about ``point``.

    ``I_P = I_C + m (|d|^2 E - d d^T)`` with ``d = com - point`` (Goldstein 5.3,
    Steiner's theorem); the reference axes do not change.

    Parameters
    ----------
    tensor_com : array_like, shape (3, 3)
        Inertia tensor (kg m^2) about the centre of mass.
    mass : float
        Total mass (kg).
    com, point : array_like, shape (3,)
        Centre of mass and the new reference point (m), same axes.

    Returns
    -------
    ndarray, shape (3, 3)
        Inertia tensor (kg m^2) about ``point``.
    """
    t = check_tensor(tensor_com)
    m = check_mass(mass)
    return t + _steiner(m, check_vector3(com, "com", InvalidBodyError, unit="m") - check_vector3(point, "point", InvalidBodyError, unit="m"))


def shift_to_com(tensor_point: ArrayLike, mass: float, com: ArrayLike, point: ArrayLike) -> np.ndarray:
    """Parallel-axis theorem backwards: tensor about ``point`` -> about the centre of mass.

    ``I_C = I_P - m (|d|^2 E - d d^T)`` with ``d = com - point``. The result is
    validated: a tensor about ``point`` smaller than the point-mass term of the
    whole mass cannot belong to a body with that mass and centre of mass.

    Parameters
    ----------
    tensor_point : array_like, shape (3, 3)
        Inertia tensor (kg m^2) about ``point``.
    mass : float
        Total mass (kg).
    com, point : array_like, shape (3,)
        Centre of mass and the point the tensor is taken about (m).

    Returns
    -------
    ndarray, shape (3, 3)
        Inertia tensor (kg m^2) about the centre of mass.
    """
    t = check_tensor(tensor_point)
    m = check_mass(mass)
    return check_tensor(t - _steiner(m, check_vector3(com, "com", InvalidBodyError, unit="m") - check_vector3(point, "point", InvalidBodyError, unit="m")))


def combine(parts: Iterable) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia tensor of a body made of parts.

    ``M = sum m_k``, ``c = sum m_k c_k / M``, and
    ``I_c = sum (I_k + m_k (|d_k|^2 E - d_k d_k^T))`` with ``d_k = c_k - c``:
    each part's tensor is shifted from its own centre of mass to the common one.

    Parameters
    ----------
    parts : iterable of (mass, com, tensor)
        Each part's mass (kg), centre of mass (m, shape (3,)) and inertia tensor
        (kg m^2, shape (3, 3)) about its own centre of mass, all in the same axes.

    Returns
    -------
    mass : float
        Total mass (kg).
    com : ndarray, shape (3,)
        Centre of mass (m).
    tensor : ndarray, shape (3, 3)
        Inertia tensor (kg m^2) about ``com``.
    """
    parts = list(parts)
    if not parts:
        raise InvalidBodyError("combine() needs at least one part (mass, com, tensor)")
    masses = np.array([check_mass(p[0], name=f"parts[{k}] mass") for k, p in enumerate(parts)])
    coms = np.array([check_vector3(p[1], f"parts[{k}] com", InvalidBodyError, unit="m") for k, p in enumerate(parts)])
    total = masses.sum()
    com = masses @ coms / total
    tensor = np.zeros((3, 3))
    for mk, ck, (_, _, tk) in zip(masses, coms, parts):
        tensor += check_tensor(tk) + _steiner(mk, ck - com)
    return float(total), com, tensor


# ---------------------------------------------------------------------------
# Principal axes and validation
# ---------------------------------------------------------------------------


def principal_moments(tensor: ArrayLike, *, rtol: float = RTOL) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments and axes of a physical inertia tensor.

    The tensor is validated ([`check_tensor`][rotframe.rigid.mass_properties.check_tensor]: finite, symmetric, positive
    semi-definite, triangle inequality) and diagonalised by
    [`rotframe.rigid.principal.principal_axes`][rotframe.rigid.principal.principal_axes].

    Parameters
    ----------
    tensor : array_like, shape (3, 3)
        Inertia tensor (kg m^2) in reference axes.
    rtol : float
        Relative tolerance on the trace for the checks.

    Returns
    -------
    moments : ndarray, shape (3,)
        Principal moments ``I1 <= I2 <= I3`` (kg m^2); round-off below zero is
        clipped to zero.
    axes : ndarray, shape (3, 3)
        Proper rotation whose columns are the principal axes in reference
        components: ``tensor = axes @ diag(moments) @ axes.T``, and ``axes``
        maps principal (body) components to reference components.
    Examples
    --------
    A phone (147 x 71 x 8 mm along x, y, z; 170 g): m (b^2 + c^2) / 12 and cyclically.

    >>> import numpy as np
    >>> moments, axes = principal_moments(box(0.17, 0.147, 0.071, 0.008))
    >>> np.round(moments * 1e6, 2)                # 1e-6 kg m^2, ascending
    array([ 72.32, 307.03, 377.54])
    >>> np.round(np.abs(axes[:, 1]), 12) + 0.0   # the intermediate axis: y, along the 71 mm edge
    array([0., 1., 0.])
    """
    t = check_tensor(tensor, rtol=rtol)
    moments, axes = principal_axes(t)
    return np.maximum(moments, 0.0), axes


def check_mass(mass: float, name: str = "mass") -> float:
    """Return ``mass`` as a float, or raise [`InvalidBodyError`][rotframe.rigid.mass_properties.InvalidBodyError].

    Parameters
    ----------
    mass : float
        Mass (kg); allowed: finite and > 0.
    name : str
        Name used in the message.

    Returns
    -------
    float
    """
    try:
        m = float(mass)
    except (TypeError, ValueError):
        raise InvalidBodyError(
            f"{name} = {mass!r} is not a number; allowed: a finite mass > 0 kg"
        ) from None
    if not np.isfinite(m) or m <= 0.0:
        raise InvalidBodyError(f"{name} = {m!r} kg; allowed: a finite mass > 0 kg")
    return m


def check_tensor(tensor: ArrayLike, *, rtol: float = RTOL) -> np.ndarray:
    """Return a physical inertia tensor (symmetrised), or raise [`InvalidBodyError`][rotframe.rigid.mass_properties.InvalidBodyError].

    Checks, each relative to the trace ``tr``: finite entries; symmetric
    (``max |T - T^T| <= rtol tr``); positive semi-definite (smallest eigenvalue
    ``>= -rtol tr``); triangle inequality of the principal moments
    (``I1 + I2 >= I3 - rtol tr``).

    Parameters
    ----------
    tensor : array_like, shape (3, 3)
        Inertia tensor (kg m^2).
    rtol : float
        Relative tolerance.

    Returns
    -------
    ndarray, shape (3, 3)
        ``(T + T^T) / 2``.
    """
    t = np.asarray(tensor, dtype=np.float64)
    if t.shape != (3, 3):
        raise InvalidBodyError(f"an inertia tensor has shape (3, 3), got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise InvalidBodyError(f"inertia tensor has non-finite entries: {t.tolist()}")
    scale = max(abs(np.trace(t)), np.max(np.abs(t)))
    asym = np.max(np.abs(t - t.T))
    if asym > rtol * scale:
        raise InvalidBodyError(
            f"inertia tensor is not symmetric: max |T - T^T| = {asym:.6g} kg m^2; "
            f"allowed: <= {rtol:g} x {scale:.6g}"
        )
    t = 0.5 * (t + t.T)
    check_moments(np.linalg.eigvalsh(t), rtol=rtol)
    return t


def check_moments(moments: ArrayLike, *, rtol: float = RTOL) -> np.ndarray:
    """Return principal moments as an array, or raise [`InvalidBodyError`][rotframe.rigid.mass_properties.InvalidBodyError].

    Allowed: three finite moments ``>= 0`` (to ``-rtol * sum``) whose two smaller
    ones add up to at least the largest (to ``rtol * sum``). A zero tensor (a
    point mass) passes; callers that need rotational inertia check for it.

    Parameters
    ----------
    moments : array_like, shape (3,)
        Principal moments (kg m^2), any order.
    rtol : float
        Relative tolerance on their sum.

    Returns
    -------
    ndarray, shape (3,)
        The moments, in the order given.
    """
    m = np.asarray(moments, dtype=np.float64)
    if m.shape != (3,):
        raise InvalidBodyError(f"principal moments are 3 numbers, got shape {m.shape}")
    if not np.all(np.isfinite(m)):
        raise InvalidBodyError(f"principal moments {m.tolist()} are not all finite")
    tol = rtol * np.sum(np.abs(m))
    if np.min(m) < -tol:
        raise InvalidBodyError(
            f"inertia is not positive semi-definite: principal moments {m.tolist()} kg m^2; "
            "allowed: all >= 0"
        )
    s = np.sort(m)
    if s[0] + s[1] < s[2] - tol:
        raise InvalidBodyError(
            f"principal moments {m.tolist()} kg m^2 violate the triangle inequality "
            f"I1 + I2 >= I3 ({s[0]:.6g} + {s[1]:.6g} < {s[2]:.6g}); no mass distribution has them"
        )
    return m


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------


def _steiner(mass, d):
    """Point-mass term ``m (|d|^2 E - d d^T)`` of the parallel-axis theorem (kg m^2)."""
    return mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))


def _length(v, name):
    """A finite length >= 0 as float, or [`InvalidBodyError`][rotframe.rigid.mass_properties.InvalidBodyError] naming it."""
    x = float(v)
    if not np.isfinite(x) or x < 0.0:
        raise InvalidBodyError(f"{name} = {x!r} m; allowed: a finite length >= 0 m")
    return x


# text, complex and object input to the public functions: a InvalidBodyError, not a numpy TypeError
from rotframe.validation import check_vector3, guard_public  # noqa: E402

guard_public(globals(), __all__, InvalidBodyError)
