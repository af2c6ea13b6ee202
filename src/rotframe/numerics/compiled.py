"""How rotframe compiles its kernels: one numba configuration for every layer.

``jit_kernel`` compiles with ``cache=True`` (on disk, reused by later processes),
``error_model="numpy"`` (a division by zero gives inf or nan, which the drivers report
as a non-finite state, instead of raising; it also lets numba drop bounds and reference
bookkeeping in small inlined functions) and ``nogil=True`` (ensembles run blocks of
particles on threads).
"""

from __future__ import annotations

from numba import njit

__all__ = ["jit_kernel"]

#: The decorator of every compiled kernel that reports failures as non-finite numbers.
jit_kernel = njit(cache=True, error_model="numpy", nogil=True)
