"""The energy-preserving collocation's stage residual after the force evaluations, the kinetic and load
terms of a step's energy balance and the velocity correction, each as one compiled call.

``R = M Y / h^2 + G BP^T - F BL^T``: the mass term (CSR product), the projection of the conservative
forces at the ``k`` silent stages ``G`` (n_dof, k) and of the loads at the 2 Gauss nodes ``F`` (n_dof, 2)
onto the 2 Legendre rows (:mod:`ancfdae.integrators.energy_collocation`). With NumPy these are four calls
and a sparse product through scipy's dispatch (on B2, 8 BE2D: about a tenth of the run); here one loop.
The sums run in another order than BLAS's: equal to the NumPy expression to a few ulp (test).
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["stage_residual", "kinetic_work", "velocity_correction"]


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


@njit(cache=True)
def velocity_correction(m_data, indptr, indices, T, MT, TMT_inv, v1, R0, h, defect, max_scaling, out):
    """:class:`~ancfdae.integrators._energy_correction.VelocityCorrection` in one pass: ``out`` the corrected ``v1``;
    returns 0 (corrected), 1 (refused: the scaling cannot carry ``defect``) or 2 (``out`` is ``v1`` with the momentum
    restored, nothing to scale: no relative kinetic energy and no defect). Its ``reference`` (NumPy) in the test, to a
    few ulp. ``T``, ``MT`` (n, d) the translations and ``M T``, ``TMT_inv`` (d, d) ``(T^T M T)^-1``."""
    n, d = T.shape
    Mv = np.empty(n)
    e = 0.0
    for p in range(n):
        acc = 0.0
        for jj in range(indptr[p], indptr[p + 1]):
            acc += m_data[jj] * v1[indices[jj]]
        Mv[p] = acc
        e += v1[p] * acc
    target = 0.5 * e - defect
    for p in range(n):
        out[p] = v1[p]
    vt = np.zeros(n)
    kin_t = 0.0
    if d > 0:
        tr = np.zeros(d)                    # T^T R0
        for p in range(n):
            for a in range(d):
                tr[a] += T[p, a] * R0[p]
        dc = np.zeros(d)                    # the momentum's translation velocity
        for a in range(d):
            for b in range(d):
                dc[a] += TMT_inv[a, b] * (-h * tr[b])
        pm = np.zeros(d)                    # the momentum T^T M v1 after it
        for p in range(n):
            for a in range(d):
                out[p] += T[p, a] * dc[a]
                Mv[p] += MT[p, a] * dc[a]
            for a in range(d):
                pm[a] += T[p, a] * Mv[p]
        c = np.zeros(d)
        for a in range(d):
            for b in range(d):
                c[a] += TMT_inv[a, b] * pm[b]
            kin_t += 0.5 * c[a] * pm[a]
        for p in range(n):
            for a in range(d):
                vt[p] += T[p, a] * c[a]
    e = 0.0
    for p in range(n):
        e += out[p] * Mv[p]
    kin_w = 0.5 * e - kin_t                 # the velocity relative to the translations is M-orthogonal to them
    if not kin_w > 0.0:
        return 1 if defect != 0.0 else 2
    delta = (target - kin_t - kin_w) / kin_w
    if not abs(delta) <= max_scaling:
        return 1
    alpha = delta / (np.sqrt(1.0 + delta) + 1.0)
    for p in range(n):
        out[p] = vt[p] + (1.0 + alpha) * (out[p] - vt[p])
    return 0
