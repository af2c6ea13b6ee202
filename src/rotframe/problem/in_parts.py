"""Loops compiled in parts: the parts made side by side, the loop handed their addresses at each call.

numba links every compiled callee into its caller's machine code and optimises it again there, in
one process. A loop of the engine whose costly callee is compiled apart, as an entry point of its
own called at its address (`rotframe.numerics.at_address`), compiles that callee once, shared and
cached on its own, and on a first run in a second process while this one compiles the loop
(`rotframe.numerics.compile_apart.made` loads or compiles such a set of kernels). `LoopWithParts`
is the loop behind the engine's call of a variant (`rotframe.problem.engine.advance`), which adds
the parts' addresses to the problem's own. The engine's DOP853 loop (`rotframe.problem.dop853_split`)
and a rigid body's splittings (`rotframe.problem.body_split_step`) are built so.
"""

from __future__ import annotations

__all__ = ["LoopWithParts"]


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

