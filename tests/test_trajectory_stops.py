"""DOP853's trajectory through a run's stops (`rotframe.numerics.dop853_loop`, ``stops``): one call takes the steps,
samples, right-hand sides and step sizes of the calls from stop to stop that the engine made before (each call's end a
stop, `rotframe.numerics.stops.next_stop`), to the bit.

Both run as plain Python (`rotframe.numerics.plain`: the loop's own code, nothing compiled) on a forced oscillator
whose forcing jumps at every stop, with a first step far too long, so that steps are rejected, cut on stops and ended
within ulps of them; and with a step budget that pauses the one call and the calls alike.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from rotframe.numerics.compiled import jit_inline, jit_uncounted
from rotframe.numerics.dop853_loop import PAUSED, REACHED, dop853_stages, dop853_trajectory
from rotframe.numerics.plain import plain
from rotframe.numerics.stops import next_stop
from rotframe.problem.dop853_variant import store_rows


@jit_uncounted
def _forced(ctx, t, z, K, s):
    """x'' = -k x + a floor(t / T): a forcing that jumps at every multiple of T (``ctx = (k, a, T, ...)``)."""
    K[s, 0] = z[1]
    K[s, 1] = -ctx[0] * z[0] + ctx[1] * math.floor(t / ctx[2])


@jit_inline
def _constants(ctx):
    return ctx[0], ctx[1], ctx[2]


@jit_inline
def _stops(ctx):
    return ctx[3]


_STAGES = dop853_stages("stops_test", _forced, 2)
_LEG = plain(dop853_trajectory("stops_test_legs", _STAGES, store_rows, 2, enter=_constants))
_THROUGH = plain(dop853_trajectory("stops_test_through", _STAGES, store_rows, 2, enter=_constants, stops=_stops))


def _arrays(times):
    K = np.zeros((16, 2))
    return dict(y=np.array([1.0, 0.0]), out=np.full((times.size, 1, 2), np.nan), K=K, y_new=np.zeros(2),
                tmp=np.zeros(2), yt=np.zeros(2), F=np.zeros((7, 2)))


_CONSTANTS = (3.0, 0.7, 0.37)
#: every jump of the forcing before the end
_S = np.arange(1, 27) * _CONSTANTS[2]


def _legs(t, times, h, budget):
    """The engine's loop before: a call to each stop, within the budget; a call ended within ulps of a stop leaves
    the samples on it to the next call."""
    a = _arrays(times)
    _forced.py_func(_CONSTANTS, t, a["y"], a["K"], 0)
    k, nf, steps, calls = 0, 0, 0, 0
    while k < times.size and steps < budget:
        stop = next_stop(_S, t)
        t, h, k, status, n, s = _LEG(_CONSTANTS, t, a["y"], h, min(stop, times[-1]), math.inf, times, k, a["out"],
                                     0, RTOL, ATOL, a["K"], a["y_new"], a["tmp"], a["yt"], a["F"], 0, budget - steps)
        nf, steps, calls = nf + n, steps + s, calls + 1
        if status != REACHED:
            break
    return a, (t, h, k, steps, nf), calls


def _through(t, times, h, budget):
    """The same with the stops in the trajectory: once, and once more where the end was reached within ulps."""
    a = _arrays(times)
    _forced.py_func(_CONSTANTS, t, a["y"], a["K"], 0)
    k, nf, steps, status = 0, 0, 0, REACHED
    while k < times.size and steps < budget:
        t, h, k, status, n, s = _THROUGH(_CONSTANTS + (_S,), t, a["y"], h, times[-1], math.inf, times, k, a["out"], 0,
                                         RTOL, ATOL, a["K"], a["y_new"], a["tmp"], a["yt"], a["F"], 0, budget - steps)
        nf, steps = nf + n, steps + s
        if status != REACHED:
            break
    return a, (t, h, k, steps, nf), status


RTOL, ATOL = 1e-9, np.full(2, 1e-12)


@pytest.mark.parametrize("budget", [10**9, 150])
def test_one_call_through_the_stops_takes_the_steps_of_a_call_to_each_stop(budget):
    times = np.linspace(0.0, 10.0, 41)
    h0 = 5.0  # far too long: rejected at first, then cut on each stop
    legs, end, calls = _legs(0.0, times, h0, budget)
    through, end_through, status = _through(0.0, times, h0, budget)
    assert calls > 5  # the calls reached several stops before the budget ran out, or all of them
    assert end_through == end
    np.testing.assert_array_equal(through["out"], legs["out"])
    np.testing.assert_array_equal(through["y"], legs["y"])
    assert status == (PAUSED if budget < 10**9 else REACHED)


def test_a_step_that_ends_within_ulps_of_a_stop_stores_the_samples_on_it():
    """A start 3 ulps short of a stop: the first step has collapsed into the stop (its end is reached, not a step
    taken), and the sample on the stop is stored there, as the next call from the stop stored it."""
    stop = _S[2]
    t0 = stop - 3 * (math.nextafter(stop, math.inf) - stop)
    times = np.array([t0, stop, stop + 0.2, stop + 1.0])
    legs, end, calls = _legs(t0, times, 0.1, 10**9)
    through, end_through, _ = _through(t0, times, 0.1, 10**9)
    assert calls >= 3 and np.all(np.isfinite(legs["out"]))
    assert end_through == end
    np.testing.assert_array_equal(through["out"], legs["out"])
