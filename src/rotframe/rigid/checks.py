"""Input checks shared by the rigid-body solvers, and the error they raise.

Conventions as in [`rotframe.rigid.free_body`][rotframe.rigid.free_body]: principal moments along body
axes 1, 2, 3 (kg m^2), angular momentum and torque in body axes, quaternions
scalar-last ``(x, y, z, w)``. Each check returns the validated value as float64
or raises [`InvalidStateError`][rotframe.rigid.checks.InvalidStateError] / [`InvalidBodyError`][rotframe.rigid.mass_properties.InvalidBodyError]
with one line naming the argument, its value and what is allowed.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.errors import RotframeError
from rotframe.rigid.mass_properties import InvalidBodyError, check_mass, check_moments
from rotframe.validation import check_vector3

__all__ = [
    "InvalidStateError",
    "check_inertia",
    "check_axis_momentum",
    "check_quaternion",
    "check_torque",
    "check_steps",
    "heavy_top_mgl",
    "symmetry_axis",
]


class InvalidStateError(RotframeError, ValueError):
    """An initial state, step size or option that the rigid-body solvers cannot take."""


def check_inertia(inertia):
    """Principal moments as float64 (3,) and their inverses (4,): ``1/I_i`` (0 for a zero moment), then
    ``1/I_s - 1/I_p`` of a symmetric body (``s`` its [`symmetry_axis`][rotframe.rigid.checks.symmetry_axis], ``p`` an equal one; 0 if none).

    The difference is computed as ``(I_p - I_s) / (I_p I_s)``: ``1/I_s - 1/I_p`` of the two rounded
    inverses cancels, losing five digits for a nearly spherical top (I3/I1 - 1 = 1e-12). The kernels
    read it as ``inv_i[3]``; every other use reads the first three entries.
    """
    moments = np.array(check_moments(inertia), dtype=np.float64)
    moments = np.maximum(moments, 0.0)
    if np.count_nonzero(moments) < 2:
        raise InvalidBodyError(
            f"principal moments {moments.tolist()} kg m^2: a rotating body needs at least two "
            "non-zero moments (a point mass has no rotational dynamics)"
        )
    inv_i = np.zeros(4)
    np.divide(1.0, moments, out=inv_i[:3], where=moments > 0.0)
    sym = symmetry_axis(moments)
    if sym is not None:
        i_s, i_p = moments[sym], moments[(sym + 1) % 3]
        if i_s > 0.0 and i_p > 0.0:
            inv_i[3] = (i_p - i_s) / (i_p * i_s)
    return moments, inv_i


def check_axis_momentum(moments, L, name="L_body"):
    """Refuse angular momentum (or torque) about an axis of zero moment (infinite spin)."""
    for i in np.flatnonzero(moments == 0.0):
        if np.any(np.asarray(L)[..., i] != 0.0):
            raise InvalidStateError(
                f"body axis {i + 1} has zero moment of inertia (a thin rod), so {name}[{i}] "
                f"must be 0; got {np.asarray(L)[..., i].ravel()[:3].tolist()}"
            )


def check_quaternion(q):
    """A finite non-zero quaternion (x, y, z, w), normalised."""
    a = np.asarray(q, dtype=np.float64)
    n = np.linalg.norm(a) if a.shape == (4,) and np.all(np.isfinite(a)) else 0.0
    if n == 0.0:
        raise InvalidStateError(
            f"q0 = {np.asarray(q).tolist()} must be 4 finite numbers (x, y, z, w), not all zero"
        )
    return a / n


def check_torque(moments, torque, frame):
    """Constant torque split into (body, space) parts, one of them zero."""
    zero = np.zeros(3)
    if frame not in ("body", "space"):
        raise InvalidStateError(f"torque_frame = {frame!r}; allowed: 'body' or 'space'")
    if torque is None:
        return zero, zero
    n = check_vector3(torque, "torque", InvalidStateError)
    if frame == "body":
        check_axis_momentum(moments, n, "torque")
        return n, zero
    if np.any(moments == 0.0) and np.any(n):
        raise InvalidStateError(
            "a body with a zero principal moment (thin rod) cannot take a space-fixed torque: "
            "its component along the rod would have no response"
        )
    return zero, n


def check_steps(h, n_steps, sample_every):
    """Validated (h, n_steps, sample_every)."""
    h = float(h)
    if not math.isfinite(h) or h == 0.0:
        raise InvalidStateError(f"h = {h!r} s; allowed: a finite non-zero step")
    if int(n_steps) != n_steps or n_steps < 0:
        raise InvalidStateError(f"n_steps = {n_steps!r}; allowed: an integer >= 0")
    if int(sample_every) != sample_every or sample_every < 1:
        raise InvalidStateError(f"sample_every = {sample_every!r}; allowed: an integer >= 1")
    return h, int(n_steps), int(sample_every)


def heavy_top_mgl(mass, length, g):
    """``m g l`` (N m) after checking its factors."""
    m = check_mass(mass)
    l, gg = float(length), float(g)
    if not (math.isfinite(l) and math.isfinite(gg)):
        raise InvalidBodyError(f"length = {length!r} m and g = {g!r} m/s^2 must be finite")
    return m * gg * l


def symmetry_axis(moments):
    """Index of the unequal axis of a body with two equal moments (0 for a sphere), else None."""
    for s in range(3):
        if moments[(s + 1) % 3] == moments[(s + 2) % 3]:
            return s
    return None
