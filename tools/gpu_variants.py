"""Time rotframe's GPU ensemble kernel under register limits, beside the hand-written kernel (a lent GPU only).

    PYTHONPATH=src python tools/gpu_variants.py

For each case of ``rotframe bench gpu`` (the splitting and RK4, with and without the
ground event) and each register limit (`rotframe.particles.gpu._MAX_REGISTERS`), the
kernel alone on device-resident arrays (no transfers): the median of 5 launches after a
compiling one, with its registers and local memory a thread, beside the hand-written
numba kernel of the same steps. Prints one line each.
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from numba import cuda

from rotframe.app.bench import ceiling
from rotframe.app.bench.gpu import _numba_ceiling
from rotframe.particles import gpu, packed
from rotframe.particles.integrators import Event
from rotframe.particles.model import OmegaSchedule, ParticleModel


def timed(launch, repeats=5):
    launch()
    cuda.synchronize()
    walls = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        launch()
        cuda.synchronize()
        walls.append(time.perf_counter() - t0)
    return statistics.median(walls)


def resources(kernel):
    try:
        return f"{kernel.get_regs_per_thread()} regs, {kernel.get_local_mem_per_thread()} B local"
    except Exception as exc:  # noqa: BLE001
        return f"no report ({type(exc).__name__})"


def main(n=2**20, steps=16384, h=1e-3):
    g, w = (0.0, 0.0, -9.81), (0.0, 4.6e-5, 5.7e-5)
    rng = np.random.default_rng(2)
    r0 = rng.normal(size=(n, 3)) + [0.0, 0.0, 1e4]
    v0 = rng.normal(size=(n, 3))
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(np.array(w)), g=np.array(g))
    P = model.pack()
    wt, wv, wint = model.omega.times, model.omega.values, model.omega.cumulative()
    structure = gpu._structure_source(packed.unpack.py_func(P, wt, wv))
    c, s = ceiling.rotation_cos_sin(w, h)
    blocks = (n + 127) // 128
    d = {k: cuda.to_device(a) for k, a in dict(r=r0, v=v0, P=P, wt=wt, wv=wv, wint=wint).items()}
    out, ev_t = cuda.device_array((n, 6)), cuda.device_array(n)
    for code, rk4 in ((0, False), (2, True)):
        for watch in (True, False):
            table = cuda.to_device(np.array([Event("ground", "r", 2, 0.0, -1, True).row()]))
            hand = _numba_ceiling(rk4, watch)
            r, v = cuda.to_device(r0), cuda.to_device(v0)
            t_hand = timed(lambda: hand[blocks, 128](r, v, g, w, c, s, h, steps))
            label = f"{'rk4' if rk4 else 'splitting'}{' + ground' if watch else ''}"
            print(f"{label:<18} hand-written: {n * steps / t_hand:.3g} steps/s ({resources(hand)})", flush=True)
            for limit in (None, 64, 56):
                gpu._MAX_REGISTERS = limit
                k = gpu._kernel(code, True if rk4 else None, None, watch, True, structure)
                t = timed(lambda: k[blocks, 128](d["r"], d["v"], 0.0, h, steps, d["P"], d["wt"], d["wv"], d["wint"],
                                                 table, out, ev_t))
                print(f"{label:<18} max_registers {limit}: {n * steps / t:.3g} steps/s, {t_hand / t:.2f} of the "
                      f"hand-written ({resources(k)})", flush=True)
    gpu._MAX_REGISTERS = None


if __name__ == "__main__":
    main()
