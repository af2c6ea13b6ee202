"""A long run's loop with the problem's functions compiled into it: the engine's loop, inlined, cached per problem.

The engine (`rotframe.problem.engine`) is compiled once for every problem and calls a problem's
functions at their addresses (`rotframe.problem.calls`), so that a new problem starts in a
fraction of a second. The price is paid at every evaluation: a call by address is opaque to the
compiler, which can neither inline the force nor keep the state in registers across it. On a
long run or a large ensemble that price outweighs a compile. `inlined_loop` compiles the
problem's variant of the loop (`rotframe.problem.engine.variant_loop`) again, with each call
by address replaced by a direct call of the problem's function (the ``direct_*`` templates of
`rotframe.problem.calls`), as the GPU's kernel is (`rotframe.problem.gpu`): the same Python
source, the same steps in the same order, so the same numbers to the bit (numba compiles
without fast-math: no operation is reordered or fused).

Only what calls a problem's function is compiled again (`_rebuilt`): the loop, the steps and
the right-hand side; the rest of the engine is shared. The copies are cached on disk beside the
problem's glue (`rotframe.problem.codegen`): their code names the glue's file, which is named by
the fingerprint of the user's functions and of rotframe's sources, so a later process loads
the loop of the same functions instead of compiling it, and an edited function or an upgraded
rotframe never loads a stale one. A glue built in memory (a function that cannot be
fingerprinted) has its inlined loop compiled in memory too.

`Inlining` decides, between the engine's calls, whether a run switches to its inlined loop:

* ``inline=False``: never; ``inline=True``: from the first call (compiled, or loaded from the
  cache, before it);
* ``inline=None`` (the default): once the run has measured its own pace, when its remaining
  work at that pace exceeds `WORTH_LOADING_S` and the loop is in the cache (loading it took
  0.02 to 0.03 s), or exceeds `WORTH_COMPILING_S` (a compile took 3 to 8 s on the 2-core
  reference machine, and the inlined loop 0.8 to 0.97 of the engine's time, 2026-11-29:
  `rotframe bench user-force` measures it, the ``dop853 inlined`` row).

What the inlined loop gains is the call by address (opaque to the compiler) and the parts of the
model the problem lacks (the engine reads them from the problem's constants at every
evaluation; the inlined loop holds them as constants, `rotframe.problem.models.with_parts`).
It does not make the engine's loop as fast as the scenes' kernels, whose steps keep the state in
registers (docs/architecture.md).

The switch happens at a call's end, where the arrays hold everything a step needs, so a run
gives the same numbers whichever loop ran which call.
"""

from __future__ import annotations

import time
import types

__all__ = ["inlined_loop", "Inlining", "WORTH_COMPILING_S", "WORTH_LOADING_S"]

#: a run switches to a loop it must compile when its remaining work, at its own pace, is longer than this (s): a compile
#: of up to 8 s repaid by a tenth of the work
WORTH_COMPILING_S = 80.0
#: ... and to a loop in the cache when longer than this (s; loading one took 0.02 to 0.03 s)
WORTH_LOADING_S = 0.5
#: the run measures its pace over calls worth at least this much wall time, after its first call, before it decides
MEASURED_S = 0.2

#: (glue module's name, model, method, events, D, the model's parts) -> the compiled loop, made once a process
_LOOPS: dict = {}


def _replacements(module, parts, where):
    """The direct calls of ``module``'s functions (the problem's glue) in place of the calls by address.

    Returns the dict that `_rebuilt` takes: each helper of `rotframe.problem.calls` -> its direct
    template bound to the glue's functions (`rotframe.problem.calls.direct_calls`, the GPU's too;
    the engine's evaluator of a varying vector rebuilt on them), and a particle's right-hand side
    and its splittings' kick with the model's ``parts`` as constants (`rotframe.problem.models.with_parts`;
    None for a body).
    """
    from rotframe.numerics.compiled import bound, jit_inline
    from rotframe.problem import calls, models, varying

    made: dict = {}
    for helper, (template, names) in calls.direct_calls(module, varying.varying_into).items():
        made[helper] = jit_inline(bound(template, template.__name__,
                                        **{name: _rebuilt(f, made, where) for name, f in names.items()}))
    if parts is not None:
        for kernel, template in models.with_parts(parts).items():
            made[kernel] = _copy(template, made, where, like=kernel)
    return made


def _rebuilt(value, made, where):
    """``value`` (a numba dispatcher or a Python function) with its compiled callees rebuilt on ``made``.

    A function that calls, at any depth, one that ``made`` replaces is copied (`_copy`); any other
    is kept as it is, shared with the engine.
    """
    from numba.core.dispatcher import Dispatcher

    try:
        done = made.get(value)
    except TypeError:  # an unhashable global: a value, not a function
        return value
    if done is not None:
        return done
    fn = value.py_func if isinstance(value, Dispatcher) else value
    if not isinstance(fn, types.FunctionType):
        return value
    made[value] = value  # while its callees are rebuilt (a recursive function keeps itself)
    names = _rebound(fn, made, where)
    if names is None:
        return value
    copy = made[value] = _copy(fn, made, where, like=value, names=names)
    return copy


def _rebound(fn, made, where):
    """``fn``'s globals with each compiled callee rebuilt (`_rebuilt`); None where none changed."""
    from numba.core.dispatcher import Dispatcher

    from rotframe.numerics.compiled import global_names

    names = dict(fn.__globals__)
    changed = False
    for name in global_names(fn.__code__):
        old = names.get(name)
        if isinstance(old, (Dispatcher, types.FunctionType)):
            new = _rebuilt(old, made, where)
            if new is not old:
                names[name] = new
                changed = True
    return names if changed else None


def _copy(fn, made, where, like, names=None):
    """The Python function ``fn`` copied onto its rebound globals (``names``, else `_rebound`'s), compiled with the
    options of ``like`` where that is a numba dispatcher.

    ``where`` is ``(file, module name, tag)``: the copy's code names the glue's file (the disk
    cache's place and stamp; None: compiled in memory), and its name ends in the tag of the
    model's parts, so that two models of the same functions are two entries of the cache.
    """
    from numba import njit
    from numba.core.dispatcher import Dispatcher

    file, module_name, tag = where
    if names is None:
        names = _rebound(fn, made, where) or dict(fn.__globals__)
    code = fn.__code__ if file is None else fn.__code__.replace(co_filename=file)
    clone = types.FunctionType(code, names, fn.__name__, fn.__defaults__, fn.__closure__)
    clone.__qualname__ = f"{fn.__qualname__}__{tag}"
    clone.__module__ = module_name
    clone.__doc__ = fn.__doc__
    if not isinstance(like, Dispatcher):
        return clone
    options = {k: v for k, v in like.targetoptions.items() if k != "nopython"}
    if options.get("cache"):
        options["cache"] = file is not None
    copy = njit(**options)(clone)
    copy.__class__ = type(like)  # a kernel for compiled code only stays so
    return copy


def _dispatcher(module, model, method, events, D, parts):
    """The inlined loop of ``module``'s problem as a numba dispatcher, not yet compiled."""
    import os

    from numba import njit

    from rotframe.problem import engine

    file = getattr(module, "__file__", None)
    tag = "parts" + "".join(f"_{parts[k]}" for k in sorted(parts)) if parts is not None else "body"
    where = (file if file and os.path.exists(file) else None), module.__name__, tag.replace("-", "m")
    loop = _rebuilt(engine.variant_loop(model, method, events, D), _replacements(module, parts, where), where)
    return njit(**dict(engine.ENTRY_OPTIONS, cache=where[0] is not None))(loop)


def _key(module, model, method, events, D, parts):
    parts = None if parts is None else tuple(sorted(parts.items()))
    return module.__name__, int(model), method, bool(events), int(D), parts


def inlined_loop(module, model, method, events, D, parts=None, compile=True):
    """The loop of the engine's variant ``(model, method, events, D)`` with ``module``'s functions in it and a
    particle model's ``parts`` as constants (`rotframe.problem.models.model_parts`; None for a body) (module
    docstring), compiled for `rotframe.problem.engine.VARIANT_SIGNATURE`, or loaded from the disk cache.

    With ``compile=False``, only loaded: None where it is neither in this process nor in the cache.
    It takes the engine's arguments, with `rotframe.problem.calls.direct_functions` for the addresses.
    """
    from rotframe.numerics.compiled import load_cached
    from rotframe.problem import engine

    key = _key(module, model, method, events, D, parts)
    kernel = _LOOPS.get(key)
    if kernel is not None:
        return kernel
    kernel = _dispatcher(module, model, method, events, D, parts)
    if not load_cached(kernel, engine.VARIANT_SIGNATURE):
        if not compile:
            return None
        kernel.compile(engine.VARIANT_SIGNATURE)
    kernel.disable_compile()
    _LOOPS[key] = kernel
    return kernel


class Inlining:
    """Whether, and from which call on, a run uses its inlined loop (module docstring).

    Parameters
    ----------
    module : module
        The problem's glue (`rotframe.problem.codegen.build_module`).
    model, method, events, D
        The engine's variant (`rotframe.problem.engine.variant`).
    parts : dict or None
        A particle model's parts (`rotframe.problem.models.model_parts`), constants of the loop; None for a body.
    mode : bool or None
        ``inline``: True, False or None (decided by the run's pace).
    """

    def __init__(self, module, model, method, events, D, parts, mode):
        self.variant = (module, model, method, bool(events), int(D), parts)
        self.mode = mode
        #: the inlined loop once the run has switched to it, else None (the engine's loop runs)
        self.kernel = None
        self.decided = mode is False
        self.note = None
        #: the seconds spent making the inlined loop after the first call (compiling or loading): a run counts them
        #: as compile time, not as integration
        self.seconds_mid_run = 0.0
        self._calls = 0
        self._wall = 0.0  # wall time of the calls measured so far (the first left out), and the simulated time they
        self._covered = 0.0  # covered

    def start(self):
        """Before the first call: make the inlined loop (`kernel`) where ``inline=True`` (compiled or loaded now)."""
        if self.mode is True:
            self._switch(compile=True, reason="inline=True")

    def after_call(self, wall, covered, remaining):
        """After each call, which took ``wall`` s to cover ``covered`` s of simulated time, summed over the particles,
        with ``remaining`` s of it still to go: switch to the inlined loop (`kernel`) where the run's pace says so.

        The first call is not a measure of the pace (it compiles or loads the engine's loop).
        """
        self._calls += 1
        if self.decided or self._calls == 1:
            return
        self._wall += wall
        self._covered += covered
        if self._wall < MEASURED_S or self._covered <= 0.0:
            return
        self.decided = True
        left = self._wall / self._covered * remaining
        if left > WORTH_LOADING_S:
            self.seconds_mid_run = self._switch(compile=left > WORTH_COMPILING_S,
                                                reason=f"about {left:.2g} s of work left at its pace")

    def _switch(self, compile, reason) -> float:
        """Load (or, with ``compile``, else compile) the inlined loop, and say so in `note`; returns the seconds it
        took."""
        t0 = time.perf_counter()
        known = _key(*self.variant) in _LOOPS
        self.kernel = inlined_loop(*self.variant, compile=False)
        how = "made earlier in this process" if known else "loaded from the disk cache"
        if self.kernel is None and compile:
            self.kernel = inlined_loop(*self.variant)
            how = "compiled"
        if self.kernel is not None:
            self.decided = True
            took = "" if known else f" in {time.perf_counter() - t0:.2g} s"
            self.note = (f"the run went on in its inlined loop, the problem's functions compiled into the engine's "
                         f"loop ({reason}; {how}{took}): the same steps and numbers")
        return time.perf_counter() - t0
