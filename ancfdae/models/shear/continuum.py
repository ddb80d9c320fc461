"""The continuum-mechanics energy density of SQ2D and SQ3D in NumPy, vectorised over points (chapter Sect. 4.2.1).

St. Venant-Kirchhoff on the Green strain (Eqs. 13, 28-33), integrated over the
cross-section by points, with its exact gradient and Hessian in the local
variables of :mod:`.points`. The compiled twin is :mod:`.continuum_numba`.
"""
from __future__ import annotations

import numpy as np

__all__ = ["voigt", "continuum_kernel"]


def voigt(dim: int) -> tuple[list[tuple[int, int]], np.ndarray]:
    """Voigt pairs (chapter Eqs. 31-32) and the tensor ``T[alpha, c, b]`` with ``eps_alpha = T:C / 2``.

    ``C = X^T X`` is the metric; normal components get ``C_aa / 2`` and shear
    components the engineering strain ``C_ab = 2 E_ab``.
    """
    pairs = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)] if dim == 3 else [(0, 0), (1, 1), (0, 1)]
    T = np.zeros((len(pairs), dim, dim))
    for a, (i, j) in enumerate(pairs):
        T[a, i, j] = T[a, j, i] = 1.0
    return pairs, T


def continuum_kernel(v: np.ndarray, dim: int, Pc: np.ndarray, ws: np.ndarray, Ds: np.ndarray,
                     ref: np.ndarray, wax: np.ndarray, order: int):
    """St. Venant-Kirchhoff energy (Eqs. 28-33) integrated over the cross-section by points.

    At section point ``s`` the convected gradient ``X = [x_xi, x_eta(, x_zeta)]``
    is ``X_c = sum_B Pc[s, c, B] v_B``; the Green strain (Eq. 13) in Voigt form
    is ``eps = T:(X^T X)/2 - ref``, the stress ``sig = Ds[s] eps`` (Eq. 33).

    Parameters
    ----------
    v : (P, n_v) local variables; Pc : (S, dim, n_blocks); ws : (S,) section weights;
    Ds : (S, n_voigt, n_voigt); ref : (P, S, n_voigt); wax : (P,) axial weights.

    Returns
    -------
    W : (P,), g : (P, n_v) or None, H : (P, n_v, n_v) or None
    """
    P = v.shape[0]
    _, T = voigt(dim)
    vb = v.reshape(P, -1, dim)                                     # (P, blocks, dim)
    X = np.einsum("scb,pbi->psic", Pc, vb)                         # (P, S, dim, dim): X[i, c]
    C = np.einsum("psic,psid->pscd", X, X)
    eps = 0.5 * np.einsum("acd,pscd->psa", T, C) - ref
    w = wax[:, None] * ws[None, :]                                 # (P, S)
    sig = np.einsum("sab,psb->psa", Ds, eps)
    W = 0.5 * np.einsum("ps,psa,psa->p", w, sig, eps)
    if order == 0:
        return W, None, None
    Bm = np.einsum("acb,psib->psaic", T, X)                        # d eps_a / d X_ic
    S = np.einsum("psa,acd->pscd", sig, T)                         # 2nd Piola-Kirchhoff stress S_cd
    gX = np.einsum("psa,psaic->psic", sig, Bm)
    g = np.einsum("ps,scb,psic->pbi", w, Pc, gX).reshape(P, -1)
    if order == 1:
        return W, g, None
    HX = (np.einsum("ij,pscd->psicjd", np.eye(dim), S)
          + np.einsum("psaic,sab,psbjd->psicjd", Bm, Ds, Bm))
    H = np.einsum("ps,scb,sde,psicjd->pbiej", w, Pc, Pc, HX).reshape(P, v.shape[1], v.shape[1])
    return W, g, H
