"""The Foucault scene's model on the engine against the scene's own kernels: what moving that scene still lacks.

The model (the local gravity, the string, Coriolis alone; Paris, a 67 m string swung 3 m) over one
hour, 100 samples, under DOP853 (rtol 1e-10), RK4 and ``rotation-splitting4`` (h = 0.05 s), run by
the engine's loop (``inline=False``), its inlined loop (``inline=True``, `rotframe.problem.inlined`)
and the scene's kernels (`rotframe.particles.integrators.integrate_particles`); DOP853 also at the
scene's absolute tolerance, where the engine takes the scene's very steps. Prints the best of 9
interleaved runs of each, in ms. Pin it to one core on a quiet machine::

    taskset -c 1 python tools/foucault_on_engine.py

docs/architecture.md quotes its numbers (the table of what the engine lacks per scene).
"""
import math, time, sys
import numpy as np
from rotframe import forces
from rotframe.problem.particles import simulate_particles
from rotframe.particles.integrators import integrate_particles
from rotframe.particles.model import OmegaSchedule, ParticleModel
lat = math.radians(48.85)
w = 7.292115e-5 * np.array([0.0, math.cos(lat), math.sin(lat)])
g = np.array([0.0, 0.0, -9.81]); L = 67.0; pivot = np.array([0.0, 0.0, L])
r0 = np.array([3.0, 0.0, L - math.sqrt(L * L - 9.0)]); v0 = np.zeros(3)
T = 3600.0
model = ParticleModel(("gravity", "coriolis", "pendulum"), omega=OmegaSchedule.constant(w), g=g, pendulum_length=L, pivot=pivot)
atol = 1e-10 * max(1.0, float(np.max(np.abs(np.concatenate([r0, v0])))))  # the scene's rule
for method, step in [("dop853", None), ("rk4", 0.05), ("rotation-splitting4", 0.05)]:
    def e(inline, a=None):
        return simulate_particles(omega=w, r0=r0, v0=v0, duration=T, rtol=1e-10, atol=a, samples=100, method=method, step=step,
                                  forces=[forces.gravity(g), forces.pendulum(L, pivot)], frame_terms=("coriolis",), inline=inline)
    s = lambda: integrate_particles(model, r0, v0, T, method=method, rtol=1e-10, samples=100, step=step)
    cands = {"engine": lambda: e(False), "inlined": lambda: e(True), "scene": s}
    if method == "dop853":
        cands["engine, scene's atol"] = lambda: e(False, atol)
        cands["inlined, scene's atol"] = lambda: e(True, atol)
    for f in cands.values():
        f()
    best = {k: math.inf for k in cands}
    for _ in range(9):
        for k, f in cands.items():
            t0 = time.perf_counter(); f(); best[k] = min(best[k], time.perf_counter() - t0)
    print(method, " | ".join(f"{k} {v*1e3:.1f} ms" for k, v in best.items()), flush=True)
