"""A run's start states checked and made into the engine's arrays by compiled calls (`rotframe.problem.starts`).

The oracle is the rule each function states, written here in numpy's array calls (as the engine
wrote it before these were compiled): the same decisions, and the same numbers to the bit, on
random ensembles with particles at rest, far away, just on and just off the string's sphere.
"""

from __future__ import annotations

import numpy as np
import pytest

from rotframe.problem.starts import ALONG_STRING, NOT_FINITE, OFF_SPHERE, start_arrays, start_defect


def numpy_scales(r, v, duration, rtol, D):
    """Each particle's absolute tolerances from its own scales (the rule of `start_arrays`), in array calls."""
    ar = np.abs(r).max(axis=1)
    av = np.abs(v).max(axis=1)
    sr = np.maximum(ar, av * duration)
    sv = np.maximum(av, sr / duration)
    still = sr == 0.0
    sr[still], sv[still] = 1.0, 1.0 / duration
    out = np.full((len(r), D), rtol)
    out[:, :3] = (rtol * sr)[:, None]
    out[:, 3:6] = (rtol * sv)[:, None]
    return out


def numpy_defect(r, v, pivot, length):
    """The first refused start (kind, particle) by the rule of `start_defect`, in array calls."""
    if not (np.isfinite(r).all() and np.isfinite(v).all()):
        return NOT_FINITE, -1
    if length == 0.0:
        return 0, -1
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


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("D", [6, 10])
def test_each_particles_tolerances_and_states_are_the_rules_to_the_bit(seed, D):
    rng = np.random.default_rng(seed)
    N = 40
    r = rng.normal(size=(N, 3)) * 10.0 ** rng.integers(-6, 7, size=(N, 1))
    v = rng.normal(size=(N, 3)) * 10.0 ** rng.integers(-6, 7, size=(N, 1))
    r[::7] = 0.0  # at the origin: the velocity sets both scales
    v[::5] = 0.0  # at rest: the position does
    v[::35] = 0.0  # at rest at the origin: 1 and 1 / T
    duration, rtol = float(rng.uniform(0.1, 1e4)), float(10.0 ** rng.uniform(-13, -3))
    y, atol = start_arrays(r, v, D, duration, rtol, np.empty(0))
    expected_y = np.zeros((N, D))
    expected_y[:, :3], expected_y[:, 3:6] = r, v
    assert np.array_equal(y, expected_y)
    assert np.array_equal(atol, numpy_scales(r, v, duration, rtol, D))
    assert np.array_equal(atol[35, :6], [rtol] * 3 + [rtol * (1.0 / duration)] * 3)


def test_given_tolerances_fill_the_first_six_columns_and_rtol_the_rest():
    r, v = np.ones((3, 3)), np.ones((3, 3))
    given = np.array([1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3])
    _, atol = start_arrays(r, v, 10, 5.0, 1e-8, given)
    assert np.array_equal(atol, np.tile(np.concatenate([given, [1e-8] * 4]), (3, 1)))


@pytest.mark.parametrize("seed", range(8))
def test_the_first_refused_start_is_the_rules(seed):
    rng = np.random.default_rng(seed)
    N, L = 30, float(rng.uniform(0.5, 100.0))
    pivot = rng.normal(size=3)
    n = rng.normal(size=(N, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    r = pivot + L * n
    v = rng.normal(size=(N, 3))
    v -= (v * n).sum(axis=1)[:, None] * n  # across the string
    k = int(rng.integers(N))
    case = seed % 4
    out = 3e-9 if seed < 4 else -3e-9  # outside, or inside, the sphere by three times the tolerance
    if case == 1:
        r[k] = pivot + L * (1 + out) * n[k]
    elif case == 2:
        v[k] += 1e-6 * np.linalg.norm(v[k]) * n[k]  # along the string
    elif case == 3:
        v[k, int(rng.integers(3))] = np.nan
    kind, i, value = start_defect(r, v, *pivot, L)
    assert (kind, i if kind != NOT_FINITE else -1) == numpy_defect(r, v, pivot, L)
    assert kind == (0, OFF_SPHERE, ALONG_STRING, NOT_FINITE)[case]
    if kind in (OFF_SPHERE, ALONG_STRING):
        assert i == k
    if kind == OFF_SPHERE:
        assert value == pytest.approx(L * (1 + out), rel=1e-12)
    assert start_defect(r, v, 0.0, 0.0, 0.0, 0.0)[0] == (NOT_FINITE if case == 3 else 0)  # no string: finite alone
