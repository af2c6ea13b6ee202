"""Your own problems on the GPU against the CPU (``rotframe.simulate(device="gpu")``): a lent GPU, or the simulator.

    PYTHONPATH=src python tools/gpu_user_check.py [particles]

Each case runs the same problem on the CPU and on the GPU and prints the largest difference of
the samples and of the event times, relative to the state's scale, with the GPU's first call
(its compile) and a second call timed. The cases cover what the GPU compiles of a problem: a
user force with parameters, a built-in term beside it, events (terminal and not), the
pendulum's string under the order-4 splitting, a force in inertial axes (the frame's attitude
integrated), a frame given as a table and one given as a function with an accelerating origin.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

import rotframe
from rotframe import forces


def wind(t, r, v, k, shear):
    return k * (1.0 - abs(r[2]) / 100.0), shear[1] * r[2], 0.0


def ground(t, r, v, k, shear):
    return r[2]


ground.terminal = True
ground.direction = -1


def apex(t, r, v, k, shear):
    return v[2]


apex.direction = -1


def push(t, r, v):
    return 0.0, 1e-3 * np.cos(t), 0.0


def omega_of_t(t):
    return 0.0, 0.05 * np.sin(0.5 * t), 0.2 + 0.01 * t


def origin_of_t(t):
    return 0.01 * np.cos(t), 0.0, 0.0


def cases(n):
    rng = np.random.default_rng(7)
    r0 = np.zeros((n, 3))
    r0[:, 2] = rng.uniform(5.0, 40.0, n)
    v0 = rng.normal(scale=3.0, size=(n, 3))
    v0[:, 2] = np.abs(v0[:, 2]) + 2.0
    L = 2.0
    theta = rng.uniform(0.1, 0.5, n)
    rp = np.stack([L * np.sin(theta), np.zeros(n), -L * np.cos(theta)], axis=1)
    vp = np.stack([np.zeros(n), rng.normal(scale=0.2, size=n), np.zeros(n)], axis=1)
    g = forces.gravity([0.0, 0.0, -9.81])
    table = (np.linspace(0.0, 4.0, 9), np.stack([np.zeros(9), 0.01 * np.arange(9), 0.3 + 0.02 * np.arange(9)], axis=1))
    return [
        ("rk4, user force with params + gravity, terminal and non-terminal events",
         dict(omega=[0.0, 4.6e-3, 5.7e-3], r0=r0, v0=v0, forces=[g, wind], params=(0.3, np.array([0.0, 0.01, 0.0])),
              events=[ground, apex], method="rk4")),
        ("rotation-splitting4, the pendulum's string + gravity + drag",
         dict(omega=[0.0, 0.0, 0.3], r0=rp, v0=vp, forces=[forces.pendulum(L), g, forces.drag(linear=0.05)],
              method="rotation-splitting4")),
        ("rk4, a force in inertial axes (the frame's attitude integrated)",
         dict(omega=[0.0, 0.2, 0.1], r0=r0, v0=v0, forces=[g, rotframe.Force(push, axes="inertial")], method="rk4")),
        ("rotation-splitting, omega as a table (its knots stop the steps)",
         dict(omega=table, r0=r0, v0=v0, forces=[g], method="rotation-splitting")),
        ("rk4, omega(t) and an accelerating origin, functions of the user's",
         dict(omega=omega_of_t, origin_acceleration=origin_of_t, r0=r0, v0=v0, forces=[g], method="rk4")),
    ]


def main(n=256):
    worst = 0.0
    for label, kw in cases(n):
        kw = dict(kw, duration=4.0, step=2e-3, samples=20)
        t0 = time.perf_counter()
        cpu = rotframe.simulate(**kw)
        t_cpu = time.perf_counter() - t0
        t0 = time.perf_counter()
        gpu = rotframe.simulate(**kw, device="gpu")
        t_first = time.perf_counter() - t0
        t0 = time.perf_counter()
        gpu = rotframe.simulate(**kw, device="gpu")
        t_again = time.perf_counter() - t0
        a, b = cpu.trajectory, gpu.trajectory
        scale = max(np.nanmax(np.abs(a.r)), 1.0), max(np.nanmax(np.abs(a.v)), 1.0)
        dr = float(np.nanmax(np.abs(a.r - b.r)) / scale[0])
        dv = float(np.nanmax(np.abs(a.v - b.v)) / scale[1])
        de = 0.0
        for name, times in a.event_times.items():
            for x, y in zip(times, b.event_times[name]):
                if len(x) != len(y):
                    de = np.inf
                elif len(x):
                    de = max(de, float(np.max(np.abs(x - y))))
        same_nan = bool(np.array_equal(np.isnan(a.r), np.isnan(b.r)))
        worst = max(worst, dr, dv, de)
        print(f"{label}: samples agree to {dr:.1e} (r), {dv:.1e} (v) of their scale, event times to {de:.1e} s, "
              f"same NaN pattern {same_nan}; CPU {t_cpu:.2f} s, GPU first {t_first:.2f} s, again {t_again:.2f} s",
              flush=True)
    from rotframe.problem.gpu import RERUNS

    print(f"worst: {worst:.1e}; particle-calls the CPU ran again (a thread ended by an exception): {RERUNS[0]}")
    return worst if RERUNS[0] == 0 else math.inf


if __name__ == "__main__":
    sys.exit(0 if main(*(int(a) for a in sys.argv[1:])) < 1e-9 else 1)
