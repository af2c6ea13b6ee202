"""Each compiled particle driver compiles only the method it runs (issue 13: a fast first run).

A first run's cost is numba compiling every function the driver reaches, so the DOP853
driver must not reach the fixed-step maps (it locates events by re-stepping DOP853,
rotframe.particles.events.locate_event_dop853) and the fixed-step driver must not reach
the DOP853 step (rotframe.particles.events.locate_event). The check is structural, not a
timing: in a fresh process with an empty numba cache, after a run with an event, the
dispatchers of the other method's step functions hold no compiled version. (With a warm
cache nothing is compiled at all and the check would prove nothing, hence the empty cache.)
"""

import os
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"

PROBE = r'''
import sys
import numpy as np
from rotframe.particles import dop853_particles, kernels
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel
from rotframe.particles.trajectory import Event

model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant([0.0, 4e-5, 5e-5]),
                      g=np.array([0.0, 0.0, -9.81]))
ground = Event("ground", "r", 2, 0.0, -1, True)
traj = integrate_particles(model, [0.0, 0.0, 10.0], [1.0, 0.0, 0.0], 3.0, method=sys.argv[1], samples=3,
                           events=[ground])
assert len(traj.event_times["ground"][0]) == 1
fixed = [kernels._free_steps, kernels._sphere_steps, kernels._rk4_steps]
print(sum(len(f.signatures) for f in fixed), len(dop853_particles.particle_stages.signatures))
# the event-free loops: a run with events compiles none of them (numba prunes ``events is None`` only where it is)
from rotframe.particles import drivers
event_free = [drivers.run_fixed, drivers.run_dop853, drivers._steady_run, dop853_particles.particle_trajectory]
print(sum(len(f.signatures) for f in event_free))
'''


def compiled_counts(method, tmp_path):
    env = dict(os.environ, PYTHONPATH=str(SRC), NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    res = subprocess.run([sys.executable, "-c", PROBE, method], capture_output=True, text=True, env=env,
                         timeout=600)
    assert res.returncode == 0, res.stderr
    fixed, dop, event_free = map(int, res.stdout.split())
    return fixed, dop, event_free


def test_dop853_driver_compiles_no_fixed_step_method_and_no_event_free_loop(tmp_path):
    fixed, dop, event_free = compiled_counts("dop853", tmp_path)
    assert dop == 1 and fixed == 0 and event_free == 0


def test_fixed_step_driver_compiles_no_dop853_step_and_no_event_free_loop(tmp_path):
    fixed, dop, event_free = compiled_counts("rotation-splitting", tmp_path)
    assert fixed >= 1 and dop == 0 and event_free == 0


def test_a_driver_without_events_refuses_an_event_table():
    # the event-free kernels do not watch events: given a table, they say so instead of ignoring it
    import numpy as np
    import pytest

    from rotframe.particles import drivers
    from rotframe.particles.dop853_ensemble import WORK_ROWS
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    model = ParticleModel(("gravity",), omega=OmegaSchedule.constant([0.0, 0.0, 0.0]), g=np.array([0.0, 0.0, -9.81]))
    r, v, alive = np.zeros((1, 3)), np.zeros((1, 3)), np.ones(1, dtype=np.bool_)
    out = np.empty((1, 1, 3))
    table = np.array([[0.0, 2.0, -1.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match="run_fixed_events"):
        drivers.run_fixed(0, r, v, alive, np.array([0.0, 0.1]), 0, 0.1, 1, 1, model.pack(), None, model.omega.values,
                          model.omega.cumulative(), table, out, out.copy(), None, None, None, None, None, 0, None, None)
    with pytest.raises(ValueError, match="run_dop853_events"):
        drivers.run_dop853(r, v, alive, 0.0, np.array([1.0]), model.pack(), None, model.omega.values, 1e-9,
                           np.full((1, 6), 1e-9), 1.0, table, out, out.copy(), None, None, None, None, None, 0, np.zeros(1),
                           np.empty((WORK_ROWS, 6)), np.empty((13, 6)))


PRUNED = r'''
import sys
import numpy as np
from rotframe.particles import dop853_particles, events, schedule
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel

# linear drag, a scene's model: the scenes' general DOP853 driver
model = ParticleModel(("gravity", "coriolis", "linear-drag"), omega=OmegaSchedule.constant([0.0, 4e-5, 5e-5]),
                      g=np.array([0.0, 0.0, -9.81]), k_linear=0.01)
traj = integrate_particles(model, [0.0, 0.0, 10.0], [1.0, 0.0, 0.0], 1.0, method=sys.argv[1], samples=3)
assert np.all(np.isfinite(traj.r))
watchers = [events.event_value, events.start_value, events.locate_event, dop853_particles.locate_event_dop853,
            dop853_particles.watch_events, events.record_event]
readers = [schedule.omega_magnitude, schedule.omega_rate, schedule.omega_angle, schedule.node_index]
print(sum(len(f.signatures) for f in watchers), sum(len(f.signatures) for f in readers))
'''


def test_a_run_without_events_at_a_steady_rate_compiles_no_event_code_and_no_schedule_reader(tmp_path):
    # what a run does not have is passed to the drivers as None and pruned by numba at compile time
    env = dict(os.environ, PYTHONPATH=str(SRC), NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    for method in ("dop853", "rotation-splitting"):
        res = subprocess.run([sys.executable, "-c", PRUNED, method], capture_output=True, text=True, env=env,
                             timeout=600)
        assert res.returncode == 0, res.stderr
        assert res.stdout.split() == ["0", "0"], (method, res.stdout)


def test_a_kernel_for_compiled_code_only_refuses_a_python_call_instead_of_crashing():
    # jit_internal kernels have no CPython entry point; numba alone would crash the interpreter
    import pytest

    from rotframe.numerics.dop853 import dop853_error_norm
    from rotframe.particles import forces, kernels

    for kernel in (forces.string_normal, forces.state_acceleration, kernels.method_steps, dop853_error_norm):
        with pytest.raises(TypeError, match="compiled code only"):
            kernel(1.0, 2.0, 3.0, None)
        assert callable(kernel.py_func)


FAMILY = r'''
import sys
import numpy as np
from rotframe.particles import kernels
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel

model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.ramp([0, 0, 1], 0.0, 0.5, 2.0),
                      g=np.array([0.0, 0.0, -9.81]))
traj = integrate_particles(model, [0.0, 0.0, 10.0], [1.0, 0.0, 0.0], 1.0, method=sys.argv[1], samples=3)
assert np.all(np.isfinite(traj.r))
print(len(kernels._free_steps.signatures), len(kernels._sphere_steps.signatures), len(kernels._rk4_steps.signatures))
'''


def test_a_free_particle_compiles_only_its_own_step_family(tmp_path):
    # rk4 and sphere are passed as None where absent: the splitting of a free particle compiles no
    # RK4 and no splitting on the sphere, RK4 no sphere
    env = dict(os.environ, PYTHONPATH=str(SRC), NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    for method, want in (("rotation-splitting4", ["1", "0", "0"]), ("rk4", ["1", "0", "1"])):
        res = subprocess.run([sys.executable, "-c", FAMILY, method], capture_output=True, text=True, env=env,
                             timeout=600)
        assert res.returncode == 0, res.stderr
        assert res.stdout.split() == want, (method, res.stdout)


STEADY = r'''
import numpy as np
from rotframe import forces
from rotframe.particles import dop853_particles, dop853_steady, drivers
from rotframe.particles import forces as scene_forces
from rotframe.problem import engine
from rotframe.problem.particles import simulate_particles

run = simulate_particles(omega=[0.0, 4e-5, 5e-5], r0=[1.0, 0.0, 10.0 - np.sqrt(99.0)], v0=[0.0, 0.0, 0.0],
                         duration=5.0, samples=5, forces=[forces.gravity([0.0, 0.0, -9.81]),
                                                          forces.pendulum(10.0, [0.0, 0.0, 10.0])])
assert np.all(np.isfinite(run.trajectory.r))
general = [drivers.run_dop853, dop853_particles.particle_stages, dop853_particles.particle_rhs,
           scene_forces.state_acceleration]
loops = [f for f in vars(engine).values() if hasattr(f, "signatures")]
print(sum(len(f.signatures) for f in general + loops), len(dop853_steady.run_dop853_steady.signatures))
'''


def test_a_steady_problem_compiles_only_the_steady_dop853_loop(tmp_path):
    # a steady rotation, uniform gravity, a string, no drag and no events: the engine's steady loop
    # (rotframe.problem.steady), which compiles a few small functions, and neither the scenes' general driver nor any
    # of the engine's own loops
    env = dict(os.environ, PYTHONPATH=str(SRC), NUMBA_CACHE_DIR=str(tmp_path / "numba"),
               ROTFRAME_CACHE_DIR=str(tmp_path / "rotframe"))
    res = subprocess.run([sys.executable, "-c", STEADY], capture_output=True, text=True, env=env, timeout=600)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["0", "1"], res.stdout
