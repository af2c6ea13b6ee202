"""`rotframe.particles.trajectory.per_particle`: event records cut into one array per particle.

The oracle is numpy's own ``np.split`` at the cumulative counts, which every caller used before.
"""

import numpy as np
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


def test_particles_without_records_share_one_empty_slice_and_the_others_are_views():
    records = np.arange(4.0)
    pieces = per_particle(records, np.array([0, 2, 0, 2, 0]))
    assert pieces[0] is pieces[2] is pieces[4] and pieces[0].size == 0
    assert [p.tolist() for p in pieces] == [[], [0.0, 1.0], [], [2.0, 3.0], []]
    assert all(p.base is records for p in pieces)  # views of the records, as np.split's were
