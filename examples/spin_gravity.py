"""Your own scene in a few lines: a ball dropped in a spinning space station.

The scene protocol (see ``rotframe.scenes``): ``simulate``, ``analyse`` and
``record``, plus ``METHODS``; the parameters, their units and defaults live in
a scenario file (``spin-gravity.toml`` beside this file). Run it

* from Python: ``python examples/spin_gravity.py`` (registers the scene and runs it);
* from the command line:
  ``ROTFRAME_PLUGINS=examples/spin_gravity.py rotframe run spin-gravity --set height=10``.

Frame: the station's, z along the spin axis, the ball released at
(0, -(R - h), 0) with the floor at |r| = R; "spinward" is the direction the
floor moves, +x at the release point for omega along +z.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

import rotframe
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.scenes.base import SceneResult, particle_methods

METHODS = particle_methods()  # every particle integrator, by the registry's names (old names accepted)


def simulate(values, terms, method, run, progress):
    """Integrate the ball in the station frame until just past the floor."""
    R, h = values["radius"], values["height"]
    w = math.sqrt(values["g_floor"] / R)
    model = ParticleModel(tuple(terms), omega=OmegaSchedule.constant([0.0, 0.0, w]))
    r0 = np.array([0.0, -(R - h), 0.0])
    t_land = math.sqrt(R * R - (R - h) ** 2) / (w * (R - h))  # straight inertial line to the floor
    traj = integrate_particles(model, r0, np.zeros(3), 1.2 * t_land, method=method or "exact",
                               samples=int(run.get("samples") or 2000), step=run.get("step"), progress=progress)
    return SceneResult(traj, list(model.terms), traj.method, traj.steps, traj.nfev, extras={"omega": w})


def landing(values, result):
    """Time and along-floor offset (m, positive spinward) where |r| first reaches R (linear interpolation)."""
    traj = result.trajectory
    r = traj.r[:, 0]
    s = np.linalg.norm(r, axis=1) - values["radius"]
    k = int(np.argmax(s >= 0))
    f = -s[k - 1] / (s[k] - s[k - 1])
    t = traj.times[k - 1] + f * (traj.times[k] - traj.times[k - 1])
    p = r[k - 1] + f * (r[k] - r[k - 1])
    angle = math.atan2(p[0], -p[1])  # from the foot (0, -R), positive spinward
    return t, values["radius"] * angle


def analyse(values, result):
    R, h = values["radius"], values["height"]
    w = result.extras["omega"]
    t, offset = landing(values, result)
    d = math.sqrt(R * R - (R - h) ** 2)
    theory_t = d / (w * (R - h))
    theory_offset = R * (math.atan2(d, R - h) - w * theory_t)  # where the ball lands minus where the foot went
    return {"metrics": {"fall_time_s": t, "spinward_offset_m": offset},
            "theory": {"fall_time_s": theory_t, "spinward_offset_m": theory_offset},
            "diagnostics": {"omega_rad_s": w},
            "notes": ["the offset is linearly interpolated between samples; raise samples to sharpen it"]}


def record(rec, values, result):
    traj = result.trajectory
    R = values["radius"]
    rec.points("world/ball", traj.times, traj.r[:, 0], radius=0.2, color=[230, 90, 40])
    phi = np.linspace(0, 2 * np.pi, 361)
    rec.line("world/floor", np.stack([R * np.cos(phi), R * np.sin(phi), 0 * phi], axis=1), color=[120, 120, 200])
    rec.frame_axes("world/frame", R / 4, labels=("x", "y", "z (spin axis)"), omega=[0.0, 0.0, result.extras["omega"]])
    rec.scalars("diagnostics/distance_to_floor_m", traj.times, R - np.linalg.norm(traj.r[:, 0], axis=1))


rotframe.register_scene("spin-gravity", sys.modules[__name__], scenario=Path(__file__).with_name("spin-gravity.toml"))

if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--height", default="2 m", help="release height, e.g. '2 m' or '6 ft'")
    args = parser.parse_args()
    result = rotframe.run("spin-gravity", height=args.height)
    for key, value in result.metrics.items():
        print(f"{key:<20} {value:12.6g}   theory {result.theory[key]:12.6g} {result.units.get(key, '')}")
