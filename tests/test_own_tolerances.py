"""A particle's default absolute tolerances, made by the engine's DOP853 loop from its start state.

`rotframe.numerics.step_control.own_tolerances` is the rule compiled into the loop (a prepared run made it
in numpy at every run, 6 us of its own 20). Checked against the rule as the docs state it, written
here apart in numpy, and, through the whole engine, against a run given those tolerances by hand:
a run with ``atol=None`` and one with ``atol=`` the rule's six numbers take the same steps, to the bit.
"""

from __future__ import annotations

import numpy as np
import pytest

import rotframe
from rotframe.numerics.step_control import own_tolerances
from rotframe.problem.particles import simulate_particles


def rule(r, v, duration, rtol, D):
    """The rule as `own_tolerances` documents it: s_r = max(|r|_inf, |v|_inf T), s_v = max(|v|_inf, s_r / T);
    a particle at rest at the origin takes 1 and 1 / T; rtol s_r for r, rtol s_v for v, rtol for the rest."""
    ar, av = np.max(np.abs(r)), np.max(np.abs(v))
    sr = max(ar, av * duration)
    sv = max(av, sr / duration)
    if sr == 0.0:
        sr, sv = 1.0, 1.0 / duration
    return np.array([rtol * sr] * 3 + [rtol * sv] * 3 + [rtol] * (D - 6))


def compiled(y, duration, rtol):
    out = np.full(y.shape[0], np.nan)
    own_tolerances(y, duration, rtol, out)
    return out


@pytest.mark.parametrize("D", [6, 10])
def test_the_compiled_rule_is_the_documented_one_to_the_bit(D):
    rng = np.random.default_rng(7)
    cases = [np.zeros(D), np.r_[np.zeros(3), [0.0, -2.0, 0.5], np.zeros(D - 6)],
             np.r_[[3.0, -40.0, 1.0], np.zeros(D - 3)]]
    for _ in range(200):  # positions and velocities of every size, either side of the crossover |r| = |v| T
        y = rng.normal(size=D) * 10.0 ** rng.uniform(-8, 8, size=D)
        cases.append(y)
    for y in cases:
        for duration in (1e-3, 1.0, 3600.0):
            for rtol in (1e-5, 1e-10):
                expected = rule(y[:3], y[3:6], duration, rtol, D)
                np.testing.assert_array_equal(compiled(y, duration, rtol), expected)


def test_an_unset_row_is_filled_and_a_given_one_kept():
    """The loop fills only a row of NaN (the default); tolerances given by the caller pass through untouched."""
    kw = dict(omega=[0.0, 0.0, 0.3], duration=5.0, samples=20, rtol=1e-8,
              forces=[rotframe.forces.spring(2.0)])
    r0, v0 = np.array([4.0, -1.0, 0.5]), np.array([0.0, 3.0, 0.0])
    atol = rule(r0, v0, 5.0, 1e-8, 6)
    default = simulate_particles(r0=r0, v0=v0, **kw).trajectory
    given = simulate_particles(r0=r0, v0=v0, atol=atol, **kw).trajectory
    np.testing.assert_array_equal(default.r, given.r)
    np.testing.assert_array_equal(default.v, given.v)
    assert default.nfev == given.nfev
    looser = simulate_particles(r0=r0, v0=v0, atol=1e3 * atol, **kw).trajectory  # a given atol is what the loop uses
    assert looser.nfev < given.nfev
