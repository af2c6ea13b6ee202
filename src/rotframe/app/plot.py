"""A picture of a run (matplotlib, Agg): for a figure rather than a viewer.

Particles: the path seen from above (east against north, with the start and
end marked) and the position components against time. Rigid bodies: the
angular momentum in body axes against time and the path of the symmetry (3)
axis's tip in space seen from above. The title carries the metrics beside
their theory.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["plot_result"]


def plot_result(result, path: str | Path | None = None):
    """Draw ``result`` (a [`rotframe.app.api.Result`][rotframe.app.api.Result]); save as PNG when ``path`` is given.

    Returns the matplotlib Figure.
    """
    import sys

    import matplotlib

    if path is not None and "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")  # a file is wanted: no window
    import matplotlib.pyplot as plt
    import numpy as np

    traj = result.trajectory
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    if traj.kind == "particles":
        r = traj.r
        scale, unit = (1e3, "km") if np.nanmax(np.abs(r)) > 2e4 else (1.0, "m")
        for k in range(r.shape[1]):
            ax1.plot(r[:, k, 0] / scale, r[:, k, 1] / scale, lw=0.8)
            ax1.plot(r[0, k, 0] / scale, r[0, k, 1] / scale, "o", color="green", ms=4)
            ax1.plot(r[-1, k, 0] / scale, r[-1, k, 1] / scale, "s", color="red", ms=4)
        ax1.set_xlabel(f"x (east) [{unit}]")
        ax1.set_ylabel(f"y (north) [{unit}]")
        ax1.set_title("path seen from above (o start, s end)")
        ax1.set_aspect("equal", adjustable="datalim")
        for k, axis in enumerate("xyz"):
            ax2.plot(traj.times, r[:, 0, k] / scale, label=axis)
        ax2.set_ylabel(f"position [{unit}]")
        ax2.legend()
    elif traj.kind == "body":
        from scipy.spatial.transform import Rotation

        for k in range(3):
            ax1.plot(traj.times, traj.L[:, k], label=f"L{k + 1}")
        ax1.set_xlabel("t [s]")
        ax1.set_ylabel("L, body axes [kg m^2/s]")
        ax1.legend()
        e3 = Rotation.from_quat(traj.q).apply([0.0, 0.0, 1.0])
        ax2.plot(e3[:, 0], e3[:, 1], lw=0.6)
        ax2.set_xlabel("e3 x (space)")
        ax2.set_ylabel("e3 y (space)")
        ax2.set_title("tip of the 3-axis seen from above")
        ax2.set_aspect("equal", adjustable="datalim")
    ax2.set_xlabel(ax2.get_xlabel() or "t [s]")
    lines = []
    for key, value in result.metrics.items():
        theory = result.theory.get(key)
        text = f"{key} = {value:.5g}" if isinstance(value, (int, float)) and value is not None else f"{key} = {value}"
        if isinstance(theory, (int, float)):
            text += f" (theory {theory:.5g})"
        lines.append(text)
    fig.suptitle(f"{result.scenario.name} ({result.method}): " + "; ".join(lines), fontsize=8)
    fig.tight_layout()
    if path is not None:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=110)
    return fig
