"""Geometric properties of plane cross-sections, and linear elastic bending.

A :class:`Section` is one outer region minus zero or more holes. A region is a
simple polygon (:class:`PolygonRegion`) or an exact circle
(:class:`CircleRegion`), so circles and tubes are exact rather than polygons
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
  from :func:`rotframe.rigid.principal.principal_axes` (the routine that also serves
  the 3D inertia tensor), are the principal moments and axes.
* Principal angle: the angle of the major principal axis, measured from +x
  counter-clockwise, in (-90, 90] degrees. It satisfies
  ``tan(2 theta) = -2 Ixy / (Ixx - Iyy)``. When the two principal moments are
  equal (relative difference below ``1e-9``; circles, squares, regular
  polygons) every centroidal axis is principal and the angle is reported as 0.
* Boundaries: polygons are accepted in either orientation and every
  :class:`PolygonRegion` is stored counter-clockwise. Holes are subtracted,
  which is Green's theorem with each hole boundary traversed clockwise
  (material always on the left of the boundary). Holes must lie strictly
  inside the outer boundary and be disjoint from each other (no shared
  points, to a relative tolerance of 1e-12 of the section size: model a
  notch as part of the outer polygon).
* Bending: see :meth:`Section.bending_stress` for the sign convention of the
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
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from rotframe.errors import RotframeError
from rotframe.rigid.principal import principal_axes

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
    "plot_section",
]

#: Units of the entries of :meth:`Section.properties`.
PROPERTY_UNITS = {
    "area": "m^2",
    "centroid_x": "m",
    "centroid_y": "m",
    "ixx": "m^4",
    "iyy": "m^4",
    "ixy": "m^4",
    "polar_moment": "m^4",
    "i_major": "m^4",
    "i_minor": "m^4",
    "principal_angle_deg": "deg",
    "r_x": "m",
    "r_y": "m",
    "r_major": "m",
    "r_minor": "m",
}

# Relative difference of the principal moments below which a section is
# treated as isotropic (every centroidal axis principal).
_ISOTROPIC_RTOL = 1e-9
# Relative tolerance (to the size of the outer boundary) for geometric tests:
# collinearity, touching, containment.
_GEOM_RTOL = 1e-12
# Edges per block in the vectorised pairwise edge tests.
_BLOCK = 256


class SectionError(RotframeError, ValueError):
    """A section that cannot exist: degenerate, self-intersecting or ill-placed.

    The message says what was wrong and what is allowed.
    """


# --------------------------------------------------------------------------
# Regions
# --------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class PolygonRegion:
    """A simple polygon, the outer boundary of a section or one of its holes.

    Parameters
    ----------
    vertices : array_like, shape (n, 2)
        Vertices (m) in order along the boundary, either orientation. A closing
        vertex equal to the first one and repeated consecutive vertices are
        dropped. At least three distinct vertices, all finite, not all
        collinear, and no two edges may cross or touch except consecutive
        edges at their shared vertex.

    Attributes
    ----------
    vertices : ndarray, shape (n, 2)
        Read-only copy, counter-clockwise (positive signed area).

    Raises
    ------
    SectionError
        For any of the defects above, naming it.
    """

    vertices: np.ndarray

    def __post_init__(self):
        v = _clean_vertices(self.vertices, "polygon")
        _check_simple(v, "polygon")
        if _signed_area(v) < 0.0:
            v = v[::-1].copy()
        v.setflags(write=False)
        object.__setattr__(self, "vertices", v)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` in m."""
        lo = self.vertices.min(axis=0)
        hi = self.vertices.max(axis=0)
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))

    def moments(self, about=(0.0, 0.0)) -> np.ndarray:
        """Raw moments of the region about a point.

        Green's theorem turns each area integral into a sum over the edges
        ``(x_i, y_i) -> (x_{i+1}, y_{i+1})`` with ``c_i = x_i y_{i+1} -
        x_{i+1} y_i`` (Steger 1996, [1]_ in the module notes)::

            A        = 1/2  sum c_i
            int x dA = 1/6  sum c_i (x_i + x_{i+1})
            int x^2  = 1/12 sum c_i (x_i^2 + x_i x_{i+1} + x_{i+1}^2)
            int x y  = 1/24 sum c_i (2 x_i y_i + x_i y_{i+1} + x_{i+1} y_i
                                     + 2 x_{i+1} y_{i+1})

        and likewise in y. These are exact for a polygon.

        Parameters
        ----------
        about : array_like, shape (2,)
            Point (m) whose coordinates are subtracted first.

        Returns
        -------
        ndarray, shape (6,)
            ``[A, int x dA, int y dA, int y^2 dA, int x^2 dA, int x y dA]``
            with x, y relative to ``about`` (m^2, m^3, m^3, m^4, m^4, m^4).
        """
        p = self.vertices - np.asarray(about, dtype=float)
        x, y = p[:, 0], p[:, 1]
        xn, yn = np.roll(x, -1), np.roll(y, -1)
        c = x * yn - xn * y
        return np.array(
            [
                c.sum() / 2.0,
                (c * (x + xn)).sum() / 6.0,
                (c * (y + yn)).sum() / 6.0,
                (c * (y * y + y * yn + yn * yn)).sum() / 12.0,
                (c * (x * x + x * xn + xn * xn)).sum() / 12.0,
                (c * (2.0 * x * y + x * yn + xn * y + 2.0 * xn * yn)).sum() / 24.0,
            ]
        )

    def transformed(self, rotation, shift) -> PolygonRegion:
        """The region moved by ``p -> rotation @ p + shift`` (rotation proper)."""
        r = np.asarray(rotation, dtype=float)
        return PolygonRegion(self.vertices @ r.T + np.asarray(shift, dtype=float))

    def outline(self) -> np.ndarray:
        """Boundary points for drawing, counter-clockwise, shape (n, 2)."""
        return np.array(self.vertices)


@dataclass(frozen=True, eq=False)
class CircleRegion:
    """An exact disk, the outer boundary of a section or one of its holes.

    Parameters
    ----------
    center : array_like, shape (2,)
        Centre (m), finite.
    radius : float
        Radius (m), finite and positive.

    Raises
    ------
    SectionError
        If the centre or radius is not finite or the radius is not positive.
    """

    center: tuple[float, float]
    radius: float

    def __post_init__(self):
        try:
            c = np.asarray(self.center, dtype=float).reshape(2)
            r = float(self.radius)
        except (TypeError, ValueError) as exc:
            raise SectionError(
                f"circle: center {self.center!r} and radius {self.radius!r} must be "
                "two numbers and a number (m)"
            ) from exc
        if not np.all(np.isfinite(c)):
            raise SectionError(f"circle: center {tuple(c)} is not finite; allowed: finite numbers (m)")
        if not (math.isfinite(r) and r > 0.0):
            raise SectionError(f"circle: radius = {r!r} m; allowed: a finite positive length (m)")
        object.__setattr__(self, "center", (float(c[0]), float(c[1])))
        object.__setattr__(self, "radius", r)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` in m."""
        (cx, cy), r = self.center, self.radius
        return (cx - r, cy - r, cx + r, cy + r)

    def moments(self, about=(0.0, 0.0)) -> np.ndarray:
        """Raw moments about a point, exact: ``pi r^4 / 4`` about a diameter
        plus the parallel-axis terms. Same layout as
        :meth:`PolygonRegion.moments`."""
        dx = self.center[0] - float(about[0])
        dy = self.center[1] - float(about[1])
        a = math.pi * self.radius**2
        i0 = math.pi * self.radius**4 / 4.0
        return np.array([a, a * dx, a * dy, i0 + a * dy * dy, i0 + a * dx * dx, a * dx * dy])

    def transformed(self, rotation, shift) -> CircleRegion:
        """The region moved by ``p -> rotation @ p + shift`` (rotation proper)."""
        c = np.asarray(rotation, dtype=float) @ np.asarray(self.center) + np.asarray(shift, dtype=float)
        return CircleRegion((c[0], c[1]), self.radius)

    def outline(self, n: int = 256) -> np.ndarray:
        """Boundary points for drawing only, counter-clockwise, shape (n, 2)."""
        t = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
        return np.column_stack(
            [self.center[0] + self.radius * np.cos(t), self.center[1] + self.radius * np.sin(t)]
        )


# --------------------------------------------------------------------------
# Section
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class NeutralAxis:
    """The line of zero bending stress, through the centroid.

    Attributes
    ----------
    point : tuple of float
        A point on the axis (the centroid), m.
    direction : tuple of float
        Unit direction of the axis, with angle in (-90, 90] degrees.
    angle_deg : float
        Angle of the axis from +x, counter-clockwise, in (-90, 90] degrees.
    """

    point: tuple[float, float]
    direction: tuple[float, float]
    angle_deg: float

    def distance(self, x, y):
        """Signed distance (m) of points from the axis (positive on the left
        of ``direction``)."""
        dx = np.asarray(x, dtype=float) - self.point[0]
        dy = np.asarray(y, dtype=float) - self.point[1]
        return self.direction[0] * dy - self.direction[1] * dx


@dataclass(frozen=True, eq=False)
class Section:
    """A plane cross-section: an outer region minus holes.

    Parameters
    ----------
    outer : PolygonRegion or CircleRegion
        Outer boundary.
    holes : sequence of PolygonRegion or CircleRegion
        Holes, each strictly inside ``outer`` and disjoint from the others.

    Raises
    ------
    SectionError
        If a hole lies outside the outer boundary, crosses or touches it, or
        overlaps or touches another hole.

    Notes
    -----
    Properties are computed exactly: each region contributes its moments
    (Green's theorem for polygons, closed forms for circles) and holes are
    subtracted, which is the same as traversing hole boundaries clockwise.
    Moments are first accumulated about the centre of the outer boundary's
    bounding box, then again about the centroid, so no large parallel-axis
    terms cancel.

    Examples
    --------
    >>> s = rectangle(0.1, 0.2)
    >>> round(s.ixx / (0.1 * 0.2**3 / 12), 12)
    1.0
    """

    outer: PolygonRegion | CircleRegion
    holes: tuple = ()

    def __post_init__(self):
        if not isinstance(self.outer, (PolygonRegion, CircleRegion)):
            raise SectionError(
                f"outer boundary is a {type(self.outer).__name__}; allowed: PolygonRegion or CircleRegion"
            )
        holes = tuple(self.holes)
        for k, h in enumerate(holes, start=1):
            if not isinstance(h, (PolygonRegion, CircleRegion)):
                raise SectionError(
                    f"hole {k} is a {type(h).__name__}; allowed: PolygonRegion or CircleRegion"
                )
        object.__setattr__(self, "holes", holes)
        tol = _GEOM_RTOL * _size(self.outer.bounds)
        for k, h in enumerate(holes, start=1):
            problem = _inside_problem(h, self.outer, tol)
            if problem:
                raise SectionError(
                    f"hole {k} {problem}; holes must lie strictly inside the outer boundary "
                    "(no shared points; model a notch as part of the outer polygon)"
                )
        for i in range(len(holes)):
            for j in range(i + 1, len(holes)):
                problem = _disjoint_problem(holes[i], holes[j], tol)
                if problem:
                    raise SectionError(
                        f"holes {i + 1} and {j + 1} {problem}; holes must be disjoint "
                        "(no shared points; merge touching holes into one polygon)"
                    )

    # -- construction helpers ------------------------------------------------

    def translated(self, dx: float, dy: float) -> Section:
        """The same section shifted by (dx, dy) m."""
        return self._moved(np.eye(2), (dx, dy))

    def rotated(self, angle_deg: float, about=(0.0, 0.0)) -> Section:
        """The same section rotated counter-clockwise by ``angle_deg`` degrees
        about the point ``about`` (m)."""
        t = math.radians(angle_deg)
        r = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
        p = np.asarray(about, dtype=float)
        return self._moved(r, p - r @ p)

    # -- basic properties --------------------------------------------------

    @property
    def area(self) -> float:
        """Net area A (m^2)."""
        return self._centroidal[0]

    @property
    def centroid(self) -> tuple[float, float]:
        """Centroid (xc, yc) in m."""
        return self._centroid_point

    @property
    def ixx(self) -> float:
        """Ixx = integral (y - yc)^2 dA (m^4), about the centroidal axis parallel to x."""
        return self._centroidal[3]

    @property
    def iyy(self) -> float:
        """Iyy = integral (x - xc)^2 dA (m^4), about the centroidal axis parallel to y."""
        return self._centroidal[4]

    @property
    def ixy(self) -> float:
        """Ixy = integral (x - xc)(y - yc) dA (m^4), the product of area about the
        centroid (zero when x or y is an axis of symmetry)."""
        return self._centroidal[5]

    @property
    def polar_moment(self) -> float:
        """Polar second moment about the centroid, Ip = Ixx + Iyy (m^4).

        This is the torsion constant only for circles and tubes."""
        return self.ixx + self.iyy

    @property
    def tensor(self) -> np.ndarray:
        """Second-moment tensor ``[[Ixx, -Ixy], [-Ixy, Iyy]]`` (m^4) about the centroid."""
        return np.array([[self.ixx, -self.ixy], [-self.ixy, self.iyy]])

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the outer boundary, m."""
        return self.outer.bounds

    # -- principal axes ------------------------------------------------------

    @property
    def principal_moments(self) -> tuple[float, float]:
        """``(I_major, I_minor)`` in m^4: the largest and smallest second
        moments about centroidal axes."""
        return self._principal[0], self._principal[1]

    @property
    def i_major(self) -> float:
        """Second moment about the major principal axis (the strongest), m^4."""
        return self._principal[0]

    @property
    def i_minor(self) -> float:
        """Second moment about the minor principal axis (the weakest), m^4."""
        return self._principal[1]

    @property
    def principal_angle(self) -> float:
        """Angle of the major principal axis from +x, counter-clockwise, in
        (-90, 90] degrees (0 when the section is isotropic)."""
        return self._principal[2]

    @property
    def major_axis(self) -> tuple[float, float]:
        """Unit direction of the major principal axis, ``(cos t, sin t)``."""
        t = math.radians(self.principal_angle)
        return (math.cos(t), math.sin(t))

    @property
    def minor_axis(self) -> tuple[float, float]:
        """Unit direction of the minor principal axis, the major one turned by +90 degrees."""
        t = math.radians(self.principal_angle)
        return (-math.sin(t), math.cos(t))

    @property
    def is_isotropic(self) -> bool:
        """True when the principal moments are equal (every centroidal axis is principal)."""
        return self._principal[3]

    # -- radii of gyration ---------------------------------------------------

    @property
    def r_x(self) -> float:
        """Radius of gyration sqrt(Ixx / A) about the centroidal x axis, m."""
        return math.sqrt(self.ixx / self.area)

    @property
    def r_y(self) -> float:
        """Radius of gyration sqrt(Iyy / A) about the centroidal y axis, m."""
        return math.sqrt(self.iyy / self.area)

    @property
    def r_major(self) -> float:
        """Radius of gyration about the major principal axis, m."""
        return math.sqrt(self.i_major / self.area)

    @property
    def r_minor(self) -> float:
        """Radius of gyration about the minor principal axis (the least), m."""
        return math.sqrt(self.i_minor / self.area)

    # -- about other points and axes -----------------------------------------

    def second_moments_about(self, point) -> tuple[float, float, float]:
        """``(Ixx, Iyy, Ixy)`` about axes parallel to x and y through ``point`` (m^4).

        Parallel-axis theorem with ``d = centroid - point``::

            Ixx_P = Ixx + A dy^2,  Iyy_P = Iyy + A dx^2,  Ixy_P = Ixy + A dx dy
        """
        px, py = _finite_point(point, "point")
        dx = self.centroid[0] - px
        dy = self.centroid[1] - py
        a = self.area
        return (self.ixx + a * dy * dy, self.iyy + a * dx * dx, self.ixy + a * dx * dy)

    def polar_moment_about(self, point) -> float:
        """Polar second moment about ``point``: Ip + A |centroid - point|^2 (m^4)."""
        ixx, iyy, _ = self.second_moments_about(point)
        return ixx + iyy

    def moment_about_axis(self, angle_deg: float, through=None) -> float:
        """Second moment about the line at ``angle_deg`` from +x through a point.

        ``I = Ixx cos^2 t - 2 Ixy sin t cos t + Iyy sin^2 t`` with the moments
        taken about ``through`` (default: the centroid), m^4.
        """
        point = self.centroid if through is None else through
        ixx, iyy, ixy = self.second_moments_about(point)
        t = math.radians(angle_deg)
        c, s = math.cos(t), math.sin(t)
        return ixx * c * c - 2.0 * ixy * s * c + iyy * s * s

    # -- bending ---------------------------------------------------------------

    def bending_stress(self, mx: float, my: float, x, y):
        """Normal stress (Pa) at points (x, y) under the bending moment (Mx, My).

        Parameters
        ----------
        mx, my : float
            Components (N m) of the bending moment, sign convention below.
        x, y : array_like
            Coordinates (m) in the section's axes (not relative to the centroid).

        Returns
        -------
        float or ndarray
            ``sigma`` in Pa, tension positive, broadcast over ``x`` and ``y``.

        Notes
        -----
        Sign convention. The beam axis is ``t = y_hat x x_hat``: it points into
        the drawing (away from a viewer who sees x to the right and y up), so
        the viewer looks along the beam. The section is the cut face whose
        outward normal is ``+t``, and (Mx, My) are the right-hand-rule
        components along x and y of the moment that the normal stresses on
        that face exert about the centroid. This is Hibbeler's convention with
        his (z, y) as our (x, y); for a horizontal beam drawn with y up,
        ``Mx > 0`` compresses the fibres above the centroid (sagging) and
        ``My > 0`` stretches the fibres at x > xc.

        Derivation. Plane sections stay plane and the material is linear
        elastic, so ``sigma = a + b u + c v`` with ``u = x - xc``,
        ``v = y - yc``. The force ``sigma dA t`` at ``(u, v)`` has moment
        ``(u, v, 0) x (0, 0, -sigma dA) = (-v sigma, u sigma, 0) dA``. Pure
        bending (no axial force) and the moment balance give::

            N  =  integral sigma dA   = a A               = 0   ->  a = 0
            Mx = -integral v sigma dA = -(b Ixy + c Ixx)
            My =  integral u sigma dA =   b Iyy + c Ixy

        whose solution, with ``D = Ixx Iyy - Ixy^2 > 0``, is::

            sigma = [(My Ixx + Mx Ixy) u - (Mx Iyy + My Ixy) v] / D

        For Ixy = 0 this reduces to ``sigma = -Mx v / Ixx + My u / Iyy``.
        The neutral axis (sigma = 0) passes through the centroid; see
        :meth:`neutral_axis`.
        """
        b, c = self._stress_gradient(mx, my)
        u = np.asarray(x, dtype=float) - self.centroid[0]
        v = np.asarray(y, dtype=float) - self.centroid[1]
        sigma = b * u + c * v
        return float(sigma) if sigma.ndim == 0 else sigma

    def neutral_axis(self, mx: float, my: float) -> NeutralAxis:
        """The neutral axis (sigma = 0) under the bending moment (Mx, My) N m.

        It passes through the centroid with direction ``(c, -b)`` where
        ``sigma = b u + c v`` (see :meth:`bending_stress`); its angle from +x
        is in (-90, 90] degrees. In unsymmetric bending (Ixy != 0, or a moment
        not along a principal axis) it is not perpendicular to the plane of
        loading.

        Raises
        ------
        SectionError
            If Mx = My = 0 (no bending, no neutral axis).
        """
        b, c = self._stress_gradient(mx, my)
        if b == 0.0 and c == 0.0:
            raise SectionError(
                f"bending moment (Mx, My) = ({mx!r}, {my!r}) N m is zero: there is no neutral "
                "axis; allowed: any finite moment with Mx or My nonzero"
            )
        angle = _half_turn_angle(c, -b)
        t = math.radians(angle)
        return NeutralAxis(self.centroid, (math.cos(t), math.sin(t)), angle)

    def extreme_bending_stress(self, mx: float, my: float) -> tuple[float, float]:
        """``(sigma_min, sigma_max)`` in Pa over the section under (Mx, My).

        The stress is linear, so its extremes are at vertices of the outer
        polygon or, for an outer circle, at the two boundary points along the
        stress gradient.
        """
        b, c = self._stress_gradient(mx, my)
        if isinstance(self.outer, CircleRegion):
            g = math.hypot(b, c)
            u0 = self.outer.center[0] - self.centroid[0]
            v0 = self.outer.center[1] - self.centroid[1]
            mid = b * u0 + c * v0
            return (mid - g * self.outer.radius, mid + g * self.outer.radius)
        p = self.outer.vertices - np.asarray(self.centroid)
        s = b * p[:, 0] + c * p[:, 1]
        return (float(s.min()), float(s.max()))

    # -- summary ---------------------------------------------------------------

    def properties(self) -> dict[str, float]:
        """All scalar properties as plain floats in SI units (see :data:`PROPERTY_UNITS`)."""
        return {
            "area": self.area,
            "centroid_x": self.centroid[0],
            "centroid_y": self.centroid[1],
            "ixx": self.ixx,
            "iyy": self.iyy,
            "ixy": self.ixy,
            "polar_moment": self.polar_moment,
            "i_major": self.i_major,
            "i_minor": self.i_minor,
            "principal_angle_deg": self.principal_angle,
            "r_x": self.r_x,
            "r_y": self.r_y,
            "r_major": self.r_major,
            "r_minor": self.r_minor,
        }

    # -- internals ---------------------------------------------------------------

    def _moved(self, rotation, shift) -> Section:
        return Section(
            self.outer.transformed(rotation, shift),
            tuple(h.transformed(rotation, shift) for h in self.holes),
        )

    def _net_moments(self, about) -> np.ndarray:
        m = self.outer.moments(about)
        for h in self.holes:
            m = m - h.moments(about)
        return m

    @cached_property
    def _centroid_point(self) -> tuple[float, float]:
        xmin, ymin, xmax, ymax = self.outer.bounds
        ref = (0.5 * (xmin + xmax), 0.5 * (ymin + ymax))
        m = self._net_moments(ref)
        if not m[0] > 0.0:
            raise SectionError(f"section has net area {float(m[0]):g} m^2; allowed: a positive area")
        return (float(ref[0] + m[1] / m[0]), float(ref[1] + m[2] / m[0]))

    @cached_property
    def _centroidal(self) -> tuple[float, ...]:
        # Second pass about the centroid itself: no parallel-axis cancellation.
        return tuple(float(m) for m in self._net_moments(self._centroid_point))

    @cached_property
    def _principal(self) -> tuple[float, float, float, bool]:
        moments, axes = principal_axes(self.tensor)
        minor, major = float(moments[0]), float(moments[1])
        if major - minor <= _ISOTROPIC_RTOL * abs(major):
            return major, minor, 0.0, True
        return major, minor, _half_turn_angle(axes[0, 1], axes[1, 1]), False

    def _stress_gradient(self, mx, my) -> tuple[float, float]:
        try:
            mx, my = float(mx), float(my)
        except (TypeError, ValueError) as exc:
            raise SectionError(f"bending moment ({mx!r}, {my!r}) must be two numbers (N m)") from exc
        if not (math.isfinite(mx) and math.isfinite(my)):
            raise SectionError(
                f"bending moment (Mx, My) = ({mx!r}, {my!r}) N m is not finite; allowed: finite numbers"
            )
        ixx, iyy, ixy = self.ixx, self.iyy, self.ixy
        d = ixx * iyy - ixy * ixy
        return ((my * ixx + mx * ixy) / d, -(mx * iyy + my * ixy) / d)


# --------------------------------------------------------------------------
# Standard shapes
# --------------------------------------------------------------------------


def polygon(vertices, holes=()) -> Section:
    """A polygonal section with optional polygonal holes.

    Parameters
    ----------
    vertices : array_like, shape (n, 2)
        Outer boundary (m), either orientation.
    holes : sequence of array_like, shape (m, 2)
        Hole boundaries (m), either orientation (each is stored
        counter-clockwise as a region and subtracted).

    Returns
    -------
    Section
    """
    outer = PolygonRegion(vertices)
    inner = []
    for k, h in enumerate(holes, start=1):
        try:
            inner.append(PolygonRegion(h))
        except SectionError as exc:
            raise SectionError(f"hole {k}: {exc}") from None
    return Section(outer, tuple(inner))


def rectangle(width: float, height: float) -> Section:
    """Solid rectangle ``[0, width] x [0, height]`` (m).

    Ixx = width height^3 / 12, Iyy = height width^3 / 12 about the centroid.
    """
    b = _positive("rectangle", "width", width)
    h = _positive("rectangle", "height", height)
    return polygon([(0.0, 0.0), (b, 0.0), (b, h), (0.0, h)])


def circle(diameter: float) -> Section:
    """Solid circle of the given diameter (m), exact, centred at (r, r) so
    that its bounding box starts at the origin. Ixx = Iyy = pi r^4 / 4."""
    d = _positive("circle", "diameter", diameter)
    r = 0.5 * d
    return Section(CircleRegion((r, r), r))


def tube(outer_diameter: float, thickness: float) -> Section:
    """Circular hollow section (m), exact, centred at (R, R).

    Ixx = Iyy = pi (R^4 - r^4) / 4 with ``r = R - thickness``. A thickness of
    ``outer_diameter / 2`` gives the solid circle.
    """
    d = _positive("tube", "outer_diameter", outer_diameter)
    t = _positive("tube", "thickness", thickness)
    big = 0.5 * d
    if t > big:
        raise SectionError(
            f"tube: thickness = {t:g} m exceeds outer_diameter/2 = {big:g} m; "
            "allowed: 0 < thickness <= outer_diameter/2"
        )
    if t == big:
        return Section(CircleRegion((big, big), big))
    return Section(CircleRegion((big, big), big), (CircleRegion((big, big), big - t),))


def i_beam(depth: float, flange_width: float, flange_thickness: float, web_thickness: float) -> Section:
    """Doubly symmetric I-section (m), sharp corners (no root fillets).

    The bounding box is ``[0, flange_width] x [0, depth]``, web centred.
    Requires ``2 flange_thickness < depth`` and ``web_thickness < flange_width``.
    """
    d = _positive("i-beam", "depth", depth)
    b = _positive("i-beam", "flange_width", flange_width)
    tf = _positive("i-beam", "flange_thickness", flange_thickness)
    tw = _positive("i-beam", "web_thickness", web_thickness)
    _less("i-beam", "flange_thickness", tf, "depth/2", d / 2)
    _less("i-beam", "web_thickness", tw, "flange_width", b)
    w0, w1 = 0.5 * (b - tw), 0.5 * (b + tw)
    return polygon(
        [
            (0.0, 0.0), (b, 0.0), (b, tf), (w1, tf), (w1, d - tf), (b, d - tf),
            (b, d), (0.0, d), (0.0, d - tf), (w0, d - tf), (w0, tf), (0.0, tf),
        ]
    )  # fmt: skip


def angle(height: float, width: float, thickness: float) -> Section:
    """L-section (m) with legs of unequal length allowed, sharp corners.

    The heel is at the origin: the vertical leg is ``[0, thickness] x
    [0, height]`` and the horizontal leg ``[0, width] x [0, thickness]``.
    Requires ``thickness < min(height, width)``. Unless the legs are equal
    the principal axes are inclined (Ixy < 0 in this placement).
    """
    h = _positive("angle", "height", height)
    b = _positive("angle", "width", width)
    t = _positive("angle", "thickness", thickness)
    _less("angle", "thickness", t, "height", h)
    _less("angle", "thickness", t, "width", b)
    return polygon([(0.0, 0.0), (b, 0.0), (b, t), (t, t), (t, h), (0.0, h)])


def channel(depth: float, flange_width: float, flange_thickness: float, web_thickness: float) -> Section:
    """C-section (m), sharp corners, symmetric about ``y = depth / 2``.

    The web is ``[0, web_thickness] x [0, depth]`` and the flanges open
    towards +x, out to ``flange_width``. Requires ``2 flange_thickness <
    depth`` and ``web_thickness < flange_width``.
    """
    d = _positive("channel", "depth", depth)
    b = _positive("channel", "flange_width", flange_width)
    tf = _positive("channel", "flange_thickness", flange_thickness)
    tw = _positive("channel", "web_thickness", web_thickness)
    _less("channel", "flange_thickness", tf, "depth/2", d / 2)
    _less("channel", "web_thickness", tw, "flange_width", b)
    return polygon(
        [(0.0, 0.0), (b, 0.0), (b, tf), (tw, tf), (tw, d - tf), (b, d - tf), (b, d), (0.0, d)]
    )


# --------------------------------------------------------------------------
# Plot
# --------------------------------------------------------------------------


def plot_section(section: Section, path, *, title: str | None = None) -> Path:
    """Draw a section to a PNG file.

    The section is filled (holes empty), with its centroid and its major and
    minor principal axes labelled with their moments, on equal axes in m.
    Circles are drawn as fine polygons (drawing only; the properties are
    exact). Uses matplotlib's Agg canvas directly, so pyplot and the global
    backend are left alone.

    Parameters
    ----------
    section : Section
    path : str or os.PathLike
        Output file; parent directories are created.
    title : str, optional
        Figure title (default: a summary of area and principal angle).

    Returns
    -------
    pathlib.Path
        The file written.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)

    verts, codes = [], []
    rings = [section.outer.outline()] + [h.outline()[::-1] for h in section.holes]
    for ring in rings:
        verts.extend(ring.tolist())
        verts.append(ring[0].tolist())
        codes.extend([MplPath.MOVETO] + [MplPath.LINETO] * (len(ring) - 1) + [MplPath.CLOSEPOLY])

    fig = Figure(figsize=(6.4, 6.0), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.add_patch(
        PathPatch(MplPath(verts, codes), facecolor="#9ecae1", edgecolor="#08519c", lw=1.2, label="section")
    )

    xmin, ymin, xmax, ymax = section.bounds
    half = 0.6 * math.hypot(xmax - xmin, ymax - ymin)
    xc, yc = section.centroid
    for name, axis, moment, colour in (
        ("major", section.major_axis, section.i_major, "#d62728"),
        ("minor", section.minor_axis, section.i_minor, "#2ca02c"),
    ):
        ex, ey = axis
        ax.plot([xc - half * ex, xc + half * ex], [yc - half * ey, yc + half * ey], color=colour, lw=1.2,
                ls="--", label=f"{name} axis: I = {moment:.4g} m$^4$")  # fmt: skip
        ax.annotate(f"{name}\nI = {moment:.3g} m$^4$", (xc + half * ex, yc + half * ey), color=colour,
                    fontsize=8, ha="center", va="center",
                    bbox={"boxstyle": "round", "fc": "white", "ec": colour, "alpha": 0.85})  # fmt: skip
    ax.plot([xc], [yc], marker="+", ms=12, mew=2, color="k", ls="none", label=f"centroid ({xc:.4g}, {yc:.4g}) m")

    pad = 0.15 * max(xmax - xmin, ymax - ymin)
    ax.set_xlim(min(xmin, xc - half) - pad, max(xmax, xc + half) + pad)
    ax.set_ylim(min(ymin, yc - half) - pad, max(ymax, yc + half) + pad)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(True, lw=0.3)
    ax.legend(loc="upper right", fontsize=7)
    ax.set_title(
        title
        if title is not None
        else f"A = {section.area:.4g} m$^2$, major axis at {section.principal_angle:.2f} deg"
        + (" (isotropic: every axis principal)" if section.is_isotropic else "")
    )
    fig.savefig(out, format="png")
    return out


# --------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------


def _positive(shape: str, key: str, value) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SectionError(f"{shape}: {key} = {value!r} is not a number; allowed: a positive length (m)") from None
    if not (math.isfinite(x) and x > 0.0):
        raise SectionError(f"{shape}: {key} = {x!r} m; allowed: a finite positive length (m)")
    return x


def _less(shape: str, key: str, value: float, limit_name: str, limit: float) -> None:
    if not value < limit:
        raise SectionError(f"{shape}: {key} = {value:g} m must be less than {limit_name} = {limit:g} m")


def _finite_point(point, what: str) -> tuple[float, float]:
    try:
        p = np.asarray(point, dtype=float).reshape(2)
    except (TypeError, ValueError):
        raise SectionError(f"{what} {point!r} must be two numbers (m)") from None
    if not np.all(np.isfinite(p)):
        raise SectionError(f"{what} {tuple(p)} is not finite")
    return float(p[0]), float(p[1])


def _size(bounds) -> float:
    xmin, ymin, xmax, ymax = bounds
    return math.hypot(xmax - xmin, ymax - ymin)


def _half_turn_angle(ex: float, ey: float) -> float:
    """Angle in degrees of the undirected line along (ex, ey), in (-90, 90]."""
    a = math.degrees(math.atan2(ey, ex))
    if a > 90.0:
        a -= 180.0
    elif a <= -90.0:
        a += 180.0
    return a


def _signed_area(v: np.ndarray) -> float:
    """Shoelace area of ``v``, on coordinates centred first: far from the origin the products
    x_i y_j would otherwise cancel catastrophically (1 mm^2 at 3e6 m: terms of 1e13 m^2)."""
    lo, hi = v.min(axis=0), v.max(axis=0)
    c = v - 0.5 * (lo + hi)
    x, y = c[:, 0], c[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _clean_vertices(vertices, what: str) -> np.ndarray:
    try:
        v = np.array(vertices, dtype=float)
    except (TypeError, ValueError):
        raise SectionError(
            f"{what}: vertices are not numbers; allowed: an (n, 2) array of finite coordinates (m), n >= 3"
        ) from None
    if v.ndim != 2 or v.shape[1] != 2:
        raise SectionError(
            f"{what}: vertices have shape {v.shape}; allowed: (n, 2), one (x, y) pair per vertex, n >= 3"
        )
    bad = ~np.all(np.isfinite(v), axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        raise SectionError(
            f"{what}: vertex {k} = ({v[k, 0]!r}, {v[k, 1]!r}) is not finite (NaN or inf); "
            "allowed: finite coordinates (m)"
        )
    if len(v) > 0:
        keep = np.ones(len(v), dtype=bool)
        keep[1:] = np.any(v[1:] != v[:-1], axis=1)  # consecutive repeats
        v = v[keep]
        while len(v) > 1 and np.array_equal(v[0], v[-1]):  # closing repeat
            v = v[:-1]
    if len(v) < 3:
        raise SectionError(
            f"{what}: {len(v)} distinct vertices; allowed: at least 3 (a closed polygon needs three corners)"
        )
    centred = v - v.mean(axis=0)
    sv = np.linalg.svd(centred, compute_uv=False)
    if sv[1] <= _GEOM_RTOL * sv[0] * 10.0:
        raise SectionError(
            f"{what}: zero area, all {len(v)} vertices are collinear; allowed: a polygon enclosing a positive area"
        )
    return v


def _check_simple(v: np.ndarray, what: str) -> None:
    """Raise SectionError unless the closed polygon ``v`` is simple."""
    n = len(v)
    tol_len = _GEOM_RTOL * _size((*v.min(axis=0), *v.max(axis=0)))
    nxt = np.roll(v, -1, axis=0)
    # Consecutive edges meet only at their shared vertex, unless they fold back
    # on each other (collinear and reversing: a zero-width spike).
    prev = np.roll(v, 1, axis=0)
    d_in, d_out = v - prev, nxt - v
    cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    dot = np.sum(d_in * d_out, axis=1)
    lengths = np.linalg.norm(d_in, axis=1) * np.linalg.norm(d_out, axis=1)
    spike = (np.abs(cross) <= _GEOM_RTOL * 10.0 * lengths) & (dot < 0.0)
    if spike.any():
        k = int(np.argmax(spike))
        raise SectionError(
            f"{what} is not simple: the boundary folds back on itself at vertex {k} "
            f"({v[k, 0]:g}, {v[k, 1]:g}); allowed: a simple polygon (edges neither cross nor touch)"
        )
    # Non-adjacent edges must not meet at all.
    def non_adjacent(i, j):
        return (j >= i + 2) & ~((i == 0) & (j == n - 1))

    hit = _first_meeting(v, nxt, v, nxt, tol_len, non_adjacent)
    if hit is not None:
        a, k = hit
        raise SectionError(
            f"{what} is not simple: edge {a} ({v[a, 0]:g}, {v[a, 1]:g})->({nxt[a, 0]:g}, {nxt[a, 1]:g}) "
            f"intersects edge {k} ({v[k, 0]:g}, {v[k, 1]:g})->({nxt[k, 0]:g}, {nxt[k, 1]:g}); "
            "allowed: a simple polygon (edges neither cross nor touch); give holes separately"
        )


def _first_meeting(a0, a1, b0, b1, tol: float, keep=None) -> tuple[int, int] | None:
    """A pair ``(i, j)`` such that segment ``a0[i]-a1[i]`` meets ``b0[j]-b1[j]``,
    or None. Only pairs whose bounding boxes overlap are tested exactly, in
    blocks of rows; ``keep(i, j)`` (broadcast index arrays) may exclude pairs."""
    alo, ahi = np.minimum(a0, a1) - tol, np.maximum(a0, a1) + tol
    blo, bhi = np.minimum(b0, b1), np.maximum(b0, b1)
    cols = np.arange(len(b0))[None, :]
    for start in range(0, len(a0), _BLOCK):
        rows = np.arange(start, min(start + _BLOCK, len(a0)))[:, None]
        cand = np.all((alo[rows[:, 0], None] <= bhi[None]) & (blo[None] <= ahi[rows[:, 0], None]), axis=-1)
        if keep is not None:
            cand &= keep(rows, cols)
        ii, jj = np.nonzero(cand)
        if ii.size:
            ii = ii + start
            hit = _segments_meet(a0[ii], a1[ii], b0[jj], b1[jj], tol)
            if hit.any():
                k = int(np.argmax(hit))
                return int(ii[k]), int(jj[k])
    return None


def _segments_meet(p0, p1, q0, q1, tol: float) -> np.ndarray:
    """Whether closed segments p0-p1 and q0-q1 meet (cross, touch or overlap).

    Arrays of points, shape (..., 2), broadcast against each other; ``tol``
    is the length below which a point counts as on a line.
    """
    p0, p1, q0, q1 = (np.asarray(a, dtype=float) for a in (p0, p1, q0, q1))

    def orient(a, b, c):
        return (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0])

    def zeroed(d, length):
        return np.where(np.abs(d) <= tol * np.maximum(length, tol), 0.0, d)

    len_p = np.linalg.norm(p1 - p0, axis=-1)
    len_q = np.linalg.norm(q1 - q0, axis=-1)
    d1 = zeroed(orient(q0, q1, p0), len_q)
    d2 = zeroed(orient(q0, q1, p1), len_q)
    d3 = zeroed(orient(p0, p1, q0), len_p)
    d4 = zeroed(orient(p0, p1, q1), len_p)

    def on(a, b, c):
        lo = np.minimum(a, b) - tol
        hi = np.maximum(a, b) + tol
        return np.all((c >= lo) & (c <= hi), axis=-1)

    proper = (d1 * d2 < 0.0) & (d3 * d4 < 0.0)
    touch = (
        ((d1 == 0.0) & on(q0, q1, p0))
        | ((d2 == 0.0) & on(q0, q1, p1))
        | ((d3 == 0.0) & on(p0, p1, q0))
        | ((d4 == 0.0) & on(p0, p1, q1))
    )
    return proper | touch


def _polygons_meet(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    return _first_meeting(a, np.roll(a, -1, axis=0), b, np.roll(b, -1, axis=0), tol) is not None


def _point_in_polygon(p, v: np.ndarray) -> bool:
    """Crossing-number test; points on the boundary are caught before this is used."""
    x, y = float(p[0]), float(p[1])
    xi, yi = v[:, 0], v[:, 1]
    xj, yj = np.roll(xi, 1), np.roll(yi, 1)
    straddle = (yi > y) != (yj > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_cross = xj + (y - yj) * (xi - xj) / (yi - yj)
    return bool(np.count_nonzero(straddle & (x < x_cross)) % 2)


def _distance_to_edges(p, v: np.ndarray) -> float:
    a, b = v, np.roll(v, -1, axis=0)
    ab = b - a
    t = np.clip(np.sum((np.asarray(p) - a) * ab, axis=1) / np.sum(ab * ab, axis=1), 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + t[:, None] * ab - np.asarray(p), axis=1)))


def _inside_problem(inner, outer, tol: float) -> str | None:
    """None if ``inner`` lies strictly inside ``outer``, else what is wrong."""
    if isinstance(inner, PolygonRegion) and isinstance(outer, PolygonRegion):
        if _polygons_meet(inner.vertices, outer.vertices, tol):
            return "crosses or touches the outer boundary"
        if _point_in_polygon(inner.vertices[0], outer.vertices):
            return None
        if _point_in_polygon(outer.vertices[0], inner.vertices):
            return "encloses the outer boundary"
        return "lies outside the outer boundary"
    if isinstance(inner, CircleRegion) and isinstance(outer, PolygonRegion):
        c, r = inner.center, inner.radius
        dist = _distance_to_edges(c, outer.vertices)
        if dist <= r + tol:
            return "crosses or touches the outer boundary"
        return None if _point_in_polygon(c, outer.vertices) else "lies outside the outer boundary"
    if isinstance(inner, PolygonRegion) and isinstance(outer, CircleRegion):
        c, r = outer.center, outer.radius
        far = float(np.max(np.linalg.norm(inner.vertices - np.asarray(c), axis=1)))
        if far < r - tol:
            return None
        if _distance_to_edges(c, inner.vertices) <= r + tol:
            return "crosses or touches the outer boundary"
        if _point_in_polygon(c, inner.vertices):
            return "encloses the outer boundary"
        return "lies outside the outer boundary"
    # circle in circle
    d = math.dist(inner.center, outer.center)
    if d + inner.radius < outer.radius - tol:
        return None
    if d >= inner.radius + outer.radius + tol:
        return "lies outside the outer boundary"
    if d + outer.radius < inner.radius - tol:
        return "encloses the outer boundary"
    return "crosses or touches the outer boundary"


def _disjoint_problem(a, b, tol: float) -> str | None:
    """None if regions ``a`` and ``b`` share no point, else what is wrong."""
    if isinstance(a, CircleRegion) and isinstance(b, PolygonRegion):
        a, b = b, a
    if isinstance(a, PolygonRegion) and isinstance(b, PolygonRegion):
        if _polygons_meet(a.vertices, b.vertices, tol):
            return "cross or touch"
        if _point_in_polygon(a.vertices[0], b.vertices) or _point_in_polygon(b.vertices[0], a.vertices):
            return "overlap (one is inside the other)"
        return None
    if isinstance(a, PolygonRegion):  # b is a circle
        if _distance_to_edges(b.center, a.vertices) <= b.radius + tol:
            return "cross or touch"
        if _point_in_polygon(b.center, a.vertices):
            return "overlap (one is inside the other)"
        return None
    d = math.dist(a.center, b.center)
    if d > a.radius + b.radius + tol:
        return None
    return "overlap or touch"
