"""The schedule's node lookup (rotframe.particles.schedule) against numpy and the schedule's definition.

node_index replaces np.searchsorted inside the compiled kernels (to spare a first run
compiling numba's generic version), and omega_rate derives searchsorted's side="right"
from it; the rate, its derivative and the angle of a piecewise-linear schedule depend on
choosing exactly the same node, so the checks are exact: equality with numpy's
searchsorted (an independent implementation) on node times, 1 ulp and 1e-12 s beside
them, far outside the table and at +-inf; and the rate at and just before each node is
the slope of the segment that starts there, or that ends there (the definition, w'
taken from the right).
"""

import numpy as np
import pytest

from rotframe.particles.schedule import node_index, omega_rate


def _table(n):
    rng = np.random.default_rng(n)
    wt = np.sort(rng.choice(np.arange(-5.0, 20.0, 0.5), n, replace=False))
    return wt, rng


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8, 17])
def test_node_index_is_searchsorted(n):
    wt, rng = _table(n)
    probes = np.concatenate([wt, np.nextafter(wt, np.inf), np.nextafter(wt, -np.inf), wt + 1e-12, wt - 1e-12,
                             rng.uniform(-10.0, 30.0, 50), [-np.inf, np.inf, -1e300, 1e300]])
    for t in probes:
        assert node_index(wt, t) == np.searchsorted(wt, t)


@pytest.mark.parametrize("n", [2, 3, 5, 8, 17])
def test_rate_at_a_node_is_the_slope_after_it(n):
    wt, rng = _table(n)
    wv = rng.uniform(-1.0, 1.0, n)
    slope = np.diff(wv) / np.diff(wt)
    for k in range(n - 1):
        assert omega_rate(wt[k], wt, wv) == slope[k]
        assert omega_rate(np.nextafter(wt[k + 1], -np.inf), wt, wv) == slope[k]
    assert omega_rate(wt[-1], wt, wv) == 0.0 and omega_rate(np.nextafter(wt[0], -np.inf), wt, wv) == 0.0
