"""The host's share of the tower drop's GPU sweeps through the engine, beside the scenes' door, with no GPU.

    NUMBA_ENABLE_CUDASIM=1 PYTHONPATH=src python tools/gpu_door_host.py [N] [rounds]

Since 2026-12-02 a GPU sweep of the tower drop runs each group of drops as one run of the engine
(``simulate(device="gpu", samples=1)``: `rotframe.scenes.tower_drop._on_gpu`), which gives it to the scenes' GPU
kernel (`rotframe.problem.steady`); before, it called that kernel through ``integrate_ensemble(device="gpu")``. Both
launch the same kernel (`rotframe.particles.gpu.GpuLaunch`), so only the host's work around it can differ. Here the
launch is replaced by a stand-in that writes the start state and no event, and numba's simulator moves the arrays
(numpy copies), so what is timed is the host's work alone, in one process, the two doors interleaved, best of
``rounds`` (default 3) after a first round that loads what each loads:

- one group of ``N`` drops (default 1,000,000), the door alone;
- ``rotframe sweep tower-drop`` of ``N`` heights (one group) and of 200 latitudes x 10 heights (400 groups), the
  whole command in process (its table written, its plots drawn).

On a real GPU the kernel adds the same time to both.
"""

from __future__ import annotations

import contextlib
import io
import sys
import time

import numpy as np


def _interleaved(calls, rounds):
    """The best wall time of each of ``calls`` (name -> function), interleaved, after a first round."""
    walls = {name: [] for name in calls}
    for _ in range(rounds + 1):
        for name, fn in calls.items():
            t = time.perf_counter()
            fn()
            walls[name].append(time.perf_counter() - t)
    return {name: min(w[1:]) for name, w in walls.items()}


def main(n=1_000_000, rounds=3):
    from numba import config

    if not config.ENABLE_CUDASIM:
        sys.exit("gpu_door_host: set NUMBA_ENABLE_CUDASIM=1 before numba is imported (the launch is a stand-in)")
    from rotframe import limits
    from rotframe.app import cli
    from rotframe.particles import gpu
    from rotframe.particles.ensemble import integrate_ensemble
    from rotframe.particles.threads import device_scope
    from rotframe.scenes import tower_drop

    def stand_in(self, r, v, out, ev_t):  # the kernel's outputs, written without running it
        out.copy_to_device(np.concatenate([r.copy_to_host(), v.copy_to_host()], axis=1))
        ev_t.copy_to_device(np.full(r.shape[0], np.nan))

    def before(model, r0, duration, method, run, keep):  # the tower drop's GPU door before 2026-12-02
        ens = integrate_ensemble(model, r0, np.zeros_like(r0), duration, tower_drop.GROUND, method=method, run=run,
                                 keep=keep)
        return ens.t_event, ens.state, ens.paths

    gpu.GpuLaunch.__call__ = stand_in
    doors = {"engine": tower_drop._on_gpu, "integrate_ensemble": before}
    values = dict(height=158.5, latitude=50.9, drag=0.0, g_model="wgs84", magnify=1000.0)
    model, _, _, duration, _ = tower_drop.build(values, ["gravity", "coriolis"])
    duration = tower_drop.ensemble_duration(duration)
    r0 = np.zeros((n, 3))
    r0[:, 2] = np.linspace(100.0, 120.0, n)
    work = limits.current().with_overrides(max_steps=float("inf"))

    def door_alone(door):
        def call():
            with device_scope("gpu"), limits.applied(work):
                door(model, r0, duration, "rk4", {"step": 1e-3}, [])
        return call

    def sweep(door, grid):
        def call():
            tower_drop._on_gpu = door
            with contextlib.redirect_stdout(io.StringIO()):
                code = cli.main(["sweep", "tower-drop", *grid, "--method", "rk4", "--device", "gpu", "--out",
                                 "/tmp/gpu_door_host.parquet", "--json"])
            tower_drop._on_gpu = doors["engine"]
            assert code == 0
        return call

    cases = [(f"{n} drops, the door alone", door_alone),
             (f"rotframe sweep, {n} heights (1 group)", lambda d: sweep(d, ["--grid", f"height=100:120:{n}"])),
             ("rotframe sweep, 200 latitudes x 10 heights (400 groups)",
              lambda d: sweep(d, ["--grid", "latitude=-80:80:200", "--grid", "height=100:120:10"]))]
    for what, make in cases:
        best = _interleaved({name: make(door) for name, door in doors.items()}, rounds)
        e, s = best["engine"], best["integrate_ensemble"]
        print(f"{what}: through the engine {e:.3f} s, through integrate_ensemble {s:.3f} s, {e / s:.2f} of its time")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:3]))
