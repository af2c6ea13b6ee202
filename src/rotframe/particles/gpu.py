"""Ensembles on a CUDA GPU, from the same physics source as the CPU kernels.

The forces (`rotframe.particles.forces`), the one-step maps
(`rotframe.particles.kernels`), the schedule readers and the event rules
(`rotframe.particles.events`) are plain Python functions that numba
compiles for the CPU (``njit``). [`device_function`][rotframe.particles.gpu.device_function] compiles the same
Python source for the GPU (``numba.cuda.jit(device=True)``): it takes a CPU
kernel's ``py_func`` and rebinds every compiled function that it calls to that
function's own GPU version, recursively. So there is one source of the physics,
compiled for two targets, and a fix to a force is a fix on both.

The engine reaches this kernel from the terms: a fixed-step run of ``rotframe.simulate(device="gpu")`` on a steady
problem that keeps its end alone (`rotframe.problem.steady`), the tower drop's GPU sweeps among them.
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

import functools
import math
import types

import numpy as np

from rotframe import method_registry as registry

__all__ = ["available", "require", "check_method", "launches", "launch_shape", "device_function", "inline_options",
           "integrate_ensemble_gpu", "GpuLaunch", "GPU_METHODS"]

#: the particle methods the GPU runs (the fixed-step ones)
GPU_METHODS = registry.names("particle scenes", gpu=True)

#: threads per block of the kernel
_THREADS_PER_BLOCK = 128

_DEVICE = {}  # CPU dispatcher -> its GPU device function
_LAUNCHES = [0]  # kernel launches in this process (`launches`)
_KERNELS = {}  # (method, rk4, sphere, watch, steady, structure, registers) -> the compiled kernel, made on first use
#: registers a thread at most (None: the compiler's choice); `tools/gpu_variants.py` times the choices
_MAX_REGISTERS = None


def available() -> bool:
    """Whether numba can run CUDA kernels here ([`rotframe.particles.threads.gpu_available`][rotframe.particles.threads.gpu_available])."""
    from rotframe.particles.threads import gpu_available

    return gpu_available()


def launches() -> int:
    """How many ensembles this process has run on the GPU (a run that asked for the GPU and ran none is told)."""
    return _LAUNCHES[0]


def launch_shape(n) -> tuple:
    """``(blocks, threads per block)`` of a launch with one thread for each of ``n`` particles."""
    return (n + _THREADS_PER_BLOCK - 1) // _THREADS_PER_BLOCK, _THREADS_PER_BLOCK


def check_method(method) -> str:
    """``method``'s canonical name if the GPU runs it (`GPU_METHODS`); ScenarioError in one line otherwise."""
    return registry.check(method, "particle scenes", gpu=True)


def require(what="device"):
    """Raise ScenarioError (one line) unless [`available`][rotframe.particles.gpu.available]."""
    from rotframe.particles.threads import require_gpu

    require_gpu(what)


def device_function(kernel, made=None):
    """The GPU version of a compiled CPU function: its Python source compiled by ``cuda.jit(device=True)``.

    Every numba-compiled function that ``kernel``'s source calls (a global name bound
    to a dispatcher) is rebound to its own GPU version, made the same way, so the whole
    call tree is compiled from the one source for the GPU. Constants and modules (math)
    are kept. Made once per function.

    ``made`` (optional) maps CPU functions (or other global values, such as an intrinsic)
    to the GPU versions to use instead, and receives what is made: a tree of its own, for
    a caller that replaces some functions of it (`rotframe.problem.gpu`: the calls by address
    become direct calls of a problem's functions). Default: the process-wide tree.

    A function that numba inlines into its callers on the CPU (``inline="always"``,
    `rotframe.numerics.compiled.jit_inline`) is inlined the same way on the GPU: a caller may
    rely on it to drop the branches that its constants rule out before they are typed. Compiled
    on its own, every branch is typed, and a branch with another method's step fails to compile on
    a real GPU (as `rotframe.problem.steps.take_step` did when it held every method's step). The
    simulator runs Python and never types them.
    """
    from numba import cuda
    from numba.core.dispatcher import Dispatcher

    from rotframe.numerics.compiled import global_names

    made = _DEVICE if made is None else made
    done = made.get(kernel)
    if done is not None:
        return done
    fn = kernel.py_func if isinstance(kernel, Dispatcher) else kernel
    names = dict(fn.__globals__)
    for name in global_names(fn.__code__):
        value = names.get(name)
        if isinstance(value, Dispatcher) or _replaced(made, value):
            names[name] = device_function(value, made)
    clone = types.FunctionType(fn.__code__, names, fn.__name__, fn.__defaults__, fn.__closure__)
    clone.__qualname__ = fn.__qualname__
    clone.__module__ = fn.__module__
    options = inline_options()
    if options and isinstance(kernel, Dispatcher) and kernel.targetoptions.get("inline") == "always":
        options = {**options, "inline": "always"}  # numba's IR inlining, as on the CPU
    done = made[kernel] = cuda.jit(device=True, **options)(clone)
    return done


def _replaced(made, value) -> bool:
    """Whether ``made`` holds a replacement for the global ``value`` (unhashable values have none)."""
    try:
        return value in made
    except TypeError:
        return False


@functools.cache
def inline_options():
    """Every device function inlined into its caller (``forceinline``, where numba's CUDA target has it).

    Not inlined, each call passes the packed model (some 30 scalars) through the call
    ABI: 68 calls and 180 registers a thread in the kernel, against 47 in a
    hand-written one (``ptxas -v``, sm_90), so that a third as many threads fit on a
    multiprocessor. numba's simulator runs Python and takes no such option.
    """
    import inspect

    from numba import config, cuda

    if not config.ENABLE_CUDASIM and "forceinline" in inspect.signature(cuda.jit).parameters:
        return {"forceinline": True}
    return {}


def _ensemble_kernel_source(r, v, t0, h, n_steps, P, wt, wv, wint, events, out, ev_t):
    """One GPU thread per particle: ``n_steps`` steps of ``METHOD`` from ``t0``, up to its first event.

    The loop of `rotframe.particles.drivers.run_fixed` for one sample interval and
    one event: the same steps (`one_step` at a steady rate, a plan per step else),
    the same crossing test, and the same location (`locate_event`, bisection on a
    re-step). ``events`` (1, 5) is the event table. ``METHOD``, ``RK4`` and ``SPHERE``
    (True, or None where false, as the CPU drivers pass them), ``WATCH`` (an event or
    not), ``STEADY`` (a constant rate) and the model's structure (``structured``,
    `_structure_source`) are constants of each compiled copy (`_kernel`), so that a
    copy holds only the branches and the values its run needs. The ensemble
    reports each particle's first event only, so the thread stops there, terminal
    event or not. ``out`` (N, 6) receives the first event's state, else the end
    state; ``ev_t`` (N,) the first event's time, else NaN. Both are written for every
    particle, so they need no upload.
    """
    p = cuda.grid(1)  # noqa: F821 -- the names in capitals and the functions are bound per compiled copy
    if p >= r.shape[0]:
        return
    m = structured(unpack(P, wt, wv))  # noqa: F821
    plan = make_plan(METHOD, t0, h, m, wt, wv, wint)  # noqa: F821
    state = (r[p, 0], r[p, 1], r[p, 2], v[p, 0], v[p, 1], v[p, 2])
    ev_t[p] = math.nan
    g_old = 0.0
    if WATCH:  # noqa: F821
        w0, wd0 = rates(t0, STEADY, m.w, wt, wv)  # noqa: F821
        g_old = start_value(events, 0, state, m, w0, wd0)  # noqa: F821
    t = t0
    start = state
    hit = False
    for k in range(n_steps):
        t = t0 + k * h
        start = state
        step_plan = plan if STEADY else make_plan(METHOD, t, h, m, wt, wv, wint)  # noqa: F821
        state = one_step(METHOD, state, h, m, step_plan, RK4, SPHERE)  # noqa: F821
        if WATCH:  # noqa: F821
            g_new = event_value(events, 0, state, m.radius)  # noqa: F821
            if crossed(events[0, 3], g_old, g_new):  # noqa: F821
                hit = True
                break
            g_old = g_new
    if hit:
        # located after the loop, so that the bisection's registers are not held through every step
        tau, state = locate_event(METHOD, events, 0, start, g_old, t, h, m, wt, wv, wint, RK4, SPHERE)  # noqa: F821
        ev_t[p] = t + tau
    out[p, 0], out[p, 1], out[p, 2], out[p, 3], out[p, 4], out[p, 5] = state


def _structure_source(host):
    """Python source of ``structured(m)``: the packed model with its structure as constants.

    ``host`` is `rotframe.particles.packed.unpack`'s model of this run, unpacked on the host;
    ``m`` is the same, read on the GPU.
    Every field that is a switch (a boolean, the gravity mode) or zero in this run is
    written as its value, the others are read from ``m``: with every device function
    inlined, the compiler drops the terms the model does not have and keeps no
    register for them (``ptxas -v``, sm_90, gravity + Coriolis: 52 registers a thread
    for RK4, 90 with the ground event, where a model read at run time took 140 and
    168; a hand-written kernel takes 47). The values are the run's own, so the
    numbers are those of the general kernel and of the CPU.
    """
    from rotframe.particles import packed

    parts = []
    for name, value in zip(packed.PackedModel._fields, host):
        if isinstance(value, (bool, np.bool_)):
            parts.append(repr(bool(value)))
        elif name == "gmode" or (not isinstance(value, tuple) and float(value) == 0.0):
            parts.append(repr(float(value)))
        elif isinstance(value, tuple) and all(float(x) == 0.0 for x in value):
            parts.append("(0.0, 0.0, 0.0)")
        else:
            parts.append(f"m.{name}")
    return f"def structured(m):\n    return PackedModel({', '.join(parts)})\n"


def _kernel(method, rk4, sphere, watch, steady, structure):
    """The compiled GPU kernel for one run's constants (made on first use, from `_ensemble_kernel_source`).

    ``structure`` is `_structure_source`'s text for the run's model.
    """
    key = (method, rk4, sphere, watch, steady, structure, _MAX_REGISTERS)
    done = _KERNELS.get(key)
    if done is not None:
        return done
    from numba import config, cuda

    from rotframe.particles import events, kernels, packed, schedule

    made = {"PackedModel": packed.PackedModel}
    exec(compile(structure, "<rotframe.particles.gpu structured>", "exec"), made)  # noqa: S102 -- our own text
    names = dict(_ensemble_kernel_source.__globals__)
    names.update(cuda=cuda, METHOD=method, RK4=rk4, SPHERE=sphere, WATCH=watch, STEADY=steady,
                 structured=cuda.jit(device=True, **inline_options())(made["structured"]),
                 unpack=device_function(packed.unpack), make_plan=device_function(kernels.make_plan),
                 rates=device_function(schedule.rates), one_step=device_function(kernels.one_step),
                 crossed=device_function(events.crossed), event_value=device_function(events.event_value),
                 start_value=device_function(events.start_value), locate_event=device_function(events.locate_event))
    fn = _ensemble_kernel_source
    clone = types.FunctionType(fn.__code__, names, "rotframe_ensemble_kernel", fn.__defaults__, fn.__closure__)
    limit = {} if config.ENABLE_CUDASIM or not _MAX_REGISTERS else {"max_registers": _MAX_REGISTERS}
    done = _KERNELS[key] = cuda.jit(clone, **limit)
    return done


def integrate_ensemble_gpu(model, r0, v0, duration, event, *, method, run):
    """``(t_event, state)`` of an ensemble run on the GPU (see the module docstring).

    The step is the CPU ensemble's for the same run settings: ``run["step"]`` (default
    1/20 of the sample interval) shortened to divide the sample interval of
    ``run["samples"]`` samples, and the steps counted from t = 0: step k starts at ``k h``, where the CPU's
    drivers start it on its sample interval's grid, ``T[s] + j h`` (`rotframe.numerics.step_control.grid_time`), so
    event times agree to round-off (and the GPU may fuse a multiply and an add).

    Raises
    ------
    ScenarioError
        No GPU ([`require`][rotframe.particles.gpu.require]), or a method the GPU does not run (`GPU_METHODS`).
    """
    return GpuLaunch(model, duration, event, method=method, run=run).from_host(r0, v0)


class GpuLaunch:
    """One ensemble run's compiled kernel and its uploaded settings, launched on device arrays.

    [`integrate_ensemble_gpu`][rotframe.particles.gpu.integrate_ensemble_gpu] makes one per call; the bench
    (``rotframe bench gpu``) times its launches on arrays already on the GPU.
    ``launch(r, v, out, ev_t)``: ``r, v`` (N, 3) device arrays of the initial state,
    ``out`` (N, 6) and ``ev_t`` (N,) device arrays that receive the first event's state
    and time, else the end state and NaN (`_ensemble_kernel_source`).
    """

    def __init__(self, model, duration, event, *, method, run):
        from numba import cuda

        from rotframe.particles import packed
        from rotframe.particles.chunked import steps_per_sample
        from rotframe.particles.integrators import METHODS
        from rotframe.particles.kernels import loop_code

        require()
        info = METHODS[check_method(method)]
        samples = max(1, int(run.get("samples") or 1))
        dt = duration / samples
        sps = steps_per_sample(dt, run.get("step"))
        self.h = dt / sps
        self.steps = sps * samples
        P = model.pack()
        wt, wv, wint = model.omega.times, model.omega.values, model.omega.cumulative()
        table = np.array([event.row() if event is not None else [0.0] * 5], dtype=np.float64)
        host = packed.unpack.py_func(P, wt, wv)  # the model as the kernel unpacks it: its switches, here
        self.kernel = _kernel(loop_code(info.name), True if info.name == "rk4" else None, True if host.length > 0.0 else None,
                              event is not None, bool(host.steady), _structure_source(host))
        self.settings = [cuda.to_device(a) for a in (P, wt, wv, wint, table)]

    def from_host(self, r0, v0):
        """``(t_event, state)`` of the particles starting at the host arrays ``r0``, ``v0`` (N, 3), brought back to
        the host (`integrate_ensemble_gpu`, and the engine's steady specialisation on the GPU,
        `rotframe.problem.steady`)."""
        from numba import cuda

        r0 = np.ascontiguousarray(r0, dtype=np.float64)
        v0 = np.ascontiguousarray(v0, dtype=np.float64)
        n = r0.shape[0]
        if n == 0:
            return np.full(0, math.nan), np.empty((0, 6))
        d_out, d_t = cuda.device_array((n, 6)), cuda.device_array(n)  # written by every thread: no upload
        self(cuda.to_device(r0), cuda.to_device(v0), d_out, d_t)
        return d_t.copy_to_host(), d_out.copy_to_host()

    def __call__(self, r, v, out, ev_t):
        blocks, threads = launch_shape(r.shape[0])
        _LAUNCHES[0] += 1
        if blocks:
            self.kernel[blocks, threads](r, v, 0.0, self.h, self.steps, *self.settings, out, ev_t)
