"""The driver cache never reuses a driver after a value it froze has changed (issue 33, class 1).

numba freezes every global, closure value and default a compiled function reads. A driver is
cached under the fingerprint of the user's functions, so every value they read must be hashed by
value: numpy scalars, module attributes (``cfg.K``), Enum members. A value that cannot be hashed
gives a driver for that run alone. The end-to-end tests compare with the closed form of a
harmonic oscillator, x(t) = cos(sqrt(k) t), which does not share code with the driver.
"""

from __future__ import annotations

import enum
import types

import numpy as np
import pytest

import rotframe
from rotframe.problem.callables import Unfingerprintable, cache_key, fingerprint

cfg = types.ModuleType("rotframe_test_cfg")
cfg.K = 1.0
cfg.inner = types.ModuleType("rotframe_test_cfg_inner")
cfg.inner.K = 1.0
K32 = np.float32(1.0)


def spring_global(t, r, v):
    return -K32 * r[0], 0.0, 0.0


def spring_module(t, r, v):
    return -cfg.K * r[0], 0.0, 0.0


def spring_nested_module(t, r, v):
    return -cfg.inner.K * r[0], 0.0, 0.0


def spring_closure(k):
    def spring(t, r, v):
        return -k * r[0], 0.0, 0.0

    return spring


def spring_default_factory(k):
    def spring(t, r, v, k=k):
        return -k * r[0], 0.0, 0.0

    return spring


class Stiffness(enum.Enum):
    SOFT = 1.0


def spring_enum(t, r, v):
    return -Stiffness.SOFT.value * r[0], 0.0, 0.0


@pytest.mark.parametrize("make", [lambda k: spring_closure(np.int64(k)), lambda k: spring_closure(np.float32(k)),
                                  lambda k: spring_default_factory(np.int64(k)),
                                  lambda k: spring_closure(np.array([k], dtype=np.int32))],
                         ids=["closure int64", "closure float32", "default int64", "closure int32 array"])
def test_fingerprint_hashes_numpy_values_by_value(make):
    assert fingerprint(make(1)) != fingerprint(make(4))
    assert fingerprint(make(4)) == fingerprint(make(4))


def test_fingerprint_hashes_module_attributes_and_globals_by_value(monkeypatch):
    before = [fingerprint(f) for f in (spring_global, spring_module, spring_nested_module, spring_enum)]
    monkeypatch.setattr(cfg, "K", 4.0)
    monkeypatch.setattr(cfg.inner, "K", 4.0)
    monkeypatch.setitem(globals(), "K32", np.float32(4.0))
    after = [fingerprint(f) for f in (spring_global, spring_module, spring_nested_module, spring_enum)]
    assert [a != b for a, b in zip(before, after)] == [True, True, True, False]


def test_fingerprint_refuses_what_it_cannot_hash_never_skips():
    holder = types.SimpleNamespace(K=1.0)

    def reads_object(t, r, v):
        return -holder.K * r[0], 0.0, 0.0

    with pytest.raises(Unfingerprintable, match="SimpleNamespace"):
        fingerprint(reads_object)
    key, note = cache_key([("forces[0]", reads_object)], "|x")
    assert key is None and "forces[0]" in note and "not cached" in note


def _end(force, k):
    res = rotframe.simulate(omega=[0, 0, 0], r0=[1, 0, 0], v0=[0, 0, 0], duration=1.0, forces=[force], samples=2,
                            rtol=1e-12)
    x = float(res.trajectory.r[-1, 0, 0])
    assert x == pytest.approx(np.cos(np.sqrt(k)), abs=1e-9), f"stale driver: k = {k}"
    return res


def test_a_changed_module_attribute_or_numpy_global_gives_a_new_answer(monkeypatch):
    monkeypatch.setattr(cfg, "K", 1.0)
    _end(spring_module, 1.0)
    monkeypatch.setattr(cfg, "K", 4.0)
    _end(spring_module, 4.0)
    monkeypatch.setitem(globals(), "K32", np.float32(1.0))
    _end(spring_global, 1.0)
    monkeypatch.setitem(globals(), "K32", np.float32(4.0))
    _end(spring_global, 4.0)


def test_closures_over_numpy_scalars_in_a_loop_each_get_their_own_answer():
    for k in np.arange(1, 5, 3):  # np.int64 1 then 4, as a notebook loop makes them
        _end(spring_closure(k), float(k))


def test_a_function_reading_an_unhashable_value_runs_uncached_and_says_so():
    import numba

    @numba.vectorize  # a DUFunc: numba calls it, rotframe cannot fingerprint it
    def stiffness(x):
        return 4.0 * x

    def spring(t, r, v):
        return -stiffness(r[0]), 0.0, 0.0

    res = _end(spring, 4.0)
    assert any("not cached" in n and "forces[0]" in n for n in res.notes)


def test_a_torque_reading_a_changed_module_attribute_gives_a_new_answer(monkeypatch):
    def torque(t, L, q):
        return 0.0, 0.0, cfg.K

    for k in (1.0, 3.0):
        monkeypatch.setattr(cfg, "K", k)
        res = rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[0.0, 0.0, 1.0], q0=[0, 0, 0, 1], duration=2.0,
                                     torque=torque, samples=2)
        assert float(res.trajectory.L[-1, 2]) == pytest.approx(1.0 + 2.0 * k, rel=1e-9)
