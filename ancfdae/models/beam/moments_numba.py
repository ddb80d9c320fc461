"""Compiled dead point moments that act through the turn of the axis tangent (BE2D, Cable3D), all in one call.

A thin element without a torsional coordinate turns its cross-section with the axis tangent: the
virtual rotation at the load point is ``delta phi = a x delta a / |a|^2`` with the slope
``a = r'(s) = S' q_e`` (chapter Sect. 2.2; in 2D only its z component, ``(a x delta a).e_z / |a|^2``).
A dead moment ``M`` then has the generalised force and derivative::

    f = S'^T b / p,   df/dq_e = S'^T (B / p - 2 b a^T / p^2) S',   b = M x a, B = [M]_x, p = a.a

(in 2D ``M = (0, 0, M_z)`` and the first two components of ``b`` and rows and columns of ``B``).
The element's ``moment_load`` is the readable reference of the same expressions; the tests hold the
two equal. The operator ``S'`` at each load point is computed once, when the beam is built
(:meth:`ancfdae.models.Element.moment_slope_operator`); a residual call then costs one compiled pass
over the moments instead of shape functions and some thirty NumPy operations per moment (issue 22:
a tip moment made an 8-element BE2D step six times dearer).
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["tangent_moments"]


@njit(cache=True)
def tangent_moments(q_full, dofs, slope_ops, moments, scales, vslot, mslot, tangent, f, kdata):
    """Add each moment's force to ``f`` and, if ``tangent``, its derivative to the CSR data ``kdata``.

    Parameters
    ----------
    q_full : (n_full,) full coordinate vector
    dofs : (n_m, n_edof) full indices of each loaded element's coordinates
    slope_ops : (n_m, dim, n_edof) ``S'`` at each load point
    moments : (n_m, 3) moment vectors (2D: ``(0, 0, M_z)``)
    scales : (n_m,) time-function values; a moment with scale 0 is skipped
    vslot, mslot : (n_m, n_edof), (n_m, n_edof**2) free index and CSR slot of each entry; an index at or
        past the end of ``f`` / ``kdata`` belongs to a fixed coordinate and is dropped
    f : (n_dof,) added to in place, moment by moment in element-coordinate order (as ``np.add.at``)
    kdata : (nnz,) added to in place if ``tangent``
    """
    n_m, dim, nd = slope_ops.shape
    n, nnz = f.size, kdata.size
    qe = np.empty(nd)
    a = np.empty(3)
    b = np.empty(3)
    C = np.empty((3, 3))
    W = np.empty((3, nd))
    for k in range(n_m):
        s = scales[k]
        if s == 0.0:
            continue
        m0, m1, m2 = s * moments[k, 0], s * moments[k, 1], s * moments[k, 2]
        for i in range(nd):
            qe[i] = q_full[dofs[k, i]]
        a[2] = 0.0
        for d in range(dim):
            acc = 0.0
            for i in range(nd):
                acc += slope_ops[k, d, i] * qe[i]
            a[d] = acc
        p = a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
        b[0] = m1 * a[2] - m2 * a[1]
        b[1] = m2 * a[0] - m0 * a[2]
        b[2] = m0 * a[1] - m1 * a[0]
        for i in range(nd):
            acc = 0.0
            for d in range(dim):
                acc += slope_ops[k, d, i] * b[d]
            slot = vslot[k, i]
            if slot < n:
                f[slot] += acc / p
        if not tangent:
            continue
        # C = [M]_x / p - 2 b a^T / p^2, then W = C S', K = S'^T W
        p2 = p * p
        C[0, 0], C[0, 1], C[0, 2] = 0.0, -m2 / p, m1 / p
        C[1, 0], C[1, 1], C[1, 2] = m2 / p, 0.0, -m0 / p
        C[2, 0], C[2, 1], C[2, 2] = -m1 / p, m0 / p, 0.0
        for d in range(dim):
            for e in range(dim):
                C[d, e] -= 2.0 * b[d] * a[e] / p2
        for d in range(dim):
            for j in range(nd):
                acc = 0.0
                for e in range(dim):
                    acc += C[d, e] * slope_ops[k, e, j]
                W[d, j] = acc
        for i in range(nd):
            for j in range(nd):
                slot = mslot[k, i * nd + j]
                if slot < nnz:
                    acc = 0.0
                    for d in range(dim):
                        acc += slope_ops[k, d, i] * W[d, j]
                    kdata[slot] += acc
