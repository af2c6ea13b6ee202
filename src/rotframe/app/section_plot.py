"""Drawing of a plane cross-section to a PNG file (matplotlib lives here, not in the rigid layer)."""

from __future__ import annotations

import math
from pathlib import Path

from rotframe.rigid.cross_section import Section

__all__ = ["plot_section"]


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
    from rotframe.app.outputs import write_atomic

    write_atomic(out, lambda f: fig.savefig(f, format="png"), what="picture")
    return out
