"""Symmetric compositions of a symmetric second-order step into orders 4, 6 and 8.

If ``S(h)`` is a symmetric (time-reversible) method of order 2, the product
``S(g_s h) ... S(g_2 h) S(g_1 h)`` with palindromic fractions ``g_i`` summing to 1
is symmetric, and of a higher order when the ``g_i`` solve the order conditions
(Hairer, Lubich & Wanner, Geometric Numerical Integration, 2nd ed., V.3; see
``docs/physics/splitting.md``):

* order 4: Yoshida's triple jump, 3 stages, ``g1 = 1 / (2 - 2^(1/3))``,
  ``g0 = -2^(1/3) g1`` (Yoshida, Phys. Lett. A 150, 262 (1990), eq. 4.14);
* order 6: Kahan & Li's ``s9odr6a``, 9 stages;
* order 8: Kahan & Li's ``s17odr8a``, 17 stages (Kahan & Li, Composition constants
  for raising the orders of unconventional schemes for ordinary differential
  equations, Math. Comp. 66, 1089 (1997); 20 digits, as Hairer, Lubich & Wanner
  tabulate them in V.3).

Kahan and Li chose their fractions among the solutions of the order conditions
for the smallest leading error: on the heavy-top bench problem the order-6
method is some 200 times more accurate than the order-6 triple jump
(``triple_jump_weights(6)``, the composition used before) at the same cost.
"""

from __future__ import annotations

import numpy as np

__all__ = ["triple_jump_weights", "composition_weights", "COMPOSITION_ORDERS", "KAHAN_LI_6", "KAHAN_LI_8",
           "YOSHIDA4_OUTER", "YOSHIDA4_INNER"]

#: Kahan & Li (1997) ``s9odr6a``: the first four fractions and the middle one (the rest mirror them).
KAHAN_LI_6 = (0.39216144400731413928, 0.33259913678935943860, -0.70624617255763935981,
              0.082213596293550800230, 0.79854399093482996340)
#: Kahan & Li (1997) ``s17odr8a``: the first eight fractions and the middle one (the rest mirror them).
KAHAN_LI_8 = (0.13020248308889008088, 0.56116298177510838456, -0.38947496264484728641,
              0.15884190655515560090, -0.39590389413323757734, 0.18453964097831570709,
              0.25837438768632204729, 0.29501172360931029887, -0.60550853383003451170)

#: The orders `composition_weights` offers.
COMPOSITION_ORDERS = (2, 4, 6, 8)


def triple_jump_weights(order: int) -> np.ndarray:
    """Step fractions of the order-2 step in the triple-jump composition of ``order``.

    Parameters
    ----------
    order : {2, 4, 6}
        Order of the composed method.

    Returns
    -------
    numpy.ndarray
        ``3 ** (order / 2 - 1)`` fractions of the step, summing to 1 (to round-off).

    Raises
    ------
    ValueError
        For an order other than 2, 4 or 6.

    Examples
    --------
    >>> w = triple_jump_weights(4)
    >>> len(w), round(float(w.sum()), 12)
    (3, 1.0)
    """
    if order not in (2, 4, 6):
        raise ValueError(f"order = {order!r}; allowed: 2, 4 or 6")
    w = np.array([1.0])
    for p in range(2, order, 2):  # raise the order from p to p + 2
        root = 2.0 ** (1.0 / (p + 1))
        g1 = 1.0 / (2.0 - root)
        w = np.concatenate([g1 * w, -root * g1 * w, g1 * w])
    return w


def _palindrome(first_and_middle):
    """``(g1, ..., gm, middle)`` -> ``[g1, ..., gm, middle, gm, ..., g1]``."""
    first = list(first_and_middle[:-1])
    return np.array(first + [first_and_middle[-1]] + first[::-1])


def composition_weights(order: int) -> np.ndarray:
    """Step fractions of the order-2 step in rotframe's composition of ``order``.

    Parameters
    ----------
    order : {2, 4, 6, 8}
        Order of the composed method: 2 is the step itself; 4 Yoshida's triple
        jump (3 stages); 6 and 8 Kahan & Li's ``s9odr6a`` (9 stages) and
        ``s17odr8a`` (17 stages).

    Returns
    -------
    numpy.ndarray
        The fractions, a palindrome summing to 1 (to round-off).

    Raises
    ------
    ValueError
        For an order other than 2, 4, 6 or 8.

    Examples
    --------
    >>> [len(composition_weights(p)) for p in (2, 4, 6, 8)]
    [1, 3, 9, 17]
    """
    if order in (2, 4):
        return triple_jump_weights(order)
    if order == 6:
        return _palindrome(KAHAN_LI_6)
    if order == 8:
        return _palindrome(KAHAN_LI_8)
    raise ValueError(f"order = {order!r}; allowed: 2, 4, 6 or 8")


#: The order-4 fractions as plain floats, for compiled kernels: ``(outer, inner, outer)``.
YOSHIDA4_OUTER = float(triple_jump_weights(4)[0])
YOSHIDA4_INNER = float(triple_jump_weights(4)[1])
