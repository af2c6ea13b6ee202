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


def test_a_steady_frames_kept_axis_is_the_one_computed_anew():
    from rotframe.problem.models import AXIS, turn_axis

    rng = np.random.default_rng(7)
    for w in [rng.normal(size=3) * 10.0 ** rng.uniform(-150, 2) for _ in range(20)] + [np.array([0.0, -0.0, 3e-5])]:
        W = np.zeros(SCRATCH)
        fresh = turn_axis.py_func(False, *w, W)
        assert not W[AXIS:].any()  # an unsteady frame keeps nothing
        norm = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
        assert fresh == (norm, w[0] / norm, w[1] / norm, w[2] / norm)
        for _ in range(3):  # the first call keeps it, the next ones answer from it: the same numbers, signs of zero too
            kept = turn_axis.py_func(True, *w, W)
            assert kept == fresh and [math.copysign(1.0, a) for a in kept] == [math.copysign(1.0, a) for a in fresh]
    W = np.zeros(SCRATCH)
    assert turn_axis.py_func(True, 0.0, 0.0, 0.0, W) == (0.0, 0.0, 0.0, 0.0) and not W[AXIS:].any()  # no turn: none kept
