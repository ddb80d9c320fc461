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

__all__ = ["gather_elements", "scatter", "gather_configurations", "weigh_into", "scatter_projection"]


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


@njit(cache=True, inline="always")
def gather_configurations(Z, q_fixed, gather, e, A, Qe):
    """Element ``e``'s coordinates at the ``k`` configurations ``Z @ A[:, l]`` into ``Qe`` (k, n_edof).

    The projection entry points' gather (:meth:`ancfdae.models.beam.stages.StageEvaluator.projection`): ``Z`` (n, p)
    holds the configurations' common vectors (e.g. a polynomial's coefficients), ``A`` (p, k) their
    coefficients per configuration; a fixed coordinate (``gather[e, j] >= n``) keeps its value
    ``q_fixed`` in every configuration.
    """
    n, p = Z.shape
    k, nd = Qe.shape
    for j in range(nd):
        g = gather[e, j]
        if g < n:
            for l in range(k):
                x = 0.0
                for m in range(p):
                    x += Z[g, m] * A[m, l]
                Qe[l, j] = x
        else:
            for l in range(k):
                Qe[l, j] = q_fixed[g - n]


@njit(cache=True, inline="always")
def weigh_into(out, B, l, x, n):
    """``out[s, :n] += B[l, s] x[:n]`` for every output ``s``: configuration ``l``'s values weighted into the
    projections (the projection entry points' one accumulation)."""
    for s in range(B.shape[1]):
        w = B[l, s]
        for j in range(n):
            out[s, j] += w * x[j]


@njit(cache=True, inline="always")
def scatter_projection(fe, e, vec_slot, out):
    """``out[vec_slot[e n_edof + j], s] += fe[s, j]``: element ``e``'s projected forces (r, n_edof) into
    ``out`` (n + 1, r), whose last row collects the fixed coordinates' share."""
    r, nd = fe.shape
    b = nd * e
    for j in range(nd):
        row = vec_slot[b + j]
        for s in range(r):
            out[row, s] += fe[s, j]

