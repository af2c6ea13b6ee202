"""The rigid-body API as one namespace (the former single module), kept for existing callers.

Each function lives in a module of one concept; this module only gathers them:

* :mod:`rotframe.rigid.free_body`: :func:`free_body_exact`, :func:`elliptic_period`
  (exact free motion; conventions of the whole rigid layer in its docstring);
* :mod:`rotframe.rigid.torqued`: :func:`lie_poisson`, :func:`torqued_splitting`,
  :func:`rigid_rhs`, :func:`rigid_rk4`;
* :mod:`rotframe.rigid.heavy_top`: :func:`heavy_top_splitting`,
  :func:`heavy_top_turning_points`, :func:`sleeping_top_threshold`,
  :func:`symmetric_top_euler_energy`, :func:`free_symmetric_precession`;
* :mod:`rotframe.rigid.observables`: :func:`energy`, :func:`omega_body`,
  :func:`body_to_space`, :func:`angular_momentum_space`;
* :mod:`rotframe.rigid.checks`: :class:`InvalidStateError` and the input checks;
* :mod:`rotframe.rigid.elliptic`: Jacobi and Carlson functions;
  :mod:`rotframe.rigid.kernels`: the compiled steps;
  :mod:`rotframe.rigid.drivers`: output arrays and the splitting driver.
"""

from __future__ import annotations

from rotframe.rigid.checks import InvalidStateError
from rotframe.rigid.free_body import elliptic_period, free_body_exact
from rotframe.rigid.heavy_top import (
    free_symmetric_precession,
    heavy_top_splitting,
    heavy_top_turning_points,
    sleeping_top_threshold,
    symmetric_top_euler_energy,
)
from rotframe.rigid.observables import angular_momentum_space, body_to_space, energy, omega_body
from rotframe.rigid.torqued import lie_poisson, rigid_rhs, rigid_rk4, torqued_splitting

__all__ = [
    "InvalidStateError",
    "free_body_exact",
    "lie_poisson",
    "torqued_splitting",
    "heavy_top_splitting",
    "rigid_rhs",
    "rigid_rk4",
    "energy",
    "omega_body",
    "body_to_space",
    "angular_momentum_space",
    "symmetric_top_euler_energy",
    "heavy_top_turning_points",
    "sleeping_top_threshold",
    "free_symmetric_precession",
    "elliptic_period",
]
