"""Save or check the samples of a set of problems of your own (``rotframe.simulate``, ``simulate_body``).

The engine's counterpart of ``tools/defaults_snapshot.py``: to prove that a change to the engine
moves no number, or to see which ones it moves and by how much::

    PYTHONPATH=/path/to/old/src python tools/simulate_snapshot.py save /tmp/engine.npz   # the old tree
    python tools/simulate_snapshot.py check /tmp/engine.npz                               # this tree

The problems: a spring in a steady frame (a user force), the same in a frame given by a table (its
knots are stops), 16 shots with a wind of t, a terminal ground event and a non-terminal one, the
built-in spring and drag, each under DOP853, RK4 and ``rotation-splitting4``; a body with a torque
of t under DOP853 and RK4. ``check`` prints each array "same" (to the bit) or its largest
difference, and exits 1 when any differs.
"""

from __future__ import annotations

import sys

import numpy as np


def spring(t, r, v, k):
    return -k * r[0], -k * r[1], -k * r[2]


def wind(t, r, v):
    return 0.1 * np.sin(t), 0.0, -9.81


def ground(t, r, v):
    return r[2]


ground.direction, ground.terminal = -1, True


def cross_x(t, r, v):
    return r[0] - 0.3


def torque(t, L, q):
    return 0.01 * np.cos(t), 0.0, 0.0


def arrays() -> dict:
    """Every problem's samples (and event times), by name."""
    import rotframe
    from rotframe import forces

    out = {}
    tk = np.linspace(0.0, 20.0, 9)
    table = (tk, np.column_stack([0.1 * np.sin(tk), 0.05 * tk, 0.3 + 0.01 * tk ** 2]))
    rng = np.random.default_rng(1)
    v0 = np.column_stack([rng.uniform(5, 30, 16), np.zeros(16), rng.uniform(5, 30, 16)])
    for method in ("dop853", "rk4", "rotation-splitting4"):
        step = {} if method == "dop853" else {"step": 0.01}
        runs = {
            "spring": dict(omega=[0, 0, 0.3], r0=[1, 0, 0], v0=[0, 1, 0], duration=20.0, forces=[spring],
                           params=(1.0,), samples=101),
            "table": dict(omega=table, r0=[1, 0, 0], v0=[0, 1, 0], duration=20.0, forces=[spring], params=(1.0,),
                          samples=57),
            "shots": dict(omega=[0, 4e-5, 7e-5], r0=np.zeros((16, 3)), v0=v0, duration=8.0, forces=[wind],
                          events=[ground, cross_x], samples=33),
            "builtin": dict(omega=[0, 0, 0.3], r0=[1, 0, 0], v0=[0, 1, 0], duration=20.0,
                            forces=[forces.spring(1.0, [0, 0, 0]), forces.drag(linear=0.05)], samples=101),
        }
        for name, kw in runs.items():
            res = rotframe.simulate(method=method, **kw, **step)
            out[f"{name}_{method}_r"] = np.asarray(res.trajectory.r)
            out[f"{name}_{method}_v"] = np.asarray(res.trajectory.v)
            for label, times in (res.trajectory.event_times or {}).items():
                out[f"{name}_{method}_events_{label}"] = np.concatenate([np.ravel(t) for t in times] or [np.zeros(0)])
    for method in ("dop853", "rk4"):
        step = {} if method == "dop853" else {"step": 0.01}
        res = rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[0.1, 2.0, 0.05], q0=[0, 0, 0, 1], duration=30.0,
                                     torque=torque, method=method, samples=61, **step)
        out[f"body_{method}_L"] = np.asarray(res.trajectory.L)
        out[f"body_{method}_q"] = np.asarray(res.trajectory.q)
    return out


def main(argv) -> int:
    if len(argv) != 3 or argv[1] not in ("save", "check"):
        print(__doc__)
        return 2
    if argv[1] == "save":
        np.savez(argv[2], **arrays())
        return 0
    before, now = np.load(argv[2]), arrays()
    moved = False
    for key in sorted(set(before.files) | set(now)):
        if key not in now or key not in before.files:
            print(f"{key:40s} only in {'the snapshot' if key in before.files else 'this tree'}")
            moved = True
            continue
        a, b = before[key], now[key]
        if a.shape != b.shape:
            print(f"{key:40s} shape {a.shape} -> {b.shape}")
            moved = True
        elif np.array_equal(a, b, equal_nan=True):
            print(f"{key:40s} same")
        else:
            print(f"{key:40s} largest difference {np.nanmax(np.abs(a - b)):.3g}")
            moved = True
    return 1 if moved else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
