"""Tests of rotframe.rigid.sections and rotframe.app.section_cli against independent references.

References used here never call the code under test for the expected value:
closed forms from textbooks, decomposition into rectangles with the
parallel-axis theorem worked out in the test, triangle-fan decomposition,
dense grid integration with matplotlib's point-in-polygon test, published
angle-section tables, and superposition of principal-axis bending.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from matplotlib.path import Path as MplPath

from rotframe.errors import RotframeError
from rotframe.app.section_cli import SHAPES, run_section, shapes_help
from rotframe.app.section_plot import plot_section
from rotframe.rigid.sections import (
    CircleRegion,
    PolygonRegion,
    Section,
    SectionError,
    angle,
    channel,
    circle,
    i_beam,
    polygon,
    rectangle,
    tube,
)

REL = 1e-12


# --------------------------------------------------------------------------
# Independent reference helpers (no code from rotframe.rigid.sections)
# --------------------------------------------------------------------------


def rect_parts(x0, y0, w, h):
    """(A, xc, yc, Ixx_c, Iyy_c, Ixy_c) of an axis-aligned rectangle: b h^3 / 12."""
    return (w * h, x0 + w / 2, y0 + h / 2, w * h**3 / 12, h * w**3 / 12, 0.0)


def composite(parts):
    """Centroidal (A, xc, yc, Ixx, Iyy, Ixy) of a union of parts, by the parallel-axis theorem."""
    area = sum(p[0] for p in parts)
    xc = sum(p[0] * p[1] for p in parts) / area
    yc = sum(p[0] * p[2] for p in parts) / area
    ixx = sum(p[3] + p[0] * (p[2] - yc) ** 2 for p in parts)
    iyy = sum(p[4] + p[0] * (p[1] - xc) ** 2 for p in parts)
    ixy = sum(p[5] + p[0] * (p[1] - xc) * (p[2] - yc) for p in parts)
    return area, xc, yc, ixx, iyy, ixy


def mohr_principal(ixx, iyy, ixy):
    """Mohr's circle: (I_major, I_minor, angle of major axis in degrees, in (-90, 90])."""
    mean = (ixx + iyy) / 2
    radius = math.hypot((ixx - iyy) / 2, ixy)
    theta = 0.5 * math.degrees(math.atan2(-2 * ixy, ixx - iyy))  # tan 2t = -2 Ixy / (Ixx - Iyy)
    return mean + radius, mean - radius, theta


def fan_moments(vertices):
    """Raw moments [A, Sx, Sy, int x^2, int y^2, int xy] of a star-shaped polygon
    (star centre at the origin) as a fan of triangles (0, p_k, p_k+1); for a
    triangle, int r r^T dA = A/12 (sum p p^T + s s^T) with s the vertex sum."""
    out = np.zeros(6)
    for p, q in zip(vertices, np.roll(vertices, -1, axis=0)):
        a = 0.5 * (p[0] * q[1] - p[1] * q[0])
        s = p + q
        m = np.outer(p, p) + np.outer(q, q) + np.outer(s, s)
        out += [a, a * s[0] / 3, a * s[1] / 3, a * m[0, 0] / 12, a * m[1, 1] / 12, a * m[0, 1] / 12]
    return out


def star_polygon(gaps, radii):
    """Vertices at increasing polar angles (gaps scaled to a full turn): simple
    and star-shaped about the origin when every gap is below half a turn."""
    t = 2 * np.pi * np.cumsum(gaps) / np.sum(gaps)
    return np.column_stack([radii * np.cos(t), radii * np.sin(t)])


class Grid:
    """Midpoint-rule integration over the cells of a square grid whose centres fall in a region.

    Two error measures for a smooth integrand f with |f| <= fmax, |f''| <= f2max:

    * ``bound``: rigorous. At most ``sqrt(2) L / h + n`` cells are cut by a
      boundary of perimeter L made of n edges, each off by at most
      ``h^2 fmax``; whole cells add at most ``A h^2 f2max / 12``.
    * ``estimate``: the cut-cell errors have either sign and largely cancel, so
      their sum grows like the square root of their number; ``estimate`` is
      ten times that random-walk size. It is the sharp check (it sees errors
      of a part in a thousand) and is also asserted.
    """

    def __init__(self, outer, holes=(), n=1200):
        outer = np.asarray(outer, dtype=float)
        lo, hi = outer.min(axis=0), outer.max(axis=0)
        self.h = float(max(hi - lo)) / n
        xs = np.arange(lo[0] + self.h / 2, hi[0], self.h)
        ys = np.arange(lo[1] + self.h / 2, hi[1], self.h)
        gx, gy = np.meshgrid(xs, ys)
        pts = np.column_stack([gx.ravel(), gy.ravel()])
        inside = MplPath(outer).contains_points(pts)
        for hole in holes:
            inside &= ~MplPath(np.asarray(hole, dtype=float)).contains_points(pts)
        self.x, self.y = pts[inside, 0], pts[inside, 1]
        self.area = inside.sum() * self.h**2
        rings = [outer, *[np.asarray(h, dtype=float) for h in holes]]
        self.perimeter = sum(np.linalg.norm(np.roll(r, -1, axis=0) - r, axis=1).sum() for r in rings)
        self.edges = sum(len(r) for r in rings)
        self.size = float(np.max(np.abs(np.concatenate(rings))))

    def integrate(self, values):
        return float(np.sum(values)) * self.h**2

    def _cut_cells(self):
        return math.sqrt(2) * self.perimeter / self.h + self.edges

    def bound(self, fmax, f2max=2.0):
        return self._cut_cells() * self.h**2 * fmax + 1.1 * self.area * self.h**2 * f2max / 12

    def estimate(self, fmax, f2max=2.0):
        return 10 * math.sqrt(self._cut_cells()) * self.h**2 * fmax + 1.1 * self.area * self.h**2 * f2max / 12


# --------------------------------------------------------------------------
# Textbook closed forms
# --------------------------------------------------------------------------


def test_rectangle_second_moments_are_bh3_over_12():
    b, h = 0.12, 0.3
    s = rectangle(b, h)
    assert s.area == pytest.approx(b * h, rel=REL)
    assert s.centroid == pytest.approx((b / 2, h / 2), rel=REL)
    assert s.ixx == pytest.approx(b * h**3 / 12, rel=REL)
    assert s.iyy == pytest.approx(h * b**3 / 12, rel=REL)
    assert abs(s.ixy) <= 1e-14 * s.ixx
    assert s.polar_moment == pytest.approx(b * h * (b * b + h * h) / 12, rel=REL)
    # Tall rectangle: strongest axis is x (angle 0), weakest is y.
    assert (s.i_major, s.i_minor) == pytest.approx((b * h**3 / 12, h * b**3 / 12), rel=REL)
    assert s.principal_angle == pytest.approx(0.0, abs=1e-9)
    assert s.r_x == pytest.approx(h / math.sqrt(12), rel=REL)
    assert s.r_minor == pytest.approx(b / math.sqrt(12), rel=REL)
    # Wide rectangle: the major axis is vertical, reported as +90 (range (-90, 90]).
    assert rectangle(h, b).principal_angle == pytest.approx(90.0, abs=1e-9)


def test_rectangle_about_its_base_is_bh3_over_3():
    b, h = 0.2, 0.05
    ixx, iyy, ixy = rectangle(b, h).second_moments_about((0.0, 0.0))
    assert ixx == pytest.approx(b * h**3 / 3, rel=REL)
    assert iyy == pytest.approx(h * b**3 / 3, rel=REL)
    assert ixy == pytest.approx(b * b * h * h / 4, rel=REL)  # int x y dA over [0,b]x[0,h]
    assert rectangle(b, h).polar_moment_about((0, 0)) == pytest.approx(b * h * (b * b + h * h) / 3, rel=REL)


def test_circle_is_exact_pi_r4_over_4():
    d = 0.08
    r = d / 2
    s = circle(d)
    assert s.area == pytest.approx(math.pi * r**2, rel=1e-15)
    assert s.ixx == pytest.approx(math.pi * r**4 / 4, rel=1e-15)
    assert s.iyy == pytest.approx(math.pi * r**4 / 4, rel=1e-15)
    assert s.polar_moment == pytest.approx(math.pi * r**4 / 2, rel=1e-15)
    assert s.ixy == 0.0
    assert s.is_isotropic and s.principal_angle == 0.0
    assert s.r_x == pytest.approx(r / 2, rel=1e-15)


def test_tube_is_exact_pi_r4_difference():
    big, t = 0.05715, 0.006
    small = big - t
    s = tube(2 * big, t)
    assert s.area == pytest.approx(math.pi * (big**2 - small**2), rel=1e-14)
    assert s.ixx == pytest.approx(math.pi * (big**4 - small**4) / 4, rel=1e-14)
    assert s.polar_moment == pytest.approx(math.pi * (big**4 - small**4) / 2, rel=1e-14)
    assert s.r_x == pytest.approx(math.sqrt(big**2 + small**2) / 2, rel=1e-14)
    # full wall thickness is the solid circle
    assert tube(0.1, 0.05).ixx == pytest.approx(circle(0.1).ixx, rel=1e-15)


def test_i_beam_equals_sum_of_three_rectangles():
    d, b, tf, tw = 0.3, 0.15, 0.0107, 0.0071
    s = i_beam(d, b, tf, tw)
    ref = composite(
        [
            rect_parts(0, 0, b, tf),
            rect_parts((b - tw) / 2, tf, tw, d - 2 * tf),
            rect_parts(0, d - tf, b, tf),
        ]
    )
    assert s.area == pytest.approx(ref[0], rel=REL)
    assert s.centroid == pytest.approx((b / 2, d / 2), rel=REL)
    assert s.ixx == pytest.approx(ref[3], rel=REL)
    assert s.iyy == pytest.approx(ref[4], rel=REL)
    assert abs(s.ixy) <= 1e-12 * s.ixx
    # the familiar "box minus two voids" form
    assert s.ixx == pytest.approx((b * d**3 - (b - tw) * (d - 2 * tf) ** 3) / 12, rel=REL)
    assert s.iyy == pytest.approx((2 * tf * b**3 + (d - 2 * tf) * tw**3) / 12, rel=REL)
    assert s.principal_angle == pytest.approx(0.0, abs=1e-9)


def test_channel_centroid_and_moments_from_rectangles():
    d, b, tf, tw = 0.2, 0.075, 0.0115, 0.0085
    s = channel(d, b, tf, tw)
    ref = composite(
        [
            rect_parts(0, 0, tw, d),  # web, full depth
            rect_parts(tw, 0, b - tw, tf),  # lower flange outstand
            rect_parts(tw, d - tf, b - tw, tf),  # upper flange outstand
        ]
    )
    area = 2 * b * tf + (d - 2 * tf) * tw
    xbar = (2 * b * tf * b / 2 + (d - 2 * tf) * tw * tw / 2) / area  # textbook centroid
    assert s.area == pytest.approx(area, rel=REL)
    assert s.centroid == pytest.approx((xbar, d / 2), rel=REL)
    assert s.ixx == pytest.approx((b * d**3 - (b - tw) * (d - 2 * tf) ** 3) / 12, rel=REL)
    assert s.iyy == pytest.approx(ref[4], rel=REL)
    assert abs(s.ixy) <= 1e-12 * s.ixx
    assert (s.i_major, s.i_minor) == pytest.approx((s.ixx, s.iyy), rel=REL)


@pytest.mark.parametrize("h, b, t", [(6.0, 4.0, 0.5), (0.15, 0.1, 0.01), (0.1, 0.2, 0.012), (0.08, 0.08, 0.008)])
def test_angle_principal_axes_from_rectangles_and_mohr(h, b, t):
    s = angle(h, b, t)
    area, xc, yc, ixx, iyy, ixy = composite([rect_parts(0, 0, t, h), rect_parts(t, 0, b - t, t)])
    assert s.area == pytest.approx(area, rel=REL)
    assert s.centroid == pytest.approx((xc, yc), rel=REL)
    assert (s.ixx, s.iyy, s.ixy) == pytest.approx((ixx, iyy, ixy), rel=1e-11)
    assert ixy < 0  # legs along +x and +y from the heel
    i1, i2, theta = mohr_principal(ixx, iyy, ixy)
    assert s.i_major == pytest.approx(i1, rel=1e-11)
    assert s.i_minor == pytest.approx(i2, rel=1e-11)
    assert s.principal_angle == pytest.approx(theta, abs=1e-9)
    # the moment about the reported major axis is the largest of all axes
    angles = np.linspace(-90, 90, 721)
    sampled = [s.moment_about_axis(a) for a in angles]
    assert max(sampled) <= s.i_major * (1 + 1e-12)
    assert s.moment_about_axis(s.principal_angle) == pytest.approx(i1, rel=1e-11)
    if h == b:  # equal legs: principal axes at +-45 degrees
        assert s.principal_angle == pytest.approx(45.0, abs=1e-9)


def test_angle_l8x4x1_matches_published_table():
    """Mott, Machine Elements in Mechanical Design, 4th ed., table A16-1 (inches):
    L8x4x1: A = 11.0, Ix = 69.6, y = 3.05, Iy = 11.6, x = 1.05, rz = 0.846, alpha = 13.9 deg.
    Tolerances are half a unit in the last printed digit (tables include fillets
    that change the third figure by less than that for this section)."""
    s = angle(8.0, 4.0, 1.0)
    assert s.area == pytest.approx(11.0, abs=0.05)
    assert s.ixx == pytest.approx(69.6, abs=0.05)
    assert s.iyy == pytest.approx(11.6, abs=0.05)
    assert s.centroid == pytest.approx((1.05, 3.05), abs=0.005)
    assert s.r_minor == pytest.approx(0.846, abs=0.0005)
    assert s.principal_angle == pytest.approx(13.9, abs=0.05)


def test_angle_l6x4x_half_matches_aisc_table():
    """AISC Steel Construction Manual, 13th ed., L6x4x1/2: A = 4.75 in^2,
    Ix = 17.4 in^4, Iy = 6.27 in^4, x = 0.987, y = 1.99 in, tan(alpha) = 0.440."""
    s = angle(6.0, 4.0, 0.5)
    assert s.area == pytest.approx(4.75, abs=0.005)
    assert s.ixx == pytest.approx(17.4, abs=0.05)
    assert s.iyy == pytest.approx(6.27, abs=0.005)
    assert s.centroid == pytest.approx((0.987, 1.99), abs=0.005)
    assert math.tan(math.radians(s.principal_angle)) == pytest.approx(0.440, abs=0.0005)


# --------------------------------------------------------------------------
# Invariance and exactness on random polygons
# --------------------------------------------------------------------------

star_polygons = st.integers(3, 14).flatmap(
    lambda n: st.tuples(
        st.lists(st.floats(0.15, 1.0), min_size=n, max_size=n),
        st.lists(st.floats(0.3, 1.5), min_size=n, max_size=n),
    )
)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(star_polygons, st.floats(-180, 180), st.floats(-50, 50), st.floats(-50, 50))
def test_principal_moments_invariant_under_rotation_and_translation(poly, turn, dx, dy):
    gaps, radii = poly
    gaps = np.asarray(gaps)
    assume(np.max(gaps) / np.sum(gaps) < 0.45)  # star centre strictly inside
    v = star_polygon(gaps, np.asarray(radii))
    s = polygon(v)
    t = math.radians(turn)
    rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    moved = polygon(v @ rot.T + [dx, dy])
    assert moved.area == pytest.approx(s.area, rel=1e-10)
    assert moved.i_major == pytest.approx(s.i_major, rel=1e-9)
    assert moved.i_minor == pytest.approx(s.i_minor, rel=1e-9)
    assert moved.polar_moment == pytest.approx(s.polar_moment, rel=1e-9)
    c = rot @ np.asarray(s.centroid) + [dx, dy]
    assert moved.centroid == pytest.approx(tuple(c), abs=1e-9 * (1 + abs(dx) + abs(dy)))
    if (s.i_major - s.i_minor) > 1e-3 * s.i_major:
        diff = (moved.principal_angle - s.principal_angle - turn) % 180.0
        assert min(diff, 180.0 - diff) < 1e-5
    # same through the Section API, rotating about an arbitrary point
    moved2 = s.rotated(turn, about=(dx, dy)).translated(dy, dx)
    assert moved2.i_major == pytest.approx(s.i_major, rel=1e-9)
    assert moved2.i_minor == pytest.approx(s.i_minor, rel=1e-9)


@settings(max_examples=40, deadline=None)
@given(star_polygons)
def test_polygon_moments_equal_triangle_fan(poly):
    gaps, radii = poly
    gaps = np.asarray(gaps)
    assume(np.max(gaps) / np.sum(gaps) < 0.45)
    v = star_polygon(gaps, np.asarray(radii))
    a, sx, sy, ixx0, iyy0, ixy0 = fan_moments(v)
    s = polygon(v[::-1])  # clockwise input, normalised
    assert s.area == pytest.approx(a, rel=1e-12)
    assert s.centroid == pytest.approx((sx / a, sy / a), abs=1e-12)
    ixx, iyy, ixy = s.second_moments_about((0.0, 0.0))
    scale = iyy0 + ixx0
    assert ixx == pytest.approx(iyy0, abs=1e-12 * scale)  # Ixx = int y^2
    assert iyy == pytest.approx(ixx0, abs=1e-12 * scale)
    assert ixy == pytest.approx(ixy0, abs=1e-12 * scale)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_polygon_agrees_with_dense_grid(seed):
    rng = np.random.default_rng(seed)
    n = rng.integers(5, 16)
    gaps = rng.uniform(0.3, 1.0, n)
    v = star_polygon(gaps, rng.uniform(0.3, 1.5, n)) + rng.uniform(-0.5, 0.5, 2)
    s = polygon(v)
    g = Grid(v, n=2000)
    fmax = g.size**2
    ixx, iyy, ixy = s.second_moments_about((0.0, 0.0))  # about the origin: no centroid needed
    checks = [
        (g.integrate(np.ones_like(g.x)), s.area, 1.0, 0.0),
        (g.integrate(g.x), s.area * s.centroid[0], g.size, 0.0),
        (g.integrate(g.y), s.area * s.centroid[1], g.size, 0.0),
        (g.integrate(g.y**2), ixx, fmax, 2.0),
        (g.integrate(g.x**2), iyy, fmax, 2.0),
        (g.integrate(g.x * g.y), ixy, fmax, 1.0),
    ]
    for grid_value, exact, f, f2 in checks:
        assert abs(grid_value - exact) <= g.bound(f, f2)
        assert abs(grid_value - exact) <= g.estimate(f, f2)
    # the sharp check resolves a part in a hundred of Ixx, Iyy and the sign of Ixy
    assert g.estimate(fmax) < 1e-2 * min(ixx, iyy)
    assert g.estimate(fmax) < 0.1 * abs(ixy)


def test_section_with_holes_agrees_with_dense_grid():
    outer = [(0, 0), (1.0, 0), (1.2, 0.8), (0.4, 1.1), (-0.1, 0.6)]
    holes = [[(0.1, 0.1), (0.4, 0.15), (0.3, 0.4)], [(0.6, 0.5), (0.9, 0.5), (0.9, 0.7), (0.6, 0.7)]]
    s = polygon(outer, holes)
    g = Grid(outer, holes, n=1500)
    fmax = g.size**2
    ixx, iyy, ixy = s.second_moments_about((0.0, 0.0))
    checks = [
        (g.integrate(np.ones_like(g.x)), s.area, 1.0, 0.0),
        (g.integrate(g.y**2), ixx, fmax, 2.0),
        (g.integrate(g.x**2), iyy, fmax, 2.0),
        (g.integrate(g.x * g.y), ixy, fmax, 1.0),
    ]
    for grid_value, exact, f, f2 in checks:
        assert abs(grid_value - exact) <= g.bound(f, f2)
        assert abs(grid_value - exact) <= g.estimate(f, f2)
    assert g.estimate(fmax) < 1e-2 * min(ixx, iyy, abs(ixy))


# --------------------------------------------------------------------------
# Holes
# --------------------------------------------------------------------------


@pytest.mark.parametrize("hole_ccw", [True, False])
def test_square_with_square_hole_is_difference_of_squares(hole_ccw):
    a, b = 1.0, 0.4
    x0, y0 = 0.15, 0.5  # off-centre hole
    hole = [(x0, y0), (x0 + b, y0), (x0 + b, y0 + b), (x0, y0 + b)]
    if not hole_ccw:
        hole = hole[::-1]
    s = polygon([(0, 0), (a, 0), (a, a), (0, a)], [hole])
    big = rectangle(a, a).second_moments_about((0, 0))
    small = rectangle(b, b).translated(x0, y0).second_moments_about((0, 0))
    expected = [big[k] - small[k] for k in range(3)]
    assert s.area == pytest.approx(a * a - b * b, rel=REL)
    assert s.second_moments_about((0, 0)) == pytest.approx(expected, rel=REL)
    # and against hand formulas about the origin: int y^2 over [x0,x0+b]x[y0,y0+b]
    hand_ixx = a**4 / 3 - b * ((y0 + b) ** 3 - y0**3) / 3
    assert s.second_moments_about((0, 0))[0] == pytest.approx(hand_ixx, rel=REL)
    # centred hole: (a^4 - b^4) / 12
    c = (a - b) / 2
    centred = polygon([(0, 0), (a, 0), (a, a), (0, a)], [[(c, c), (c + b, c), (c + b, c + b), (c, c + b)]])
    assert centred.ixx == pytest.approx((a**4 - b**4) / 12, rel=REL)


def test_plate_with_exact_circular_hole():
    a, r = 0.2, 0.03
    s = Section(PolygonRegion([(0, 0), (a, 0), (a, a), (0, a)]), (CircleRegion((a / 2, a / 2), r),))
    assert s.area == pytest.approx(a * a - math.pi * r * r, rel=REL)
    assert s.ixx == pytest.approx(a**4 / 12 - math.pi * r**4 / 4, rel=REL)


def test_closing_vertex_and_orientation_are_normalised():
    ccw = [(0, 0), (2, 0), (2, 1), (0, 1)]
    closed = ccw + [(0, 0)]
    for v in (ccw, ccw[::-1], closed, closed[::-1]):
        s = polygon(v)
        assert s.area == pytest.approx(2.0, rel=REL)
        assert s.ixx == pytest.approx(2 / 12, rel=REL)
    region = PolygonRegion(ccw[::-1])
    x, y = region.vertices[:, 0], region.vertices[:, 1]
    assert np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0  # stored counter-clockwise


# --------------------------------------------------------------------------
# Bending: stress and neutral axis
# --------------------------------------------------------------------------


def test_rectangle_bending_stress_is_mc_over_i():
    b, h, m = 0.1, 0.2, 3.0e3
    s = rectangle(b, h)
    # sagging Mx > 0 compresses the top fibre: sigma = -M c / I = -6 M / (b h^2)
    assert s.bending_stress(m, 0.0, b / 2, h) == pytest.approx(-6 * m / (b * h * h), rel=REL)
    assert s.bending_stress(m, 0.0, b / 2, 0.0) == pytest.approx(6 * m / (b * h * h), rel=REL)
    # My > 0 stretches x > xc
    assert s.bending_stress(0.0, m, b, h / 2) == pytest.approx(6 * m / (h * b * b), rel=REL)
    assert s.extreme_bending_stress(m, 0.0) == pytest.approx((-6 * m / (b * h * h), 6 * m / (b * h * h)), rel=REL)
    assert s.neutral_axis(m, 0.0).angle_deg == pytest.approx(0.0, abs=1e-12)
    assert s.neutral_axis(0.0, m).angle_deg == pytest.approx(90.0, abs=1e-12)


def test_circle_extreme_stress_is_m_over_section_modulus():
    d, mx, my = 0.05, 120.0, -50.0
    s = circle(d)
    smax = math.hypot(mx, my) * 32 / (math.pi * d**3)
    assert s.extreme_bending_stress(mx, my) == pytest.approx((-smax, smax), rel=1e-14)


def unsymmetric_cases():
    return [
        (angle(0.15, 0.1, 0.01), 2.0e3, 0.0),
        (angle(0.15, 0.1, 0.01), -1.0e3, 3.0e3),
        (polygon([(0, 0), (0.1, 0), (0.12, 0.05), (0.02, 0.09), (-0.03, 0.04)]), 500.0, -800.0),
    ]


@pytest.mark.parametrize("section, mx, my", unsymmetric_cases())
def test_neutral_axis_has_zero_stress_and_passes_through_centroid(section, mx, my):
    na = section.neutral_axis(mx, my)
    assert na.point == pytest.approx(section.centroid, abs=1e-15)
    assert section.bending_stress(mx, my, *section.centroid) == pytest.approx(0.0, abs=1e-6)
    t = np.linspace(-0.2, 0.2, 41)
    x = na.point[0] + t * na.direction[0]
    y = na.point[1] + t * na.direction[1]
    scale = max(abs(v) for v in section.extreme_bending_stress(mx, my))
    assert np.max(np.abs(section.bending_stress(mx, my, x, y))) <= 1e-12 * scale
    assert -90.0 < na.angle_deg <= 90.0
    # off the axis the stress is not zero, and changes sign across it
    normal = np.array([-na.direction[1], na.direction[0]])
    p = np.asarray(section.centroid) + 0.01 * normal
    q = np.asarray(section.centroid) - 0.01 * normal
    assert section.bending_stress(mx, my, *p) * section.bending_stress(mx, my, *q) < 0


@pytest.mark.parametrize("section, mx, my", unsymmetric_cases())
def test_stress_resultants_reproduce_applied_moments(section, mx, my):
    """Dense grid: N = int sigma dA = 0, so moments may be taken about any point;
    about the centroid (u, v) they are Mx = -int v sigma dA, My = int u sigma dA."""
    g = Grid(section.outer.vertices, n=2000)
    sigma = section.bending_stress(mx, my, g.x, g.y)
    s0 = section.bending_stress(mx, my, 0.0, 0.0)
    grad = math.hypot(section.bending_stress(mx, my, 1.0, 0.0) - s0, section.bending_stress(mx, my, 0.0, 1.0) - s0)
    u, v = g.x - section.centroid[0], g.y - section.centroid[1]
    reach = float(np.max(np.hypot(u, v))) + g.h
    smax = float(np.max(np.abs(sigma))) + grad * g.h
    f_n = (smax, 0.0)
    f_m = (smax * reach, 2 * grad)  # |v sigma| and its second derivatives
    assert abs(g.integrate(sigma)) <= g.bound(*f_n)
    assert abs(g.integrate(sigma)) <= g.estimate(*f_n)
    for got, applied in ((g.integrate(-v * sigma), mx), (g.integrate(u * sigma), my)):
        assert abs(got - applied) <= g.bound(*f_m)
        assert abs(got - applied) <= g.estimate(*f_m)
    # sharp enough to see a wrong sign, factor or swapped term
    assert g.estimate(*f_m) < 3e-2 * math.hypot(mx, my)


@pytest.mark.parametrize("section, mx, my", unsymmetric_cases())
def test_generalized_formula_equals_principal_axis_superposition(section, mx, my):
    """Resolve M on the principal axes (u along the major axis, v along the minor,
    right-handed), bend about each: sigma = -Mu v / Iu + Mv u / Iv."""
    t = math.radians(section.principal_angle)
    eu = np.array([math.cos(t), math.sin(t)])
    ev = np.array([-math.sin(t), math.cos(t)])
    m = np.array([mx, my])
    mu, mv = m @ eu, m @ ev
    rng = np.random.default_rng(0)
    xmin, ymin, xmax, ymax = section.bounds
    pts = rng.uniform([xmin, ymin], [xmax, ymax], size=(50, 2))
    rel = pts - np.asarray(section.centroid)
    pu, pv = rel @ eu, rel @ ev
    expected = -mu * pv / section.i_major + mv * pu / section.i_minor
    got = section.bending_stress(mx, my, pts[:, 0], pts[:, 1])
    assert got == pytest.approx(expected, rel=1e-9, abs=1e-9 * np.max(np.abs(expected)))


def test_unsymmetric_angle_neutral_axis_is_inclined():
    """For Mx alone, sigma = 0 on the line tan(beta) = Ixy / Iyy (not horizontal)."""
    s = angle(0.15, 0.1, 0.01)
    area, xc, yc, ixx, iyy, ixy = composite([rect_parts(0, 0, 0.01, 0.15), rect_parts(0.01, 0, 0.09, 0.01)])
    beta = math.degrees(math.atan(ixy / iyy))
    assert s.neutral_axis(1.0e3, 0.0).angle_deg == pytest.approx(beta, abs=1e-9)
    assert beta < -30.0


def test_zero_moment_has_no_neutral_axis():
    with pytest.raises(SectionError, match="no neutral axis"):
        rectangle(1, 1).neutral_axis(0.0, 0.0)
    with pytest.raises(SectionError, match="not finite"):
        rectangle(1, 1).bending_stress(float("nan"), 0.0, 0, 0)


# --------------------------------------------------------------------------
# Degenerate input
# --------------------------------------------------------------------------


@pytest.mark.parametrize(
    "vertices, holes, pattern",
    [
        ([(0, 0), (1, 1), (1, 0), (0, 1)], (), r"not simple.*intersects edge"),  # bow tie
        ([(0, 0), (2, 0), (2, 2), (1, 0), (0, 2)], (), r"not simple.*intersects"),  # vertex on an edge
        ([(0, 0), (2, 0), (1, 0), (1, 1)], (), r"folds back"),  # zero-width spike
        ([(0, 0), (1, 1), (2, 2)], (), r"zero area.*collinear"),
        ([(0, 0), (1, 1)], (), r"2 distinct vertices.*at least 3"),
        ([(0, 0), (1, 0), (0, 0)], (), r"at least 3"),
        ([(0, 0), (1, float("nan")), (0, 1)], (), r"vertex 1 .*not finite"),
        ([(0, 0), (float("inf"), 0), (0, 1)], (), r"not finite"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], (), r"shape \(3, 3\).*\(n, 2\)"),
        ([(0, 0), (1, 0), (1, 1), (0, 1)], [[(2, 2), (3, 2), (3, 3)]], r"hole 1 lies outside the outer boundary"),
        ([(0, 0), (1, 0), (1, 1), (0, 1)], [[(0.5, 0.5), (1.5, 0.5), (0.5, 0.8)]], r"hole 1 crosses or touches"),
        ([(0, 0), (1, 0), (1, 1), (0, 1)], [[(0, 0), (0.5, 0.2), (0.2, 0.5)]], r"hole 1 crosses or touches"),
        ([(0, 0), (1, 0), (1, 1), (0, 1)], [[(-1, -1), (2, -1), (2, 2), (-1, 2)]], r"hole 1 encloses"),
        (
            [(0, 0), (1, 0), (1, 1), (0, 1)],
            [[(0.1, 0.1), (0.5, 0.1), (0.5, 0.5)], [(0.3, 0.2), (0.8, 0.2), (0.8, 0.8)]],
            r"holes 1 and 2 cross or touch",
        ),
        (
            [(0, 0), (1, 0), (1, 1), (0, 1)],
            [[(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9)], [(0.4, 0.4), (0.6, 0.4), (0.5, 0.6)]],
            r"holes 1 and 2 overlap",
        ),
        ([(0, 0), (1, 0), (1, 1), (0, 1)], [[(0.1, 0.1), (0.9, 0.9), (0.9, 0.1), (0.1, 0.9)]], r"hole 1: .*not simple"),
    ],
)
def test_degenerate_polygons_raise_section_error(vertices, holes, pattern):
    with pytest.raises(SectionError, match=pattern) as info:
        polygon(vertices, holes)
    assert isinstance(info.value, ValueError) and isinstance(info.value, RotframeError)
    assert "allowed" in str(info.value) or "must" in str(info.value)


def test_circle_holes_must_be_inside_and_apart():
    square = PolygonRegion([(0, 0), (1, 0), (1, 1), (0, 1)])
    with pytest.raises(SectionError, match="crosses or touches"):
        Section(square, (CircleRegion((0.5, 0.5), 0.5),))  # tangent to the sides
    with pytest.raises(SectionError, match="outside"):
        Section(square, (CircleRegion((3, 3), 0.5),))
    with pytest.raises(SectionError, match="holes 1 and 2 overlap"):
        Section(square, (CircleRegion((0.3, 0.5), 0.15), CircleRegion((0.5, 0.5), 0.1)))
    with pytest.raises(SectionError, match="holes 1 and 2"):
        Section(square, (CircleRegion((0.5, 0.5), 0.1), PolygonRegion([(0.55, 0.45), (0.9, 0.45), (0.9, 0.9)])))
    disk = CircleRegion((0, 0), 1.0)
    with pytest.raises(SectionError, match="crosses or touches"):
        Section(disk, (CircleRegion((0.5, 0), 0.6),))
    with pytest.raises(SectionError, match="crosses or touches"):
        Section(disk, (PolygonRegion([(0, 0), (2, 0), (0, 0.5)]),))
    with pytest.raises(SectionError, match="radius"):
        CircleRegion((0, 0), -1.0)
    ok = Section(disk, (PolygonRegion([(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]),))
    assert ok.ixx == pytest.approx(math.pi / 4 - 1 / 12, rel=REL)


@pytest.mark.parametrize(
    "build, pattern",
    [
        (lambda: rectangle(-0.1, 0.2), r"rectangle: width = -0\.1"),
        (lambda: rectangle(0.1, float("nan")), r"rectangle: height = nan"),
        (lambda: circle(0.0), r"circle: diameter = 0\.0"),
        (lambda: tube(0.1, 0.06), r"tube: thickness = 0\.06 m exceeds outer_diameter/2"),
        (lambda: i_beam(0.2, 0.1, 0.1, 0.005), r"i-beam: flange_thickness = 0\.1 m must be less than depth/2"),
        (lambda: i_beam(0.2, 0.1, 0.01, 0.1), r"i-beam: web_thickness .* less than flange_width"),
        (lambda: angle(0.1, 0.05, 0.05), r"angle: thickness = 0\.05 m must be less than width"),
        (lambda: channel(0.2, 0.05, 0.01, 0.06), r"channel: web_thickness"),
    ],
)
def test_bad_shape_dimensions_name_the_parameter(build, pattern):
    with pytest.raises(SectionError, match=pattern):
        build()


# --------------------------------------------------------------------------
# Plot
# --------------------------------------------------------------------------


def test_plot_section_writes_png(tmp_path):
    s = Section(
        PolygonRegion([(0, 0), (0.3, 0), (0.3, 0.2), (0, 0.2)]),
        (CircleRegion((0.08, 0.1), 0.04), PolygonRegion([(0.18, 0.05), (0.26, 0.05), (0.22, 0.15)])),
    )
    out = plot_section(s, tmp_path / "sub" / "plate.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert plot_section(tube(0.1, 0.01), tmp_path / "tube.png").stat().st_size > 1000


# --------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------


def test_cli_json_with_quantity_strings_and_png(tmp_path, capsys):
    png = tmp_path / "rect.png"
    code = run_section("rectangle", ["width=120 mm", "height=0.2"], str(png), True)
    out, err = capsys.readouterr()
    assert code == 0 and err == ""
    data = json.loads(out)
    assert data["shape"] == "rectangle"
    assert data["params"] == {"width": pytest.approx(0.12), "height": 0.2}
    assert data["properties"]["area"] == pytest.approx(0.12 * 0.2, rel=REL)
    assert data["properties"]["ixx"] == pytest.approx(0.12 * 0.2**3 / 12, rel=REL)
    assert data["units"]["ixx"] == "m^4"
    assert data["png"] == str(png)
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_cli_table_lists_properties_with_units(capsys):
    code = run_section("i-beam", ["depth=0.3", "flange_width=150 mm"], None, False)
    out, err = capsys.readouterr()
    assert code == 0 and err == ""
    assert "Ixx" in out and "m^4" in out and "m^2" in out and "deg" in out
    d, b, tf, tw = 0.3, 0.15, 0.0085, 0.0056
    ixx = (b * d**3 - (b - tw) * (d - 2 * tf) ** 3) / 12
    assert f"{ixx:.6g}" in out


def test_cli_polygon_with_unit_and_hole(tmp_path, capsys):
    code = run_section(
        "polygon",
        ["vertices=0,0;100,0;100,100;0,100", "holes=25,25;75,25;75,75;25,75", "unit=mm"],
        str(tmp_path / "p.png"),
        True,
    )
    out, _ = capsys.readouterr()
    assert code == 0
    props = json.loads(out)["properties"]
    assert props["area"] == pytest.approx(0.1**2 - 0.05**2, rel=REL)
    assert props["ixx"] == pytest.approx((0.1**4 - 0.05**4) / 12, rel=REL)


def test_cli_defaults_for_every_shape(capsys):
    for shape in SHAPES:
        assert run_section(shape, [], None, True) == 0
        assert json.loads(capsys.readouterr().out)["properties"]["area"] > 0
    assert all(shape in shapes_help() for shape in SHAPES)


@pytest.mark.parametrize(
    "shape, sets, words",
    [
        ("rectangel", [], ["'rectangel'", "did you mean 'rectangle'", "allowed"]),
        ("rectangle", ["widht=3"], ["'widht'", "'3'", "did you mean 'width'", "allowed: width, height"]),
        ("rectangle", ["width=3 kg"], ["width", "'3 kg'", "not a length", "allowed"]),
        ("rectangle", ["width=-3"], ["width", "'-3'", "not positive", "allowed"]),
        ("rectangle", ["width=abc"], ["width", "'abc'", "allowed"]),
        ("rectangle", ["width"], ["'width'", "KEY=VALUE"]),
        ("circle", ["diameter=nan"], ["diameter", "'nan'", "not finite"]),
        ("tube", ["thickness=1 m"], ["thickness", "outer_diameter/2"]),
        ("i-beam", ["web_thickness=0.5"], ["web_thickness", "0.5", "flange_width"]),
        ("polygon", ["vertices=0,0;1,1;1,0;0,1"], ["vertices", "not simple"]),
        ("polygon", ["vertices=0,0;1"], ["vertices", "'1'", "x,y"]),
        ("polygon", ["unit=kg"], ["unit", "'kg'", "not a length"]),
        ("rectangle", ["width=1", "width=2"], ["'width'", "twice"]),
    ],
)
def test_cli_bad_input_returns_2_with_one_line(shape, sets, words, capsys, tmp_path):
    png = tmp_path / "never.png"
    code = run_section(shape, sets, str(png), False)
    out, err = capsys.readouterr()
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert not png.exists()
