"""One call of a compiled particle driver over many particles, on every core.

The drivers (`rotframe.particles.drivers`) integrate each particle on its
own: a particle's result depends on its own initial state and the call's
arguments (times, step, tolerances, event table), never on the others. So a
call over N particles can be cut into blocks of at most
`rotframe.particles.threads.BLOCK` particles, each block run by the same
driver on a thread of a pool (the drivers release the GIL), and the result is
bitwise that of one call, for any number of threads and any cut. The cut
(`block_bounds`) gives each thread the same number of particles. Each block
has contiguous arrays of its own (copies in and out), so the driver sees the
array types of a single call and compiles nothing more.

The count of threads is [`rotframe.particles.threads.resolve_threads`][rotframe.particles.threads.resolve_threads]
(the ``--threads`` option, ``rotframe.run(..., threads=N)``, else every core).
"""

from __future__ import annotations

import math
import threading

import numpy as np

__all__ = ["block_bounds", "run_blocks", "thread_pool"]

#: thread pools by size, made on first use and kept (a pool per call would cost ~100 us)
_POOLS: dict = {}


def block_bounds(n, workers=1):
    """``[(lo, hi), ...]``: the blocks of ``n`` particles for ``workers`` threads (one block when ``n <= BLOCK``).

    On one thread, blocks of `rotframe.particles.threads.BLOCK`. On more, at least as many
    blocks, their count a multiple of ``workers`` and their sizes within one particle of each
    other, so that every thread gets the same work: 10,000 particles on 2 threads are four
    blocks of 2,500, not 4,096 + 4,096 + 1,808 (one thread doing 59 % of the work). Each
    particle is integrated alone, so the cut changes no number (``tests/test_ensemble_parallel.py``).
    """
    from rotframe.particles import threads

    size = int(threads.BLOCK)
    if n <= size or workers <= 1:
        return [(lo, min(n, lo + size)) for lo in range(0, n, size)] or [(0, 0)]
    count = -(-n // size)
    count = -(-count // workers) * workers
    return [(k * n // count, (k + 1) * n // count) for k in range(count)]


_LOCAL = threading.local()
#: largest scratch array (bytes) a thread keeps between calls
_KEEP_BYTES = 8 << 20


def _scratch(i, shape):
    """An uninitialised float array of ``shape``: the calling thread's ``i``-th, reused when small."""
    if 8 * math.prod(shape) > _KEEP_BYTES:
        return np.empty(shape)
    kept = getattr(_LOCAL, "arrays", None)
    if kept is None:
        kept = _LOCAL.arrays = {}
    a = kept.get((i, shape))
    if a is None:
        if len(kept) >= 8:
            kept.clear()
        a = kept[(i, shape)] = np.empty(shape)
    return a


def thread_pool(workers):
    """The kept pool of ``workers`` threads (made on first use)."""
    pool = _POOLS.get(workers)
    if pool is None:
        from concurrent.futures import ThreadPoolExecutor

        pool = _POOLS[workers] = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="rotframe-block")
    return pool


def run_blocks(one, n, per_particle, per_sample, scalars=(), most=False):
    """Run ``one(*block_arrays)`` on every block of ``n`` particles, on the thread pool; merged results.

    Parameters
    ----------
    one : callable
        ``one(*arrays)`` runs the driver on one block and returns ``(n_done, bad, nfev, steps)``.
    n : int
        Particles.
    per_particle : sequence of arrays or None
        Arrays whose first axis is the particle (``r``, ``v``, ``alive``, event records,
        ``h_state``); each block gets a contiguous copy, written back after the run.
        None stays None.
    per_sample : sequence of arrays
        Arrays (K, N, ...) whose second axis is the particle (the output samples);
        each block gets contiguous copies, written back.
    scalars : sequence
        Passed after the arrays unchanged.
    most : bool
        Whether each block reports the most any of its particles took (the cost returned is then the most over
        the blocks), not its first particle's.

    Returns
    -------
    (n_done, bad, nfev, steps)
        The fewest samples done over the blocks, the first bad particle (an index into
        the whole call) or -1, and the cost of particle 0 (block 0's), or with ``most`` the most of any.
    """
    from rotframe.particles import threads

    if n <= threads.BLOCK:  # one block: the driver itself (before counting threads: a short run's overhead)
        return one(*per_particle, *per_sample, *scalars)
    workers = threads.resolve_threads(None)
    bounds = block_bounds(n, workers)

    def block(b):
        lo, hi = b
        # a block of a C-contiguous array is one already (its view is passed, nothing copied);
        # only a strided one (samples of several times) is copied in and back
        views = [None if a is None else a[lo:hi] for a in per_particle]
        mine = [None if a is None else np.ascontiguousarray(a) for a in views]
        out_views = [a[:, lo:hi] for a in per_sample]
        # the drivers only write the samples: a strided block gets a scratch array of its thread's
        # (kept between calls, so that its pages are not faulted in again), copied out after the run
        outs = [a if a.flags.c_contiguous else _scratch(i, a.shape) for i, a in enumerate(out_views)]
        res = one(*mine, *outs, *scalars)
        for a, m in zip(views, mine):
            if a is not None and m is not a:
                a[...] = m
        for a, m in zip(out_views, outs):
            if m is not a:
                a[...] = m
        return res

    workers = min(workers, len(bounds))
    if workers == 1:
        results = [block(b) for b in bounds]
    else:
        results = list(thread_pool(workers).map(block, bounds))  # block order; the first failure is raised
    n_done = min(r[0] for r in results)
    bad = -1
    for (lo, _), r in zip(bounds, results):
        if r[1] >= 0:
            bad = lo + int(r[1])
            break
    if most:
        return n_done, bad, max(r[2] for r in results), max(r[3] for r in results)
    return n_done, bad, results[0][2], results[0][3]
