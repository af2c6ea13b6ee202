"""``rotframe.simulate(device="gpu")``: your own problem on the GPU (`rotframe.problem.gpu`), on numba's simulator.

The GPU runs the engine's own loop (`rotframe.problem.engine.variant_loop`) with the problem's
functions, built-in and the user's, compiled for it, so it must give the CPU's numbers to
round-off for every kind of problem it takes: `tools/gpu_user_check.py` runs each case on both
(a user force with array params beside built-in terms, terminal and non-terminal events, the
pendulum's string under the order-4 splitting with drag's exact flow, a force in inertial axes,
a frame given as a table, omega(t) and an accelerating origin as the user's functions). The
simulator (``NUMBA_ENABLE_CUDASIM=1``, set before numba is imported) runs the kernel in Python:
a new process, a few particles. Without a GPU, ``device="gpu"`` is refused in one line.
"""

import os
import subprocess
import sys
import textwrap
import types
from pathlib import Path

import pytest

import rotframe
from rotframe.errors import ScenarioError
from rotframe.particles import gpu

ROOT = Path(__file__).resolve().parents[1]


def _simulated(args, timeout=900):
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    return subprocess.run([sys.executable, *args], env=env, capture_output=True, text=True, timeout=timeout,
                          cwd=ROOT)


def test_every_kind_of_user_problem_gives_the_cpu_numbers_on_the_gpu():
    res = _simulated([str(ROOT / "tools" / "gpu_user_check.py"), "3"])
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    lines = [line for line in res.stdout.splitlines() if "samples agree" in line]
    assert len(lines) == 5 and "worst: " in res.stdout
    assert all("same NaN pattern True" in line for line in lines)
    assert float(res.stdout.split("worst: ")[1].split(";")[0]) <= 1e-12
    assert res.stdout.rstrip().endswith("ran again (a thread ended by an exception): 0")  # the GPU answered, not the CPU


def test_the_kernel_with_the_models_parts_compiled_in_gives_the_numbers_of_the_one_that_reads_them():
    """`tools/gpu_user_rows.py` runs your own problem with the model's parts as constants of the kernel
    (`rotframe.problem.models.with_parts`) and with them read as the run goes: on the simulator, the same Python,
    so the same numbers to the bit (the ``apart`` column), under both methods, with and without the ground event."""
    res = _simulated([str(ROOT / "tools" / "gpu_user_rows.py")])
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    rows = [line.split() for line in res.stdout.splitlines() if line.startswith(("rotation-splitting", "rk4"))]
    assert len(rows) == 4, res.stdout
    for row in rows:
        apart = row[row.index("first") - 1]
        assert float(apart) == 0.0, row


REFUSALS = textwrap.dedent("""
    import numpy as np, rotframe
    from numba import config
    assert config.ENABLE_CUDASIM
    from rotframe.errors import ScenarioError
    from rotframe.problem.callables import UserFunctionError

    def spring(t, r, v):
        return -r[0], -r[1], -r[2]

    common = dict(omega=[0, 0, 0.1], r0=[1.0, 0, 0], v0=[0, 1.0, 0], duration=1.0, forces=[spring], samples=4)
    for kw in (dict(), dict(method="dop853"), dict(method="rk4", jit=False), dict(method="rk4", max_events=0)):
        try:
            rotframe.simulate(**common, **kw, device="gpu")
        except ScenarioError as exc:
            print("REFUSED", str(exc).replace(chr(10), " "))

    def breaks(t, r, v):
        if t > 0.5:
            raise ValueError("too late")
        return -r[0], -r[1], -r[2]

    try:
        rotframe.simulate(**dict(common, forces=[breaks]), method="rk4", step=0.01, device="gpu")
    except UserFunctionError as exc:
        print("RAISED", str(exc).replace(chr(10), " "), exc.partial.trajectory.times.size)
""")


def test_the_gpu_refuses_what_it_does_not_run_in_one_line_each_and_names_a_raising_force():
    res = _simulated(["-c", REFUSALS])
    assert res.returncode == 0, res.stderr[-3000:]
    refused = [line for line in res.stdout.splitlines() if line.startswith("REFUSED")]
    assert len(refused) == 4, res.stdout
    assert "method: none given" in refused[0] and "rk4" in refused[0] and "dop853" in refused[0]
    assert "does not run on the GPU" in refused[1] and "rotation-splitting" in refused[1]
    assert "jit=False" in refused[2]
    assert "max_events=0" in refused[3]
    raised = [line for line in res.stdout.splitlines() if line.startswith("RAISED")]
    assert len(raised) == 1 and "breaks" in raised[0] and "too late" in raised[0], res.stdout
    assert int(raised[0].split()[-1]) >= 2  # the samples before the failure are kept


STEADY_ON_THE_GPU = textwrap.dedent("""
    import json
    import numpy as np
    from numba import config
    assert config.ENABLE_CUDASIM
    from rotframe import forces as rf
    from rotframe.events import crossing
    from rotframe.problem.particles import simulate_particles  # simulate's core: the counts and statuses kept
    from rotframe.problem.terms import StringConstraint

    rng = np.random.default_rng(5)
    N = 7
    r0 = np.zeros((N, 3))
    r0[:, 2] = rng.uniform(5.0, 60.0, N)
    r0[-1, 2] = 1e4  # never lands
    v0 = rng.normal(size=(N, 3))
    g = rf.gravity([0.0, 0.0, -9.8])
    ground = crossing(2, 0.0, direction=-1, terminal=True, name="ground")
    apex = crossing(2, 0.0, of="v", direction=-1, name="apex")
    cases = [
        ("rk4", [g, rf.drag(quadratic=2e-3)], ("coriolis", "centrifugal"), [ground], 1),
        ("rotation-splitting", [g], ("coriolis",), [ground], 1),  # every particle lands (below): its counts are theirs
        ("rotation-splitting4", [rf.altitude_gravity(9.8, 6.4e6), rf.drag(linear=0.1)], ("coriolis", "centrifugal"),
         [ground], 1),
        ("rotation-splitting", [rf.pendulum(70.0, (0.0, 0.0, 70.0)), g], ("coriolis",), [], 1),
        ("rk4", [g], ("coriolis",), [ground], 3),  # samples between: the engine's own loop
        ("rk4", [g], ("coriolis",), [apex], 1),  # an event that does not end the run: the engine's own loop
    ]
    out = []
    for method, forces, frame_terms, events, samples in cases:
        kw = dict(omega=[0.0, 4e-3, 5e-3], v0=v0, duration=4.0, forces=forces, frame_terms=frame_terms, events=events,
                  method=method, step=0.01, samples=samples)
        kw["r0"] = r0[:-1] if len(out) == 1 else r0
        if isinstance(forces[0], StringConstraint):  # the pendulum's string: its particles on its sphere, at rest
            x = 70.0 * np.sin(rng.uniform(0.1, 0.5, N))
            kw["r0"] = np.stack([x, np.zeros(N), 70.0 - np.sqrt(70.0 ** 2 - x * x)], axis=1)
            kw["v0"] = np.zeros((N, 3))
        elif len(out) == 1:
            kw["v0"] = v0[:-1]
        gpu = simulate_particles(**kw, device="gpu")
        cpu = simulate_particles(**kw, inline=False)  # the engine's own loop on the CPU: no code of the scenes'
        counted = simulate_particles(**kw)  # the CPU's choice: the scenes' drivers count as the GPU's kernel
        a, b = gpu.trajectory, cpu.trajectory
        scale = max(1.0, float(np.max(np.abs(np.nan_to_num(b.r)))), float(np.max(np.abs(np.nan_to_num(b.v)))))
        row = {"method": method, "kernel": any("scenes' GPU kernel" in n for n in gpu.notes),
               "times": bool(np.array_equal(a.times, b.times)),
               "nan": bool(np.array_equal(np.isnan(a.r), np.isnan(b.r))),
               "drv": float(max(np.nanmax(np.abs(a.r - b.r)), np.nanmax(np.abs(a.v - b.v))) / scale),
               "counts": [a.steps, b.steps, a.nfev, counted.trajectory.nfev,
                          any("scenes' fixed-step drivers" in n for n in counted.notes)],
               "status": bool(np.array_equal(a.extras["status"], b.extras["status"])), "events": []}
        for name in b.event_times:
            ta, tb = a.event_times[name], b.event_times[name]
            row["events"].append([[len(x) for x in ta] == [len(x) for x in tb],
                                  max((float(np.max(np.abs(x - y), initial=0.0)) for x, y in zip(ta, tb)), default=0.0),
                                  max((float(np.max(np.abs(x - y), initial=0.0)) / scale
                                       for x, y in zip(a.event_states[name], b.event_states[name])), default=0.0),
                                  sum(len(x) for x in tb)])
        out.append(row)
    print(json.dumps(out))
""")


def test_a_steady_problem_that_keeps_its_end_alone_runs_the_scenes_gpu_kernel_with_the_engines_numbers():
    """`rotframe.problem.steady` gives a fixed-step run on the GPU that keeps its end alone (``samples=1``), its one
    event terminal, to the scenes' GPU kernel: against the engine's own loop on the CPU (``inline=False``, which runs
    none of the scenes' code), the same samples, event times and states, statuses and counts, drag, a string and
    altitude gravity among the terms. A run with samples between, or an event that does not end it, is the engine's
    own loop's on the GPU."""
    import json

    res = _simulated(["-c", STEADY_ON_THE_GPU])
    assert res.returncode == 0, res.stderr[-3000:]
    rows = json.loads(res.stdout.strip().splitlines()[-1])
    assert [row["kernel"] for row in rows] == [True] * 4 + [False] * 2, rows
    for row in rows:
        assert row["times"] and row["nan"] and row["status"], row
        assert row["drv"] <= 1e-13, row  # round-off (the simulator runs the GPU's arithmetic in Python)
        steps_gpu, steps_cpu, nfev_gpu, nfev_drivers, on_drivers = row["counts"]
        assert steps_gpu == steps_cpu and (nfev_gpu == nfev_drivers or not (on_drivers and row["kernel"])), row
        for same_counts, dt, dstate, located in row["events"]:
            assert same_counts and located > 0 and dt <= 1e-13 and dstate <= 1e-13, row


@pytest.mark.skipif(gpu.available(), reason="a GPU (or the simulator) is here")
def test_device_gpu_without_a_gpu_is_refused_in_one_line():
    with pytest.raises(ScenarioError, match="no CUDA GPU") as err:
        rotframe.simulate(omega=[0, 0, 0], r0=[1.0, 0, 0], v0=[0, 1.0, 0], duration=1.0, method="rk4", device="gpu")
    assert "\\n" not in str(err.value)
    with pytest.raises(ScenarioError, match="device: 'tpu'; allowed: cpu, gpu"):
        rotframe.simulate(omega=[0, 0, 0], r0=[1.0, 0, 0], v0=[0, 1.0, 0], duration=1.0, device="tpu")


def test_the_gpu_kernel_is_the_engine_loop_with_the_problems_calls_made_direct():
    """One source: the GPU compiles `engine.variant_loop`'s own code; only the calls by address are replaced."""
    from rotframe.problem import calls, engine, stubs
    from rotframe.problem.signatures import PARTICLE

    loop = engine.variant_loop(PARTICLE, "rk4", False)
    assert loop.__code__ is engine.variant_loop(PARTICLE, "rk4", True).__code__  # one loop for every variant
    replaced = {calls.call_terms, calls.call_event, calls.call_vector, calls.call_varying}
    # every call by address has its direct call (the GPU's and the CPU's inlined loop's), a stub where the glue lacks
    # the role
    direct = calls.direct_calls(types.ModuleType("glue"), None)
    assert set(direct) == replaced
    assert direct[calls.call_terms][1]["TERMS"] is stubs.no_terms


def test_a_function_inlined_by_numba_on_the_cpu_is_inlined_by_numba_on_the_gpu(monkeypatch):
    """A step of `take_step` (RK4's here) is inlined by numba on the GPU, as on the CPU (``inline="always"``).

    Compiled for a GPU as a function of its own, `take_step` (then one function with every method's
    branch) typed every branch with one method's step and failed at the first launch on an H200,
    which the simulator (Python) never showed. Here the GPU's options are read off `device_function`
    with numba's CUDA ``jit`` recording them.
    """
    from numba import cuda

    from rotframe.problem import steps
    from rotframe.problem.models import RK4

    seen = {}

    def recording_jit(*args, **options):
        def made(fn):
            seen[fn.__name__] = options
            return fn
        return made

    monkeypatch.setattr(cuda, "jit", recording_jit)
    monkeypatch.setattr(gpu, "inline_options", lambda: {"forceinline": True})  # a real GPU's numba-cuda
    take = steps.take_step(RK4)
    gpu.device_function(take, {})
    gpu.device_function(steps.particle_rk4, {})
    assert seen[take.py_func.__name__] == {"device": True, "forceinline": True, "inline": "always"}
    assert seen["particle_rk4"] == {"device": True, "forceinline": True}  # LLVM's inlining only, as on the CPU
    assert take.targetoptions["inline"] == "always"  # what the rule reads: jit_inline's option


@pytest.mark.skipif(os.environ.get("NUMBA_ENABLE_CUDASIM") == "1" or "NVIDIA" not in
                    getattr(__import__("numba").cuda, "implementation", ""),
                    reason="needs NVIDIA's numba-cuda and a CUDA toolkit's libnvvm (no GPU): tools/gpu_ptx_check.py")
def test_every_gpu_kernel_compiles_for_a_hopper_gpu():
    res = subprocess.run([sys.executable, str(ROOT / "tools" / "gpu_ptx_check.py")], capture_output=True, text=True,
                         timeout=1200, cwd=ROOT)
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    assert res.stdout.rstrip().endswith("0 failed")
