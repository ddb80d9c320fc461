"""CSR matrices on a pattern the package built itself, without scipy's checks per construction.

The beam's assembly and the joints' compiled rows rebuild CSR matrices on patterns fixed at construction many
times per run; scipy's checked constructor re-validates the pattern every time. :data:`fast_csr` skips that
where it behaves exactly like scipy's constructor on the installed version (checked once at import).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["fast_csr"]


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


#: CSR matrix from (data, indices, indptr, shape) on a pattern built here: the unchecked constructor where it
#: behaves exactly like scipy's (checked once at import), shared by the beam and the joints' compiled rows.
fast_csr = _select_csr_builder()
