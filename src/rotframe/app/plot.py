"""A picture of a run (matplotlib): for a figure rather than a viewer.

Each picture shows the effect its scene exists to show, beside its theory:

- ``foucault``: the path seen from above, and the swing plane's angle against
  time beside ``-Omega sin(latitude) t`` (less Airy's correction): the
  precession itself, not a block of swings;
- ``projectile``: the lateral deflection against the downrange distance (each
  on its own scale, so the deflection is not hidden by the range), and the
  altitude and deflection against time, up to the landing;
- other particle scenes: the path seen from above (east against north, start and
  end marked) and the position components against time;
- rigid bodies: the angular momentum in body axes against time and the path of
  the symmetry (3) axis's tip in space seen from above.

The title carries the metrics beside their theory. The figure is a
`matplotlib.figure.Figure` made without pyplot: nothing is drawn through
pyplot's global state, so Jupyter shows the returned figure once, and no
window opens. matplotlib is the ``plot`` extra; without it a
`rotframe.errors.MissingExtraError` names the extra.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["plot_result", "new_figure", "require_matplotlib"]

#: the one line a missing matplotlib gives (exit 2 on the command line)
MISSING = 'pictures need matplotlib, the plot extra: python -m pip install "rotframe[plot]"'


def require_matplotlib() -> None:
    """Raise `rotframe.errors.MissingExtraError` (naming the ``plot`` extra) if matplotlib is not installed."""
    import importlib.util

    if importlib.util.find_spec("matplotlib") is None:
        from rotframe.errors import MissingExtraError

        raise MissingExtraError(MISSING)


def new_figure(figsize=(11, 4.5)):
    """A pyplot-free matplotlib Figure; a one-line error naming the ``plot`` extra when matplotlib is missing."""
    try:
        from matplotlib.figure import Figure
    except ImportError:
        from rotframe.errors import MissingExtraError

        raise MissingExtraError(MISSING) from None
    _show_in_jupyter()
    return Figure(figsize=figsize)


def _show_in_jupyter() -> None:
    """In IPython, show a Figure returned by a cell as a PNG (once: nothing goes through pyplot).

    pyplot's inline backend registers this display itself when pyplot is imported;
    a pyplot-free figure needs it registered here. Outside IPython, nothing happens.
    """
    import sys

    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    if shell is None:
        return
    png = shell.display_formatter.formatters.get("image/png")
    if png is not None:
        png.for_type_by_name("matplotlib.figure", "Figure", _figure_png)


def _figure_png(fig) -> bytes:
    import io

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=90, bbox_inches="tight")
    return buffer.getvalue()


def plot_result(result, path: str | Path | None = None):
    """Draw ``result`` (a [`rotframe.app.api.Result`][rotframe.app.api.Result]); save as PNG when ``path`` is given.

    Returns the matplotlib Figure (made without pyplot; in Jupyter it shows once,
    as the cell's value).
    """
    fig = new_figure()
    ax1, ax2 = fig.subplots(1, 2)
    draw = _SCENE_PICTURES.get(result.scenario.scene)
    if draw is None or not draw(result, ax1, ax2):
        _generic(result, ax1, ax2)
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
        from rotframe.app.outputs import write_atomic

        path = Path(path)
        fmt = path.suffix.lower().lstrip(".") or "png"
        write_atomic(path, lambda f: fig.savefig(f, dpi=110, format=fmt), what="picture")
    return fig


#: Scenes whose frame is the local East-North-Up frame on the rotating Earth
_ENU_SCENES = ("tower-drop", "foucault", "inertial-oscillation", "projectile")


def _horizontal_axes(result):
    """The words for a picture's x and y: east and north on Earth, the frame's own name elsewhere."""
    if result.scenario.scene in _ENU_SCENES:
        return "x (east)", "y (north)"
    if result.scenario.scene == "turntable":
        return "x (turntable)", "y (turntable)"
    return "x", "y"


def _turntable(result, ax1, ax2) -> bool:
    """The curl on the table, and the same motion seen from the lab: the straight line it is measured against."""
    import numpy as np

    traj = result.trajectory
    omega = getattr(result, "_scene_result", None) and result._scene_result.extras.get("omega")
    if traj.kind != "particles" or omega is None:
        return False
    r = traj.r[:, 0]
    theta = np.asarray(omega.angle(traj.times), dtype=float).reshape(-1)
    c, s = np.cos(theta), np.sin(theta)
    lab = np.stack([c * r[:, 0] - s * r[:, 1], s * r[:, 0] + c * r[:, 1]], axis=1)  # table -> inertial axes
    R = float(result.params["table_radius"])
    phi = np.linspace(0.0, 2.0 * np.pi, 181)
    for ax, (x, y), title, words in ((ax1, (r[:, 0], r[:, 1]), "on the turntable: the path curls",
                                      ("x (turntable)", "y (turntable)")),
                                     (ax2, (lab[:, 0], lab[:, 1]), "from the lab: a straight line",
                                      ("X (inertial)", "Y (inertial)"))):
        ax.plot(R * np.cos(phi), R * np.sin(phi), color="0.75", lw=0.8, label="the table's rim")
        ax.plot(x, y, color="C1", lw=1.2, label="the puck")
        ax.plot(x[0], y[0], "o", color="green", ms=4)
        ax.plot(x[-1], y[-1], "s", color="red", ms=4)
        ax.set_xlabel(f"{words[0]} [m]")
        ax.set_ylabel(f"{words[1]} [m]")
        ax.set_title(title + " (o start, s end)", fontsize=9)
        ax.set_aspect("equal", adjustable="datalim")
    ax2.plot([lab[0, 0], lab[-1, 0]], [lab[0, 1], lab[-1, 1]], "--", color="0.3", lw=0.8,
             label="straight line (the exact answer)")
    ax2.legend(fontsize=7, loc="best")
    return True


def _generic(result, ax1, ax2) -> None:
    import numpy as np

    traj = result.trajectory
    if traj.kind == "particles":
        r, times = traj.r, traj.times
        landed = [float(np.max(t)) for t in traj.event_times.get("ground", []) if np.size(t)]
        if landed:  # after the ground the samples only repeat the landing: the picture ends there
            keep = times <= max(landed)
            keep[: int(np.argmin(keep)) + 1 if not keep.all() else len(keep)] = True  # the landing sample too
            r, times = r[keep], times[keep]
        scale, unit = (1e3, "km") if np.nanmax(np.abs(r)) > 2e4 else (1.0, "m")
        for k in range(r.shape[1]):
            ax1.plot(r[:, k, 0] / scale, r[:, k, 1] / scale, lw=0.8)
            ax1.plot(r[0, k, 0] / scale, r[0, k, 1] / scale, "o", color="green", ms=4)
            ax1.plot(r[-1, k, 0] / scale, r[-1, k, 1] / scale, "s", color="red", ms=4)
        x_word, y_word = _horizontal_axes(result)
        ax1.set_xlabel(f"{x_word} [{unit}]")
        ax1.set_ylabel(f"{y_word} [{unit}]")
        ax1.set_title("path seen from above (o start, s end)")
        ax1.set_aspect("equal", adjustable="datalim")
        t_scale, t_unit = _time_unit(times)
        for k, axis in enumerate("xyz"):
            ax2.plot(times / t_scale, r[:, 0, k] / scale, label=axis)
        if times[-1] > 0:  # a run interrupted before its first step has one sample at t = 0
            ax2.set_xlim(0.0, float(times[-1]) / t_scale)
        ax2.set_xlabel(f"t [{t_unit}]" + (" (to the landing)" if landed else ""))
        ax2.set_ylabel(f"position [{unit}]")
        ax2.legend()
    elif traj.kind == "body":
        from scipy.spatial.transform import Rotation

        t_scale, t_unit = _time_unit(traj.times)
        L = traj.L
        across = float(np.max(np.abs(L[:, :2])))
        if across < 1e-3 * float(np.max(np.abs(L[:, 2]))):
            # a body spinning almost about its 3-axis: L3 would flatten the small L1, L2 that carry the motion
            for k in range(2):
                ax1.plot(traj.times / t_scale, L[:, k], label=f"L{k + 1}")
            ax1.set_title(f"L1, L2 in the body (L3 = {float(np.mean(L[:, 2])):.4g}, on its own scale)", fontsize=9)
        else:
            for k in range(3):
                ax1.plot(traj.times / t_scale, L[:, k], label=f"L{k + 1}")
        ax1.set_xlabel(f"t [{t_unit}]")
        ax1.set_ylabel("L, body axes [kg m^2/s]")
        ax1.legend()
        e3 = Rotation.from_quat(traj.q).apply([0.0, 0.0, 1.0])
        ax2.plot(e3[:, 0], e3[:, 1], lw=0.6)
        ax2.set_xlabel("e3 x (space)")
        ax2.set_ylabel("e3 y (space)")
        ax2.set_title("tip of the 3-axis seen from above")
        ax2.set_aspect("equal", adjustable="datalim")


def _time_unit(times):
    """(seconds per unit, unit name) for a time axis: days beyond two days, hours beyond two hours."""
    end = float(times[-1]) if len(times) else 0.0
    if end > 2 * 86400:
        return 86400.0, "days"
    if end > 2 * 3600:
        return 3600.0, "h"
    return 1.0, "s"


def _heavy_top(result, ax1, ax2) -> bool:
    """The tilt between the turning points of Goldstein's cubic (the nutation), and the tip's path."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    traj = result.trajectory
    lo, hi = result.theory.get("theta_min_deg"), result.theory.get("theta_max_deg")
    if traj.kind != "body" or not all(isinstance(x, (int, float)) for x in (lo, hi)):
        return False
    e3 = Rotation.from_quat(traj.q).apply([0.0, 0.0, 1.0])
    theta = np.degrees(np.arccos(np.clip(e3[:, 2], -1.0, 1.0)))
    period = result.metrics.get("nutation_period_s")
    end = float(traj.times[-1])
    if isinstance(period, (int, float)) and period == period and period > 0:
        end = min(end, 6 * period)  # a few nutations, each one readable
    keep = traj.times <= end
    ax1.plot(traj.times[keep], theta[keep], color="C0", label="tilt theta (simulated)")
    for value, text in ((lo, "theta_min"), (hi, "theta_max")):
        ax1.axhline(value, color="C1", ls="--", lw=1.0)
        ax1.annotate(f"{text} (Goldstein's cubic) {value:.4g}", (0.01, value), xycoords=("axes fraction", "data"),
                     fontsize=7, color="C1", va="bottom")
    ax1.set_xlabel("t [s]")
    ax1.set_ylabel("tilt of the symmetry axis [deg]")
    ax1.set_title("nutation between the turning points")
    ax2.plot(e3[:, 0], e3[:, 1], lw=0.6)
    ax2.set_xlabel("e3 x (space)")
    ax2.set_ylabel("e3 y (space)")
    ax2.set_title("tip of the 3-axis seen from above (precession)")
    ax2.set_aspect("equal", adjustable="datalim")
    return True


def _foucault(result, ax1, ax2) -> bool:
    """The path from above, and the swing plane's angle against its theory (the precession)."""
    import math

    import numpy as np

    from rotframe.scenes.foucault import swing_angle

    traj = result.trajectory
    g = (getattr(result, "_scene_result", None) and result._scene_result.extras.get("g")) or None
    rate_theory = result.theory.get("precession_rate_deg_per_hour")
    if traj.kind != "particles" or g is None or not isinstance(rate_theory, (int, float)):
        return False
    r, v, t = traj.r[:, 0], traj.v[:, 0], traj.times
    length = float(result.params["length"])
    angle = np.degrees(swing_angle(r, v, math.sqrt(g / length)))
    hours = t / 3600.0
    ax1.plot(r[:, 0], r[:, 1], lw=0.3, color="0.55")
    ends = {"start": (0, "green"), "end": (-1, "red")}
    for label, (k, color) in ends.items():
        # the swing plane at the start and at the end: the turn seen from above
        d = np.array([math.cos(math.radians(angle[k])), math.sin(math.radians(angle[k]))]) * result.params["amplitude"]
        ax1.plot([-d[0], d[0]], [-d[1], d[1]], color=color, lw=2, label=f"swing plane at the {label}")
    ax1.set_aspect("equal", adjustable="datalim")
    ax1.set_xlabel("x (east) [m]")
    ax1.set_ylabel("y (north) [m]")
    ax1.set_title("the bob seen from above")
    ax1.legend(fontsize=7, loc="upper right")
    ax2.plot(hours, angle, color="C0", lw=1.5, label="swing plane (measured)")
    ax2.plot(hours, angle[0] - rate_theory * hours, "--", color="C1", lw=1.2,
             label=f"theory: {-rate_theory:+.4g} deg/h (clockwise < 0)")
    ax2.set_xlabel("t [h]")
    ax2.set_ylabel("swing-plane angle from east [deg]")
    ax2.set_title("the swing plane turns")
    ax2.legend(fontsize=7)
    return True


def _projectile(result, ax1, ax2) -> bool:
    """Lateral deflection against downrange (separate scales) and the flight up to the landing."""
    import numpy as np

    from rotframe.scenes.base import landing
    from rotframe.scenes.projectile import ground_track

    scene_result = getattr(result, "_scene_result", None)
    model = scene_result.extras.get("model") if scene_result is not None else None
    if model is None:
        return False
    times, r, _, landed = landing(scene_result.trajectory)
    rng, lateral = ground_track(result.params, r, model)
    ax1.plot(rng / 1000.0, lateral, color="C0", lw=1.5, label="simulated")
    theory = result.theory.get("lateral_deflection_m")
    if isinstance(theory, (int, float)):
        ax1.plot([rng[-1] / 1000.0], [theory], "x", color="C1", ms=9, mew=2, label="theory at the landing")
    ax1.axhline(0.0, color="0.6", lw=0.8)
    ax1.set_xlabel("downrange [km]")
    ax1.set_ylabel("deflection right of the aim [m]")
    ax1.set_title("the Coriolis deflection (its own scale)")
    ax1.legend(fontsize=7)
    ax2.plot(times, r[:, 2] / 1000.0, color="C2", label="altitude [km]")
    ax2.set_xlabel("t [s]" + (" (to the landing)" if landed else ""))
    ax2.set_ylabel("altitude [km]", color="C2")
    ax2.set_xlim(0.0, float(times[-1]))
    twin = ax2.twinx()
    twin.plot(times, lateral, color="C0", label="deflection [m]")
    twin.set_ylabel("deflection [m]", color="C0")
    ax2.set_title("flight")
    return True


def _cr3bp(result, ax1, ax2) -> bool:
    """The orbit in the co-rotating frame with the primaries, the Lagrange points and the zero-velocity
    curve of its Jacobi constant; the Jacobi constant's relative error against time."""
    import numpy as np

    from rotframe.scenes.cr3bp import jacobi_constant, lagrange_points, zero_velocity_curve

    traj = result.trajectory
    if traj.kind != "particles":
        return False
    mu = float(result.params["mu"])
    r, v, t = traj.r[:, 0], traj.v[:, 0], traj.times
    C = jacobi_constant(r, v, mu)
    for seg in zero_velocity_curve(mu, float(C[0])):
        ax1.plot(seg[:, 0], seg[:, 1], color="C2", lw=0.8)
    ax1.plot(r[:, 0], r[:, 1], color="C0", lw=0.5, label="orbit")
    pts = lagrange_points(mu)
    ax1.plot(pts[:, 0], pts[:, 1], "k+", ms=8, label="L1..L5")
    for k, (x, y, _) in enumerate(pts):
        ax1.annotate(f"L{k + 1}", (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax1.plot([-mu, 1 - mu], [0, 0], "o", color="C3", ms=5, label="primaries")
    ax1.plot([], [], color="C2", lw=0.8, label=f"zero-velocity curve, C = {C[0]:.6g}")
    ax1.set_aspect("equal", adjustable="datalim")
    ax1.set_xlabel("x [primaries' distance]")
    ax1.set_ylabel("y [primaries' distance]")
    ax1.set_title("co-rotating frame")
    ax1.legend(fontsize=7, loc="lower left")
    err = np.maximum.accumulate(np.abs(C - C[0]) / abs(C[0]))
    ax2.semilogy(t / (2 * np.pi), np.maximum(err, 1e-18), lw=1.2)
    ax2.axhline(1e-12, color="C3", lw=0.8, ls="--", label="1e-12")
    ax2.set_xlabel("t [synodic periods]")
    ax2.set_ylabel("largest |C - C(0)| / |C(0)| so far")
    ax2.set_title("Jacobi constant's drift")
    ax2.legend(fontsize=7)
    return True


def _tumbling_ball(result, ax1, ax2) -> bool:
    """The ball's curl in the body's axes beside its straight line in space, and the error against it."""
    import numpy as np

    from rotframe.scenes.tumbling_ball import oracle

    scene_result = getattr(result, "_scene_result", None)
    ex = scene_result.extras if scene_result is not None else {}
    if "body" not in ex:
        return False
    traj = result.trajectory
    exact, line = oracle(ex["body"], traj.times, ex["r0"], ex["v0"], ex["w0"])
    r = traj.r[:, 0]
    ax1.plot(r[:, 0], r[:, 1], color="C1", lw=1.0, label="in the body's axes (curls)")
    ax1.plot(line[:, 0], line[:, 1], color="C0", lw=1.5, label="in space (straight)")
    ax1.set_aspect("equal", adjustable="datalim")
    ax1.set_xlabel("x [m]")
    ax1.set_ylabel("y [m]")
    ax1.set_title("the ball, seen along axis 3")
    ax1.legend(fontsize=7)
    err = np.linalg.norm(r - exact, axis=1)
    ax2.semilogy(traj.times, np.maximum(err, 1e-18), lw=0.8, label="|simulated - exact| (floor 1e-18 m)")
    w2 = ex["body"].L[:, 1] / float(result.params["i2"])
    twin = ax2.twinx()
    twin.plot(ex["body"].times, w2, color="C3", lw=0.6, label="omega_2 (flips)")
    twin.set_ylabel("omega_2 [rad/s]", color="C3")
    ax2.set_xlabel("t [s]")
    ax2.set_ylabel("position error [m]")
    ax2.set_title("error against the inertial line, and the body's flips")
    ax2.legend(fontsize=7, loc="upper left")
    return True


#: scene -> function drawing its two panels (False: fall back to the generic picture)
_SCENE_PICTURES = {"turntable": _turntable, "foucault": _foucault, "projectile": _projectile, "heavy-top": _heavy_top, "cr3bp": _cr3bp,
                   "tumbling-ball": _tumbling_ball}
