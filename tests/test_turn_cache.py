"""The Coriolis turn's kept cosines and sines (`rotframe.problem.models.turn_cos_sin`) are those computed anew.

The engine's rotation splitting keeps the last two angles' cosines and sines in its scratch: a fixed step in a
steady frame turns by the same angle every step (two in turn under Yoshida's composition). Whatever the order of the
angles, each answer must be ``math.cos``, ``math.sin`` of that angle, to the bit, from a scratch of zeros.
"""

import math

import numpy as np
import pytest

from rotframe.problem.models import SCRATCH, TURN, turn_cos_sin


@pytest.mark.parametrize("seed", range(5))
def test_each_answer_is_that_angles_cosine_and_sine(seed):
    rng = np.random.default_rng(seed)
    pool = list(rng.normal(size=4) * 10.0 ** rng.uniform(-300, 1, size=4)) + [-0.0, 0.0, 1e-320, -2.5e-310]
    W = np.zeros(SCRATCH)
    for _ in range(200):
        angle = float(pool[int(rng.integers(len(pool)))])
        c, s = turn_cos_sin.py_func(angle, W)
        assert (c, s) == (math.cos(angle), math.sin(angle)), angle
        assert math.copysign(1.0, s) == math.copysign(1.0, math.sin(angle)), angle  # the zeros' signs too


def test_the_slots_before_the_turns_are_left_alone():
    W = np.arange(SCRATCH, dtype=float)
    before = W[:TURN].copy()
    for angle in (0.3, -0.7, 0.3, 1.1):
        turn_cos_sin.py_func(angle, W)
    assert np.array_equal(W[:TURN], before)


def test_a_compiled_step_keeps_the_same_numbers():
    # the compiled function, as the engine's loop inlines it, against the plain one, on alternating angles
    W1, W2 = np.zeros(SCRATCH), np.zeros(SCRATCH)
    for angle in (0.1, 0.2, 0.1, 0.1, 0.2, 0.3, 0.1, -0.0):
        assert turn_cos_sin(angle, W1) == turn_cos_sin.py_func(angle, W2)
