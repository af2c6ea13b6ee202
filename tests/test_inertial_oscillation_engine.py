"""The inertial-oscillation scene, built on the engine of your own problems, against the scenes' own kernels.

The scene chooses its frame (the f-plane) and its terms (Coriolis alone) and hands them to
`rotframe.problem.particles.simulate_particles`; its metrics are checked against their closed
forms by the scene's own tests. Here its trajectory, under every method it takes, is checked
against the scenes' kernels (`rotframe.particles.integrators`) running the same model, a second
integrator of the same equations, to the method's accuracy; a term that is not the frame's is
refused by name.
"""

from __future__ import annotations

import numpy as np
import pytest

import rotframe
from rotframe.errors import ScenarioError


@pytest.mark.parametrize("method", ["exact", "dop853", "rk4", "rotation-splitting", "rotation-splitting4"])
def test_the_scene_on_the_engine_agrees_with_the_scenes_kernels(method):
    """Each of the two is within its method's error of the exact circle, so they agree to twice it: round-off for
    ``exact``, DOP853's rtol grown over the run (1e-8), and (f h)^p for a fixed step h of order p (f the
    angular rate of the circle)."""
    from rotframe import method_registry
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel
    from rotframe.scenes.base import earth_model_constants

    res = rotframe.run("inertial-oscillation", method=method, duration=86400.0, samples=240)
    traj = res.trajectory
    _, w_site, _ = earth_model_constants(rotframe.load("inertial-oscillation").parameters["latitude"].default)
    w = np.array([0.0, 0.0, w_site[2]])  # the f-plane
    model = ParticleModel(("coriolis",), omega=OmegaSchedule.constant(w))
    v0 = traj.v[0, 0]
    step = 86400.0 / 240 / 20 if method not in ("exact", "dop853") else None
    scene = integrate_particles(model, np.zeros(3), v0, 86400.0, method=method, samples=240, step=step)
    radius = np.linalg.norm(v0) / (2.0 * w[2])
    order = method_registry.get(method).order
    tol = {"exact": 1e-13, "dop853": 1e-8}.get(method) or 2.0 * (2.0 * w[2] * step) ** order
    assert res.method == method
    assert np.max(np.abs(traj.r[:, 0] - scene.r[:, 0])) < tol * radius


@pytest.mark.parametrize("scene", ["inertial-oscillation", "turntable"])  # the two scenes of the frame's terms alone
def test_a_term_that_is_not_the_frames_is_refused(tmp_path, scene):
    scn = tmp_path / "io.toml"
    scn.write_text(f'scene = "{scene}"\nname = "io"\nmodel = ["coriolis", "gravity"]\n')
    with pytest.raises(ScenarioError) as info:
        rotframe.run(str(scn))
    assert "'gravity'" in str(info.value) and "coriolis, centrifugal, euler" in str(info.value)
