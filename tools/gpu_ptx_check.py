"""Compile every GPU kernel rotframe makes to PTX for a Hopper GPU (sm_90), on a machine with no GPU.

    PYTHONPATH=src python tools/gpu_ptx_check.py

numba's CUDA simulator runs the kernels as Python, so it never types them: code that the
simulator runs can still fail to compile for a real GPU (on 2026-11-30 the engine's RK4 and
splitting kernels did, at their first launch on an H200). This tool types and compiles them as
the GPU would, with NVIDIA's ``numba-cuda``, ``cuda-bindings``, NVRTC and a CUDA toolkit's
``libnvvm`` installed, and no driver: the kernels of `tools/gpu_user_check.py` (your own
problems through ``rotframe.simulate(device="gpu")``), the user rows of ``rotframe bench gpu``
and the scenes' ensembles (`rotframe.particles.gpu`). Where ``ptxas`` is found (CUDA's ``bin``),
it prints each kernel's registers a thread, as ``ptxas -v`` counts them for sm_90.

No kernel runs: each launch is intercepted, its arguments' types read, and the kernel compiled
to PTX in their place. Exits 1 if any kernel fails to compile, 2 where the tools are missing.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

CC = (9, 0)


class _Launched(Exception):
    """Raised in place of a launch, once the kernel compiled (or failed to); the run ends there."""


def _ptxas():
    found = shutil.which("ptxas")
    if found:
        return found
    for root in sorted(Path("/usr/local").glob("cuda*"), reverse=True):
        if (root / "bin" / "ptxas").exists():
            return str(root / "bin" / "ptxas")
    return None


def _compile(py_func, args, failures, name):
    """Compile ``py_func`` for sm_90 with the types of ``args``; print the registers; record a failure."""
    compiled = failures.compiled
    from numba import cuda, typeof
    from numba.core import types

    sig = tuple(types.Array(typeof(a).dtype, a.ndim, "C") if isinstance(a, np.ndarray) else typeof(a) for a in args)
    try:
        ptx, _ = cuda.compile_ptx(py_func, sig, cc=CC)
    except Exception as exc:  # noqa: BLE001 -- every failure is reported, then the next kernel
        failures.append(name)
        print(f"FAILED {name}: {str(exc)[-2000:]}", flush=True)
        raise _Launched() from None
    registers = ""
    if os.environ.get("PTX_DIR"):  # each kernel's PTX kept for reading (ld.local / st.local: its local memory)
        Path(os.environ["PTX_DIR"], f"{len(compiled) + len(failures):02d}.ptx").write_text(f"// {name}\n{ptx}")
    ptxas = _ptxas()
    if ptxas:
        with tempfile.NamedTemporaryFile("w", suffix=".ptx", delete=False) as f:
            f.write(ptx)
        out = subprocess.run([ptxas, f"-arch=sm_{CC[0]}{CC[1]}", "-v", f.name, "-o", os.devnull],
                             capture_output=True, text=True).stderr
        os.unlink(f.name)
        registers = "; " + "; ".join(line.split(":", 1)[-1].strip() for line in out.splitlines()
                                     if "registers" in line or "stack frame" in line)
    print(f"ok {name}{registers}", flush=True)
    compiled.append(name)
    raise _Launched()


class _Failures(list):
    """The kernels that failed to compile; ``compiled``, those that did."""

    def __init__(self):
        super().__init__()
        self.compiled = []


class HostArray(np.ndarray):
    """A host array in place of a device array (what a run does with its arrays after the launch)."""

    def copy_to_host(self, host=None):
        if host is None:
            return np.array(self)
        host[...] = self
        return host

    def copy_to_device(self, host):
        self[...] = host


def _intercept(failures, current):
    """Replace the launches and the device arrays by the compile of `_compile` (no driver is needed)."""
    from numba import cuda
    import numba.cuda.dispatcher as dispatcher

    import rotframe.particles.gpu as particles_gpu
    import rotframe.particles.threads as threads
    import rotframe.problem.gpu as problem_gpu

    class Device:
        compute_capability = CC

    class Launch:
        def __init__(self, kernel):
            self.kernel = kernel

        def __getitem__(self, shape):
            return self

        def __call__(self, *args):
            _compile(self.kernel.py_func, args, failures, current[0])

    made = problem_gpu._kernel
    problem_gpu._kernel = lambda *a: Launch(made(*a))
    problem_gpu._launch_failed = lambda exc: (_ for _ in ()).throw(exc)

    def ensemble_launch(self, r, v, out, ev_t):
        _compile(self.kernel.py_func, (r, v, 0.0, self.h, self.steps, *self.settings, out, ev_t), failures,
                 current[0])

    particles_gpu.GpuLaunch.__call__ = ensemble_launch
    particles_gpu.launch_shape = lambda n: (1, 1)
    dispatcher.get_current_device = Device
    cuda.is_available = lambda: True
    threads.gpu_available = lambda: True
    cuda.to_device = lambda a, *args, **kw: np.array(a).view(HostArray)
    cuda.device_array_like = lambda a, *args, **kw: np.empty_like(a).view(HostArray)
    cuda.device_array = lambda shape, *args, **kw: np.zeros(shape).view(HostArray)


def _cases():
    """(name, call) of every kernel to compile."""
    import rotframe
    from rotframe.app.bench import gpu as bench_gpu
    from rotframe.particles.ensemble import integrate_ensemble
    from rotframe.particles.integrators import Event
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    import gpu_user_check

    cases = [(name, lambda kw=kw: rotframe.simulate(**kw, device="gpu", duration=0.5, samples=3))
             for name, kw in gpu_user_check.cases(4)]
    r0 = np.zeros((4, 3))
    r0[:, 2] = 1e4
    v0 = np.ones((4, 3))
    g, w = (0.0, 0.0, -9.81), (0.0, 4.6e-5, 5.7e-5)
    ground = Event("ground", "r", 2, 0.0, -1, True)
    for method in ("rotation-splitting", "rk4"):
        for event in (True, False):
            label = f"{method}{' + ground event' if event else ''}"
            cases.append((f"bench gpu, user row: {label}",
                          bench_gpu._user_problem(method, event, r0, v0, g, w, 1e-3, 0.016)))
            for terms in (("gravity", "coriolis"), ("gravity", "coriolis", "centrifugal")):
                model = ParticleModel(terms, omega=OmegaSchedule.constant(np.array(w)), g=np.array(g))
                cases.append((f"ensemble {'+'.join(terms)}: {label}",
                              lambda model=model, method=method, event=event: integrate_ensemble(
                                  model, r0, v0, 0.016, ground if event else None, method=method,
                                  run={"step": 1e-3, "samples": 16}, device="gpu")))
    only = os.environ.get("ONLY")  # the cases whose names hold this text (all by default)
    return [case for case in cases if not only or only in case[0]]


def main() -> int:
    from numba import config

    if config.ENABLE_CUDASIM:
        print("gpu_ptx_check: unset NUMBA_ENABLE_CUDASIM: the simulator compiles nothing", file=sys.stderr)
        return 2
    from numba import cuda

    if getattr(cuda, "implementation", "") != "NVIDIA":
        print("gpu_ptx_check: needs NVIDIA's numba-cuda (pip install numba-cuda cuda-bindings nvidia-cuda-nvrtc) "
              "and a CUDA toolkit's libnvvm", file=sys.stderr)
        return 2
    failures = _Failures()
    current = [""]
    _intercept(failures, current)
    for name, call in _cases():
        current[0] = name
        reason = ""
        try:
            call()
        except Exception as exc:  # noqa: BLE001 -- _Launched, or the run's own wrapping of it (a user function's call)
            reason = f" ({type(exc).__name__}: {exc})"
        if name not in failures and name not in failures.compiled:
            failures.append(name)
            print(f"FAILED {name}: no kernel was launched{reason}", flush=True)
    print(f"{len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
