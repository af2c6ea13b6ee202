"""The prepared exact flow's call, compiled: every sample's state from the kept matrices in one loop.

[`rotframe.particles.prepared.PreparedRun`][rotframe.particles.prepared.PreparedRun] with method ``exact`` keeps the
flow's matrices ``phi_t`` (K, 7, 6), ``phi_t[k, i, j] = Phi_k[j, i]``
(`rotframe.particles.linear.ExactFlow`). Each call multiplies them into the
initial states ``s0 = (r0, v0, 1)``; numpy spent most of a call's few microseconds
on the calls around one tiny product, so the product and the finiteness check are
one compiled loop. (``integrate_particles`` stays numpy: a first exact run compiles
nothing.)
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.numerics.compiled import jit_kernel

__all__ = ["apply_flow"]


@jit_kernel
def apply_flow(phi_t, r0, v0):
    """(r, v, k_bad): ``r[k, p] = (Phi_k s0_p)[0:3]``, ``v`` the next three, ``s0_p = (r0[p], v0[p], 1)``.

    ``r0``, ``v0`` (n, 3). ``k_bad`` is the first sample with a non-finite state, -1 if none.
    """
    K = phi_t.shape[0]
    n = r0.shape[0]
    r = np.empty((K, n, 3))
    v = np.empty((K, n, 3))
    k_bad = -1
    for k in range(K):
        for p in range(n):
            for j in range(6):
                acc = phi_t[k, 6, j]
                for i in range(3):
                    acc += r0[p, i] * phi_t[k, i, j]
                for i in range(3):
                    acc += v0[p, i] * phi_t[k, 3 + i, j]
                if j < 3:
                    r[k, p, j] = acc
                else:
                    v[k, p, j - 3] = acc
                if k_bad < 0 and not math.isfinite(acc):
                    k_bad = k
    return r, v, k_bad
