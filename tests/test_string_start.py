"""The compiled check that a pendulum's particles start on its string's sphere (`rotframe.problem.string_start`).

The oracle is the rule the function states, written here in numpy's array calls (as the engine
wrote it before the check was compiled): the same first refused particle, on random ensembles
with one particle just outside, just inside the sphere, or moving along the string.
"""

from __future__ import annotations

import numpy as np
import pytest

from rotframe.problem.string_start import ALONG_STRING, OFF_SPHERE, string_defect


def numpy_defect(r, v, pivot, length):
    """The first refused start (kind, particle) by the rule of `string_defect`, in array calls."""
    rel = r - pivot
    d = np.sqrt((rel * rel).sum(axis=1))
    bad = np.abs(d - length) > 1e-9 * length
    if bad.any():
        return OFF_SPHERE, int(bad.argmax())
    radial = np.abs((v * (rel / length)).sum(axis=1))
    bad = radial > 1e-9 * np.maximum(np.sqrt((v * v).sum(axis=1)), 1e-300)
    if bad.any():
        return ALONG_STRING, int(bad.argmax())
    return 0, -1


@pytest.mark.parametrize("seed", range(9))
def test_the_first_refused_start_is_the_rules(seed):
    rng = np.random.default_rng(seed)
    N, L = 30, float(rng.uniform(0.5, 100.0))
    pivot = rng.normal(size=3)
    n = rng.normal(size=(N, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    r = pivot + L * n
    v = rng.normal(size=(N, 3))
    v -= (v * n).sum(axis=1)[:, None] * n  # across the string
    v[::4] = 0.0  # at rest
    k = int(rng.integers(N))
    case = seed % 3
    out = 3e-9 if seed < 5 else -3e-9  # outside, or inside, the sphere by three times the tolerance
    if case == 1:
        r[k] = pivot + L * (1 + out) * n[k]
    elif case == 2:
        v[k] += (1e-6 if seed < 5 else -1e-6) * max(np.linalg.norm(v[k]), 1.0) * n[k]  # along the string, out or in
    kind, i, value = string_defect(r, v, *pivot, L)
    assert (kind, i) == numpy_defect(r, v, pivot, L)
    assert kind == (0, OFF_SPHERE, ALONG_STRING)[case]
    if kind:
        assert i == k
    if kind == OFF_SPHERE:
        assert value == pytest.approx(L * (1 + out), rel=1e-12)
    if kind == ALONG_STRING:
        assert value == pytest.approx(abs(v[k] @ n[k]), rel=1e-6)
