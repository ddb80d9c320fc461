"""Compiled products with the constraint Jacobian ``G`` (CSR, few rows) for the constrained steppers.

Each Newton iteration of a constrained step needs ``G v``, ``G^T lam`` and ``G^T mu`` per stage; through
scipy each costs more to call (format checks, index-dtype checks: 10-30 us) than to compute for the
few rows of a joint set, so the products run as compiled loops on the CSR arrays.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["csr_matvec", "csr_rmatvec"]


@njit(cache=True)
def csr_matvec(indptr, indices, data, x):
    """``G x`` for ``G = (data, indices, indptr)``."""
    m = indptr.size - 1
    out = np.zeros(m)
    for i in range(m):
        s = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            s += data[k] * x[indices[k]]
        out[i] = s
    return out


@njit(cache=True)
def csr_rmatvec(indptr, indices, data, u, n):
    """``G^T u`` for ``G = (data, indices, indptr)`` with ``n`` columns."""
    out = np.zeros(n)
    for i in range(indptr.size - 1):
        ui = u[i]
        for k in range(indptr[i], indptr[i + 1]):
            out[indices[k]] += data[k] * ui
    return out
