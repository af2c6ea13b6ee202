"""Regions of a plane cross-section (polygons and exact circles) and the checks of their placement.

A `PolygonRegion` is a simple polygon stored counter-clockwise; its
second moments come from sums over its edges (Green's theorem; Steger 1996,
see `rotframe.rigid.sections`). A `CircleRegion` is an exact circle.
The checks refuse degenerate, self-intersecting, touching or ill-placed
boundaries with a `SectionError` that says what was wrong and what is
allowed; geometric tests use a relative tolerance `GEOM_RTOL` of the size
of the outer boundary. Conventions as in `rotframe.rigid.sections`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotframe.errors import RotframeError

__all__ = [
    "SectionError",
    "PolygonRegion",
    "CircleRegion",
    "GEOM_RTOL",
    "boundary_size",
    "inside_problem",
    "disjoint_problem",
]

# Relative tolerance (to the size of the outer boundary) for geometric tests:
# collinearity, touching, containment.
GEOM_RTOL = 1e-12
# Edges per block in the vectorised pairwise edge tests.
_BLOCK = 256


class SectionError(RotframeError, ValueError):
    """A section that cannot exist: degenerate, self-intersecting or ill-placed.

    The message says what was wrong and what is allowed.
    """


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
        `PolygonRegion.moments`."""
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


def boundary_size(bounds) -> float:
    xmin, ymin, xmax, ymax = bounds
    return math.hypot(xmax - xmin, ymax - ymin)


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
    if sv[1] <= GEOM_RTOL * sv[0] * 10.0:
        raise SectionError(
            f"{what}: zero area, all {len(v)} vertices are collinear; allowed: a polygon enclosing a positive area"
        )
    return v


def _check_simple(v: np.ndarray, what: str) -> None:
    """Raise SectionError unless the closed polygon ``v`` is simple."""
    n = len(v)
    tol_len = GEOM_RTOL * boundary_size((*v.min(axis=0), *v.max(axis=0)))
    nxt = np.roll(v, -1, axis=0)
    # Consecutive edges meet only at their shared vertex, unless they fold back
    # on each other (collinear and reversing: a zero-width spike).
    prev = np.roll(v, 1, axis=0)
    d_in, d_out = v - prev, nxt - v
    cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    dot = np.sum(d_in * d_out, axis=1)
    lengths = np.linalg.norm(d_in, axis=1) * np.linalg.norm(d_out, axis=1)
    spike = (np.abs(cross) <= GEOM_RTOL * 10.0 * lengths) & (dot < 0.0)
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


def inside_problem(inner, outer, tol: float) -> str | None:
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


def disjoint_problem(a, b, tol: float) -> str | None:
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
