"""Named cross-section shapes: polygon, rectangle, circle, tube, I-beam, angle, channel.

Each builds a `Section` centred as its
docstring says, after checking its dimensions (positive, and the thicknesses
smaller than what they cut into) with a
`SectionError` naming the shape, the key
and the value. Dimensions in m.
"""

from __future__ import annotations

import math


from rotframe.rigid.cross_section import Section
from rotframe.rigid.section_geometry import CircleRegion, PolygonRegion, SectionError

__all__ = ["polygon", "rectangle", "circle", "tube", "i_beam", "angle", "channel"]


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
    d, b, tf, tw = _flanged("i-beam", depth, flange_width, flange_thickness, web_thickness)
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
    d, b, tf, tw = _flanged("channel", depth, flange_width, flange_thickness, web_thickness)
    return polygon(
        [(0.0, 0.0), (b, 0.0), (b, tf), (tw, tf), (tw, d - tf), (b, d - tf), (b, d), (0.0, d)]
    )


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


def _flanged(shape: str, depth, flange_width, flange_thickness, web_thickness) -> tuple[float, ...]:
    """Checked ``(depth, flange_width, flange_thickness, web_thickness)`` of a flanged shape.

    All positive, ``2 flange_thickness < depth`` and ``web_thickness < flange_width``.
    """
    d = _positive(shape, "depth", depth)
    b = _positive(shape, "flange_width", flange_width)
    tf = _positive(shape, "flange_thickness", flange_thickness)
    tw = _positive(shape, "web_thickness", web_thickness)
    _less(shape, "flange_thickness", tf, "depth/2", d / 2)
    _less(shape, "web_thickness", tw, "flange_width", b)
    return d, b, tf, tw
