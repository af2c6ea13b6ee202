"""The specialised DOP853 driver of steady models gives bitwise the general driver's results.

rotframe.particles.dop853_steady is the general driver (rotframe.particles.drivers.run_dop853)
with the force of a steady model written in place, so that a first run compiles three
functions instead of fourteen. It must be the same algorithm in the same floating-point order:
every sample, the step and evaluation counts, the failures. The reference here is the general
driver on the same model, forced by making ``is_steady_model`` say no; the general driver's
physics is proven against closed forms and scipy elsewhere (test_particles, test_i11b_*).
"""

import numpy as np
import pytest

from rotframe.errors import IntegrationError
from rotframe.particles import dop853_steady
from rotframe.particles.chunked import KernelSetup
from rotframe.particles.integrators import METHODS, integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.particles.prepared import PreparedRun
from rotframe.particles.trajectory import Event


def general_driver(monkeypatch):
    """Make every run in this test take the general DOP853 driver.

    The set-ups that earlier runs kept (`rotframe.particles.integrators._SETUPS`, each holding its
    driver) are set aside too: a repeated run would reuse the steady one.
    """
    from rotframe.particles import integrators

    monkeypatch.setattr(dop853_steady, "is_steady_model", lambda model, events=(), packed=None: False)
    monkeypatch.setattr(integrators, "_SETUPS", {})


def random_case(seed):
    """A random steady model, ensemble and run length (seeded)."""
    rng = np.random.default_rng(seed)
    terms = ["gravity"] if rng.random() < 0.8 else []
    terms += [t for t in ("coriolis", "centrifugal") if rng.random() < 0.7]
    pendulum = rng.random() < 0.5
    axis = rng.normal(size=3)
    w = rng.uniform(1e-5, 2.0) * axis / np.linalg.norm(axis)
    g = rng.normal(size=3) * 5.0
    n = int(rng.integers(1, 4))
    if pendulum:
        L = rng.uniform(0.5, 80.0)
        pivot = rng.normal(size=3)
        u = rng.normal(size=(n, 3))
        r0 = pivot + L * u / np.linalg.norm(u, axis=1, keepdims=True)
        n_hat = (r0 - pivot) / L
        v0 = rng.normal(size=(n, 3))
        v0 -= np.sum(v0 * n_hat, axis=1, keepdims=True) * n_hat  # tangent to the sphere
        model = ParticleModel(tuple(terms + ["pendulum"]), omega=OmegaSchedule.constant(w), g=g,
                              pendulum_length=L, pivot=pivot)
    else:
        r0 = rng.normal(size=(n, 3)) * 10.0
        v0 = rng.normal(size=(n, 3)) * 3.0
        model = ParticleModel(tuple(terms), omega=OmegaSchedule.constant(w), g=g)
    duration = rng.uniform(0.5, 30.0)
    samples = int(rng.integers(1, 50))
    rtol = 10.0 ** rng.uniform(-12, -4)
    return model, r0, v0, duration, samples, rtol


def both(model, r0, v0, duration, monkeypatch, **kw):
    """The run through the steady driver, then through the general one."""
    steady = integrate_particles(model, r0, v0, duration, method="dop853", **kw)
    with monkeypatch.context() as m:
        general_driver(m)
        general = integrate_particles(model, r0, v0, duration, method="dop853", **kw)
    return steady, general


@pytest.mark.parametrize("seed", range(16))
def test_steady_driver_is_bitwise_the_general_driver_on_random_models(seed, monkeypatch):
    model, r0, v0, duration, samples, rtol = random_case(seed)
    assert dop853_steady.is_steady_model(model)
    steady, general = both(model, r0, v0, duration, monkeypatch, samples=samples, rtol=rtol)
    assert np.array_equal(steady.r, general.r) and np.array_equal(steady.v, general.v)
    assert (steady.nfev, steady.steps) == (general.nfev, general.steps)
    assert np.all(np.isfinite(steady.r))


def test_the_foucault_scene_takes_the_steady_driver_with_the_same_numbers(monkeypatch):
    from rotframe.app import runner

    calls = []
    monkeypatch.setattr(dop853_steady, "is_steady_model",
                        lambda model, events=(), packed=None, real=dop853_steady.is_steady_model:
                        calls.append(real(model, events, packed)) or calls[-1])
    summary, result = runner.run("foucault", {"duration": 120.0})
    assert result.method == "dop853" and calls == [True]
    with monkeypatch.context() as m:
        general_driver(m)
        ref_summary, reference = runner.run("foucault", {"duration": 120.0})
    assert ref_summary["metrics"] == summary["metrics"]
    assert np.array_equal(reference.trajectory.r, result.trajectory.r)


def _foucault_model():
    """A Foucault-like pendulum model (uniform g, Coriolis, string)."""
    return ParticleModel(("gravity", "coriolis", "pendulum"), omega=OmegaSchedule.constant([0.0, 4.8e-5, 5.5e-5]),
                         g=np.array([0.0, 0.0, -9.81]), pendulum_length=67.0, pivot=np.array([0.0, 0.0, 67.0]))


def test_a_prepared_run_of_a_steady_model_is_bitwise_integrate_particles():
    model = _foucault_model()
    r0 = np.array([3.0, 0.0, 67.0 - np.sqrt(67.0**2 - 9.0)])
    prepared = PreparedRun(model, "dop853", 60.0, samples=7, rtol=1e-9)
    traj = integrate_particles(model, r0, np.zeros(3), 60.0, method="dop853", samples=7, rtol=1e-9)
    assert KernelSetup(model, METHODS["dop853"], 60.0, 7).steady_args is not None
    out_r, out_v = prepared.run(r0, np.zeros(3))
    assert np.array_equal(out_r.reshape(traj.r.shape), traj.r)
    assert np.array_equal(out_v.reshape(traj.v.shape), traj.v)


def test_a_failure_is_reported_at_the_same_sample_by_both_drivers(monkeypatch):
    # a rate so large that the centrifugal acceleration overflows once the particle moves out
    # (its closed-form work estimate, 1e150 steps, is over the limit: raised here so that it runs to the failure)
    from rotframe import limits

    model = ParticleModel(("centrifugal",), omega=OmegaSchedule.constant([0.0, 0.0, 1e150]))
    with limits.applied(limits.current().with_overrides(max_steps=1e300)):
        with pytest.raises(IntegrationError) as steady:
            integrate_particles(model, [1e-160, 0.0, 0.0], [0.0, 0.0, 0.0], 1.0, method="dop853", samples=4)
        with monkeypatch.context() as m:
            general_driver(m)
            with pytest.raises(IntegrationError) as general:
                integrate_particles(model, [1e-160, 0.0, 0.0], [0.0, 0.0, 0.0], 1.0, method="dop853", samples=4)
    assert str(steady.value) == str(general.value)
    assert steady.value.t_reached == general.value.t_reached
    assert np.array_equal(steady.value.partial.r, general.value.partial.r)


@pytest.mark.parametrize("change", ["drag", "events", "varying rate", "altitude gravity", "spring"])
def test_models_outside_the_steady_family_take_the_general_driver(change):
    w = OmegaSchedule.constant([0.0, 0.0, 1e-4])
    g = np.array([0.0, 0.0, -9.81])
    events = ()
    if change == "drag":
        model = ParticleModel(("gravity", "coriolis", "linear-drag"), omega=w, g=g, k_linear=0.1)
    elif change == "events":
        model = ParticleModel(("gravity", "coriolis"), omega=w, g=g)
        events = (Event("ground", "r", 2, 0.0, -1, True),)
    elif change == "varying rate":
        model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.ramp([0, 0, 1], 0.0, 0.1, 5.0), g=g)
    elif change == "altitude gravity":
        model = ParticleModel(("altitude-gravity", "coriolis"), omega=w, g0=9.8, radius=6.4e6)
    else:
        model = ParticleModel(("coriolis", "spring"), omega=w, spring=0.3)
    assert not dop853_steady.is_steady_model(model, events)
    setup = KernelSetup(model, METHODS["dop853"], 1.0, 1, events=events)
    assert setup.steady_args is None
