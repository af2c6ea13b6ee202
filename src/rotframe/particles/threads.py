"""Where ensembles run: on how many threads, and on which device.

``threads=None`` means the count in force: the one set by [`threads_scope`][rotframe.particles.threads.threads_scope]
for the duration of a command (the CLI's ``--threads N``, ``rotframe.run(...,
threads=N)``), else every core (``os.cpu_count()``). The device in force is set
the same way by [`device_scope`][rotframe.particles.threads.device_scope] (``--device``, ``rotframe.run(...,
device=...)``): ``"cpu"`` unless a command asks for ``"gpu"``. Both are held in
`contextvars.ContextVar` s, like `rotframe.limits`, so nothing
outlives the command that set them.

`BLOCK` is the size of the blocks a many-particle call is cut into
(`rotframe.particles.blocks`; on several threads, the blocks are evened out so
that each thread gets the same share). Each particle is integrated alone, so the
results depend neither on the number of threads nor on the cut. [`rotframe.particles.ensemble`][rotframe.particles.ensemble] re-exports
these names.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import os

__all__ = ["BLOCK", "check_threads", "threads_scope", "threads_in_force", "resolve_threads", "DEVICES",
           "gpu_available", "require_gpu", "check_device", "device_scope", "device_in_force"]

#: particles per block (at most; on several threads the blocks are evened out, `rotframe.particles.blocks.block_bounds`)
BLOCK = 4096

#: threads in force (None: every core); set per command by [`threads_scope`][rotframe.particles.threads.threads_scope]
_THREADS: contextvars.ContextVar[int | None] = contextvars.ContextVar("rotframe_threads", default=None)

#: where ensembles run: the CPU's cores, or a CUDA GPU ([`rotframe.particles.gpu`][rotframe.particles.gpu])
DEVICES = ("cpu", "gpu")
#: device in force (None: cpu); set per command by [`device_scope`][rotframe.particles.threads.device_scope]
_DEVICE: contextvars.ContextVar[str | None] = contextvars.ContextVar("rotframe_device", default=None)


def gpu_available() -> bool:
    """Whether numba can run CUDA kernels here: a CUDA GPU, or numba's simulator (``NUMBA_ENABLE_CUDASIM=1``)."""
    from numba import config

    if config.ENABLE_CUDASIM:
        return True
    try:
        from numba import cuda

        return bool(cuda.is_available())
    except Exception:  # noqa: BLE001 -- no driver, no toolkit: no GPU
        return False


def require_gpu(what="device"):
    """Raise ScenarioError (one line) unless [`gpu_available`][rotframe.particles.threads.gpu_available]."""
    if not gpu_available():
        from rotframe.errors import ScenarioError

        raise ScenarioError(f"{what}: 'gpu', but no CUDA GPU is available here (numba.cuda.is_available() is "
                            "False); use 'cpu'")


def check_device(device, what="device") -> str | None:
    """``device`` as one of `DEVICES` (None stays None); ScenarioError in one line otherwise.

    ``"gpu"`` also needs a CUDA GPU (or numba's simulator): without one, ScenarioError
    saying so (the command line exits 2).
    """
    if device is None:
        return None
    from rotframe.errors import ScenarioError

    if not isinstance(device, str) or device not in DEVICES:  # an array's `in` would ask its truth value
        raise ScenarioError(f"{what}: {device!r}; allowed: {', '.join(DEVICES)}")
    if device == "gpu":
        require_gpu(what)
    return device


@contextlib.contextmanager
def device_scope(device):
    """Make ``device`` (None: cpu) the device of the ensembles run inside the block (checked first)."""
    token = _DEVICE.set(check_device(device))
    try:
        yield _DEVICE.get()
    finally:
        _DEVICE.reset(token)


def device_in_force() -> str:
    """The device set by the innermost [`device_scope`][rotframe.particles.threads.device_scope]: ``"cpu"`` where none was set."""
    return _DEVICE.get() or "cpu"


def check_threads(threads, what="threads") -> int | None:
    """``threads`` as a whole number >= 1 (None stays None); ScenarioError in one line otherwise."""
    if threads is None:
        return None
    from rotframe.errors import ScenarioError

    try:
        ok = not isinstance(threads, bool) and float(threads) == int(threads)
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok or int(threads) < 1:
        raise ScenarioError(f"{what}: {threads!r}; must be a whole number >= 1 (default: every core, "
                            f"{cores()} here)")
    return int(threads)


@contextlib.contextmanager
def threads_scope(threads):
    """Make ``threads`` (None: every core) the count in force inside the block."""
    token = _THREADS.set(check_threads(threads))
    try:
        yield _THREADS.get()
    finally:
        _THREADS.reset(token)


def threads_in_force() -> int | None:
    """The count set by the innermost [`threads_scope`][rotframe.particles.threads.threads_scope]; None where none was set (every core)."""
    return _THREADS.get()


def resolve_threads(threads=None) -> int:
    """The number of threads for ``threads`` (None: the count in force, else every core)."""
    if threads is None:
        threads = _THREADS.get()
    if threads is None:
        threads = cores()
    return check_threads(threads)


@functools.lru_cache(maxsize=1)
def cores() -> int:
    """The machine's cores (``os.cpu_count()``), read once a process: the call reads the system's files (some 40
    microseconds), and every run asks."""
    return os.cpu_count() or 1
