"""The per-particle wrapper of the one DOP853 loop, and its sample writer: light to import.

`run_particles` runs `rotframe.numerics.dop853_loop`'s trajectory for each particle of an
ensemble; the particle's right-hand side and events live in `rotframe.particles.dop853_particles`,
the engine's steady problems' in `rotframe.particles.dop853_steady` (which imports only this module,
so that a steady run imports neither scipy nor the general force).

Work arrays (`WORK_ROWS`, 6): rows 0..15 the stages ``K``, 16 ``y``, 17 ``y_new``, 18 and 19
scratch states, 20..26 the interpolant's coefficients (the absolute tolerances are the caller's rows).
"""

from __future__ import annotations

import math

from rotframe.numerics.compiled import jit_inline, jit_llvm_inline
from rotframe.numerics.dop853_loop import REACHED, STOPPED, UNLIMITED, dop853_start

__all__ = ["run_particles", "store_sample", "WORK_ROWS"]

#: rows of the (WORK_ROWS, 6) work array of `run_particles`
WORK_ROWS = 27


@jit_llvm_inline
def store_sample(out, k, p, y):
    """Sample ``k`` of particle ``p``: ``y`` (6,) into ``out = (out_r, out_v)``, each (n, N, 3)."""
    out_r, out_v = out
    for i in range(3):
        out_r[k, p, i] = y[i]
        out_v[k, p, i] = y[3 + i]


@jit_inline
def run_particles(rhs, trajectory, start, ctx, r, v, alive, t0, times, rtol, atol, span, out_r, out_v, h_state, work,
                  wctx, most=False):
    """Each particle of ``r, v`` (N, 3) from ``t0`` over the sample ``times``, by `dop853_trajectory`.

    ``h_state`` (N,) each particle's next step (0: Hairer's starting step, at most ``span``, the
    whole run's length, the same in every call; a call still ends with a step cut to land on its last
    sample, so the steps depend on where the calls end: `rotframe.particles.chunked.RunNeedsCuts`);
    ``alive`` (N,) whether it moves (None: all do; a terminal event clears it); ``rhs`` and
    ``trajectory`` the system's (`particle_trajectory`, or `particle_trajectory_events` with the
    events' data ``wctx``, None for none), and ``start(wctx, ctx, t, y)`` the events' values at
    each particle's start (`rotframe.particles.dop853_particles.start_events`; None for none). ``r, v`` receive the
    states at the end, ``out_r, out_v`` (n, N, 3) the samples: a particle that stopped or failed
    keeps its last state in the rest. ``atol`` (N, 6) each particle's absolute tolerances (r then v:
    `rotframe.particles.chunked.KernelSetup.abs_tol`). Returns ``(n_done, bad, nfev, steps)``: samples completed
    by every particle, the first particle that failed (or -1), and particle 0's cost (the scenes' cost of one
    trajectory), or with ``most`` the most any particle took (the engine's count: `rotframe.problem.particles`).

    Inlined into each driver (numba IR), so that ``rhs`` and ``trajectory`` are the driver's globals:
    a function passed on from an argument is compiled as a dynamic address, which numba cannot cache.
    """
    K = work[0:16]
    y = work[16]
    y_new = work[17]
    tmp = work[18]
    yt = work[19]
    F = work[20:27]
    n_out = times.shape[0]
    t_end = times[n_out - 1]
    n_done = n_out
    bad = -1
    nfev0 = 0
    steps0 = 0
    for p in range(r.shape[0]):
        for i in range(3):
            y[i] = r[p, i]
            y[3 + i] = v[p, i]
        atol_vec = atol[p]
        t = t0
        h = h_state[p]
        rhs(ctx, t, y, K, 0)
        nf = 1
        if h <= 0.0:  # Hairer's starting step, one more evaluation at its trial step
            h = dop853_start(rhs, ctx, t, y, K, yt, rtol, atol_vec, span)
            nf += 1
        if start is not None:
            start(wctx, ctx, t, y)
        k_out = 0
        steps = 0
        if alive is None or alive[p]:
            t, h, k_out, status, n_steps_f, steps = trajectory(ctx, t, y, h, t_end, math.inf, times, 0, (out_r, out_v),
                                                               p, rtol, atol_vec, K, y_new, tmp, yt, F, wctx,
                                                               UNLIMITED)
            nf += n_steps_f
            if status == STOPPED:
                if alive is not None:
                    alive[p] = False
            elif status != REACHED:  # the step size collapsed, or the state is not finite
                bad = p if bad < 0 else bad
                n_done = k_out if k_out < n_done else n_done
        while k_out < n_out:
            store_sample((out_r, out_v), k_out, p, y)
            k_out += 1
        for i in range(3):
            r[p, i] = y[i]
            v[p, i] = y[3 + i]
        h_state[p] = h
        if p == 0 or (most and nf > nfev0):
            nfev0 = nf
        if p == 0 or (most and steps > steps0):
            steps0 = steps
    return n_done, bad, nfev0, steps0
