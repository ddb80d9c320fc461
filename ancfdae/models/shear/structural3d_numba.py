"""Compiled SQ3D structural kernel: one element's energy, force and tangent from sparse point blocks.

The SQ3D specialisation of :func:`.structural_numba.structural_point` and the scatter of
:mod:`.kernels_numba` (the same energy, chapter Eqs. 7, 16, 19, 25, 45, 50). Two things make it
cheaper than the general path, neither changes a sum beyond rounding:

* the point's Hessian ``H`` in the local variables ``v = (a2, a3 | r', a2', a3')`` is built from its
  nonzero blocks only. Each strain is ``eps_k = sum_j c_kj(p) . d_j + f_k s_k(p)`` with at most two
  derivative blocks ``d_j``, so ``d eps_k / d v`` is a 6-vector over the slopes ``p`` plus one or two
  3-vectors ``c_kj``; the Gauss-Newton part ``sum_k Dw_k (d eps_k)(d eps_k)^T`` is formed block by
  block (no 9 x 15 strain Jacobian with two thirds zeros) and the second-derivative part from the jets'
  upper triangles;
* the element tangent ``sum_p B^T H B`` uses ``B = S (x) I_3`` (each block of ``v`` is one node vector
  times a scalar shape function): first ``Y = H B`` per point, a 15 x 27 product with one scalar per
  3 x 3 block, then rows ``K[(i, u), :] += S[b, i] Y[b, :]`` over contiguous rows of 27 -- two passes
  of ``15 * 27 * n_nodes`` multiply-adds instead of one pass over every pair of (block, node).

Points that carry only the cross-section strains (the end-point rule's) touch the slopes ``a2, a3``
only: their blocks are 6 x 6 and their scatter runs over the first two blocks.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..jets import vector_numba as jet
from .structural_numba import N_JETS, SQUARES_3D, TERMS_3D, frame3d, needs_frame
from .structural3d_force_numba import N_ROWS, point_force

__all__ = ["sq3d_structural_elements"]

_INLINE = dict(cache=True, inline="always", fastmath={"contract"})
NV = 15        # local variables of a point
NP = 6         # slope variables p = (a2, a3)
NK = 9         # strain components


# Rows of the scalar jets (value SV, gradient SG, Hessian SH over p) of _slope_hessian.
S33, S22, S23, N2, IM, IN, IN2, M, PR, QR, DR, P3, Q3, D3, D2, UR, U3, Y, IMD3, Z, PSI, T1, T2 = range(23)
N_SCALARS = 23


@njit(**_INLINE)
def _prod(SV, SG, SH, o, a, b):
    """Scalar jet ``o = a b``."""
    va, vb = SV[a], SV[b]
    SV[o] = va * vb
    for k in range(NP):
        SG[o, k] = va * SG[b, k] + vb * SG[a, k]
    for k in range(NP):
        gak, gbk = SG[a, k], SG[b, k]
        for m in range(NP):
            SH[o, k, m] = va * SH[b, k, m] + vb * SH[a, k, m] + gak * SG[b, m] + gbk * SG[a, m]


@njit(**_INLINE)
def _lin(SV, SG, SH, o, ca, a, cb, b):
    """Scalar jet ``o = ca a + cb b`` (``o`` may be ``a`` or ``b``)."""
    SV[o] = ca * SV[a] + cb * SV[b]
    for k in range(NP):
        SG[o, k] = ca * SG[a, k] + cb * SG[b, k]
        for m in range(NP):
            SH[o, k, m] = ca * SH[a, k, m] + cb * SH[b, k, m]


@njit(**_INLINE)
def _chain(SV, SG, SH, o, a, f0, f1, f2):
    """Scalar jet ``o = phi(a)`` with ``phi, phi', phi''`` at ``a`` given."""
    SV[o] = f0
    for k in range(NP):
        SG[o, k] = f1 * SG[a, k]
    for k in range(NP):
        x = f2 * SG[a, k]
        for m in range(NP):
            SH[o, k, m] = f1 * SH[a, k, m] + x * SG[a, m]


@njit(**_INLINE)
def _forms(SV, SG, SH, v, w0, oP, oQ, oD):
    """The forms of ``w = v[w0:w0 + 3]`` (a derivative block, constant in p): ``P = a2.w``, ``Q = a3.w``,
    ``D = w.(a2 x a3)`` -- linear, linear and bilinear in p, so their jets are written out."""
    SV[oP] = v[0] * v[w0] + v[1] * v[w0 + 1] + v[2] * v[w0 + 2]
    SV[oQ] = v[3] * v[w0] + v[4] * v[w0 + 1] + v[5] * v[w0 + 2]
    for k in range(NP):
        for m in range(NP):
            SH[oP, k, m] = 0.0
            SH[oQ, k, m] = 0.0
            SH[oD, k, m] = 0.0
    for i in range(3):
        SG[oP, i], SG[oP, 3 + i], SG[oQ, i], SG[oQ, 3 + i] = v[w0 + i], 0.0, 0.0, v[w0 + i]
    # a3 x w and w x a2: the gradient of D in a2 and a3
    SG[oD, 0] = v[4] * v[w0 + 2] - v[5] * v[w0 + 1]
    SG[oD, 1] = v[5] * v[w0] - v[3] * v[w0 + 2]
    SG[oD, 2] = v[3] * v[w0 + 1] - v[4] * v[w0]
    SG[oD, 3] = v[w0 + 1] * v[2] - v[w0 + 2] * v[1]
    SG[oD, 4] = v[w0 + 2] * v[0] - v[w0] * v[2]
    SG[oD, 5] = v[w0] * v[1] - v[w0 + 1] * v[0]
    SV[oD] = v[0] * SG[oD, 0] + v[1] * SG[oD, 1] + v[2] * SG[oD, 2]
    # d2 D / d a2_i d a3_j = eps_ijk w_k
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        SH[oD, i, 3 + j] = v[w0 + k]
        SH[oD, 3 + j, i] = v[w0 + k]
        SH[oD, j, 3 + i] = -v[w0 + k]
        SH[oD, 3 + i, j] = -v[w0 + k]


@njit(**_INLINE)
def _slope_hessian(v, sig, SV, SG, SH, H, need_frame):
    """``H[:6, :6] += d2 psi / dp2`` for ``psi = sum_k sig_k eps_k`` at fixed ``sig`` and derivatives ``d``.

    The frame strains in scalars of p (``s33 = a3.a3``, ``s23 = a2.a3``, ``n2 = |a2 x a3|^2 =
    s33 (a2.a2) - s23^2``, ``m = sqrt(s33)``, and per derivative block ``w`` the forms of :func:`_forms`):
    ``e1.w = D_w / n``, ``e2.w = (s33 P_w - s23 Q_w) / (m n)``, ``e3.w = Q_w / m``, so
    ``Gamma_1..3`` are those with ``w = r'``, ``kappa_1 = -e2.a3' / m``, ``kappa_2 = e1.a3' / m`` and
    ``kappa_3 = (t D_3 - m D_2) / n^2`` with ``t = s23 / m`` (Eqs. 7, 16, 25). One scalar jet chain
    instead of the second derivatives of every frame vector.
    """
    a2a2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    for i in range(3):        # cross-section strains: a2.a2 / 2, a3.a3 / 2, a2.a3 (constant Hessians)
        H[i, i] += sig[6]
        H[3 + i, 3 + i] += sig[7]
        H[i, 3 + i] += sig[8]
    if not need_frame:
        return
    s33 = v[3] * v[3] + v[4] * v[4] + v[5] * v[5]
    s23 = v[0] * v[3] + v[1] * v[4] + v[2] * v[5]
    SV[S33], SV[S22], SV[S23] = s33, a2a2, s23
    for k in range(NP):
        for m in range(NP):
            SH[S33, k, m] = 0.0
            SH[S22, k, m] = 0.0
            SH[S23, k, m] = 0.0
    for i in range(3):
        SG[S33, i], SG[S33, 3 + i] = 0.0, 2.0 * v[3 + i]
        SG[S22, i], SG[S22, 3 + i] = 2.0 * v[i], 0.0
        SG[S23, i], SG[S23, 3 + i] = v[3 + i], v[i]
        SH[S33, 3 + i, 3 + i] = 2.0
        SH[S22, i, i] = 2.0
        SH[S23, i, 3 + i] = 1.0
        SH[S23, 3 + i, i] = 1.0
    _forms(SV, SG, SH, v, 6, PR, QR, DR)
    _forms(SV, SG, SH, v, 9, T1, T2, D2)       # a2': only D enters
    _forms(SV, SG, SH, v, 12, P3, Q3, D3)
    _prod(SV, SG, SH, T1, S33, S22)
    _prod(SV, SG, SH, T2, S23, S23)
    _lin(SV, SG, SH, N2, 1.0, T1, -1.0, T2)
    n2 = SV[N2]
    m = np.sqrt(s33)
    n = np.sqrt(n2)
    _chain(SV, SG, SH, M, S33, m, 0.5 / m, -0.25 / (m * s33))
    _chain(SV, SG, SH, IM, S33, 1.0 / m, -0.5 / (m * s33), 0.75 / (m * s33 * s33))
    _chain(SV, SG, SH, IN, N2, 1.0 / n, -0.5 / (n * n2), 0.75 / (n * n2 * n2))
    _chain(SV, SG, SH, IN2, N2, 1.0 / n2, -1.0 / (n2 * n2), 2.0 / (n2 * n2 * n2))
    for oU, oP, oQ in ((UR, PR, QR), (U3, P3, Q3)):      # U_w = s33 P_w - s23 Q_w
        _prod(SV, SG, SH, T1, S33, oP)
        _prod(SV, SG, SH, T2, S23, oQ)
        _lin(SV, SG, SH, oU, 1.0, T1, -1.0, T2)
    # Y = sig1 U_r - sig3 U_3 / m;  Z = sig0 D_r + sig4 D_3 / m + Y / m;  psi = Z / n + sig2 Q_r / m + ...
    _prod(SV, SG, SH, T1, IM, U3)
    _lin(SV, SG, SH, Y, sig[1], UR, -sig[3], T1)
    _prod(SV, SG, SH, IMD3, IM, D3)
    _prod(SV, SG, SH, T1, IM, Y)
    _lin(SV, SG, SH, Z, sig[0], DR, sig[4], IMD3)
    _lin(SV, SG, SH, Z, 1.0, Z, 1.0, T1)
    _prod(SV, SG, SH, PSI, IN, Z)
    _prod(SV, SG, SH, T1, IM, QR)
    _lin(SV, SG, SH, PSI, 1.0, PSI, sig[2], T1)
    # ... + sig5 (s23 D_3 / m - m D_2) / n^2
    _prod(SV, SG, SH, T1, S23, IMD3)
    _prod(SV, SG, SH, T2, M, D2)
    _lin(SV, SG, SH, T1, 1.0, T1, -1.0, T2)
    _prod(SV, SG, SH, T2, IN2, T1)
    _lin(SV, SG, SH, PSI, 1.0, PSI, sig[5], T2)
    for k in range(NP):
        for m2 in range(k, NP):
            H[k, m2] += SH[PSI, k, m2]


@njit(**_INLINE)
def _point(v, Dw, ref, JV, JG, JH, SV, SG, SH, eps, sig, Jp, g, H, order, need_frame):
    """Energy density at one point; gradient into ``g`` and Hessian (upper triangle first, then mirrored)
    into ``H``, both overwritten. ``Jp[k]`` receives ``d eps_k / d p``."""
    o1 = min(order, 1)            # the frame's jets to first order; second derivatives from _slope_hessian
    jet.variable(JV, JG, JH, 0, v, 0, 3, 0, o1)
    jet.variable(JV, JG, JH, 1, v, 3, 3, 3, o1)
    frame3d(JV, JG, JH, o1, need_frame)
    nt = TERMS_3D.shape[0] if need_frame else 0
    for k in range(NK):
        eps[k] = -ref[k]
    for t in range(nt):
        k, off, c = TERMS_3D[t, 0], NP + 3 * TERMS_3D[t, 1], TERMS_3D[t, 2]
        eps[k] += JV[c, 0] * v[off] + JV[c, 1] * v[off + 1] + JV[c, 2] * v[off + 2]
    for t in range(SQUARES_3D.shape[0]):
        k, c = SQUARES_3D[t, 0], SQUARES_3D[t, 1]
        eps[k] += 0.5 * SQUARES_3D[t, 2] * JV[c, 0]
    W = 0.0
    for k in range(NK):
        sig[k] = Dw[k] * eps[k]
        W += 0.5 * sig[k] * eps[k]
    if order == 0:
        return W
    # d eps_k / d p
    for k in range(NK):
        for kk in range(NP):
            Jp[k, kk] = 0.0
    for t in range(nt):
        k, off, c = TERMS_3D[t, 0], NP + 3 * TERMS_3D[t, 1], TERMS_3D[t, 2]
        for kk in range(NP):
            Jp[k, kk] += JG[c, 0, kk] * v[off] + JG[c, 1, kk] * v[off + 1] + JG[c, 2, kk] * v[off + 2]
    for t in range(SQUARES_3D.shape[0]):
        k, c, f = SQUARES_3D[t, 0], SQUARES_3D[t, 1], 0.5 * SQUARES_3D[t, 2]
        for kk in range(NP):
            Jp[k, kk] += f * JG[c, 0, kk]
    for i in range(NV):
        g[i] = 0.0
    for k in range(NK):
        if Dw[k] != 0.0:
            for kk in range(NP):
                g[kk] += sig[k] * Jp[k, kk]
    for t in range(nt):
        k, off, c = TERMS_3D[t, 0], NP + 3 * TERMS_3D[t, 1], TERMS_3D[t, 2]
        for a in range(3):
            g[off + a] += sig[k] * JV[c, a]
    if order == 1:
        return W
    nvh = NV if need_frame else NP
    for i in range(nvh):
        for j in range(i, nvh):
            H[i, j] = 0.0
    # slope-slope block: Gauss-Newton part and sig_k d2 eps_k (c_kj is linear in d_j)
    for k in range(NK):
        if Dw[k] == 0.0:
            continue
        for kk in range(NP):
            x = Dw[k] * Jp[k, kk]
            for ll in range(kk, NP):
                H[kk, ll] += x * Jp[k, ll]
    _slope_hessian(v, sig, SV, SG, SH, H, need_frame)
    # slope-derivative blocks and derivative-derivative blocks (pairs of terms of the same strain)
    for t in range(nt):
        k, off, c = TERMS_3D[t, 0], NP + 3 * TERMS_3D[t, 1], TERMS_3D[t, 2]
        dk, sk = Dw[k], sig[k]
        for a in range(3):
            y = dk * JV[c, a]
            for kk in range(NP):
                H[kk, off + a] += y * Jp[k, kk] + sk * JG[c, a, kk]
        for t2 in range(nt):
            if TERMS_3D[t2, 0] != k:
                continue
            off2, c2 = NP + 3 * TERMS_3D[t2, 1], TERMS_3D[t2, 2]
            if off2 < off:
                continue
            for a in range(3):
                y = dk * JV[c, a]
                for b in range(a if off2 == off else 0, 3):
                    H[off + a, off2 + b] += y * JV[c2, b]
    for i in range(nvh):
        for j in range(i):
            H[i, j] = H[j, i]
    return W


@njit(**_INLINE)
def _scatter(g, H, Sb, col, nba, Y, f_row, K_row, order):
    """``f_row += B^T g``; for order 2 ``K_row += B^T H B`` in two passes over the first ``nba`` blocks.

    ``B`` maps node vector ``col[b, i]`` with the scalar ``Sb[b, i]`` onto block ``b`` of ``v``;
    ``Y = H B`` (rows: the ``3 nba`` local variables; columns: the element's coordinates).
    """
    nn = Sb.shape[1]
    ne = K_row.shape[1]
    for b in range(nba):
        for i in range(nn):
            s = Sb[b, i]
            c0 = col[b, i]
            for c in range(3):
                f_row[c0 + c] += s * g[3 * b + c]
    if order < 2:
        return
    nr = 3 * nba
    for r in range(nr):
        for m in range(ne):
            Y[r, m] = 0.0
    for r in range(nr):
        for b2 in range(nba):
            h0, h1, h2 = H[r, 3 * b2], H[r, 3 * b2 + 1], H[r, 3 * b2 + 2]
            for j in range(nn):
                s = Sb[b2, j]
                c0 = col[b2, j]
                Y[r, c0] += s * h0
                Y[r, c0 + 1] += s * h1
                Y[r, c0 + 2] += s * h2
    for b in range(nba):
        for i in range(nn):
            s = Sb[b, i]
            if s == 0.0:
                continue
            r0 = col[b, i]
            for c in range(3):
                for m in range(ne):
                    K_row[r0 + c, m] += s * Y[3 * b + c, m]


@njit(cache=True, fastmath={"contract"})
def sq3d_structural_elements(q, N, dN, Dw, ref, order, Sb, col, W, f, K):
    """SQ3D structural kernel over all elements into ``W``, ``f``, ``K`` (zeroed by the caller; ``K`` has one
    element's room when ``order`` < 2). Arguments as :func:`.kernels_numba.sq_structural`; ``Sb``, ``col``
    hold the per-point shape table (:func:`.kernels_numba._shape_table`, filled here)."""
    n_el, n_pts, nn = N.shape
    ne = K.shape[1]
    v, g, H = np.empty(NV), np.zeros(NV), np.zeros((NV, NV))
    Y = np.zeros((NV, ne))
    JV, JG, JH = np.zeros((N_JETS, 3)), np.zeros((N_JETS, 3, NP)), np.zeros((N_JETS, 3, NP, NP))
    eps, sig, Jp = np.empty(NK), np.empty(NK), np.zeros((NK, NP))
    SV, SG, SH = np.zeros(N_SCALARS), np.zeros((N_SCALARS, NP)), np.zeros((N_SCALARS, NP, NP))
    FV, FG = np.zeros(N_ROWS), np.zeros((N_ROWS, NP))
    for e in range(n_el):
        qe = q[e]
        f_row = f[e]
        K_row = K[e if order >= 2 else 0]
        w = 0.0
        for p in range(n_pts):
            for b in range(5):
                vec = b + 1 if b < 2 else b - 2
                for i in range(nn):
                    Sb[b, i] = N[e, p, i] if b < 2 else dN[e, p, i]
                    col[b, i] = (i * 3 + vec) * 3
            for b in range(5):
                for c in range(3):
                    x = 0.0
                    for i in range(nn):
                        x += Sb[b, i] * qe[col[b, i] + c]
                    v[3 * b + c] = x
            need_frame = needs_frame(3, Dw[e, p])
            if order == 1:     # the force alone: scalar chain, no vector jets (:mod:`.structural3d_force_numba`)
                w += point_force(v, Dw[e, p], ref[e, p], FV, FG, eps, sig, g, need_frame)
            else:
                w += _point(v, Dw[e, p], ref[e, p], JV, JG, JH, SV, SG, SH, eps, sig, Jp, g, H, order, need_frame)
            if order >= 1:
                _scatter(g, H, Sb, col, 5 if need_frame else 2, Y, f_row, K_row, order)
        W[e] = w
