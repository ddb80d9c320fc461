"""Compiled structural-mechanics energy density of SQ2D and SQ3D at one quadrature point.

The same energy as :func:`.structural.structural_kernel` with
the strains of :meth:`SQ2D._strains` and :meth:`SQ3D._strains` (chapter
Eqs. 7, 16, 19, 25, 45, 50): ``W = 1/2 sum_k Dw_k (eps_k - ref_k)^2`` with
every strain linear in the derivative variables ``d = (r', a_k')`` and
nonlinear in the slopes ``p = (a_k)`` only, ``eps_k = sum_j c_kj(p) . d_j +
f_k s_k(p)``. The coefficient vectors ``c_kj`` and the quadratic terms
``s_k`` are jets over ``p`` (:mod:`ancfdae.models.jets.vector_numba`), so the
gradient and the Hessian of ``W`` in the local variables ``v = (p, d)`` are
exact. Jets are rows of the work arrays ``JV``, ``JG``, ``JH``; the tables
below say which row holds which quantity.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..jets import vector_numba as jet

__all__ = ["frame2d", "frame3d", "needs_frame", "N_JETS", "TERMS_2D", "SQUARES_2D", "TERMS_3D", "SQUARES_3D",
           "structural_point"]

_OPTS = dict(cache=True, fastmath={"contract"})

#: rows of the jet work arrays
N_JETS = 22
# Terms c_kj . d_j as rows (strain k, derivative block j, jet row). Frame terms first: a point that
# carries only the cross-section strains skips them and the frame.
# 3D: blocks 0 = r', 1 = a2', 2 = a3'; Gamma_1..3 = e_i . r'; kappa_1 = -e2.a3'/m, kappa_2 = e1.a3'/m,
# kappa_3 = e1.(t a3' - m a2')/n (see SQ3D).
TERMS_3D = np.array([[0, 0, 10], [1, 0, 11], [2, 0, 5], [3, 2, 13], [4, 2, 14], [5, 1, 16], [5, 2, 18]],
                    dtype=np.int64)
# Quadratic terms f_k s_k(p) as rows (strain k, jet row, 2 f_k): E_22 = a2.a2/2, E_33 = a3.a3/2, gamma_23 = a2.a3.
SQUARES_3D = np.array([[6, 19, 1], [7, 2, 1], [8, 21, 2]], dtype=np.int64)
# 2D: blocks 0 = r', 1 = a'; Gamma_1 = (e2y, -e2x).r', Gamma_2 = e2.r', kappa = (-a_y, a_x).a'/|a|^2;
# E_22 = a.a/2.
TERMS_2D = np.array([[0, 0, 5], [1, 0, 4], [2, 1, 8]], dtype=np.int64)
SQUARES_2D = np.array([[3, 1, 1]], dtype=np.int64)


@njit(**_OPTS)
def frame3d(JV, JG, JH, order, need_frame):
    """Jets of the frame of chapter Eq. 7 and the curvature coefficients (rows of TERMS_3D).

    Rows: 0 a2, 1 a3, 2 m2 = a3.a3, 3 m, 4 1/m, 5 e3, 6 a2 x a3, 7 n2, 8 n, 9 1/n, 10 e1,
    11 e2, 12 t = a2.e3, 13 -e2/m, 14 e1/m, 15 m/n, 16 -(m/n) e1, 17 t/n, 18 (t/n) e1,
    19 a2.a2, 21 a2.a3.
    """
    jet.dot(JV, JG, JH, 2, 1, 1, 3, order)
    jet.dot(JV, JG, JH, 19, 0, 0, 3, order)
    jet.dot(JV, JG, JH, 21, 0, 1, 3, order)
    if not need_frame:
        return
    jet.sqrt(JV, JG, JH, 3, 2, order)
    jet.recip(JV, JG, JH, 4, 3, order)
    jet.mul(JV, JG, JH, 5, 4, 1, 1.0, 3, order)
    jet.cross(JV, JG, JH, 6, 0, 1, order)
    jet.dot(JV, JG, JH, 7, 6, 6, 3, order)
    jet.sqrt(JV, JG, JH, 8, 7, order)
    jet.recip(JV, JG, JH, 9, 8, order)
    jet.mul(JV, JG, JH, 10, 9, 6, 1.0, 3, order)
    jet.cross(JV, JG, JH, 11, 5, 10, order)
    jet.dot(JV, JG, JH, 12, 0, 5, 3, order)
    jet.mul(JV, JG, JH, 13, 4, 11, -1.0, 3, order)
    jet.mul(JV, JG, JH, 14, 4, 10, 1.0, 3, order)
    jet.mul(JV, JG, JH, 15, 3, 9, 1.0, 1, order)
    jet.mul(JV, JG, JH, 16, 15, 10, -1.0, 3, order)
    jet.mul(JV, JG, JH, 17, 12, 9, 1.0, 1, order)
    jet.mul(JV, JG, JH, 18, 17, 10, 1.0, 3, order)


@njit(**_OPTS)
def frame2d(JV, JG, JH, order, need_frame):
    """Jets of the planar frame: rows 0 a, 1 a.a, 2 |a|, 3 1/|a|, 4 e2, 5 turn(e2), 6 1/a.a,
    7 (-a_y, a_x), 8 (-a_y, a_x)/a.a."""
    jet.dot(JV, JG, JH, 1, 0, 0, 2, order)
    if not need_frame:
        return
    jet.sqrt(JV, JG, JH, 2, 1, order)
    jet.recip(JV, JG, JH, 3, 2, order)
    jet.mul(JV, JG, JH, 4, 3, 0, 1.0, 2, order)
    jet.turn(JV, JG, JH, 5, 4, 1.0, order)
    jet.recip(JV, JG, JH, 6, 1, order)
    jet.turn(JV, JG, JH, 7, 0, -1.0, order)
    jet.mul(JV, JG, JH, 8, 6, 7, 1.0, 2, order)


@njit(**_OPTS)
def needs_frame(dim, Dw):
    """Whether a point carries any strain of the frame (all but the cross-section strains E_kl)."""
    for k in range(Dw.shape[0] - (3 if dim == 3 else 1)):
        if Dw[k] != 0.0:
            return True
    return False


@njit(cache=True, inline="always", fastmath={"contract"})
def structural_point(dim, v, Dw, ref, JV, JG, JH, eps, sig, Jm, g, H, order):
    """Energy density ``W`` at one point; its gradient into ``g`` and Hessian into ``H`` (overwritten).

    Parameters
    ----------
    dim : 2 or 3
    v : (n_v,) local variables ``[a_k | r', a_k']``.
    Dw, ref : (n_strain,) stiffness x weight and reference strains (zero where a term does not act).
    JV, JG, JH : jet work arrays (N_JETS, 3[, K[, K]]) with ``K = dim (dim - 1)``.
    eps, sig : (n_strain,) work; Jm : (n_strain, n_v) work.
    order : 0 energy, 1 plus gradient, 2 plus Hessian.
    """
    npv = dim * (dim - 1)
    nv = v.shape[0]
    nk = Dw.shape[0]
    need_frame = needs_frame(dim, Dw)
    if dim == 3:
        jet.variable(JV, JG, JH, 0, v, 0, 3, 0, order)
        jet.variable(JV, JG, JH, 1, v, 3, 3, 3, order)
        frame3d(JV, JG, JH, order, need_frame)
        terms, squares = TERMS_3D, SQUARES_3D
    else:
        jet.variable(JV, JG, JH, 0, v, 0, 2, 0, order)
        frame2d(JV, JG, JH, order, need_frame)
        terms, squares = TERMS_2D, SQUARES_2D
    nt = terms.shape[0] if need_frame else 0
    for k in range(nk):
        eps[k] = -ref[k]
    if order >= 1:
        Jm[:, :] = 0.0
    for t in range(nt):
        k, off, c = terms[t, 0], npv + terms[t, 1] * dim, terms[t, 2]
        s = 0.0
        for a in range(dim):
            s += JV[c, a] * v[off + a]
        eps[k] += s
        if order >= 1:
            for kk in range(npv):
                s = 0.0
                for a in range(dim):
                    s += JG[c, a, kk] * v[off + a]
                Jm[k, kk] += s
            for a in range(dim):
                Jm[k, off + a] += JV[c, a]
    for t in range(squares.shape[0]):
        k, c, f = squares[t, 0], squares[t, 1], 0.5 * squares[t, 2]
        eps[k] += f * JV[c, 0]
        if order >= 1:
            for kk in range(npv):
                Jm[k, kk] += f * JG[c, 0, kk]
    W = 0.0
    for k in range(nk):
        sig[k] = Dw[k] * eps[k]
        W += 0.5 * sig[k] * eps[k]
    if order == 0:
        return W
    for i in range(nv):
        s = 0.0
        for k in range(nk):
            s += sig[k] * Jm[k, i]
        g[i] = s
    if order == 1:
        return W
    # Gauss-Newton part Jm^T Dw Jm over the strains that act here: upper triangle, then mirrored.
    H[:, :] = 0.0
    for k in range(nk):
        if Dw[k] == 0.0:
            continue
        for i in range(nv):
            x = Dw[k] * Jm[k, i]
            if x != 0.0:
                for j in range(i, nv):
                    H[i, j] += x * Jm[k, j]
    for i in range(nv):
        for j in range(i):
            H[i, j] = H[j, i]
    # Second-derivative part sum_k sig_k d2 eps_k: c_kj is a jet in p, linear in d_j.
    for t in range(nt):
        k, off, c = terms[t, 0], npv + terms[t, 1] * dim, terms[t, 2]
        sk = sig[k]
        for kk in range(npv):
            for ll in range(npv):
                s = 0.0
                for a in range(dim):
                    s += v[off + a] * JH[c, a, kk, ll]
                H[kk, ll] += sk * s
            for a in range(dim):
                x = sk * JG[c, a, kk]
                H[kk, off + a] += x
                H[off + a, kk] += x
    for t in range(squares.shape[0]):
        k, c, f = squares[t, 0], squares[t, 1], 0.5 * squares[t, 2]
        x = sig[k] * f
        for kk in range(npv):
            for ll in range(npv):
                H[kk, ll] += x * JH[c, 0, kk, ll]
    return W
