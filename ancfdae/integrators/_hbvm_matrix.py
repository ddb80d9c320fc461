"""The energy-preserving collocation's iteration matrices: the frozen split matrix and the exact Jacobian on
its interleaved pattern (:mod:`ancfdae.integrators.energy_collocation`)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.integrators._linsolve import StageMatrix

__all__ = ["ExactMatrix", "interleaved_pattern"]


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


class ExactMatrix:
    """The exact Jacobian of the stage equations, ``delta_im M / h^2 + sum_l C[i, m, l] H[l] - sum_j Cl[i, m, j]
    Kf[j]`` (Hessians ``H`` at the ``k`` nodes of ``co``, load tangents ``Kf`` at the nodes of ``loads``), as an
    interleaved CSR of size ``2 n``; the index map of the last pattern is kept.

    Parameters
    ----------
    co, loads : HBVMCoefficients
        The rule of the conservative force and that of the loads.
    """

    def __init__(self, co, loads) -> None:
        self._co, self._loads, self._pattern = co, loads, None

    def __call__(self, H, Kf, M, h):
        s = self._co.s
        mats = [sp.csr_matrix(A) for A in list(H) + list(Kf)] + [M]
        n = M.shape[0]
        weights = np.concatenate([self._co.C, -self._loads.C, np.eye(s)[:, :, None] / (h * h)], axis=2)   # (s, s, k+3)
        A0 = mats[0]
        if all(A.indptr is A0.indptr and A.indices is A0.indices for A in mats) or all(
                np.array_equal(A.indptr, A0.indptr) and np.array_equal(A.indices, A0.indices) for A in mats):
            if self._pattern is None or not np.array_equal(self._pattern[0], A0.indptr) \
                    or not np.array_equal(self._pattern[1], A0.indices):
                self._pattern = (A0.indptr, A0.indices, *interleaved_pattern(A0.indptr, A0.indices, n, s))
            _, _, order, big_indices, big_indptr = self._pattern
            vals = np.einsum("iml,le->eim", weights, np.stack([A.data for A in mats]))   # (nnz, s, s)
            return sp.csr_matrix((vals.ravel()[order], big_indices, big_indptr), shape=(s * n, s * n))
        out = None
        for i in range(s):
            for j in range(s):
                B = sum(w * A for w, A in zip(weights[i, j], mats))
                E = sp.csr_matrix(([1.0], ([i], [j])), shape=(s, s))
                term = sp.kron(B, E, format="csr")
                out = term if out is None else out + term
        return out.tocsr()
