"""Compiled gather and scatter of the fused assembly (needs numba).

An element with a compiled kernel provides a *fused* entry point that takes the
free coordinates and returns assembled arrays in one compiled call::

    fused(q, q_fixed, gather, vec_slot, mat_slot, tangent, r, kdata, *element_args)

It gathers the element coordinates with :func:`gather_elements`, runs the
element kernel (a loop over elements returning ``f`` of shape (n_el, n_edof)
and, if ``tangent``, ``K`` of shape (n_el, n_edof, n_edof)), and sums them with
:func:`scatter` into ``r`` (length ``n_dof + 1``) and ``kdata`` (length
``nnz + 1``): the CSR data array of the beam's fixed pattern. The extra last
bin receives the entries of fixed coordinates and is dropped. Entries are
added in element order starting from zero, which is exactly what
``np.bincount`` does in the NumPy assembly, so both give the same bits for the
same element arrays. See :func:`ancfdae.models.thin.be2d_numba.be2d_fused` for the template.

numba's on-disk cache is keyed on the source file of the cached function only, and a fused entry
point holds a compiled copy of the kernel it calls: after editing a kernel in another file, delete the
``*.nbi``/``*.nbc`` files in ``ancfdae/models/beam/__pycache__`` (a fresh install has no stale cache).
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["gather_elements", "scatter"]


@njit(cache=True)
def gather_elements(q, q_fixed, gather):
    """Element coordinates ``(n_el, n_edof)``: ``gather[e, k] < q.size`` indexes ``q``, the rest ``q_fixed``."""
    n_el, nd = gather.shape
    nq = q.size
    qe = np.empty((n_el, nd))
    for e in range(n_el):
        for k in range(nd):
            g = gather[e, k]
            qe[e, k] = q[g] if g < nq else q_fixed[g - nq]
    return qe


@njit(cache=True)
def scatter(values, slot, out):
    """``out[:] = 0``, then ``out[slot[k]] += values.flat[k]`` in order (``np.bincount`` semantics)."""
    out[:] = 0.0
    flat = values.reshape(-1)
    for k in range(slot.size):
        out[slot[k]] += flat[k]
