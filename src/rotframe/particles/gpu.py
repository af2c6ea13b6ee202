"""Ensembles on a CUDA GPU, from the same physics source as the CPU kernels.

The forces (`rotframe.particles.forces`), the one-step maps
(`rotframe.particles.kernels`), the schedule readers and the event rules
(`rotframe.particles.events`) are plain Python functions that numba
compiles for the CPU (``njit``). [`device_function`][rotframe.particles.gpu.device_function] compiles the same
Python source for the GPU (``numba.cuda.jit(device=True)``): it takes a CPU
kernel's ``py_func`` and rebinds every compiled function that it calls to that
function's own GPU version, recursively. So there is one source of the physics,
compiled for two targets, and a fix to a force is a fix on both.

[`integrate_ensemble_gpu`][rotframe.particles.gpu.integrate_ensemble_gpu] runs one GPU thread per particle through the
fixed-step methods (``rotation-splitting``, ``rotation-splitting4``, ``rk4``),
watching one event as the CPU driver does (the same crossing rule and
bisection on the method's own step), in float64. It returns what
[`rotframe.particles.ensemble.integrate_ensemble`][rotframe.particles.ensemble.integrate_ensemble] needs: the first event's
time and state of every particle, else its state at the end. Without a GPU
(``numba.cuda.is_available()`` False) it refuses in one line, unless numba's
CUDA simulator is on (``NUMBA_ENABLE_CUDASIM=1``, set before numba is first
imported), which runs the same kernel in Python: that is how the tests check
it against the CPU ensemble on a machine without a GPU.
"""

from __future__ import annotations

import math
import types

import numpy as np

__all__ = ["available", "require", "device_function", "integrate_ensemble_gpu", "GPU_METHODS"]

#: the particle methods the GPU runs (the fixed-step ones)
GPU_METHODS = ("rotation-splitting", "rotation-splitting4", "rk4")

#: threads per block of the kernel
_THREADS_PER_BLOCK = 128

_DEVICE = {}  # CPU dispatcher -> its GPU device function
_KERNEL = []  # the compiled kernel, made on first use


def available() -> bool:
    """Whether numba can run CUDA kernels here ([`rotframe.particles.threads.gpu_available`][rotframe.particles.threads.gpu_available])."""
    from rotframe.particles.threads import gpu_available

    return gpu_available()


def require(what="device"):
    """Raise ScenarioError (one line) unless [`available`][rotframe.particles.gpu.available]."""
    from rotframe.particles.threads import require_gpu

    require_gpu(what)


def device_function(kernel):
    """The GPU version of a compiled CPU function: its Python source compiled by ``cuda.jit(device=True)``.

    Every numba-compiled function that ``kernel``'s source calls (a global name bound
    to a dispatcher) is rebound to its own GPU version, made the same way, so the whole
    call tree is compiled from the one source for the GPU. Constants and modules (math)
    are kept. Made once per function.
    """
    from numba import cuda
    from numba.core.dispatcher import Dispatcher

    done = _DEVICE.get(kernel)
    if done is not None:
        return done
    fn = kernel.py_func if isinstance(kernel, Dispatcher) else kernel
    names = dict(fn.__globals__)
    for name in _global_names(fn.__code__):
        value = names.get(name)
        if isinstance(value, Dispatcher):
            names[name] = device_function(value)
    clone = types.FunctionType(fn.__code__, names, fn.__name__, fn.__defaults__, fn.__closure__)
    clone.__qualname__ = fn.__qualname__
    clone.__module__ = fn.__module__
    done = _DEVICE[kernel] = cuda.jit(device=True)(clone)
    return done


def _global_names(code):
    """Every global name ``code`` (and the code objects nested in it) may read."""
    out = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            out |= _global_names(const)
    return out


def _ensemble_kernel_source(method, r, v, t0, h, n_steps, P, wt, wv, wint, events, watch, out, ev_t):
    """One GPU thread per particle: ``n_steps`` steps of ``method`` from ``t0``, up to its first event.

    The loop of `rotframe.particles.drivers.run_fixed` for one sample interval and
    one event: the same steps (`one_step` at a steady rate, a plan per step else),
    the same crossing test, and the same location (`locate_event`, bisection on a
    re-step). ``events`` (1, 5) is the event table, ``watch`` 0 (none) or 1. The
    ensemble reports each particle's first event only, so the thread stops there,
    terminal event or not. ``out`` (N, 6) receives the first event's state, else the
    end state; ``ev_t`` (N,) the first event's time, else NaN. Both are written for
    every particle, so they need no upload.
    """
    p = cuda.grid(1)  # noqa: F821 -- bound to numba.cuda in the compiled copy
    if p >= r.shape[0]:
        return
    m = unpack(P, wt, wv)  # noqa: F821
    rk4 = method == 2
    sphere = m.length > 0.0
    plan = make_plan(method, t0, h, m, wt, wv, wint)  # noqa: F821
    state = (r[p, 0], r[p, 1], r[p, 2], v[p, 0], v[p, 1], v[p, 2])
    ev_t[p] = math.nan
    g_old = 0.0
    if watch != 0:
        w0, wd0 = rates(t0, m.steady, m.w, wt, wv)  # noqa: F821
        g_old = start_value(events, 0, state, m, w0, wd0)  # noqa: F821
    for k in range(n_steps):
        t = t0 + k * h
        start = state
        step_plan = plan if m.steady else make_plan(method, t, h, m, wt, wv, wint)  # noqa: F821
        state = one_step(method, state, h, m, step_plan, rk4, sphere)  # noqa: F821
        if watch != 0:
            g_new = event_value(events, 0, state, m.radius)  # noqa: F821
            if crossed(events[0, 3], g_old, g_new):  # noqa: F821
                tau, state = locate_event(method, events, 0, start, g_old, t, h, m, wt, wv, wint, rk4,  # noqa: F821
                                          sphere)
                ev_t[p] = t + tau
                break
            g_old = g_new
    for i in range(6):
        out[p, i] = state[i]


def _kernel():
    """The compiled GPU kernel (made on first use, from `_ensemble_kernel_source`)."""
    if _KERNEL:
        return _KERNEL[0]
    from numba import cuda

    from rotframe.particles import events, kernels, packed, schedule

    names = dict(_ensemble_kernel_source.__globals__)
    names.update(cuda=cuda, unpack=device_function(packed.unpack), make_plan=device_function(kernels.make_plan),
                 rates=device_function(schedule.rates), one_step=device_function(kernels.one_step),
                 crossed=device_function(events.crossed), event_value=device_function(events.event_value),
                 start_value=device_function(events.start_value), locate_event=device_function(events.locate_event))
    fn = _ensemble_kernel_source
    clone = types.FunctionType(fn.__code__, names, "rotframe_ensemble_kernel", fn.__defaults__, fn.__closure__)
    _KERNEL.append(cuda.jit(clone))
    return _KERNEL[0]


def integrate_ensemble_gpu(model, r0, v0, duration, event, *, method, run):
    """``(t_event, state)`` of an ensemble run on the GPU (see the module docstring).

    The step is the CPU ensemble's for the same run settings: ``run["step"]`` (default
    1/20 of the sample interval) shortened to divide the sample interval of
    ``run["samples"]`` samples, and the steps counted from t = 0 (the CPU driver's
    times ``t0 + k h`` of one chunk, so event times agree to round-off).

    Raises
    ------
    ScenarioError
        No GPU ([`require`][rotframe.particles.gpu.require]), or a method the GPU does not run (`GPU_METHODS`).
    """
    from rotframe.errors import ScenarioError
    from rotframe.particles.chunked import steps_per_sample
    from rotframe.particles.integrators import METHODS, canonical_method

    require()
    method = canonical_method(method)
    if method not in GPU_METHODS:
        raise ScenarioError(f"method: {method!r} on device 'gpu'; the GPU runs {', '.join(GPU_METHODS)}")
    from numba import cuda

    info = METHODS[method]
    samples = max(1, int(run.get("samples") or 1))
    dt = duration / samples
    sps = steps_per_sample(dt, run.get("step"))
    h = dt / sps
    r0 = np.ascontiguousarray(r0, dtype=np.float64)
    v0 = np.ascontiguousarray(v0, dtype=np.float64)
    n = r0.shape[0]
    if n == 0:
        return np.full(0, math.nan), np.empty((0, 6))
    table = np.array([event.row() if event is not None else [0.0] * 5], dtype=np.float64)
    P = model.pack()
    wt, wv, wint = model.omega.times, model.omega.values, model.omega.cumulative()
    d_out, d_t = cuda.device_array((n, 6)), cuda.device_array(n)  # written by every thread: no upload
    kernel = _kernel()
    blocks = (n + _THREADS_PER_BLOCK - 1) // _THREADS_PER_BLOCK
    kernel[blocks, _THREADS_PER_BLOCK](info.code, cuda.to_device(r0), cuda.to_device(v0), 0.0, h, sps * samples,
                                       cuda.to_device(P), cuda.to_device(wt), cuda.to_device(wv),
                                       cuda.to_device(wint), cuda.to_device(table), 0 if event is None else 1,
                                       d_out, d_t)
    return d_t.copy_to_host(), d_out.copy_to_host()
