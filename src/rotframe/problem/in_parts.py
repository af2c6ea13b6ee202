"""Loops compiled in parts: the parts made side by side, the loop handed their addresses at each call.

numba links every compiled callee into its caller's machine code and optimises it again there, in
one process. A loop of the engine whose costly callee is compiled apart, as an entry point of its
own called at its address (`rotframe.numerics.at_address`), compiles that callee once, shared and
cached on its own, and on a first run in a second process while this one compiles the loop
(`rotframe.numerics.compile_apart`). `made` loads or compiles such a set of kernels; `LoopWithParts`
is the loop behind the engine's call of a variant (`rotframe.problem.engine.advance`), which adds
the parts' addresses to the problem's own. The engine's DOP853 loop (`rotframe.problem.dop853_split`)
and a rigid body's splittings (`rotframe.problem.body_split_step`) are built so.
"""

from __future__ import annotations

__all__ = ["made", "LoopWithParts"]


def made(kernels, module, load_only=False, apart=()) -> bool:
    """Load ``kernels`` (``[(dispatcher, signature), ...]``) from numba's cache, compiling those that are not there;
    False, compiling nothing, where ``load_only`` and one is not.

    A kernel made in this process is not loaded again: a run in the trajectory tier asks whether the whole
    loop is made (`rotframe.problem.tiers.loop_is_compiled`), which would otherwise load the tier's kernels
    from the disk again each time (some 10 ms a run); the kernels are made once a process for that
    (``functools.cache`` where they are built).

    ``apart`` names, for some of them by index, the function of ``module`` that compiles it in another process
    (``{index: (name, its arguments)}``). Where more than one is to compile, those compile in processes of their
    own while this one compiles the rest (`rotframe.numerics.compile_apart`), then load them from the cache. Each
    kernel is then closed to new compiles.
    """
    from contextlib import ExitStack

    from rotframe.numerics.compile_apart import CompiledApart
    from rotframe.numerics.compiled import load_cached

    todo = [k for k, (kernel, sig) in enumerate(kernels)
            if tuple(getattr(sig, "args", sig)) not in kernel.overloads  # made in this process already
            and not load_cached(kernel, sig)]  # else from the cache, under the key numba saved it (the signature)
    if todo and load_only:
        return False
    away = [k for k in todo if k in apart] if len(todo) > 1 else []
    if away and len(away) == len(todo):
        away.pop()  # one compiles here
    with ExitStack() as stack:
        children = {k: stack.enter_context(CompiledApart(module, apart[k][0], *apart[k][1])) for k in away}
        for k in todo:
            if k not in children:
                kernels[k][0].compile(kernels[k][1])
        for k, child in children.items():
            child.load(*kernels[k])
    for kernel, _ in kernels:
        kernel.disable_compile()
    return True


class LoopWithParts:
    """A variant's compiled loop behind the engine's call (`rotframe.problem.engine.advance`): ``loop(lo, hi, T, ...,
    prob, fns, K, Kb, V, F, W)``, which hands the compiled loop ``fns`` with the addresses ``at`` of its parts after
    the problem's five (`rotframe.problem.signatures.FUNCTIONS`). The compiled loop's attributes (``signatures``,
    ``stats``) are its own; ``kernels`` keeps the parts, whose addresses live as long as they do."""

    def __init__(self, loop, at, kernels):
        self.loop = loop
        self.at = tuple(int(a) for a in at)
        self.kernels = kernels

    def __getattr__(self, name):
        return getattr(self.__dict__["loop"], name)

    def __call__(self, lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, rtol,
                 atol, hfix, EDIR, ETERM, S, prob, fns, K, Kb, V, F, W):
        return self.loop(lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, rtol,
                         atol, hfix, EDIR, ETERM, S, prob, tuple(fns) + self.at, K, Kb, V, F, W)

