"""The energy-preserving collocation's stage residual after the force evaluations, and the kinetic and load
terms of a step's energy balance, each as one compiled call.

``R = M Y / h^2 + G BP^T - F BL^T``: the mass term (CSR product), the projection of the conservative
forces at the ``k`` silent stages ``G`` (n_dof, k) and of the loads at the 2 Gauss nodes ``F`` (n_dof, 2)
onto the 2 Legendre rows (:mod:`ancfdae.integrators.energy_collocation`). With NumPy these are four calls
and a sparse product through scipy's dispatch (on B2, 8 BE2D: about a tenth of the run); here one loop.
The sums run in another order than BLAS's: equal to the NumPy expression to a few ulp (test).
"""
from __future__ import annotations

from numba import njit

__all__ = ["stage_residual", "kinetic_work"]


@njit(cache=True)
def stage_residual(Y, G, BPT, F, BlT, m_data, indptr, indices, ih2, R):
    """``R[p, i] = ih2 (M Y)[p, i] + sum_l G[p, l] BPT[l, i] - sum_j F[p, j] BlT[j, i]`` into ``R`` (n_dof, 2)."""
    n, s = Y.shape
    k, nl = G.shape[1], F.shape[1]
    for p in range(n):
        for i in range(s):
            acc = 0.0
            for jj in range(indptr[p], indptr[p + 1]):
                acc += m_data[jj] * Y[indices[jj], i]
            g = 0.0
            for l in range(k):
                g += G[p, l] * BPT[l, i]
            f = 0.0
            for j in range(nl):
                f += F[p, j] * BlT[j, i]
            R[p, i] = ih2 * acc + (g - f)


@njit(cache=True)
def kinetic_work(m_data, indptr, indices, v0, v1, F, Y, WdT, b, h):
    """``(T(v1) - T(v0), W)``: ``T(v) = v . M v / 2`` and the loads' work by their rule,
    ``W = sum_j b_j F[:, j] . (h v0 + Y WdT[:, j])`` (``F`` the loads at the rule's nodes, ``h v0 + Y WdT`` the
    nodes' ``h sigma'``); the NumPy expression in the test, to a few ulp."""
    n, s = Y.shape
    nl = F.shape[1]
    t1 = 0.0
    t0 = 0.0
    w = 0.0
    for p in range(n):
        a1 = 0.0
        a0 = 0.0
        for jj in range(indptr[p], indptr[p + 1]):
            a1 += m_data[jj] * v1[indices[jj]]
            a0 += m_data[jj] * v0[indices[jj]]
        t1 += v1[p] * a1
        t0 += v0[p] * a0
        for j in range(nl):
            hs = h * v0[p]
            for i in range(s):
                hs += Y[p, i] * WdT[i, j]
            w += b[j] * F[p, j] * hs
    return 0.5 * (t1 - t0), w
