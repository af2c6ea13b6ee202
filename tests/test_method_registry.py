"""The one method registry (``rotframe.methods()``, issue 32): what it says is what runs.

- every problem's methods are the registry's: the scenes' ``METHODS``, the GPU's, and what
  ``rotframe.simulate`` and ``simulate_body`` accept, refusing the rest by name;
- the order it states is the order measured: each fixed-step particle method against the exact
  flow of a linear model (the matrix exponential, another code path), halving the step;
- no integer method code is part of a method's description.
"""

from __future__ import annotations

import numpy as np
import pytest

import rotframe
from rotframe import method_registry as registry
from rotframe import scenes
from rotframe.errors import ScenarioError


def test_methods_lists_every_method_with_the_contract_fields():
    listed = rotframe.methods()
    assert len({m.name for m in listed}) == len(listed) >= 13
    for m in listed:
        entry = dict(m)
        for key in ("name", "order", "conserves", "accepts", "gpu"):
            assert key in entry and m[key] == getattr(m, key)
        assert m.step in ("fixed", "adaptive", "exact")
        assert (m.order is None) == (m.step == "exact")
        assert set(m.runs) <= set(registry.PROBLEMS) and m.runs
        assert "code" not in entry and not hasattr(m, "code")
    assert {m.name for m in listed if m.gpu} == {"rotation-splitting", "rotation-splitting4", "rk4"}


@pytest.mark.parametrize("scene, problem", [("turntable", "particle scenes"), ("foucault", "particle scenes"),
                                            ("free-top", "free body"), ("dzhanibekov", "free body"),
                                            ("heavy-top", "heavy top")])
def test_the_scenes_methods_are_the_registrys(scene, problem):
    mine = scenes.get(scene).METHODS
    assert tuple(mine) == tuple(m.name for m in rotframe.methods(problem))
    assert mine.aliases == registry.names(problem).aliases


def test_the_gpu_runs_what_the_registry_says():
    from rotframe.particles.gpu import GPU_METHODS

    assert tuple(GPU_METHODS) == tuple(m.name for m in rotframe.methods("particle scenes") if m.gpu)


@pytest.mark.parametrize("method", [m.name for m in registry.methods() if "particles" not in m.runs])
def test_simulate_refuses_by_name_a_method_it_does_not_run(method):
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=[0, 0, 1.0], r0=[1.0, 0, 0], v0=[0, 0, 0], duration=1.0, method=method)
    msg = str(info.value)
    assert f"method={method!r} does not run rotframe.simulate" in msg and "\n" not in msg
    assert "allowed: exact, rotation-splitting, rotation-splitting4, rk4, dop853" in msg


@pytest.mark.parametrize("method", [m.name for m in registry.methods() if "bodies" not in m.runs])
def test_simulate_body_refuses_by_name_a_method_it_does_not_run(method):
    with pytest.raises(ScenarioError, match=f"method='{method}' does not run rotframe.simulate_body"):
        rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[0.1, 0.0, 1.0], q0=[0, 0, 0, 1], duration=1.0,
                               method=method)


def test_an_unknown_name_lists_the_problems_methods():
    with pytest.raises(ScenarioError, match=r"method='verlet': unknown; allowed for the heavy top: top-splitting"):
        registry.check("verlet", "heavy top")


@pytest.mark.parametrize("name", [m.name for m in registry.methods("particle scenes") if m.step == "fixed"])
def test_a_fixed_step_particle_method_has_the_order_the_registry_states(name):
    """Spring + Coriolis + centrifugal + gravity (linear, constant coefficients): its exact flow is the matrix
    exponential (``exact``); the error at T for steps h and h/2 gives the order, log2(e(h) / e(h/2))."""
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    model = ParticleModel(("gravity", "spring", "coriolis", "centrifugal"),
                          omega=OmegaSchedule.constant([0.0, 0.3, 0.4]), g=np.array([0.0, 0.0, -1.0]), spring=2.0)
    r0, v0, T = [1.0, 0.5, 0.0], [0.0, 0.3, 0.2], 4.0
    exact = integrate_particles(model, r0, v0, T, method="exact", samples=1).r[-1, 0]
    errors = [np.max(np.abs(integrate_particles(model, r0, v0, T, method=name, step=h, samples=1).r[-1, 0] - exact))
              for h in (0.02, 0.01)]
    measured = np.log2(errors[0] / errors[1])
    assert abs(measured - registry.get(name).order) < 0.3, (name, measured, errors)


def test_the_engines_codes_are_named_once_and_never_leave_it():
    """The method codes are named in `rotframe.problem.models` and mapped from the registry's names in the engine
    alone (`engine.METHOD_CODES`): every method a problem steps has one, a splitting's is the model's own step's, and
    the modules that run problems pass the method by name (no code, no map of their own)."""
    import inspect

    from rotframe.problem import body, engine, frame_error, gpu, models, particles, steps

    codes = engine.METHOD_CODES
    stepped = {m.name for m in registry.methods() if {"particles", "bodies"} & set(m.runs) and m.step != "exact"}
    assert set(codes) == stepped, (set(codes), stepped)
    assert codes["dop853"] == models.DOP853 and codes["rk4"] == models.RK4
    assert {codes[n] for n in ("rotation-splitting", "lie-poisson")} == {models.SPLITTING}
    assert {codes[n] for n in ("rotation-splitting4", "lie-poisson4")} == {models.SPLITTING4}
    assert {models.DOP853, models.RK4, models.SPLITTING, models.SPLITTING4} == {0, 1, 2, 3}
    for module in (particles, body, frame_error, gpu):
        source = inspect.getsource(module)
        assert "_CODES" not in source and "models import DOP853" not in source, module.__name__
    assert "take_step" in vars(steps) and "own_step" in vars(models)


def test_the_scenes_loop_codes_stay_with_the_modules_that_compile_their_loops():
    """The scenes' fixed-step loops branch on an integer per method (`rotframe.particles.kernels.loop_code`); only the
    modules that compile those loops turn a name into it (the CPU's drivers, the GPU's kernel). Every other module,
    the Python driver of a run among them, passes the method by name, and the bound driver it gets steps the method
    it names: its code is the one `loop_code` gives."""
    import pathlib

    from rotframe.particles import drivers, kernels

    src = pathlib.Path(kernels.__file__).parent.parent
    users = sorted(str(p.relative_to(src)) for p in src.rglob("*.py") if "loop_code" in p.read_text())
    assert users == ["particles/drivers.py", "particles/gpu.py", "particles/kernels.py"], users
    for name in ("rotation-splitting", "rotation-splitting4", "rk4"):
        for events in (False, True):
            bound = drivers.fixed_step_driver(name, events)
            assert bound.func is (drivers.run_fixed_events if events else drivers.run_fixed)
            assert bound.args == (kernels.loop_code(name),)
    assert len({kernels.loop_code(n) for n in ("rotation-splitting", "rotation-splitting4", "rk4")}) == 3
