"""A plane cross-section (outer region minus holes): area, centroid, second moments, bending.

`Section` holds the regions of `rotframe.rigid.section_geometry` and
derives its properties (second moments about the centroid or any point,
principal moments and axes from [`rotframe.rigid.principal.principal_axes`][rotframe.rigid.principal.principal_axes],
radii of gyration) and the linear elastic bending stress and neutral axis under
a bending moment ``(Mx, My)`` (Hibbeler 6.5). Conventions and references in
`rotframe.rigid.sections`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rotframe.rigid.principal import principal_axes
from rotframe.rigid.section_geometry import (
    GEOM_RTOL,
    CircleRegion,
    PolygonRegion,
    SectionError,
    boundary_size,
    disjoint_problem,
    inside_problem,
)

__all__ = ["Section", "NeutralAxis", "PROPERTY_UNITS"]

#: Units of the entries of `Section.properties`.
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
    >>> from rotframe.rigid.section_shapes import rectangle
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
        tol = GEOM_RTOL * boundary_size(self.outer.bounds)
        for k, h in enumerate(holes, start=1):
            problem = inside_problem(h, self.outer, tol)
            if problem:
                raise SectionError(
                    f"hole {k} {problem}; holes must lie strictly inside the outer boundary "
                    "(no shared points; model a notch as part of the outer polygon)"
                )
        for i in range(len(holes)):
            for j in range(i + 1, len(holes)):
                problem = disjoint_problem(holes[i], holes[j], tol)
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
        `neutral_axis`.
        """
        b, c = self._stress_gradient(mx, my)
        u = np.asarray(x, dtype=float) - self.centroid[0]
        v = np.asarray(y, dtype=float) - self.centroid[1]
        sigma = b * u + c * v
        return float(sigma) if sigma.ndim == 0 else sigma

    def neutral_axis(self, mx: float, my: float) -> NeutralAxis:
        """The neutral axis (sigma = 0) under the bending moment (Mx, My) N m.

        It passes through the centroid with direction ``(c, -b)`` where
        ``sigma = b u + c v`` (see `bending_stress`); its angle from +x
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
        """All scalar properties as plain floats in SI units (see `PROPERTY_UNITS`)."""
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


def _finite_point(point, what: str) -> tuple[float, float]:
    try:
        p = np.asarray(point, dtype=float).reshape(2)
    except (TypeError, ValueError):
        raise SectionError(f"{what} {point!r} must be two numbers (m)") from None
    if not np.all(np.isfinite(p)):
        raise SectionError(f"{what} {tuple(p)} is not finite")
    return float(p[0]), float(p[1])


def _half_turn_angle(ex: float, ey: float) -> float:
    """Angle in degrees of the undirected line along (ex, ey), in (-90, 90]."""
    a = math.degrees(math.atan2(ey, ex))
    if a > 90.0:
        a -= 180.0
    elif a <= -90.0:
        a += 180.0
    return a
