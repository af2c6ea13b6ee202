"""A prepared run's arrays, made once in one block per dtype and reset by one copy each (`ArrayBlocks`).

numpy's cost is per array made, not per number: sixteen small arrays made anew took 5 us of a
prepared particle run's 20, a third of a short body run's time. A prepared run
(`rotframe.problem.prepared.PreparedProblem`, `rotframe.problem.prepared_body.PreparedBody`) keeps its
arrays as views of a few blocks instead, and resets them to their fresh values by copying each block.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ArrayBlocks"]


class ArrayBlocks:
    """The arrays of ``arrays`` (a mapping of name -> array; a value that is itself a mapping is a group of them,
    kept under its name) as views of one block per dtype, fresh at every `reset`.

    ``views`` has the same names and nesting; the views are the same objects at every run, so a caller may bind
    them once (a loop's call with every argument bound).
    """

    def __init__(self, arrays):
        flat = {}
        for name, a in arrays.items():
            if isinstance(a, dict):
                flat.update({(name, k): v for k, v in a.items()})
            else:
                flat[name] = a
        self._blocks, views = [], {}
        for kind in dict.fromkeys(a.dtype for a in flat.values()):  # one block a dtype, in the arrays' order
            group = {k: a for k, a in flat.items() if a.dtype == kind}
            block = np.concatenate([a.ravel() for a in group.values()])
            self._blocks.append((block, block.copy()))
            at = 0
            for k, a in group.items():
                views[k] = block[at:at + a.size].reshape(a.shape)
                at += a.size
        #: the arrays by their names (a group as a dict), views of the blocks
        self.views = {}
        for k, v in views.items():
            if isinstance(k, tuple):
                self.views.setdefault(k[0], {})[k[1]] = v
            else:
                self.views[k] = v

    def reset(self):
        """Every array back to its value when made; returns `views`."""
        for block, fresh in self._blocks:
            block[:] = fresh
        return self.views
