"""Compiled dead-moment load of SQ2D and SQ3D at one axis point (chapter Sect. 2.2).

The same generalised force and derivative as :meth:`SQElement.moment_load`
with :meth:`SQ2D._rotation_force` / :meth:`SQ3D._rotation_force`: the virtual
rotation of the cross-section frame, ``delta phi = 1/2 e_i x delta e_i`` with
the frame of chapter Eq. 7 (3D) or ``delta phi = (a x delta a).e_z / |a|^2``
of the slope ``a = x_eta`` (2D), gives the force ``G^T M`` in the slopes ``p``
at the point; ``p`` is interpolated from the element's nodal slopes with the
Lagrange functions of chapter Eqs. 104-107, so the element force is
``N_i`` times it at node ``i``. One compiled call replaces some two hundred
small NumPy operations per load and Newton iteration.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .structural_numba import N_JETS, frame2d, frame3d
from ..jets import vector_numba as jet

__all__ = ["sq_moment_load"]


@njit(cache=True, fastmath={"contract"})
def sq_moment_load(qe, s, nodes, dim, moment, tangent):
    """Force (n_edof,) and its derivative (n_edof, n_edof) (zeros unless ``tangent``) of a dead moment.

    ``qe``: element coordinates; ``s`` in [-1, 1]; ``nodes`` 2 or 3; ``moment`` (3,) (2D: ``moment[2]``).
    """
    if nodes == 3:
        N = np.array([0.5 * s * (s - 1.0), 0.5 * s * (s + 1.0), 1.0 - s * s])
    else:
        N = np.array([0.5 - 0.5 * s, 0.5 + 0.5 * s])
    npv = dim * (dim - 1)
    order = 2 if tangent else 1
    p = np.zeros(npv)
    for i in range(nodes):
        for k in range(npv):
            p[k] += N[i] * qe[i * dim * dim + dim + k]       # node i: [r, a_2(, a_3)], slopes after r
    JV, JG, JH = np.zeros((N_JETS, 3)), np.zeros((N_JETS, 3, npv)), np.zeros((N_JETS, 3, npv, npv))
    fp = np.zeros(npv)
    Kp = np.zeros((npv, npv))
    if dim == 3:
        jet.variable(JV, JG, JH, 0, p, 0, 3, 0, order)
        jet.variable(JV, JG, JH, 1, p, 3, 3, 3, order)
        frame3d(JV, JG, JH, order, True)
        M = moment
        for e in (10, 11, 5):                              # e1, e2, e3
            # M . (e x de) = de . (M x e)
            w0 = M[1] * JV[e, 2] - M[2] * JV[e, 1]
            w1 = M[2] * JV[e, 0] - M[0] * JV[e, 2]
            w2 = M[0] * JV[e, 1] - M[1] * JV[e, 0]
            for k in range(npv):
                fp[k] += 0.5 * (JG[e, 0, k] * w0 + JG[e, 1, k] * w1 + JG[e, 2, k] * w2)
            if tangent:
                for k in range(npv):
                    for l in range(npv):
                        # w . d2e + de_k . (M x de_l)
                        m0 = M[1] * JG[e, 2, l] - M[2] * JG[e, 1, l]
                        m1 = M[2] * JG[e, 0, l] - M[0] * JG[e, 2, l]
                        m2 = M[0] * JG[e, 1, l] - M[1] * JG[e, 0, l]
                        Kp[k, l] += 0.5 * (w0 * JH[e, 0, k, l] + w1 * JH[e, 1, k, l] + w2 * JH[e, 2, k, l]
                                           + JG[e, 0, k] * m0 + JG[e, 1, k] * m1 + JG[e, 2, k] * m2)
    else:
        jet.variable(JV, JG, JH, 0, p, 0, 2, 0, order)
        frame2d(JV, JG, JH, order, True)
        Mz = moment[2]
        for k in range(2):
            fp[k] = Mz * JV[8, k]                          # (-a_y, a_x) / a.a
            if tangent:
                for l in range(2):
                    Kp[k, l] = Mz * JG[8, k, l]
    nedof = nodes * dim * dim
    f = np.zeros(nedof)
    K = np.zeros((nedof, nedof))
    for i in range(nodes):
        for k in range(npv):
            f[i * dim * dim + dim + k] += N[i] * fp[k]
            if tangent:
                for j in range(nodes):
                    for l in range(npv):
                        K[i * dim * dim + dim + k, j * dim * dim + dim + l] += N[i] * N[j] * Kp[k, l]
    return f, K
