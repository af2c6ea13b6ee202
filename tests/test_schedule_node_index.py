"""The schedule's node lookup (rotframe.particles.schedule.node_index) against numpy's searchsorted.

node_index replaces np.searchsorted inside the compiled kernels (to spare a first run
compiling numba's generic version); the rate, its derivative and the angle of a
piecewise-linear schedule depend on it choosing exactly the same node, so the check
is exact equality with numpy (an independent implementation), on node times, just
beside them (1 ulp and 1e-12 s), far outside the table and at +-inf.
"""

import numpy as np
import pytest

from rotframe.particles.schedule import node_index


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8, 17])
def test_node_index_is_searchsorted(n):
    rng = np.random.default_rng(n)
    wt = np.sort(rng.choice(np.arange(-5.0, 20.0, 0.5), n, replace=False))
    probes = np.concatenate([wt, np.nextafter(wt, np.inf), np.nextafter(wt, -np.inf), wt + 1e-12, wt - 1e-12,
                             rng.uniform(-10.0, 30.0, 50), [-np.inf, np.inf, -1e300, 1e300]])
    for t in probes:
        for right in (False, True):
            assert node_index(wt, t, right) == np.searchsorted(wt, t, side="right" if right else "left")
