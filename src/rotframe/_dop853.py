"""Butcher tableau of Dormand-Prince 8(5,3) (Hairer, Norsett & Wanner, Solving ODEs I, II.10).

The coefficients are published constants; we take them from scipy's table of
them (``scipy.integrate._ivp.dop853_coefficients``) rather than retype 150
30-digit numbers, and check them in the tests (row sums equal the nodes, the
weights sum to one, and the observed order is 8).
"""

from __future__ import annotations

import functools

import numpy as np


@functools.cache
def coefficients():
    """(A (12, 12), B (12,), C (12,), E3 (13,), E5 (13,)) as contiguous float64 arrays."""
    from scipy.integrate._ivp import dop853_coefficients as d

    n = d.N_STAGES
    A = np.ascontiguousarray(d.A[:n, :n], dtype=np.float64)
    B = np.ascontiguousarray(d.B, dtype=np.float64)
    C = np.ascontiguousarray(d.C[:n], dtype=np.float64)
    E3 = np.ascontiguousarray(d.E3, dtype=np.float64)
    E5 = np.ascontiguousarray(d.E5, dtype=np.float64)
    return A, B, C, E3, E5
