"""The energy-preserving collocation's iteration matrices: the frozen split matrix and the interleaved
pattern of the exact Jacobian (:mod:`ancfdae.integrators.energy_collocation`)."""
from __future__ import annotations

import numpy as np

from ancfdae.integrators._linsolve import StageMatrix

__all__ = ["interleaved_pattern"]


class _SplitMatrix(StageMatrix):
    """The frozen iteration matrix ``M / h^2 + K X^2`` for the unknowns ``Y = h^2 gamma``.

    :class:`StageMatrix` with ``a = X`` solves for ``gamma`` (acceleration units); the solution is
    scaled by ``h^2``.
    """

    def factorize(self):
        return _Scaled(super().factorize(), self.h * self.h)


class _Scaled:
    def __init__(self, inner, factor):
        self.inner, self.factor = inner, factor
        self.singular = getattr(inner, "singular", False)

    def solve(self, rhs):
        return self.factor * self.inner.solve(rhs)


def interleaved_pattern(indptr: np.ndarray, indices: np.ndarray, n: int, m: int) -> tuple:
    """Index map from per-entry block values ``(nnz, m, m)`` to an interleaved CSR of size ``n m``.

    Row ``p m + i``, column ``q m + j`` holds block ``(i, j)`` at ``(p, q)`` of the shared pattern.

    Returns
    -------
    order, big_indices, big_indptr : ndarray
        ``csr_matrix((vals.ravel()[order], big_indices, big_indptr))``.
    """
    nnz = indices.size
    row = np.repeat(np.arange(n), np.diff(indptr))
    e, i, j = (g.ravel() for g in np.meshgrid(np.arange(nnz), np.arange(m), np.arange(m), indexing="ij"))
    order = np.lexsort((j, e, i, row[e]))
    big_indices = (indices[e] * m + j)[order]
    big_indptr = np.r_[0, np.cumsum(np.repeat(np.diff(indptr) * m, m))]
    return order, big_indices, big_indptr
