"""Sparse assembly with a pattern fixed at construction.

Element matrices of shape (n_el, n_edof, n_edof) land in a CSR matrix over the
free coordinates through a precomputed slot per entry, so that every assembly
is one ``np.bincount`` (no COO sorting, no pattern reallocation at run time).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..._csr import fast_csr
from .pattern_numba import diagonal_slots, element_slots, row_columns

__all__ = ["Assembler", "entry_pattern", "node_pattern", "element_nodes_of"]


def entry_pattern(fe: np.ndarray, n_free: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(indptr, indices, slot_all)`` of the element matrices' entries, from a sort of every entry's key.

    The readable reference of :func:`node_pattern` and the pattern of any coordinate layout: ``fe`` (n_el,
    n_edof) holds the free index of each element coordinate (-1: fixed). ``slot_all`` (n_el * n_edof**2)
    is the CSR data position of each element-matrix entry, ``nnz`` where the row or column is fixed. Sorts
    n_el * n_edof**2 keys (729 per SQ3D element): seconds and gigabytes for large meshes.
    """
    rows = np.broadcast_to(fe[:, :, None], fe.shape + (fe.shape[1],)).ravel()
    cols = np.broadcast_to(fe[:, None, :], fe.shape + (fe.shape[1],)).ravel()
    keep = (rows >= 0) & (cols >= 0)
    key = rows[keep].astype(np.int64) * n_free + cols[keep]
    uniq, slot = np.unique(key, return_inverse=True)
    r, c = np.divmod(uniq, n_free)
    indptr = np.concatenate([[0], np.cumsum(np.bincount(r, minlength=n_free))]).astype(np.int32)
    slot_all = np.full(keep.size, uniq.size, dtype=np.intp)
    slot_all[keep] = slot.ravel()
    return indptr, c.astype(np.int32), slot_all


def element_nodes_of(edofs: np.ndarray, n_full: int, node_dof: int) -> np.ndarray | None:
    """The nodes of each element if ``edofs`` numbers ``node_dof`` consecutive coordinates per node
    (``edofs[e, a * node_dof + i] = node * node_dof + i``), else None."""
    n_el, nd = edofs.shape
    if node_dof < 1 or nd % node_dof or n_full % node_dof:
        return None
    blocks = edofs.reshape(n_el, nd // node_dof, node_dof)
    nodes = blocks[:, :, 0] // node_dof
    if not np.array_equal(blocks, nodes[:, :, None] * node_dof + np.arange(node_dof)):
        return None
    return nodes


def node_pattern(nodes: np.ndarray, free_of_full: np.ndarray, node_dof: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`entry_pattern` from the element-node adjacency: the same three arrays, bit for bit.

    Two coordinates couple when their nodes share an element, so the pattern is that of the node pairs
    (n_el * n_nodes_per_el**2 keys, 9 per SQ3D element, instead of 729) with a block of the free
    coordinates of each pair. Every row of a node has the same columns (those of the node's neighbours,
    ascending since free indices ascend with full indices); an entry's slot is its row's start, plus the
    offset of its column node among the row node's neighbours, plus its column's rank among the free
    coordinates of that node. The pairs in whole-array operations, the n_el * n_edof**2 slots and the
    columns in compiled loops (:mod:`.pattern_numba`).
    """
    n_el, npe = nodes.shape
    F = free_of_full.reshape(-1, node_dof)                     # free index per (node, coordinate) or -1
    n_nodes = F.shape[0]
    free_mask = F >= 0
    n_free_node = free_mask.sum(axis=1)
    rank = np.cumsum(free_mask, axis=1) - 1                     # rank among the node's free coordinates
    key = (nodes[:, :, None].astype(np.int64) * n_nodes + nodes[:, None, :]).ravel()
    pairs, pair_of = np.unique(key, return_inverse=True)        # sorted by (row node, column node)
    a, b = np.divmod(pairs, n_nodes)
    width = n_free_node[b]
    before = np.cumsum(width) - width                           # free columns of earlier pairs
    first = np.searchsorted(a, a)                               # first pair of the same row node
    offset = before - before[first]                             # column offset of node b in node a's rows
    node_len = np.bincount(a, weights=width, minlength=n_nodes).astype(np.int64)
    node_ptr = np.concatenate([[0], np.cumsum(node_len)])
    node_cols = F[b][free_mask[b]]                              # every node's columns, pair by pair
    free_full = np.flatnonzero(free_of_full >= 0)               # free_of_full[free_full] = 0, 1, 2, ...
    row_node = free_full // node_dof
    indptr = np.concatenate([[0], np.cumsum(node_len[row_node])])
    nnz = int(indptr[-1])
    indices = np.empty(nnz, dtype=np.int32)
    row_columns(row_node, node_ptr, node_cols.astype(np.int32), indptr, indices)
    slot_all = np.empty((n_el, npe, node_dof, npe, node_dof), dtype=np.intp)
    element_slots(nodes.astype(np.intp), F.astype(np.intp), rank.astype(np.intp), indptr.astype(np.intp),
                  offset.astype(np.intp), pair_of.astype(np.intp).ravel(), nnz, slot_all)
    return indptr.astype(np.int32), indices, slot_all.ravel()


class Assembler:
    """Scatter element vectors and matrices into free-coordinate arrays.

    Parameters
    ----------
    edofs : ndarray of int, shape (n_el, n_edof)
        Full-vector index of every element coordinate.
    free_of_full : ndarray of int, shape (n_full,)
        Free index of each full coordinate, -1 where fixed.
    n_free : int
    node_dof : int, optional
        Coordinates per node: with it (and ``edofs`` numbering each node's coordinates consecutively) the
        pattern comes from the node pairs (:func:`node_pattern`), else from every entry
        (:func:`entry_pattern`); the two give the same arrays.
    """

    def __init__(self, edofs: np.ndarray, free_of_full: np.ndarray, n_free: int, node_dof: int | None = None):
        self.n_free = n_free
        self._shape = edofs.shape
        fe = free_of_full[edofs]                      # (n_el, n_edof) free index or -1
        nodes = None if node_dof is None else element_nodes_of(edofs, free_of_full.size, node_dof)
        if nodes is None:
            self.indptr, self.indices, self._slot_all = entry_pattern(fe, n_free)
        else:
            self.indptr, self.indices, self._slot_all = node_pattern(nodes, free_of_full, node_dof)
        self.nnz = int(self.indptr[-1])
        # Whole-array scatter indices: fixed entries go to one extra bin past the end, which is
        # dropped; cheaper than boolean-mask indexing every call, and the same sums in the same
        # order (bincount adds in input order), so bit-for-bit the masked result.
        self._vec_all = np.where(fe.ravel() >= 0, fe.ravel(), n_free)
        # Diagonal slots, for adding a multiple of the identity with the pattern kept.
        self.diag_slot = _diagonal_slots(self.indptr, self.indices)

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
        return fast_csr(data, self.indices, self.indptr, (self.n_free, self.n_free))

    def product_csr(self, data: np.ndarray) -> sp.csr_matrix:
        """The CSR matrix of ``data`` without its stored zeros, for products only (its own pattern).

        A constant mass matrix stores zeros where the stiffness pattern has entries (BE2D: every
        x-y coupling, half the pattern); a product skips their terms. Rows are summed in the
        same order, and adding a zero term changes no bit of a finite sum, so ``M @ a`` is the
        same for finite ``a`` at half the work.
        """
        m = self.csr(data).copy()
        m.eliminate_zeros()
        return m

    def matrix(self, ke: np.ndarray) -> sp.csr_matrix:
        """Assemble element matrices into a CSR matrix with the fixed pattern."""
        return self.csr(self.data(ke))

    def element_scatter(self, e: int):
        """Index arrays to add one element's vector and matrix (for point loads).

        Returns ``(vmask, vidx, mmask, mslot)``: ``out[vidx] += f[vmask]`` and
        ``data[mslot] += K.ravel()[mmask]`` (``np.add.at``, slots may repeat).
        """
        n_el, nd = self._shape
        vall = self._vec_all.reshape(n_el, nd)[e]
        sall = self._slot_all.reshape(n_el, nd * nd)[e]
        vmask, mmask = vall < self.n_free, sall < self.nnz
        return vmask, vall[vmask], mmask, sall[mmask]


def _diagonal_slots(indptr: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Data position of the diagonal entry of every row (each row of an element pattern holds it)."""
    hit = np.empty(indptr.size - 1, dtype=np.intp)
    diagonal_slots(indptr, indices, hit)
    if np.any(hit < 0):
        raise ValueError(f"the assembly pattern lacks {int(np.sum(hit < 0))} diagonal entries (a coordinate in "
                         "no element)")
    return hit
