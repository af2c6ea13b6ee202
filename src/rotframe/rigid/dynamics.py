"""The rigid-body API as one namespace (the former single module), kept for existing callers.

Each function lives in a module of one concept; this module only gathers them:

* [`rotframe.rigid.free_body`][rotframe.rigid.free_body]: [`free_body_exact`][rotframe.rigid.free_body.free_body_exact], [`elliptic_period`][rotframe.rigid.free_body.elliptic_period]
  (exact free motion; conventions of the whole rigid layer in its docstring);
* [`rotframe.rigid.torqued`][rotframe.rigid.torqued]: [`lie_poisson`][rotframe.rigid.torqued.lie_poisson], [`torqued_splitting`][rotframe.rigid.torqued.torqued_splitting],
  [`rigid_rhs`][rotframe.rigid.torqued.rigid_rhs], [`rigid_rk4`][rotframe.rigid.torqued.rigid_rk4];
* [`rotframe.rigid.heavy_top`][rotframe.rigid.heavy_top]: [`heavy_top_splitting`][rotframe.rigid.heavy_top.heavy_top_splitting],
  [`heavy_top_turning_points`][rotframe.rigid.heavy_top.heavy_top_turning_points], [`sleeping_top_threshold`][rotframe.rigid.heavy_top.sleeping_top_threshold],
  [`symmetric_top_euler_energy`][rotframe.rigid.heavy_top.symmetric_top_euler_energy], [`free_symmetric_precession`][rotframe.rigid.heavy_top.free_symmetric_precession];
* [`rotframe.rigid.observables`][rotframe.rigid.observables]: [`energy`][rotframe.rigid.observables.energy], [`omega_body`][rotframe.rigid.observables.omega_body],
  [`body_to_space`][rotframe.rigid.observables.body_to_space], [`angular_momentum_space`][rotframe.rigid.observables.angular_momentum_space];
* [`rotframe.rigid.checks`][rotframe.rigid.checks]: [`InvalidStateError`][rotframe.rigid.checks.InvalidStateError] and the input checks;
* [`rotframe.rigid.elliptic`][rotframe.rigid.elliptic]: Jacobi and Carlson functions;
  `rotframe.rigid.kernels`: the compiled steps;
  `rotframe.rigid.drivers`: output arrays and the splitting driver.
"""

from __future__ import annotations

from rotframe.rigid.checks import InvalidStateError
from rotframe.rigid.free_body import elliptic_period, free_body_closed_form, free_body_exact
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
    "free_body_closed_form",
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
