"""A flip that lands on a sample is a flip (issue 33, class 16).

By symmetry a run of a whole or half number of omega periods puts flips exactly on samples
(omega_mid = 0 there). Oracle: the closed-form period of the free body (the scene's own theory is
checked against an independent Jacobi-elliptic period elsewhere) and a sine's zeros.
"""

import numpy as np
import pytest

import rotframe
from rotframe.scenes.dzhanibekov import flip_times


def test_zeros_on_samples_and_at_the_ends_are_crossings():
    t = np.linspace(0.0, 2.0, 9)  # sin(pi t) is 0 at t = 0, 1, 2: samples 0, 4 and 8
    w = np.sin(np.pi * t)
    w[[0, 4, 8]] = 0.0
    np.testing.assert_allclose(flip_times(t, w), [0.0, 1.0, 2.0])
    # a plain crossing between samples keeps its linear interpolation
    np.testing.assert_allclose(flip_times(np.array([0.0, 1.0]), np.array([1.0, -3.0])), [0.25])
    assert flip_times(t, np.ones_like(t)).size == 0 and flip_times(t, np.zeros_like(t)).size == 0


@pytest.mark.parametrize("periods", [4.5, 4.0])
def test_a_run_of_whole_and_half_periods_counts_every_flip(periods):
    base = rotframe.run("dzhanibekov", i1=4, i2=3, i3=1.5, omega=[1e-5, 1.5, 0])
    period = base.diagnostics["omega_period_s"]
    res = rotframe.run("dzhanibekov", i1=4, i2=3, i3=1.5, omega=[1e-5, 1.5, 0], duration=periods * period)
    assert res.diagnostics["flips"] == int(2 * periods)  # two flips a period, the first at a quarter period
    assert res.metrics["flip_interval_s"] == pytest.approx(period / 2, rel=1e-6)
    assert not res.warnings
