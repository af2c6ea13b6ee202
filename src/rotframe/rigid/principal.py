"""Principal axes of a symmetric second-moment tensor, in 2D or 3D.

One routine serves the 3x3 inertia tensor of a rigid body
([`rotframe.rigid.mass_properties`][rotframe.rigid.mass_properties]) and the 2x2 second-moment-of-area tensor of a
cross-section (`rotframe.rigid.sections`).

Conventions
-----------
* The tensor ``T`` is symmetric, given in some reference axes. Its principal
  axes are returned as the *columns* of ``axes`` in those reference axes, so
  ``T = axes @ diag(moments) @ axes.T`` and ``axes.T`` maps reference
  components to principal components (a direction-cosine matrix in the sense
  of [`rotframe.frames`][rotframe.frames]).
* Moments are sorted ascending (``I1 <= I2 <= I3``).
* ``axes`` is a proper rotation (det +1, right-handed), and each axis has its
  sign fixed so that its largest-magnitude component is positive (the last
  axis excepted in 3D, whose sign is fixed by right-handedness): the result is
  deterministic for a given tensor.
* Equal or nearly equal moments: any orthonormal basis of the degenerate
  subspace is principal. ``numpy.linalg.eigh`` (LAPACK ``syevd``) returns an
  orthonormal one with eigenvalues accurate to ``eps * ||T||`` however close
  the moments are, which is the stability that matters here.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from rotframe.errors import RotframeError

__all__ = ["principal_axes"]


def principal_axes(tensor: ArrayLike, *, rtol: float = 1e-10) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments and axes of a symmetric 2x2 or 3x3 tensor.

    Parameters
    ----------
    tensor : array_like, shape (n, n), n in {2, 3}
        Symmetric second-moment tensor (inertia tensor in kg m^2, or area
        moments in m^4) in reference axes.
    rtol : float
        Relative tolerance on the asymmetry ``|T - T^T| / |T|``.

    Returns
    -------
    moments : ndarray, shape (n,)
        Principal moments, ascending.
    axes : ndarray, shape (n, n)
        Proper rotation whose columns are the principal axes in reference
        components.

    Raises
    ------
    RotframeError
        (a ``ValueError``) if the tensor is not square 2x2 / 3x3, not finite or
        not symmetric.
    """
    t = np.asarray(tensor, dtype=np.float64)
    if t.shape not in ((2, 2), (3, 3)):
        raise _TensorError(f"tensor must have shape (2, 2) or (3, 3), got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise _TensorError("tensor has non-finite entries")
    scale = np.max(np.abs(t))
    asym = np.max(np.abs(t - t.T))
    if asym > rtol * max(scale, np.finfo(float).tiny):
        raise _TensorError(
            f"tensor is not symmetric: max |T - T^T| = {asym:.3g} (allowed {rtol:g} x {scale:.3g})"
        )
    moments, axes = np.linalg.eigh(0.5 * (t + t.T))
    n = t.shape[0]
    for k in range(n):
        column = axes[:, k]
        if column[np.argmax(np.abs(column))] < 0:
            axes[:, k] = -column
    if np.linalg.det(axes) < 0:
        axes[:, n - 1] = -axes[:, n - 1]
    return moments, axes


class _TensorError(RotframeError, ValueError):
    """A tensor that cannot have principal axes."""
