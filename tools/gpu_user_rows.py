"""Your own problem on the GPU beside the scenes' ensemble: the engine's kernel with the model's parts compiled in and
its calls sized to the host's work between them, and without either (as before 2026-11-30's second session), in one
run.

    PYTHONPATH=src python tools/gpu_user_rows.py [PARTICLES] [STEPS]

The work of ``rotframe bench gpu``'s user rows (`rotframe.app.bench.gpu`): gravity as a force of the user's,
the ground as an event of the user's, the frame's Coriolis and centrifugal terms rotframe's, one sample at the end,
through ``rotframe.simulate(device="gpu")``; beside it the scenes' ensemble of the same terms
(``integrate_ensemble(device="gpu")``, gravity + Coriolis + centrifugal). Each a call from host arrays to host arrays,
the best of interleaved rounds after a call that compiles. Prints particle-steps per second and the ratio of each
user row to the scenes' ensemble, and how far the two user kernels' final states are apart (round-off: the GPU fuses
multiplies and adds as its compiler likes); then, for one more call of each user row, its compiled calls and the
seconds spent in them (the kernels, and the per-particle state brought back after each). Needs a GPU (or
``NUMBA_ENABLE_CUDASIM=1``, which times nothing).
"""

from __future__ import annotations

import sys
import time

import numpy as np


def main(n=2**20, steps=8192):
    from numba import config

    from rotframe.app.bench import gpu as bench_gpu
    from rotframe.app.bench.throughput import best_interleaved
    from rotframe.particles.ensemble import integrate_ensemble
    from rotframe.particles.integrators import Event
    from rotframe.particles.model import OmegaSchedule, ParticleModel
    from rotframe.problem import gpu as problem_gpu
    from rotframe.problem import pacing

    if config.ENABLE_CUDASIM:
        n, steps = 8, 16
    made = problem_gpu._kernel
    g, w, h = (0.0, 0.0, -9.81), (0.0, 4.6e-5, 5.7e-5), 1e-3
    duration = steps * h
    rng = np.random.default_rng(2)
    r0 = rng.normal(size=(n, 3)) + [0.0, 0.0, 1e4]  # none lands: every particle takes every step
    v0 = rng.normal(size=(n, 3))
    model = ParticleModel(("gravity", "coriolis", "centrifugal"), omega=OmegaSchedule.constant(np.array(w)),
                          g=np.array(g))
    print(f"{n} particles x {steps} steps of {h:g} s, fp64; particle-steps per second, best of 3 interleaved rounds")
    print(f"{'case':<32} {'scenes':>9} {'parts in':>9} {'ratio':>6} {'parts read':>10} {'ratio':>6} "
          f"{'new/old':>7} {'apart':>8}")
    for method in ("rotation-splitting", "rk4"):
        for event in (True, False):
            ground = Event("ground", "r", 2, 0.0, -1, True) if event else None
            user = bench_gpu._user_problem(method, event, r0, v0, g, w, h, duration)

            def scenes():
                return integrate_ensemble(model, r0, v0, duration, ground, method=method,
                                          run={"step": h, "samples": 16}, device="gpu")

            def old():  # the kernel that reads the model's parts from the problem's constants, calls of 0.1 s
                problem_gpu._kernel = lambda module, m, e, D, parts=None: made(module, m, e, D, None)
                factor = pacing.BETWEEN_CALLS_FACTOR
                pacing.BETWEEN_CALLS_FACTOR = 0.0
                try:
                    return user()
                finally:
                    problem_gpu._kernel = made
                    pacing.BETWEEN_CALLS_FACTOR = factor

            compiles = []
            states = []
            for fn in (scenes, user, old):
                t0 = time.perf_counter()
                res = fn()
                compiles.append(time.perf_counter() - t0)
                states.append(res)
            walls = best_interleaved([scenes, user, old], 30.0, 3)
            rates = [n * steps / wall for wall in walls]
            new_state, old_state = (bench_gpu._user_state(s)[0] for s in states[1:])
            scale = np.max(np.abs(old_state), axis=0)
            apart = float(np.max(np.abs(new_state - old_state) / scale))
            label = f"{method}{' + ground' if event else ''}"
            inside = [_inside(fn, problem_gpu.GpuAdvance) for fn in (user, old)]
            print(f"{label:<32} {rates[0]:9.3g} {rates[1]:9.3g} {rates[1] / rates[0]:6.3f} {rates[2]:10.3g} "
                  f"{rates[2] / rates[0]:6.3f} {rates[1] / rates[2]:7.2f} {apart:8.1e}   first calls (s): "
                  + ", ".join(f"{c:.1f}" for c in compiles) + "; compiled calls, s in them, s in all: "
                  + ", ".join(f"{k} {s_in:.3f} {s_all:.3f}" for k, s_in, s_all in inside), flush=True)


def _inside(fn, advance):
    """``(calls, seconds in them, seconds in all)`` of one call of ``fn``: its GPU calls (`GpuAdvance`), each a
    launch, its wait and the per-particle state brought back."""
    made = advance.__call__
    seen = [0, 0.0]

    def timed(self, *args):
        t0 = time.perf_counter()
        try:
            return made(self, *args)
        finally:
            seen[0] += 1
            seen[1] += time.perf_counter() - t0

    advance.__call__ = timed
    try:
        t0 = time.perf_counter()
        fn()
        return seen[0], seen[1], time.perf_counter() - t0
    finally:
        advance.__call__ = made


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:]))
