"""Rigid bodies: mass properties, principal axes, free and torqued motion, sections.

Layer 2 of the house (see ``docs/architecture.md``): imports only
`rotframe.numerics`, [`rotframe.frames`][rotframe.frames], `rotframe.validation`,
[`rotframe.errors`][rotframe.errors] and `rotframe.limits`; never ``particles``, ``scenes`` or ``app``.

Modules, one concept each:

* ``mass_properties``, ``principal``: inertia tensors and principal axes;
* ``checks``: [`InvalidStateError`][rotframe.rigid.checks.InvalidStateError] and the input checks of the solvers;
* ``elliptic``: Jacobi ``sn, cn, dn`` and Carlson's integrals (one source);
* ``kernels``: compiled steps, the one Euler right-hand side ``euler_rates``;
* ``drivers``: sample arrays and the splitting driver;
* ``free_body`` (exact motion), ``exact_flow`` (the same, one compiled call),
  ``torqued`` (Lie-Poisson splitting, RK4), ``heavy_top``, ``observables``,
  ``adaptive`` (DOP853);
* ``section_geometry``, ``cross_section``, ``section_shapes``: plane sections
  (``sections`` gathers them; drawing is in `rotframe.app.section_plot`);
* ``dynamics``: the former single module's names, gathered.

Every name of the former ``rotframe.rigid.dynamics.__all__`` is also reachable as
``rotframe.rigid.NAME`` (loaded on first access).
"""

from __future__ import annotations

import importlib
from typing import Any

#: Modules whose public names (``__all__``) are also reachable as ``rotframe.rigid.NAME``,
#: as they were when the rigid-body API was one module. Loaded on first access.
_PUBLIC_FROM = (
    "rotframe.rigid.checks",
    "rotframe.rigid.free_body",
    "rotframe.rigid.torqued",
    "rotframe.rigid.heavy_top",
    "rotframe.rigid.observables",
)


def __getattr__(name: str) -> Any:
    if not name.startswith("_"):
        for module_name in _PUBLIC_FROM:
            module = importlib.import_module(module_name)
            if name in getattr(module, "__all__", ()):
                return getattr(module, name)
    raise AttributeError(f"module 'rotframe.rigid' has no attribute {name!r}")
