"""The error a body frame's interpolation between its samples makes, estimated and flagged.

A rigid-body solution used as a frame (``omega=result``) is known at its samples only; between
them omega is a Hermite interpolant (`rotframe.problem.frame`), of order 6 in the sample
interval for a free body and 4 where the body had a torque. Its error is the user's to control
(the body run's samples), so it is estimated on every such run and flagged when it exceeds rtol.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.problem.frame import stop_times

__all__ = ["frame_interpolation"]


def frame_interpolation(advance, frame, origin, y0, times, after, OUT, duration, rtol, diagnostics, warnings,
                        notes, problem_in):
    """Estimate the error a body frame's interpolation between its samples makes, and warn where it exceeds rtol.

    The first particle is integrated again in the frame made of every other sample
    (`rotframe.problem.frame.FrameSpec.coarsened`), with the same method and tolerances; the
    step stops at the knots keep the integrator's own error far below the interpolant's, so the
    difference is the interpolation's, of order ``frame.order`` in the sample interval h:
    ``error(h) ~ |r(h) - r(2h)| / (2^p - 1)`` (Richardson). Reported relative to the largest |r|
    as ``frame_interpolation_rel_error``. ``advance`` is the engine's (`rotframe.problem.engine`),
    ``after`` the run's arguments after the budget, ``problem_in(spec)`` the run's problem tuple in
    the frame ``spec``.
    """
    coarse = frame.coarsened()
    if coarse is None:
        return
    D = y0.shape[1]
    n = times.size
    Y = y0.copy()
    OUT2 = np.full((n, 1, D), np.nan)
    st = {k: np.zeros(1, np.int64) for k in ("IDX", "SUB", "ST", "EVN", "NSTEP", "NFEV")}
    TC, H = np.zeros(1), np.zeros(1)
    EVT, EVY, EVK = np.zeros((1, 1)), np.zeros((1, 1, D)), np.zeros((1, 1), np.int64)
    GPREV = np.zeros((1, 1))
    method, _, atol, hfix, _, _, _, _, fns = after
    no_events = (np.zeros(0), np.zeros(0, dtype=bool))
    coarse_after = (method, rtol, np.ascontiguousarray(atol[:1]), hfix, *no_events, stop_times((coarse, origin), duration),
                    problem_in(coarse), fns)
    while st["ST"][0] == 0:
        advance(0, 1, times, Y, TC, H, st["IDX"], st["SUB"], st["ST"], OUT2, EVT, EVY, EVK, st["EVN"], GPREV,
                       st["NSTEP"], st["NFEV"], 20000, *coarse_after)
    fine, rough = OUT[:, 0, :3], OUT2[:, 0, :3]
    both = np.all(np.isfinite(fine), axis=1) & np.all(np.isfinite(rough), axis=1)
    if not np.any(both) or st["ST"][0] >= 3:
        notes.append("the body frame's interpolation error could not be estimated (the run in the frame at half "
                     "its samples did not finish)")
        return
    scale = float(np.max(np.abs(fine[both]))) or 1.0
    estimate = float(np.max(np.abs(fine[both] - rough[both]))) / (2.0 ** frame.order - 1.0) / scale
    diagnostics["frame_interpolation_rel_error"] = estimate
    notes.append("frame_interpolation_rel_error: the error the body frame's interpolation between its samples "
                 f"makes in r, relative to max |r|, estimated from a run in the frame at half its samples (order "
                 f"{frame.order} in the sample interval)")
    if estimate > rtol:
        more = 2 ** max(1, math.ceil(math.log2((estimate / rtol) ** (1.0 / frame.order))))
        warnings.append(f"the body frame's samples limit the accuracy: its interpolation error is about "
                        f"{estimate:.1e} of max |r|, above rtol = {rtol:.1e}; run the body with about {more}x "
                        "more samples")
