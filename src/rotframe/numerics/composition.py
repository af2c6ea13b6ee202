"""Composition of a symmetric second-order step into higher orders (Yoshida's triple jump).

If ``S(h)`` is a symmetric (time-reversible) method of order ``p``, then
``S(g1 h) S(g0 h) S(g1 h)`` with ``g1 = 1 / (2 - 2^(1/(p+1)))`` and
``g0 = -2^(1/(p+1)) g1`` (so ``2 g1 + g0 = 1``) is symmetric of order ``p + 2``
(Yoshida, Phys. Lett. A 150, 262 (1990), eq. 4.14; see ``docs/physics/splitting.md``).
Applying the rule again to each of the three sub-steps raises the order by two more.
"""

from __future__ import annotations

import numpy as np

__all__ = ["triple_jump_weights", "YOSHIDA4_OUTER", "YOSHIDA4_INNER"]


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


#: The order-4 fractions as plain floats, for compiled kernels: ``(outer, inner, outer)``.
YOSHIDA4_OUTER = float(triple_jump_weights(4)[0])
YOSHIDA4_INNER = float(triple_jump_weights(4)[1])
