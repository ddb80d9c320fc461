"""Sparse assembly with a pattern fixed at construction.

Element matrices of shape (n_el, n_edof, n_edof) land in a CSR matrix over the
free coordinates through a precomputed slot per entry, so that every assembly
is one ``np.bincount`` (no COO sorting, no pattern reallocation at run time).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["Assembler"]


def _checked_csr(data, indices, indptr, shape):
    m = sp.csr_matrix((data, indices, indptr), shape=shape)
    m.has_sorted_indices = True
    return m


def _unchecked_csr(data, indices, indptr, shape):
    m = sp.csr_matrix.__new__(sp.csr_matrix)
    m._shape = shape
    m.indices, m.indptr, m.data = indices, indptr, data
    m.maxprint = 50
    return m


def _select_csr_builder():
    """Use the unchecked constructor only if it behaves exactly like scipy's on this scipy version."""
    try:
        ind = np.array([0, 1, 1], dtype=np.int32)
        ptr = np.array([0, 2, 3], dtype=np.int32)
        data = np.array([1.0, 2.0, 3.0])
        m = _unchecked_csr(data, ind, ptr, (2, 2))
        ref = _checked_csr(data, ind, ptr, (2, 2))
        ok = (np.array_equal(m @ np.ones(2), ref @ np.ones(2)) and np.array_equal(m.toarray(), ref.toarray())
              and np.array_equal(m.tocsc().toarray(), ref.toarray()) and m.indices is ind and m.has_sorted_indices)
        return _unchecked_csr if ok else _checked_csr
    except Exception:   # any scipy internals change: fall back to the public constructor
        return _checked_csr


_fast_csr = _select_csr_builder()


class Assembler:
    """Scatter element vectors and matrices into free-coordinate arrays.

    Parameters
    ----------
    edofs : ndarray of int, shape (n_el, n_edof)
        Full-vector index of every element coordinate.
    free_of_full : ndarray of int, shape (n_full,)
        Free index of each full coordinate, -1 where fixed.
    n_free : int
    """

    def __init__(self, edofs: np.ndarray, free_of_full: np.ndarray, n_free: int):
        self.n_free = n_free
        self._shape = edofs.shape
        fe = free_of_full[edofs]                      # (n_el, n_edof) free index or -1
        self._vec_mask = (fe >= 0).ravel()
        self._vec_idx = fe.ravel()[self._vec_mask]
        rows = np.broadcast_to(fe[:, :, None], fe.shape + (fe.shape[1],)).ravel()
        cols = np.broadcast_to(fe[:, None, :], fe.shape + (fe.shape[1],)).ravel()
        keep = (rows >= 0) & (cols >= 0)
        self._mat_mask = keep
        key = rows[keep].astype(np.int64) * n_free + cols[keep]
        uniq, slot = np.unique(key, return_inverse=True)
        self._slot = slot.ravel()
        self.nnz = uniq.size
        r, c = np.divmod(uniq, n_free)
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(r, minlength=n_free))]).astype(np.int32)
        self.indices = c.astype(np.int32)
        # Whole-array scatter indices: fixed entries go to one extra bin past the end, which is
        # dropped; cheaper than boolean-mask indexing every call, and the same sums in the same
        # order (bincount adds in input order), so bit-for-bit the masked result.
        self._vec_all = np.where(fe.ravel() >= 0, fe.ravel(), n_free)
        slot_all = np.full(keep.size, self.nnz, dtype=np.intp)
        slot_all[keep] = self._slot
        self._slot_all = slot_all
        # Diagonal slots, for adding a multiple of the identity with the pattern kept.
        self.diag_slot = np.searchsorted(uniq, np.arange(n_free, dtype=np.int64) * (n_free + 1))

    def vector(self, fe: np.ndarray) -> np.ndarray:
        """Sum element vectors (n_el, n_edof) into a free-coordinate vector."""
        return np.bincount(self._vec_all, weights=fe.ravel(), minlength=self.n_free + 1)[:self.n_free]

    def data(self, ke: np.ndarray) -> np.ndarray:
        """CSR data array of the sum of element matrices (n_el, n_edof, n_edof)."""
        return np.bincount(self._slot_all, weights=ke.ravel(), minlength=self.nnz + 1)[:self.nnz]

    def csr(self, data: np.ndarray) -> sp.csr_matrix:
        """A CSR matrix with the fixed pattern and the given data.

        The matrix shares this assembler's ``indices`` and ``indptr`` arrays
        (the same objects every call), which lets solvers cache pattern
        analyses (e.g. the band map) by identity; it skips scipy's format
        checks, which cost more than the assembly itself on small meshes.
        """
        return _fast_csr(data, self.indices, self.indptr, (self.n_free, self.n_free))

    def matrix(self, ke: np.ndarray) -> sp.csr_matrix:
        """Assemble element matrices into a CSR matrix with the fixed pattern."""
        return self.csr(self.data(ke))

    def element_scatter(self, e: int):
        """Index arrays to add one element's vector and matrix (for point loads).

        Returns ``(vmask, vidx, mmask, mslot)``: ``out[vidx] += f[vmask]`` and
        ``data[mslot] += K.ravel()[mmask]`` (``np.add.at``, slots may repeat).
        """
        n_el, nd = self._shape
        vm = self._vec_mask.reshape(n_el, nd)
        vstart = int(vm[:e].sum())
        vmask = vm[e]
        vidx = self._vec_idx[vstart:vstart + int(vmask.sum())]
        mm = self._mat_mask.reshape(n_el, nd * nd)
        mstart = int(mm[:e].sum())
        mmask = mm[e]
        mslot = self._slot[mstart:mstart + int(mmask.sum())]
        return vmask, vidx, mmask, mslot
