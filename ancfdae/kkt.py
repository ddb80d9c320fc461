"""KKT matrices ``[[A, c G1^T], [c G2, 0]]`` of constrained models, assembled on a fixed pattern.

Newton matrices of the constrained steps and the multipliers at output times
(:mod:`ancfdae.constrained`) are of this form.

``scipy.sparse.bmat`` rebuilds the structure at every call (measured: a third of the run time of an
index-3 generalized-alpha run of a 4-element BE2D pendulum). The blocks' patterns are fixed (the
Jacobian blocks share one, ``d(G^T lam)/dq`` and ``G`` each have one), so :class:`KKTAssembler` finds, once,
where each block's entries land in the combined CSR matrix and then forms it with one ``bincount``. A
block whose pattern differs from the one seen first (checked cheaply, by its index arrays) rebuilds the
map, so a model whose pattern is not fixed still gets the right matrix, only slower.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["KKTAssembler"]


def _csr(M):
    M = M if sp.issparse(M) and M.format == "csr" else sp.csr_matrix(M)
    if not M.has_canonical_format:
        M = M.copy()
        M.sum_duplicates()
    return M


def _key(M):
    return (M.shape, M.indptr.tobytes(), M.indices.tobytes())


class KKTAssembler:
    """``[[sum_k A_k, c1 G1^T], [c2 G2, 0]]`` from CSR blocks on fixed patterns (see the module docstring)."""

    def __init__(self) -> None:
        self._keys = None

    def _build(self, blocks, n, m):
        rows, cols = [], []
        for kind, M in blocks:
            C = M.tocoo()
            r, c = (C.col, C.row + n) if kind == "GT" else (C.row, C.col)
            if kind == "G":
                r = C.row + n
            rows.append(r)
            cols.append(c)
        r, c = np.concatenate(rows), np.concatenate(cols)
        P = sp.csr_matrix((np.ones(r.size), (r, c)), shape=(n + m, n + m))
        P.sum_duplicates()
        P.sort_indices()
        lookup = sp.csr_matrix((np.arange(P.nnz, dtype=float) + 1, P.indices, P.indptr), shape=P.shape)
        slots, start = [], 0
        for rr in rows:
            k = rr.size
            if k:
                slots.append(np.asarray(lookup[r[start:start + k], c[start:start + k]]).ravel().astype(np.int64) - 1)
            start += k
        # a canonical CSR matrix's tocoo keeps the order of its data array, which assemble() reads
        self._slots = np.concatenate(slots)
        self._pattern = P

    def assemble(self, A_blocks, G1, c1, G2, c2) -> sp.csr_matrix:
        """The matrix for square CSR blocks ``A_blocks`` (summed), ``c1 G1^T`` and ``c2 G2``."""
        G1, G2 = _csr(G1), _csr(G2)
        A_blocks = [_csr(A) for A in A_blocks]
        n, m = A_blocks[0].shape[0], G2.shape[0]
        blocks = [("A", A) for A in A_blocks] + [("GT", G1), ("G", G2)]
        keys = [_key(M) for _, M in blocks]
        if keys != self._keys:
            self._build(blocks, n, m)
            self._keys = keys
        data = np.concatenate([A.data for A in A_blocks] + [c1 * G1.data, c2 * G2.data])
        vals = np.bincount(self._slots, weights=data, minlength=self._pattern.nnz)
        return sp.csr_matrix((vals, self._pattern.indices, self._pattern.indptr), shape=self._pattern.shape)
