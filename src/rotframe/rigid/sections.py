"""Geometric properties of plane cross-sections, and linear elastic bending.

A `Section` is one outer region minus zero or more holes. A region is a
simple polygon (`PolygonRegion`) or an exact circle
(`CircleRegion`), so circles and tubes are exact rather than polygons
with many sides. From the section come its area, centroid, second moments of
area about the centroid or any point, principal moments and axes (the major
axis is the strongest in bending, the minor the weakest; see the end of the
inertia section of the rigid-body lecture, docs/physics/seed-errata.md), radii of gyration, and
the bending stress and neutral axis under a bending moment (Mx, My).

Conventions
-----------
* SI units throughout: lengths in m, areas in m^2, second moments in m^4,
  moments in N m, stresses in Pa. Angles are in degrees.
* Coordinates (x, y) are right-handed, x to the right and y up as drawn.
* Second moments about the centroid (xc, yc), with ``u = x - xc`` and
  ``v = y - yc``::

      Ixx = integral v^2 dA     (about the centroidal axis parallel to x)
      Iyy = integral u^2 dA     (about the centroidal axis parallel to y)
      Ixy = integral u v dA     (product of area; may be negative)
      Ip  = Ixx + Iyy           (polar moment about the centroid)

  The second-moment tensor, with the tensor sign convention of the inertia
  tensor, is ``J = [[Ixx, -Ixy], [-Ixy, Iyy]]``: the second moment about the
  centroidal axis of unit direction ``e`` is ``e @ J @ e``. Its eigenpairs,
  from [`rotframe.rigid.principal.principal_axes`][rotframe.rigid.principal.principal_axes] (the routine that also serves
  the 3D inertia tensor), are the principal moments and axes.
* Principal angle: the angle of the major principal axis, measured from +x
  counter-clockwise, in (-90, 90] degrees. It satisfies
  ``tan(2 theta) = -2 Ixy / (Ixx - Iyy)``. When the two principal moments are
  equal (relative difference below ``1e-9``; circles, squares, regular
  polygons) every centroidal axis is principal and the angle is reported as 0.
* Boundaries: polygons are accepted in either orientation and every
  `PolygonRegion` is stored counter-clockwise. Holes are subtracted,
  which is Green's theorem with each hole boundary traversed clockwise
  (material always on the left of the boundary). Holes must lie strictly
  inside the outer boundary and be disjoint from each other (no shared
  points, to a relative tolerance of 1e-12 of the section size: model a
  notch as part of the outer polygon).
* Bending: see `Section.bending_stress` for the sign convention of the
  moments and its derivation.

References
----------
.. [1] C. Steger, "On the calculation of arbitrary moments of polygons",
   Technical Report FGBV-96-05, TU Muenchen, 1996 (moments of a polygon as
   sums over its edges, from Green's theorem).
.. [2] R. C. Hibbeler, *Mechanics of Materials*, section 6.5 "Unsymmetric
   bending" (stress from a moment with components about both axes).
.. [3] W. D. Pilkey, *Formulas for Stress, Strain, and Structural Matrices*,
   2nd ed., Wiley 2005, table 2-2 (properties of plane sections).

Modules
-------
This module gathers the public names of `rotframe.rigid.section_geometry`
(regions, `SectionError`), `rotframe.rigid.cross_section`
(`Section`, `NeutralAxis`, bending) and
`rotframe.rigid.section_shapes` (named shapes). Drawing is
`rotframe.app.section_plot.plot_section`.
"""

from __future__ import annotations

from rotframe.rigid.cross_section import PROPERTY_UNITS, NeutralAxis, Section
from rotframe.rigid.section_geometry import CircleRegion, PolygonRegion, SectionError
from rotframe.rigid.section_shapes import angle, channel, circle, i_beam, polygon, rectangle, tube

__all__ = [
    "SectionError",
    "PolygonRegion",
    "CircleRegion",
    "Section",
    "NeutralAxis",
    "PROPERTY_UNITS",
    "polygon",
    "rectangle",
    "circle",
    "tube",
    "i_beam",
    "angle",
    "channel",
]
