"""The Foucault scene's model on the engine against the scene's own kernels: what moving that scene still lacks.

The model (the local gravity, the string, Coriolis alone; Paris, a 67 m string swung 3 m) over one
hour, 100 samples, under DOP853 (rtol 1e-10 and 1e-5, the bench's loosest row, each at the scene's
absolute tolerance, where the engine takes the scene's very steps), RK4 and ``rotation-splitting4``
(h = 0.05 s), run by the engine's loop (``inline=False``), its inlined loop (``inline=True``,
`rotframe.problem.inlined`) and the scene's kernels (`rotframe.particles.integrators.integrate_particles`),
each a whole call; then set up once and run again (`rotframe.problem.prepared.PreparedProblem`, inlined,
beside the scene's `rotframe.particles.prepared.PreparedRun`). Prints the best of 9 interleaved runs of
each, in ms. Pin it to one core on a quiet machine::

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
from rotframe.particles.prepared import PreparedRun
from rotframe.problem.prepared import PreparedProblem
scale = max(1.0, float(np.max(np.abs(np.concatenate([r0, v0])))))  # the scene's absolute tolerance: rtol times this
fs = [forces.gravity(g), forces.pendulum(L, pivot)]
for method, step, rtol in [("dop853", None, 1e-10), ("dop853", None, 1e-5), ("rk4", 0.05, 1e-10),
                           ("rotation-splitting4", 0.05, 1e-10)]:
    atol = rtol * scale if method == "dop853" else None
    kw = dict(omega=w, duration=T, rtol=rtol, atol=atol, samples=100, method=method, step=step, forces=fs,
              frame_terms=("coriolis",))
    prepared = PreparedProblem(r0=r0, v0=v0, **kw)
    scene_prepared = PreparedRun(model, method, T, step=step, rtol=rtol, samples=100)
    cands = {"engine": lambda: simulate_particles(r0=r0, v0=v0, inline=False, **kw),
             "inlined": lambda: simulate_particles(r0=r0, v0=v0, inline=True, **kw),
             "scene": lambda: integrate_particles(model, r0, v0, T, method=method, rtol=rtol, samples=100, step=step),
             "prepared": lambda: prepared.run(r0, v0), "scene prepared": lambda: scene_prepared.run(r0, v0)}
    for f in cands.values():
        f()
    best = {k: math.inf for k in cands}
    for _ in range(9):
        for k, f in cands.items():
            t0 = time.perf_counter(); f(); best[k] = min(best[k], time.perf_counter() - t0)
    label = f"{method} rtol {rtol:g}" if method == "dop853" else method
    print(label, " | ".join(f"{k} {v*1e3:.2f} ms" for k, v in best.items()), flush=True)
