"""The host's share of ``rotframe bench gpu``'s user rows: the GPU replaced by a kernel that does nothing.

    PYTHONPATH=src python tools/gpu_host_share.py [particles]

The bench's user row (`rotframe.app.bench.gpu`) runs ``rotframe.simulate(device="gpu")`` on
1,048,576 particles. On a lent GPU its calls took 1.4 to 4.5 s where the scenes' ensemble took
0.07 to 0.17 s (`docs/bench/gpu.md`). This tool times the same calls with every launch replaced
by one that marks each particle done and every device array by a host array, so that what it
prints is what the host spends around the kernel: the checks, the start states, the copies and
the `Trajectory` with its per-particle event lists. No GPU and no CUDA toolkit are needed; the
first call of each case is a warm-up, then the best of three.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from gpu_ptx_check import HostArray  # noqa: E402 -- a tool beside this one


class _Done:
    """A kernel that marks every particle done (status 1) and computes nothing."""

    def __getitem__(self, shape):
        return self

    def __call__(self, *args):
        args[6][:] = 1  # ST, the per-particle status (`rotframe.problem.gpu._ARRAYS`)


def main(n=2**20) -> int:
    from numba import cuda

    import rotframe.particles.threads as threads
    import rotframe.problem.gpu as problem_gpu
    from rotframe.app.bench import gpu as bench_gpu

    problem_gpu._kernel = lambda *args: _Done()
    cuda.to_device = lambda a, *args, **kw: np.array(a).view(HostArray)
    cuda.device_array_like = lambda a, *args, **kw: np.empty_like(a).view(HostArray)
    cuda.is_available = lambda: True
    cuda.synchronize = lambda: None
    threads.gpu_available = lambda: True
    rng = np.random.default_rng(2)
    r0 = rng.normal(size=(n, 3)) + [0.0, 0.0, 1e4]
    v0 = rng.normal(size=(n, 3))
    for method in ("rotation-splitting", "rk4"):
        for event in (True, False):
            call = bench_gpu._user_problem(method, event, r0, v0, (0.0, 0.0, -9.81), (0.0, 4.6e-5, 5.7e-5), 1e-3,
                                            16.384)
            call()
            walls = []
            for _ in range(3):
                t0 = time.perf_counter()
                call()
                walls.append(time.perf_counter() - t0)
            print(f"{method}{' + ground event' if event else ''}: the host's share {min(walls):.3f} s, best of 3 "
                  f"({n} particles)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(*(int(a) for a in sys.argv[1:])))
