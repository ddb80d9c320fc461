"""The exact IDA iteration matrix ``[[cj I, -I], [K, D + cj M]]`` scattered into a fixed pattern."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["_JacobianFiller"]


class _JacobianFiller:
    """Scatter ``[[cj I, -I], [K, D + cj M]]`` into the CSC data array of a fixed pattern."""

    def __init__(self, blocks, n):
        self.n = n
        K, D, M = (sp.csr_matrix(b) for b in (blocks.K, blocks.D, blocks.M))
        self.same = bool(blocks.same_pattern)
        eye = np.arange(n)
        parts = [(eye, eye), (eye, eye + n)]  # cj I at (q, q'); -I at (q, v)
        if self.same:
            kr, kc = self._coords(K)
            parts += [(kr + n, kc), (kr + n, kc + n)]
        else:
            for X, off in ((K, 0), (D, n), (M, n)):
                r, c = self._coords(X)
                parts.append((r + n, c + off))
        rows = np.concatenate([p[0] for p in parts])
        cols = np.concatenate([p[1] for p in parts])
        N = 2 * n
        self.pattern = sp.csc_matrix((np.ones(rows.size), (rows, cols)), shape=(N, N))
        self.pattern.sum_duplicates()
        self.pattern.sort_indices()
        key = cols.astype(np.int64) * N + rows
        csc_key = (np.repeat(np.arange(N), np.diff(self.pattern.indptr)).astype(np.int64) * N
                   + self.pattern.indices)
        slot = np.searchsorted(csc_key, key)
        sizes = np.cumsum([p[0].size for p in parts])[:-1]
        self.slots = np.split(slot, sizes)
        self.nnz = self.pattern.nnz
        self._ref = K.indptr.copy(), K.indices.copy()

    @staticmethod
    def _coords(X):
        X = sp.csr_matrix(X)
        return np.repeat(np.arange(X.shape[0]), np.diff(X.indptr)), X.indices

    def fill(self, JJ, blocks, cj):
        K = blocks.K
        if self.same:
            if K.indices.size != self._ref[1].size or not np.array_equal(K.indices, self._ref[1]):
                raise ValueError("the model's Jacobian pattern changed during the run; IDA needs a fixed pattern.")
            JJ[:] = 0.0
            JJ[self.slots[0]] = cj
            JJ[self.slots[1]] = -1.0
            JJ[self.slots[2]] = K.data
            JJ[self.slots[3]] = blocks.D.data + cj * blocks.M.data
        else:
            vals = [np.full(self.n, cj), -np.ones(self.n)]
            slots = list(self.slots[:2])
            N = 2 * self.n
            csc_key = (np.repeat(np.arange(N), np.diff(self.pattern.indptr)).astype(np.int64) * N
                       + self.pattern.indices)
            for X, off, scale in ((K, 0, 1.0), (blocks.D, self.n, 1.0), (blocks.M, self.n, cj)):
                X = sp.csr_matrix(X)
                r, c = self._coords(X)
                key = (c + off).astype(np.int64) * N + r + self.n
                s = np.searchsorted(csc_key, key)
                if np.any(s >= csc_key.size) or np.any(csc_key[np.minimum(s, csc_key.size - 1)] != key):
                    raise ValueError("the model's Jacobian has entries outside the pattern seen at t0.")
                slots.append(s)
                vals.append(scale * X.data)
            JJ[:] = np.bincount(np.concatenate(slots), weights=np.concatenate(vals), minlength=self.nnz)
