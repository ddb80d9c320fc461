"""Compiled SQ3D structural force at one point, without the frame's vector jets: the order-1 (force-only) pass.

The energy density is that of :func:`.structural3d_numba._point` (chapter Eqs. 7, 16, 19, 25, 45, 50),
``W = 1/2 sum_k Dw_k (eps_k - ref_k)^2``, with the strains written in scalars of the slopes ``p = (a2, a3)``
and the derivative blocks ``w`` (as :func:`.structural3d_numba._slope_hessian` does for the Hessian):
``s33 = a3.a3``, ``s22 = a2.a2``, ``s23 = a2.a3``, ``n2 = s33 s22 - s23^2``, ``m = sqrt(s33)``,
``n = sqrt(n2)`` and per block ``P_w = a2.w``, ``Q_w = a3.w``, ``D_w = w.(a2 x a3)``, ``U_w = s33 P_w - s23 Q_w``:

    Gamma_1 = D_r / n,  Gamma_2 = U_r / (m n),  Gamma_3 = Q_r / m,
    kappa_1 = -U_3 / (m^2 n),  kappa_2 = D_3 / (m n),  kappa_3 = (s23 D_3 / m - m D_2) / n^2,
    E_22 = s22 / 2,  E_33 = s33 / 2,  gamma_23 = s23

(``r = r'``, ``2 = a2'``, ``3 = a3'``). The gradient in the slopes is ``d psi / dp`` of
``psi = sum_k sig_k eps_k`` at fixed ``sig`` and ``w``, carried forward as scalar jets of first order (value
and 6-gradient) through the same chain; the gradient in the derivative blocks is linear in the frame's
values (``e1 = (a2 x a3) / n``, ``e2 = (s33 a2 - s23 a3) / (m n)``, ``e3 = a3 / m``). The vector jets of
:func:`.structural_numba.frame3d` carry a 3 x 6 gradient per frame vector through about twenty calls; the
force needs only these scalars. Equal to the jet path to round-off (``tests/models/shear/test_sq_kernels.py``
holds the compiled force-only path equal to the NumPy reference).
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["point_force", "N_ROWS", "NP"]

_INLINE = dict(cache=True, inline="always", fastmath={"contract"})
NP = 6        # slope variables p = (a2, a3)

# Rows of the scalar jets (value SV, gradient SG over p).
S33, S22, S23, N2, M, IM, IN, IN2, PR, QR, DR, P3, Q3, D3, D2, UR, U3, Y, IMD3, Z, PSI, T1, T2 = range(23)
N_ROWS = 23


@njit(**_INLINE)
def _prod(SV, SG, o, a, b):
    """``o = a b``."""
    va, vb = SV[a], SV[b]
    SV[o] = va * vb
    for k in range(NP):
        SG[o, k] = va * SG[b, k] + vb * SG[a, k]


@njit(**_INLINE)
def _lin(SV, SG, o, ca, a, cb, b):
    """``o = ca a + cb b`` (``o`` may be ``a`` or ``b``)."""
    SV[o] = ca * SV[a] + cb * SV[b]
    for k in range(NP):
        SG[o, k] = ca * SG[a, k] + cb * SG[b, k]


@njit(**_INLINE)
def _chain(SV, SG, o, a, f0, f1):
    """``o = phi(a)`` with ``phi, phi'`` at ``a`` given."""
    SV[o] = f0
    for k in range(NP):
        SG[o, k] = f1 * SG[a, k]


@njit(**_INLINE)
def _forms(SV, SG, v, w0, oP, oQ, oD):
    """``P = a2.w``, ``Q = a3.w``, ``D = w.(a2 x a3)`` of the block ``w = v[w0:w0 + 3]`` and their gradients."""
    SV[oP] = v[0] * v[w0] + v[1] * v[w0 + 1] + v[2] * v[w0 + 2]
    SV[oQ] = v[3] * v[w0] + v[4] * v[w0 + 1] + v[5] * v[w0 + 2]
    for i in range(3):
        SG[oP, i], SG[oP, 3 + i], SG[oQ, i], SG[oQ, 3 + i] = v[w0 + i], 0.0, 0.0, v[w0 + i]
    SG[oD, 0] = v[4] * v[w0 + 2] - v[5] * v[w0 + 1]      # a3 x w
    SG[oD, 1] = v[5] * v[w0] - v[3] * v[w0 + 2]
    SG[oD, 2] = v[3] * v[w0 + 1] - v[4] * v[w0]
    SG[oD, 3] = v[w0 + 1] * v[2] - v[w0 + 2] * v[1]      # w x a2
    SG[oD, 4] = v[w0 + 2] * v[0] - v[w0] * v[2]
    SG[oD, 5] = v[w0] * v[1] - v[w0 + 1] * v[0]
    SV[oD] = v[0] * SG[oD, 0] + v[1] * SG[oD, 1] + v[2] * SG[oD, 2]


# One compiled function with an explicit signature, called (not inlined) by the element loops: inlined, its
# unrolled jet loops made every caller's compile 40 s longer (cold numba cache, B3-8 with Lobatto IIIA-3).
@njit("float64(float64[::1], float64[:], float64[:], float64[::1], float64[:, ::1], float64[::1], float64[::1], "
      "float64[::1], boolean)", cache=True, fastmath={"contract"})
def point_force(v, Dw, ref, SV, SG, eps, sig, g, need_frame):
    """Energy density ``W`` at one point and its gradient in ``v = (a2, a3 | r', a2', a3')`` into ``g`` (15,),
    overwritten; ``eps``, ``sig`` (9,) receive the strains and stresses. ``need_frame`` False: only the
    cross-section strains act (their stiffness alone is nonzero), the frame is not formed."""
    s22 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    s33 = v[3] * v[3] + v[4] * v[4] + v[5] * v[5]
    s23 = v[0] * v[3] + v[1] * v[4] + v[2] * v[5]
    for k in range(6):
        eps[k] = -ref[k]
    eps[6], eps[7], eps[8] = 0.5 * s22 - ref[6], 0.5 * s33 - ref[7], s23 - ref[8]
    for i in range(15):
        g[i] = 0.0
    if need_frame:
        SV[S33], SV[S22], SV[S23] = s33, s22, s23
        for i in range(3):
            SG[S33, i], SG[S33, 3 + i] = 0.0, 2.0 * v[3 + i]
            SG[S22, i], SG[S22, 3 + i] = 2.0 * v[i], 0.0
            SG[S23, i], SG[S23, 3 + i] = v[3 + i], v[i]
        _forms(SV, SG, v, 6, PR, QR, DR)
        _forms(SV, SG, v, 9, T1, T2, D2)       # a2': only D enters
        _forms(SV, SG, v, 12, P3, Q3, D3)
        _prod(SV, SG, T1, S33, S22)
        _prod(SV, SG, T2, S23, S23)
        _lin(SV, SG, N2, 1.0, T1, -1.0, T2)
        n2 = SV[N2]
        m = np.sqrt(s33)
        n = np.sqrt(n2)
        _chain(SV, SG, M, S33, m, 0.5 / m)
        _chain(SV, SG, IM, S33, 1.0 / m, -0.5 / (m * s33))
        _chain(SV, SG, IN, N2, 1.0 / n, -0.5 / (n * n2))
        _chain(SV, SG, IN2, N2, 1.0 / n2, -1.0 / (n2 * n2))
        for oU, oP, oQ in ((UR, PR, QR), (U3, P3, Q3)):      # U_w = s33 P_w - s23 Q_w
            _prod(SV, SG, T1, S33, oP)
            _prod(SV, SG, T2, S23, oQ)
            _lin(SV, SG, oU, 1.0, T1, -1.0, T2)
        im, i_n, in2 = SV[IM], SV[IN], SV[IN2]
        imn = im * i_n
        eps[0] += SV[DR] * i_n
        eps[1] += SV[UR] * imn
        eps[2] += SV[QR] * im
        eps[3] -= SV[U3] * im * imn
        eps[4] += SV[D3] * imn
        eps[5] += (s23 * SV[D3] * im - m * SV[D2]) * in2
    W = 0.0
    for k in range(9):
        sig[k] = Dw[k] * eps[k]
        W += 0.5 * sig[k] * eps[k]
    for i in range(3):          # cross-section strains: d(s22 / 2) = a2, d(s33 / 2) = a3, d s23 = (a3, a2)
        g[i] = sig[6] * v[i] + sig[8] * v[3 + i]
        g[3 + i] = sig[7] * v[3 + i] + sig[8] * v[i]
    if not need_frame:
        return W
    # slopes: d psi / dp, psi = sum_k<6 sig_k eps_k, the chain of _slope_hessian to first order
    _prod(SV, SG, T1, IM, U3)
    _lin(SV, SG, Y, sig[1], UR, -sig[3], T1)
    _prod(SV, SG, IMD3, IM, D3)
    _prod(SV, SG, T1, IM, Y)
    _lin(SV, SG, Z, sig[0], DR, sig[4], IMD3)
    _lin(SV, SG, Z, 1.0, Z, 1.0, T1)
    _prod(SV, SG, PSI, IN, Z)
    _prod(SV, SG, T1, IM, QR)
    _lin(SV, SG, PSI, 1.0, PSI, sig[2], T1)
    _prod(SV, SG, T1, S23, IMD3)
    _prod(SV, SG, T2, M, D2)
    _lin(SV, SG, T1, 1.0, T1, -1.0, T2)
    _prod(SV, SG, T2, IN2, T1)
    _lin(SV, SG, PSI, 1.0, PSI, sig[5], T2)
    for k in range(NP):
        g[k] += SG[PSI, k]
    # derivative blocks: d psi / dw is linear in the frame's values
    c0 = v[1] * v[5] - v[2] * v[4]           # a2 x a3 = n e1
    c1 = v[2] * v[3] - v[0] * v[5]
    c2 = v[0] * v[4] - v[1] * v[3]
    a_r, b_r, c_r = sig[0] * i_n, sig[1] * imn, sig[2] * im                    # r': Gamma_1..3
    a_3, b_3 = sig[4] * imn + sig[5] * s23 * im * in2, -sig[3] * im * imn      # a3': kappa_2, 3 and kappa_1
    a_2 = -sig[5] * m * in2                                                     # a2': kappa_3
    for i, ci in ((0, c0), (1, c1), (2, c2)):
        u = s33 * v[i] - s23 * v[3 + i]          # m n e2
        g[6 + i] = a_r * ci + b_r * u + c_r * v[3 + i]
        g[9 + i] = a_2 * ci
        g[12 + i] = a_3 * ci + b_3 * u
    return W
