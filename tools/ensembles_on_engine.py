"""How the engine runs the tower drop's sweep ensembles, beside the scenes' kernels that run them today (issue 32).

The sweeps' vectorised ensembles (`rotframe.scenes.tower_drop.simulate_ensemble`) run on the engine since
2026-12-01 (before, `rotframe.particles.ensemble.integrate_ensemble` on the scenes' kernels, which the bench's
ensemble rows still measure against the hand-written ceiling, `rotframe bench ensemble`: 0.7 or more). This
tool times the same ensemble (gravity and Coriolis, the ground as a terminal event that no particle
reaches in the run, so both take the same steps) both ways, best of three after a first run that
compiles or loads every loop, and prints the engine's time over the scenes' kernels': by address
(``inline=False``) and with the problem's functions compiled into the loop (``inline=True``)::

    python tools/ensembles_on_engine.py            # 20000 particles, 2 s at h = 1e-3 s, every core
    python tools/ensembles_on_engine.py 100000     # the bench's ensemble size
    python tools/ensembles_on_engine.py 20000 1    # on one thread (steadier on a shared machine)

Each method is timed with the ground event and without it (the engine's loop then compiles no
watcher; the scenes' kernels run their event-free driver). Last, ``simulate``'s own choice (``inline`` not
given): this problem (uniform gravity, the Coriolis term, a built-in crossing, a steady frame) runs on the
scenes' fixed-step drivers (`rotframe.problem.steady`), the engine's numbers to the bit.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np


def best(func, repeats=3):
    """The least wall time (s) of ``repeats`` calls of ``func``."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        func()
        times.append(time.perf_counter() - t0)
    return min(times)


def main(argv):
    from rotframe import earth, forces
    from rotframe.events import crossing
    from rotframe.particles.ensemble import integrate_ensemble, resolve_threads, threads_scope
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.integrators import Event
    from rotframe.particles.model import OmegaSchedule, ParticleModel
    from rotframe.problem.particles import simulate_particles

    n = int(argv[0]) if argv else 20000
    threads = int(argv[1]) if len(argv) > 1 else None
    duration, h = 2.0, 1e-3
    lat = math.radians(50.88)
    g = float(earth.normal_gravity(lat))
    w = earth.omega_enu(lat)
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=np.array([0.0, 0.0, -g]))
    rng = np.random.default_rng(1)
    r0 = np.zeros((n, 3))
    r0[:, 2] = rng.uniform(100.0, 200.0, n)  # none lands within the run: the same steps for every particle
    v0 = np.zeros((n, 3))
    ground = Event("ground", "r", 2, 0.0, -1, True)
    with threads_scope(resolve_threads(threads)):
        for method in ("rk4", "rotation-splitting"):
            for watched in (True, False):
                run = {"step": h, "samples": 16}
                if watched:
                    def scenes():
                        return integrate_ensemble(model, r0, v0, duration, ground, method=method, run=run)
                else:
                    def scenes():
                        return integrate_particles(model, r0, v0, duration, method=method, step=h, samples=16)
                scenes()
                scene = best(scenes)
                engine = {}
                for inline in (False, True, None):
                    events = [crossing(2, 0.0, direction=-1, terminal=True, name="ground")] if watched else []
                    kw = dict(omega=w, r0=r0, v0=v0, duration=duration, forces=[forces.gravity([0.0, 0.0, -g])],
                              frame_terms=("coriolis",), method=method, step=h, samples=16, inline=inline,
                              events=events)
                    simulate_particles(**kw)  # compiles or loads the loop
                    engine[inline] = best(lambda: simulate_particles(**kw))
                print(f"{method}, {'the ground event' if watched else 'no event'}: the scenes' kernels "
                      f"{n * duration / h / scene / 1e6:.1f} M particle-steps/s; the engine {engine[False] / scene:.2f}x "
                      f"their time by address, {engine[True] / scene:.2f}x inlined; simulate's own choice "
                      f"{engine[None] / scene:.2f}x", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
