"""`rotframe.particles.trajectory.per_particle`: event records cut into one array per particle.

The oracle is numpy's own ``np.split`` at the cumulative counts, which every caller used before.
"""

import pickle

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from rotframe.particles.trajectory import per_particle


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 3), min_size=1, max_size=40), st.sampled_from([(), (6,)]))
def test_the_cut_is_numpys_split_at_the_cumulative_counts(counts, tail):
    counts = np.array(counts)
    records = np.random.default_rng(len(counts)).random((int(counts.sum()), *tail))
    mine = per_particle(records, counts)
    theirs = np.split(records, np.cumsum(counts)[:-1])
    assert len(mine) == len(theirs) == len(counts)
    for a, b, k in zip(mine, theirs, counts):
        assert a.shape == b.shape == (k, *tail)
        assert np.array_equal(a, b)


def test_each_particles_records_are_views_made_when_asked_for():
    records = np.arange(4.0)
    pieces = per_particle(records, np.array([0, 2, 0, 2, 0]))
    assert [p.tolist() for p in pieces] == [[], [0.0, 1.0], [], [2.0, 3.0], []]
    assert all(p.base is records for p in pieces)  # views of the records, as np.split's were
    assert pieces[-2].tolist() == [2.0, 3.0] and [p.tolist() for p in pieces[1:4]] == [[0.0, 1.0], [], [2.0, 3.0]]
    with pytest.raises(IndexError):
        pieces[5]
    assert pickle.loads(pickle.dumps(pieces))[3].tolist() == [2.0, 3.0]  # a sweep's worker sends them back


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 3), min_size=1, max_size=40))
def test_the_first_records_are_each_particles_first(counts):
    counts = np.array(counts)
    records = np.random.default_rng(len(counts)).random((int(counts.sum()), 6))
    hit, first = per_particle(records, counts).firsts()
    theirs = np.split(records, np.cumsum(counts)[:-1])
    assert hit.tolist() == [len(x) > 0 for x in theirs]
    assert np.array_equal(first, np.array([x[0] for x in theirs if len(x)]).reshape(-1, 6))


def test_a_trajectorys_first_events_are_the_same_from_lists_and_from_records():
    from rotframe.particles.trajectory import Trajectory

    rng = np.random.default_rng(3)
    counts = np.array([0, 2, 1, 0, 3])
    t_rec, y_rec = np.sort(rng.random(6)), rng.random((6, 6))
    r, v = rng.random((4, 5, 3)), rng.random((4, 5, 3))
    lazy = Trajectory(np.arange(4.0), r, v, "rk4", event_times={"x": per_particle(t_rec, counts)},
                      event_states={"x": per_particle(y_rec, counts)})
    lists = Trajectory(np.arange(4.0), r, v, "rk4", event_times={"x": list(per_particle(t_rec, counts))},
                       event_states={"x": list(per_particle(y_rec, counts))})
    for traj in (lazy, lists):
        t, state = traj.first_events("x")
        assert np.array_equal(t, [np.nan, t_rec[0], t_rec[2], np.nan, t_rec[3]], equal_nan=True)
        assert np.array_equal(state[[1, 2, 4]], y_rec[[0, 2, 3]])
        assert np.array_equal(state[[0, 3]], np.concatenate([r[-1], v[-1]], axis=1)[[0, 3]])  # none: the last sample
    t, state = lazy.first_events("never")
    assert np.all(np.isnan(t)) and np.array_equal(state, np.concatenate([r[-1], v[-1]], axis=1))
