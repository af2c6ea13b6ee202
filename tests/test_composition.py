"""The composition fractions of rotframe.numerics.composition, checked without rotframe's kernels.

The order of a composition is a property of its fractions alone: composing the Strang
splitting ``exp(A h/2) exp(B h) exp(A h/2)`` of ``exp(h (A + B))`` (scipy's ``expm``; two
random matrices that do not commute) must converge at the stated order. A fraction changed
in its sixth digit destroys the order, so the test would see a misprinted constant.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from rotframe.numerics.composition import (
    COMPOSITION_ORDERS,
    KAHAN_LI_6,
    KAHAN_LI_8,
    composition_weights,
    triple_jump_weights,
)
from rotframe.rigid.checks import InvalidStateError
from rotframe.rigid.drivers import composition_weights as rigid_composition_weights

RNG = np.random.default_rng(20261123)
A, B = RNG.normal(size=(2, 4, 4))
A, B = A / np.linalg.norm(A, 2), B / np.linalg.norm(B, 2)
T = 1.0
EXACT = expm(T * (A + B))


def composed_error(weights, n):
    """Largest entry of ``(S_w(T/n))^n - exp(T (A + B))``, ``S_w`` the composed Strang step."""
    h = T / n
    step = np.eye(4)
    for g in weights:
        step = expm(0.5 * g * h * A) @ expm(g * h * B) @ expm(0.5 * g * h * A) @ step
    return float(np.max(np.abs(np.linalg.matrix_power(step, n) - EXACT)))


def observed_orders(weights, ns):
    """log2 of the error ratios between step counts ``ns`` (each twice the one before)."""
    errors = np.array([composed_error(weights, n) for n in ns])
    return np.log2(errors[:-1] / errors[1:])


@pytest.mark.parametrize("order", COMPOSITION_ORDERS)
def test_each_composition_converges_at_its_order(order):
    # the order-8 errors reach round-off (1e-14) at 8 steps: take larger steps for it
    ns = (1, 2, 4) if order == 8 else (2, 4, 8)
    np.testing.assert_allclose(observed_orders(composition_weights(order), ns), order, atol=0.2)


@pytest.mark.parametrize("order, stages", [(2, 1), (4, 3), (6, 9), (8, 17)])
def test_fractions_are_palindromes_summing_to_one(order, stages):
    w = composition_weights(order)
    assert w.shape == (stages,)
    np.testing.assert_array_equal(w, w[::-1])
    assert abs(w.sum() - 1.0) < 4e-16 * stages


@pytest.mark.parametrize("table, index", [(KAHAN_LI_6, 2), (KAHAN_LI_8, 5)])
def test_a_misprinted_fraction_destroys_the_order(table, index):
    """The order test sees a change in the sixth digit (so it would see a typo in the table)."""
    order = 6 if table is KAHAN_LI_6 else 8
    w = composition_weights(order).copy()
    w[index] += 1e-6
    w[-1 - index] += 1e-6
    w[len(w) // 2] -= 2e-6  # still summing to one
    # with steps short enough that the planted error term (second order) dominates
    assert np.all(observed_orders(w, (8, 16, 32)) < order - 2)


def test_kahan_li_order_6_beats_the_double_triple_jump_at_the_same_cost():
    """Both compose 9 Strang steps to order 6; Kahan & Li's leading error is far smaller."""
    assert len(triple_jump_weights(6)) == len(composition_weights(6)) == 9
    np.testing.assert_allclose(observed_orders(triple_jump_weights(6), (2, 4, 8)), 6, atol=0.2)
    assert composed_error(composition_weights(6), 2) < composed_error(triple_jump_weights(6), 2) / 50


@pytest.mark.parametrize("order", [0, 3, 10, 4.5])
def test_other_orders_are_refused(order):
    with pytest.raises(ValueError, match="allowed: 2, 4, 6 or 8"):
        composition_weights(order)
    with pytest.raises(InvalidStateError, match="allowed: 2, 4, 6 or 8"):
        rigid_composition_weights(order)
