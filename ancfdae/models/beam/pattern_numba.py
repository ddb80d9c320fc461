"""Compiled fills of the assembly pattern from node pairs (needs numba); see :func:`.assembly.node_pattern`.

Both loops write each output entry once, without the temporaries of whole-array expressions
(n_el * n_edof**2 slots: 729 per SQ3D element).
"""
from __future__ import annotations

from numba import njit

__all__ = ["row_columns", "element_slots", "diagonal_slots"]


@njit(cache=True)
def row_columns(row_node, node_ptr, node_cols, indptr, indices):
    """``indices`` of every row: the columns of its node, ``node_cols[node_ptr[a]:node_ptr[a + 1]]``."""
    for i in range(row_node.size):
        start = node_ptr[row_node[i]]
        for k in range(indptr[i + 1] - indptr[i]):
            indices[indptr[i] + k] = node_cols[start + k]


@njit(cache=True)
def element_slots(nodes, F, rank, indptr, offset, pair_of, nnz, out):
    """``out[e, a, i, b, j]``: the CSR data slot of element ``e``'s entry (node a coordinate i, node b
    coordinate j), ``nnz`` if either coordinate is fixed (``F`` < 0): row start + offset of node b among
    node a's neighbours + rank of j among node b's free coordinates."""
    n_el, npe = nodes.shape
    nd = F.shape[1]
    for e in range(n_el):
        for ia in range(npe):
            na = nodes[e, ia]
            for i in range(nd):
                fi = F[na, i]
                for ib in range(npe):
                    nb = nodes[e, ib]
                    base = indptr[fi] + offset[pair_of[(e * npe + ia) * npe + ib]] if fi >= 0 else 0
                    for j in range(nd):
                        out[e, ia, i, ib, j] = base + rank[nb, j] if fi >= 0 and F[nb, j] >= 0 else nnz


@njit(cache=True)
def diagonal_slots(indptr, indices, out):
    """``out[i]``: the position of column ``i`` in row ``i``, -1 where the row lacks it."""
    for i in range(out.size):
        out[i] = -1
        for k in range(indptr[i], indptr[i + 1]):
            if indices[k] == i:
                out[i] = k
                break
