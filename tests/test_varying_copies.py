"""The evaluator of a varying frame or origin compiled for the problem's own kinds (`rotframe.problem.varying.varying_into_for`).

A table's spline, a body frame's Hermite interpolant and a user's omega(t) are each compiled only where a
problem has one. The copy is the same arithmetic as the evaluator of every kind: a run through it gives the
same numbers to the bit (the oracle: the same run with the engine handed the every-kind evaluator), and a
copy answers NaN for a kind it does not hold, never another kind's numbers.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rotframe
from rotframe.problem import codegen, models, varying

T_KNOTS = np.linspace(0.0, 2.0, 9)
W_KNOTS = np.stack([0.1 * np.sin(T_KNOTS), 0.2 * np.cos(T_KNOTS), 0.5 + 0.1 * T_KNOTS], axis=1)


def _body():
    return rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[0.1, 1.0, 0.1], q0=[0, 0, 0, 1], duration=2.0,
                                  samples=50, method="exact")


FRAMES = {"table": lambda: dict(omega=(T_KNOTS, W_KNOTS)),
          "body": lambda: dict(omega=_body()),
          "function": lambda: dict(omega=lambda t: (0.1 * math.sin(t), 0.2, 0.5)),
          "table and function": lambda: dict(omega=(T_KNOTS, W_KNOTS),
                                             origin_acceleration=lambda t: (0.01 * t, 0.0, 0.0))}


@pytest.mark.parametrize("frame", list(FRAMES))
def test_the_problems_own_copy_gives_the_every_kind_evaluators_numbers(frame, monkeypatch):
    kw = dict(r0=[1.0, 0.0, 0.0], v0=[0.0, 0.5, 0.0], duration=2.0, samples=20, rtol=1e-10,
              forces=[rotframe.forces.spring(1.0)], **FRAMES[frame]())
    own = rotframe.simulate(**kw)
    monkeypatch.setattr(varying, "varying_into_for", lambda kinds: varying.varying_into)
    codegen._ADDRESSES.clear()
    every = rotframe.simulate(**kw)
    assert np.array_equal(own.trajectory.r, every.trajectory.r) and np.array_equal(own.trajectory.v, every.trajectory.v)


def test_a_copy_holds_its_kinds_alone():
    C = np.zeros((3, 4, 3))
    C[:, 3, :] = 1.0  # a table of constant ones
    T = np.array([0.0, 1.0, 2.0, 3.0])
    table_only = varying.varying_into_for((models.TABLE, models.ZERO))
    assert table_only is varying.varying_into_for((models.TABLE,))  # one copy a process for each set of kinds
    from rotframe.numerics.plain import plain

    evaluate = plain(table_only)  # its plain-Python remake: the same code, the kinds it holds
    out = np.zeros(6)
    evaluate(models.TABLE, T, C, 0, 0.5, out)
    assert np.array_equal(out, [1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    evaluate(models.BODY_FRAME, T, C, 0, 0.5, out)
    assert np.all(np.isnan(out))
