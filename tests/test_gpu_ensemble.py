"""The GPU ensemble (rotframe.particles.gpu) on numba's CUDA simulator, against the CPU ensemble.

The simulator (``NUMBA_ENABLE_CUDASIM=1``, set before numba is first imported) runs the
CUDA kernel in Python on a machine without a GPU, so these checks run in a new process
with the variable set. The GPU kernel is compiled from the same Python source as the CPU
kernels (the forces, steps and event rules), so it must agree with the CPU ensemble to
round-off: event times and states, terminal and non-terminal events, every fixed-step
method, a varying rotation rate. The simulator is slow: a handful of particles.

Without a GPU (and without the simulator) ``device="gpu"`` is refused in one line, exit 2.
"""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from rotframe.app import cli
from rotframe.errors import ScenarioError
from rotframe.particles import gpu
from rotframe.particles.ensemble import check_device

SCRIPT = textwrap.dedent("""
    import json, math
    import numpy as np
    from numba import config
    assert config.ENABLE_CUDASIM
    from rotframe.particles.ensemble import integrate_ensemble
    from rotframe.particles.integrators import Event
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    g = np.array([0.0, 0.0, -9.81])
    steady = OmegaSchedule.constant(np.array([0.0, 4.6e-5, 5.7e-5]) * 300)
    varying = OmegaSchedule(np.array([0.0, 0.6, 0.8]), np.array([0.0, 1.0, 3.0]), np.array([0.02, 0.05, 0.01]))
    cases = [
        ("rotation-splitting", ParticleModel(("gravity", "coriolis"), omega=steady, g=g),
         Event("ground", "r", 2, 0.0, -1, True)),
        ("rk4", ParticleModel(("gravity", "coriolis", "centrifugal", "quadratic-drag"), omega=steady, g=g,
                              k_quadratic=2e-3), Event("ground", "r", 2, 0.0, -1, True)),
        ("rotation-splitting4", ParticleModel(("gravity", "coriolis"), omega=steady, g=g),
         Event("apex", "v", 2, 0.0, -1, False)),
        ("rotation-splitting", ParticleModel(("coriolis", "centrifugal", "euler", "gravity"), omega=varying, g=g),
         Event("ground", "r", 2, 0.0, -1, True)),
        ("rotation-splitting", ParticleModel(("altitude-gravity", "coriolis", "linear-drag"), omega=steady,
                                             g0=9.81, radius=6.371e6, k_linear=0.05),
         Event("ground", "altitude", 0, 0.0, -1, True)),
    ]
    rng = np.random.default_rng(11)
    out = []
    for method, model, event in cases:
        n = 5
        r0 = np.zeros((n, 3))
        r0[:, 2] = rng.uniform(5.0, 40.0, n)
        v0 = rng.normal(scale=3.0, size=(n, 3))
        v0[:, 2] = np.abs(v0[:, 2]) + 2.0  # rising first: the apex and the ground both come
        run = {"step": 2e-2, "samples": 4}
        cpu = integrate_ensemble(model, r0, v0, 4.0, event, method=method, run=run, keep=[1], device="cpu")
        gpu = integrate_ensemble(model, r0, v0, 4.0, event, method=method, run=run, keep=[1], device="gpu")
        hit = np.isfinite(cpu.t_event)
        out.append({"method": method, "event": event.name, "hits": int(hit.sum()),
                    "same_hits": bool(np.array_equal(hit, np.isfinite(gpu.t_event))),
                    "dt": float(np.max(np.abs(cpu.t_event[hit] - gpu.t_event[hit]), initial=0.0)),
                    "ds": float(np.max(np.abs(cpu.state - gpu.state) / np.maximum(1.0, np.abs(cpu.state)))),
                    "path": bool(np.allclose(cpu.paths[1][1], gpu.paths[1][1], rtol=0, atol=1e-9))})
    print(json.dumps(out))
""")


def _simulated(code, *args):
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    return subprocess.run([sys.executable, *code, *args], env=env, capture_output=True, text=True, timeout=900)


def test_gpu_kernel_on_the_simulator_agrees_with_the_cpu_ensemble():
    res = _simulated(["-c", SCRIPT])
    assert res.returncode == 0, res.stderr[-3000:]
    rows = json.loads(res.stdout.strip().splitlines()[-1])
    assert len(rows) == 5
    for row in rows:
        assert row["hits"] > 0 and row["same_hits"], row  # the events fire, for the same particles
        # round-off: the same steps from the same source (a real GPU may fuse multiply-adds)
        assert row["dt"] <= 1e-12 and row["ds"] <= 1e-12 and row["path"], row


def test_sweep_device_gpu_on_the_simulator_gives_the_cpu_rows(tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    rows = {}
    for device in ("cpu", "gpu"):
        out = tmp_path / f"{device}.parquet"
        res = _simulated(["-m", "rotframe", "sweep", "tower-drop", "--grid", "height=20:60:3", "--method",
                          "rotation-splitting", "--set", "step=0.01", "--device", device, "--out", str(out), "--json"])
        assert res.returncode == 0, res.stderr[-3000:]
        assert json.loads(res.stdout)["path"] == "ensemble"
        rows[device] = pq.read_table(out).to_pydict()
    for key in ("east_deflection_m", "fall_time_s"):
        a, b = rows["cpu"][key], rows["gpu"][key]
        assert len(a) == 3 and all(abs(x - y) <= 1e-12 * max(1.0, abs(x)) for x, y in zip(a, b)), key


SWEEP_SCRIPT = textwrap.dedent("""
    import json
    import numpy as np
    from numba import config
    assert config.ENABLE_CUDASIM
    from rotframe.particles import gpu
    from rotframe.particles.threads import device_scope
    from rotframe.scenes import tower_drop

    points = [dict(height=h, latitude=50.9, drag=d, g_model="wgs84", magnify=1000.0)
              for h in (20.0, 45.0, 130.0) for d in (0.0, 2e-3)]
    out = []
    for terms in (["gravity", "coriolis"], ["gravity", "coriolis", "altitude-gravity", "centrifugal"]):
        for method in ("rk4", "rotation-splitting", "rotation-splitting4"):
            before = gpu.launches()
            on_gpu, on_cpu = {2: None, 5: None}, {2: None, 5: None}
            with device_scope("gpu"):
                a = tower_drop.simulate_ensemble(points, terms, method, {"step": 0.03}, tracks=on_gpu)
            launched = gpu.launches() - before
            b = tower_drop.simulate_ensemble(points, terms, method, {"step": 0.03}, tracks=on_cpu)
            out.append({"terms": terms, "method": method, "launched": launched,
                        "metrics": max(abs(x[k] - y[k]) / max(1e-300, abs(y[k])) for x, y in zip(a, b) for k in y),
                        "tracks": max(float(np.max(np.abs(on_gpu[k][1] - on_cpu[k][1]))) for k in on_cpu)})
    print(json.dumps(out))
""")


def test_a_gpu_sweep_runs_the_engine_which_gives_the_scenes_gpu_kernel_the_cpu_sweeps_steps():
    """The tower drop's sweep on the GPU is one run of the engine a group (`tower_drop._on_gpu`), which keeps each
    drop's end alone and so runs on the scenes' GPU kernel (`rotframe.problem.steady`; the kernel's launches are
    counted), altitude gravity, drag and the centrifugal term among the terms: every metric and kept path that of the
    CPU's sweep on the engine's loops, to round-off, each drop taking the CPU's steps."""
    res = _simulated(["-c", SWEEP_SCRIPT])
    assert res.returncode == 0, res.stderr[-3000:]
    rows = json.loads(res.stdout.strip().splitlines()[-1])
    assert len(rows) == 6
    for row in rows:
        assert row["launched"] >= 2, row  # the scenes' kernel, not the engine's own GPU loop (which it does not count)
        assert row["metrics"] <= 1e-12 and row["tracks"] == 0.0, row  # the tracks: the CPU's, both


@pytest.mark.skipif(gpu.available(), reason="a GPU (or the simulator) is here")
def test_device_gpu_without_a_gpu_exits_2_in_one_line(capsys):
    code = cli.main(["run", "tower-drop", "--device", "gpu", "--no-record"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "no CUDA GPU" in err and "'gpu'" in err
    with pytest.raises(ScenarioError, match="no CUDA GPU"):
        check_device("gpu")


def test_device_names_are_checked(capsys):
    with pytest.raises(ScenarioError, match="device: 'tpu'; allowed: cpu, gpu"):
        check_device("tpu")
    assert cli.main(["run", "tower-drop", "--device", "tpu", "--no-record"]) == 2
    assert "invalid choice" in capsys.readouterr().err


def test_gpu_physics_is_the_cpu_source():
    """The device functions are compiled from the CPU kernels' own Python functions (one source)."""
    from rotframe.particles import forces, kernels

    for kernel in (forces.state_acceleration, kernels.free_step, kernels.one_step):
        assert gpu.device_function(kernel).py_func.__code__ is kernel.py_func.__code__
    # the calls inside are rebound to the GPU versions of the same functions
    assert gpu.device_function(kernels.one_step).py_func.__globals__["free_step"] is gpu.device_function(
        kernels.free_step)


def test_a_sweep_batch_carries_the_device_to_a_dask_worker(monkeypatch):
    """A Dask worker runs the batch in its own context, where no ``--device`` was set: the batch
    task carries the command's device, and `run_batch` applies it there (a thread with a fresh
    context stands for the worker)."""
    import contextvars
    import threading

    from rotframe.app.sweep import batch, execute
    from rotframe.particles import threads

    monkeypatch.setattr(threads, "gpu_available", lambda: True)  # the check on the worker passes
    monkeypatch.setattr(batch, "_run_batch", lambda task: threads.device_in_force())
    with threads.device_scope("gpu"):
        device = execute._device_now()
    assert device == "gpu" and execute._device_now() is None  # the CPU is None (the default)
    task = batch.BatchTask(index=1, scenario=None, sets={}, keys=[], rows=np.arange(1), values=np.zeros((1, 0)),
                           method=None, path="ensemble", track_rows=frozenset(), device=device)
    seen = []
    worker = threading.Thread(target=lambda: seen.append(contextvars.Context().run(batch.run_batch, task)))
    worker.start()
    worker.join(30)
    assert seen == ["gpu"]


def _models():
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    steady = OmegaSchedule.constant(np.array([0.0, 4.6e-5, 5.7e-5]))
    varying = OmegaSchedule(np.array([0.0, 0.6, 0.8]), np.array([0.0, 1.0, 3.0]), np.array([0.02, 0.05, 0.01]))
    g = np.array([0.0, 0.0, -9.81])
    return [ParticleModel(("gravity", "coriolis"), omega=steady, g=g),
            ParticleModel(("coriolis", "centrifugal", "euler", "gravity"), omega=varying, g=g),
            ParticleModel(("altitude-gravity", "coriolis", "linear-drag"), omega=steady, g0=9.81, radius=6.371e6,
                          k_linear=0.05),
            ParticleModel(("gravity", "coriolis", "centrifugal", "quadratic-drag"), omega=steady, g=g,
                          k_quadratic=2e-3)]


@pytest.mark.parametrize("k", range(4))
def test_the_gpu_model_structure_is_the_run_s_own_model(k):
    """`_structure_source` writes switches and zeros as constants and reads the rest: applied to the
    run's own model, it must give that model back, field by field (a constant that differed from the
    run's value would change the GPU's numbers)."""
    from rotframe.particles import packed

    model = _models()[k]
    P, wt, wv = model.pack(), model.omega.times, model.omega.values
    host = packed.unpack.py_func(P, wt, wv)
    made = {"PackedModel": packed.PackedModel}
    exec(gpu._structure_source(host), made)
    assert made["structured"](host) == host
    # every field that is neither a switch nor zero is read, not frozen (so another run's values pass through)
    other = host._replace(**{f: 1.25 for f, v in zip(host._fields, host)
                             if isinstance(v, float) and v != 0.0 and f != "gmode"})
    for field, value in zip(host._fields, made["structured"](other)):
        original = getattr(host, field)
        if isinstance(original, float) and original != 0.0 and field != "gmode":
            assert value == 1.25, field


def test_bench_gpu_on_the_simulator_does_the_same_work_as_the_hand_written_kernel():
    """``rotframe bench gpu`` on numba's simulator: every case runs rotframe's GPU door, the
    hand-written numba kernel (and JAX where installed), they end in the same states, and the
    ratios are there (the simulator times nothing of meaning)."""
    res = _simulated(["-m", "rotframe", "bench", "gpu", "--json"])
    assert res.returncode == 0, res.stderr[-3000:]
    rows = [r for r in json.loads(res.stdout) if r.get("scenario") == "gpu-ensemble"]
    assert {(r["integrator"], r["event"]) for r in rows} == {(m, e) for m in ("rotation-splitting", "rk4")
                                                             for e in (True, False)}
    doors = [r for r in rows if r["method"].startswith("rotframe integrate_ensemble(device='gpu'):")]
    assert len(doors) == 4 and all(r["simulator"] for r in rows)
    # the user's own problem (rotframe.simulate(device="gpu")) beside the scenes' ensemble of the same terms
    users = [r for r in rows if "of_scene_gpu" in r]
    assert len(users) == 4 and all(r["same_work"] and r["of_scene_gpu"] > 0 for r in users)
    # the same with the built-in terms and one sample: the engine's steady specialisation, the scenes' kernel
    builtins = [r for r in rows if "builtin_of_scene_gpu" in r]
    assert len(builtins) == 4 and all(r["same_work"] and r["builtin_of_scene_gpu"] > 0 for r in builtins)
    for r in doors:
        assert r["of_ceiling"] > 0 and r["kernel_of_ceiling"] > 0 and r["ceiling_goal"] == 0.5
    timed_from_host = [r for r in rows if "same_work" in r]
    assert all(r["same_work"] for r in timed_from_host), [r["same_work_note"] for r in timed_from_host]
    assert any(r["method"].startswith("hand-written numba") for r in timed_from_host)
    assert {r["method"].split(":")[0] for r in rows if r.get("kernel_alone")} == {
        "rotframe kernel alone (GpuLaunch)", "hand-written numba CUDA kernel alone"}


def test_bench_gpu_hands_over_its_rows_after_every_case():
    """A lent machine's run cut short keeps the cases it finished (`tools/device_check.sh` writes them)."""
    code = ("from rotframe.app.bench.gpu import gpu_rows\n"
            "seen = []\n"
            "rows = gpu_rows(True, each=lambda rows: seen.append([r['method'] for r in rows]))\n"
            "print(len(seen), [len(s) for s in seen], seen[-1] == [r['method'] for r in rows])\n")
    res = _simulated(["-c", code])
    assert res.returncode == 0, res.stderr[-3000:]
    line = res.stdout.strip().splitlines()[-1]
    assert line.startswith("4 ") and line.endswith(" True"), line
    sizes = [int(x) for x in line[line.index("[") + 1:line.index("]")].split(",")]
    assert sizes == sorted(sizes) and sizes[0] > 0 and len(set(sizes)) == 4  # each case adds its rows


@pytest.mark.skipif(gpu.available(), reason="a GPU (or the simulator) is here")
def test_bench_gpu_without_a_gpu_exits_2_in_one_line(capsys):
    assert cli.main(["bench", "gpu"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "bench: 'gpu' needs a CUDA GPU" in err


def test_a_run_that_asked_for_the_gpu_and_had_no_ensemble_says_so():
    """``rotframe run foucault --device gpu``: one pendulum, no ensemble, so the CPU ran it; the
    summary's warnings say that the device was not used (it was silent before)."""
    res = _simulated(["-m", "rotframe", "run", "foucault", "--device", "gpu", "--no-record", "--json"])
    assert res.returncode == 0, res.stderr[-3000:]
    warnings = json.loads(res.stdout)["warnings"]
    assert any(w.startswith("device = gpu is not used: this run of foucault has no ensemble") for w in warnings)


@pytest.mark.parametrize("args, expected", [
    (["tower-drop", "--grid", "height=20:60:3", "--method", "dop853"], "method='dop853' does not run on the GPU"),
    (["foucault", "--grid", "latitude=10:60:3"], "device: 'gpu' for a sweep of foucault"),
])
def test_a_gpu_sweep_no_row_could_run_on_the_gpu_is_refused_up_front(tmp_path, args, expected):
    out = tmp_path / "s.parquet"
    res = _simulated(["-m", "rotframe", "sweep", *args, "--device", "gpu", "--out", str(out)])
    assert res.returncode == 2 and expected in res.stderr and len(res.stderr.strip().splitlines()) == 1, res.stderr
    assert not out.exists()
