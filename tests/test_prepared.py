"""PreparedRun gives bitwise the results of integrate_particles (the same kernels, the same arguments).

The physics of the kernels is tested elsewhere; here only that preparing once and
calling many times changes nothing, for every method, and that bad input is refused.
"""

import numpy as np
import pytest

from rotframe.errors import ScenarioError
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.particles.prepared import PreparedRun


def _models():
    w = np.array([0.0, 4.6e-5, 5.7e-5])
    yield ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=np.array([0.0, 0.0, -9.81]))
    yield ParticleModel(("coriolis", "centrifugal", "euler"), omega=OmegaSchedule.ramp([0, 0, 1], 1.0, 0.2, 4.0))


@pytest.mark.parametrize("method,kw", [("splitting", {"step": 1e-2}), ("splitting4", {"step": 1e-2}),
                                       ("rk4", {"step": 1e-2}), ("dop853", {"rtol": 1e-9})])
@pytest.mark.parametrize("which", [0, 1])
@pytest.mark.parametrize("samples", [5, 1])  # one sample: DOP853's probe is the run itself
def test_prepared_equals_integrate_particles(method, kw, which, samples):
    model = list(_models())[which]
    rng = np.random.default_rng(4)
    pr = PreparedRun(model, method, 3.0, samples=samples, n=3, **kw)
    for _ in range(2):  # repeated calls: no state carried over
        r0, v0 = rng.normal(size=(3, 3)), rng.normal(size=(3, 3))
        r, v = pr(r0, v0)
        traj = integrate_particles(model, r0, v0, 3.0, method=method, samples=samples, **kw)
        assert np.array_equal(r, traj.r) and np.array_equal(v, traj.v)
        assert np.array_equal(pr.times, traj.times)
        assert pr.nfev == traj.nfev


def test_bad_method_and_duration_are_refused():
    model = next(_models())
    pendulum = ParticleModel(("gravity", "pendulum"), g=np.array([0.0, 0.0, -9.81]), pendulum_length=1.0)
    with pytest.raises(ScenarioError, match="method: 'exact'"):  # no exact flow: a nonlinear model
        PreparedRun(pendulum, "exact", 1.0)
    with pytest.raises(ScenarioError, match="duration"):
        PreparedRun(model, "rk4", -1.0)
