"""Your own problem's particles on a CUDA GPU: the engine's own loop and your forces, compiled for the GPU.

``rotframe.simulate(..., device="gpu")`` runs one GPU thread per particle through the very
loop that the CPU runs (`rotframe.problem.engine.variant_loop`: the same steps, sample grid,
event location and status codes), with the same equations (`rotframe.problem.models`) and the
same glue (`rotframe.problem.glue`: the problem's forces, built-in and user's alike). It is one
Python source compiled for two targets, as the scenes' GPU ensembles are
(`rotframe.particles.gpu.device_function`): nothing of the physics or the integrators is
written for the GPU.

The one difference is how the loop reaches the problem's functions. On the CPU it calls
them at their addresses (`rotframe.problem.calls`), so that the engine compiles once for
every problem; a GPU has no such calls, so each call by address is replaced by a direct
call of the problem's function (`_overrides`) and the loop is compiled with the problem's
functions inlined into it, once per problem and method (kept for the process, `_KERNELS`), with the
model's parts as constants (`rotframe.problem.models.with_parts`, as the CPU's inlined loop): the
frame's kinds and terms the problem lacks are not compiled in (a third fewer registers a thread).
The user's functions must then compile for the GPU too: plain arithmetic on numbers and
arrays, returning a tuple, allocating no array (one line names the failure otherwise).

What stays on the CPU: the checks, the events' start values, the energy diagnostics and the
frame's interpolation check (`rotframe.problem.particles`). The GPU runs the fixed-step
methods (`rotframe.method_registry`, ``gpu=True``). The arrays stay on the GPU for the whole
run: after each call (a budget of steps, as on the CPU) only what the run's loop reads between
calls comes back (`_PACED`: times, statuses, counts), for the progress and the pacing; the rest of
the state, the samples and the events come back once, at the end (`GpuAdvance.fetch`). The state
before each call is copied on the GPU, and brought back only to replay a call on the CPU
(`GpuAdvance.saved`).

Results agree with the CPU's to round-off, not to the bit: the GPU's compiler fuses
multiplies and adds, and its ``sin``, ``cos`` and ``exp`` are its own.
"""

from __future__ import annotations

import numpy as np

from rotframe.errors import ScenarioError
from rotframe.numerics.compiled import bound

__all__ = ["GpuAdvance"]

#: (driver module, method name, events, D) -> the compiled kernel
_KERNELS: dict = {}
#: particle-calls of this process that a user function's exception ended on the GPU and the CPU ran again
#: (`GpuAdvance.ended`): `tools/gpu_user_check.py` shows that none of its checks were answered by the CPU
RERUNS = [0]
#: the per-particle arrays of the loop (`rotframe.problem.engine.advance`)
_STATE = ("Y", "TC", "H", "IDX", "SUB", "ST", "EVN", "GPREV", "NSTEP", "NFEV")
#: those that come back after every call: what the pacing, the progress and the run's loop read between calls (the
#: rest, two thirds of the bytes, come back with the results, `GpuAdvance.fetch`)
_PACED = ("TC", "IDX", "ST", "NSTEP", "NFEV")
#: the arrays that come back at the end (`GpuAdvance.fetch`)
_RESULTS = ("OUT", "EVT", "EVY", "EVK")
#: the loop's arguments, in order, up to the budget (`rotframe.problem.engine.advance`)
_ARRAYS = ("T", "Y", "TC", "H", "IDX", "SUB", "ST", "OUT", "EVT", "EVY", "EVK", "EVN", "GPREV", "NSTEP", "NFEV")


def _overrides(module, parts=None):
    """The GPU versions of the calls by address (`rotframe.problem.calls`): direct calls of ``module``'s functions.

    ``module`` is the problem's compiled glue (`rotframe.problem.codegen.build_module`); a role it
    lacks is the stub the CPU would call (`rotframe.problem.stubs`). The calls are the templates of
    `rotframe.problem.calls` (``direct_*``), which tell the frame's and the origin's functions apart
    by their tags where the CPU has their addresses.
    Returns the dict that `rotframe.particles.gpu.device_function` takes: the replacements, and
    the tree it makes.
    """
    from numba import cuda

    from rotframe.particles.gpu import inline_options, device_function
    from rotframe.problem import calls, readonly, varying

    made: dict = {}

    def device(template, **names):
        """``template`` compiled for the GPU with its capitalised global names bound to ``names``."""
        return cuda.jit(device=True, **inline_options())(bound(template, template.__name__, **names))

    made[readonly.readonly] = device(_same_array)  # the read-only check is the CPU compile's (the glue is built there)
    for helper, (template, names) in calls.direct_calls(module, varying.varying_into).items():
        made[helper] = device(template, **{name: device_function(f, made) for name, f in names.items()})
    if parts is not None:  # the model's parts as constants: the parts the problem lacks are pruned
        from rotframe.problem import models

        for kernel, template in models.with_parts(parts).items():
            made[kernel] = device_function(template, made)
    return made


def _same_array(a):
    return a


def _kernel_source(T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, rtol, atol, hfix,
                   EDIR, ETERM, S, M, p, FK, FT, FC, OK, OT, OC, LIVE):
    """One thread per particle: the engine's loop (``loop``, `rotframe.problem.engine.variant_loop`) over particle i.

    The work arrays are the thread's own (``DIM``, the state's length, and ``SCRATCH`` are constants
    of each compiled copy). ``LIVE[i]`` is 1 while the loop runs: a thread that a raised
    exception ended (CUDA ends the thread, and says nothing) leaves it at 1.
    """
    i = cuda.grid(1)  # noqa: F821 -- the names in capitals, cuda and loop are bound per compiled copy
    if i >= Y.shape[0]:
        return
    K = cuda.local.array((16, DIM), float64)  # noqa: F821
    Kb = cuda.local.array((13, DIM), float64)  # noqa: F821
    V = cuda.local.array((7, DIM), float64)  # noqa: F821
    F = cuda.local.array((7, DIM), float64)  # noqa: F821
    W = cuda.local.array(SCRATCH, float64)  # noqa: F821
    for j in range(SCRATCH):  # noqa: F821
        W[j] = 0.0
    LIVE[i] = 1
    loop(i, i + 1, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, rtol,  # noqa: F821
         atol, hfix, EDIR, ETERM, S, (0, M, p, FK, FT, FC, OK, OT, OC), FNS, K, Kb, V, F, W)
    LIVE[i] = 0


def _kernel(module, method, events, D, parts=None):
    """The compiled kernel of one problem (its glue ``module``), method (its name) and events, for states of D numbers."""
    key = (module.__name__, method, bool(events), int(D), None if parts is None else tuple(sorted(parts.items())))
    done = _KERNELS.get(key)
    if done is not None:
        return done
    from numba import cuda, float64

    from rotframe.particles.gpu import device_function
    from rotframe.problem import engine, models
    from rotframe.problem.calls import direct_functions
    from rotframe.problem.signatures import PARTICLE

    loop = device_function(engine.variant_loop(PARTICLE, method, events, D), _overrides(module, parts))
    done = _KERNELS[key] = cuda.jit(bound(_kernel_source, "rotframe_problem_kernel", cuda=cuda, float64=float64,
                                           loop=loop, DIM=int(D), SCRATCH=models.SCRATCH,
                                           FNS=direct_functions()))
    return done


class GpuAdvance:
    """`rotframe.problem.engine.advance` on the GPU, for one run: the same arguments, the arrays kept on the GPU.

    The first call uploads every array; each call keeps a copy of the per-particle state on the
    GPU (`saved`: what a call is replayed from), launches one thread per particle (``lo``, ``hi``
    are the whole ensemble: the GPU takes every particle at once) and brings back what the run's
    loop reads between calls (`_PACED`) into the caller's arrays. `fetch` brings back the rest of
    the state, the samples and the events. A thread that a user function's exception ended is
    given status 6 (a user function raised) by the caller, which runs its call again on the CPU
    from `saved`.
    """

    def __init__(self, module, method, events, D):
        self.module = module
        self.key = (method, events, D)
        self.device = None  # name -> device array
        self.before = None  # name -> the device array's copy before the last call (`saved`)
        self.host = None  # name -> the caller's array
        self.live = None
        #: the particles whose thread a user function's exception ended in the last call (`rotframe.problem.particles`
        #: runs that call again for them on the CPU, which stops at the step and names the function)
        self.ended = np.zeros(0, np.int64)
        self.fetched = False

    def __call__(self, lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, method,
                 rtol, atol, hfix, EDIR, ETERM, S, prob, fns):
        from numba import cuda

        from rotframe.particles.gpu import launch_shape

        host = dict(zip(_ARRAYS, (T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV)))
        if self.device is None:
            from rotframe.problem.models import model_parts

            self.kernel = _kernel(self.module, *self.key, model_parts(prob))
            self.host = host
            self.device = {name: cuda.to_device(np.ascontiguousarray(a)) for name, a in host.items()}
            self.settings = [cuda.to_device(np.ascontiguousarray(a)) for a in (atol, EDIR, ETERM, S, prob[1], prob[2],
                                                                                 prob[4], prob[5], prob[7], prob[8])]
            self.kinds = (int(prob[3]), int(prob[6]))
            self.live = cuda.to_device(np.zeros(Y.shape[0], np.int64))
            self.before = {name: cuda.device_array_like(self.device[name]) for name in _STATE}
        atol_d, edir, eterm, stops, M, p, FT, FC, OT, OC = self.settings
        d = self.device
        for name in _STATE:  # on the GPU, at its own memory's speed (some 0.1 ms for a million particles)
            self.before[name].copy_to_device(d[name])
        self.fetched = False
        try:
            self.kernel[launch_shape(Y.shape[0])](
                *(d[name] for name in _ARRAYS), int(budget), float(rtol), atol_d, float(hfix), edir, eterm, stops, M, p,
                self.kinds[0], FT, FC, self.kinds[1], OT, OC, self.live)
        except Exception as exc:  # noqa: BLE001 -- numba's compile errors, named for the user
            _launch_failed(exc)
        cuda.synchronize()
        for name in _PACED:
            d[name].copy_to_host(self.host[name])
        live = self.live.copy_to_host()
        # a user function raised: CUDA ended the thread (its state is the call's start), where the CPU sets status 6
        self.ended = np.flatnonzero((live != 0) & (self.host["ST"] == 0))
        RERUNS[0] += int(self.ended.size)

    def resume(self):
        """Send the caller's arrays back to the GPU (after the CPU ran a call again for some particles)."""
        for name in _STATE + _RESULTS:
            self.device[name].copy_to_device(np.ascontiguousarray(self.host[name]))
        self.fetched = False

    def fetch(self):
        """Bring the state, the samples and the event records back into the caller's arrays (after a call; once)."""
        if self.device is None or self.fetched:
            return
        self.fetched = True
        for name in _STATE + _RESULTS:
            if name not in _PACED:
                self.device[name].copy_to_host(self.host[name])

    def saved(self):
        """The per-particle state as it was before the last call, ``{name: host array}`` (`_STATE`'s names, ``Y``
        among them): what `rotframe.problem.particles` replays a call from; None before the first upload."""
        if self.before is None:  # nothing was uploaded: the caller's arrays are the state
            return None
        return {name: self.before[name].copy_to_host() for name in _STATE}


def _launch_failed(exc):
    """A kernel that numba cannot compile for the GPU: one line (a `ScenarioError`) with numba's reason.

    On numba's simulator a user function's exception comes here (it runs the threads in Python):
    it ends the thread, as on a GPU, and the call goes on (`GpuAdvance.ended`).
    """
    import numba

    if numba.config.ENABLE_CUDASIM and not isinstance(exc, numba.core.errors.NumbaError):
        return
    if not isinstance(exc, numba.core.errors.NumbaError):
        raise exc
    from rotframe.problem.callables import numba_reason

    raise ScenarioError(f"simulate: device='gpu': the problem's functions cannot be compiled for the GPU "
                        f"({numba_reason(exc)}); a GPU force is plain arithmetic returning a tuple, allocating no "
                        "array; use device='cpu'") from None
