"""The structural-mechanics energy density of SQ2D and SQ3D in NumPy, vectorised over points (chapter Sect. 4.2.2).

``W = 1/2 sum_k Dw_k (eps_k - ref_k)^2`` over the generalised strains of
Eqs. 16, 25, 45 and 50 (:meth:`.sq2d.SQ2D._strains`, :meth:`.sq3d.SQ3D._strains`),
with its exact gradient and Hessian in the local variables of :mod:`.points`
from vector jets. The compiled twin is :mod:`.structural_numba`.
"""
from __future__ import annotations

import numpy as np

from ..jets import vector as jet

__all__ = ["structural_kernel"]


def structural_kernel(strains, which, v: np.ndarray, dim: int, ref: np.ndarray, Dw: np.ndarray, order: int):
    """Energy, gradient and Hessian of ``W = 1/2 sum_k Dw_k (eps_k - ref_k)^2`` in the local variables.

    Parameters
    ----------
    strains : callable
        ``strains(p_jets, which) -> list`` over the strain components ``k`` in ``which`` of pairs
        ``(terms, s)``: ``eps_k = sum_(j, c) c(p) . d_j + s(p)``, with ``c`` a
        vector jet multiplying derivative block ``j`` and ``s`` a scalar jet or
        None. Every strain of chapter Eqs. 16, 25, 45 has this form: linear in
        the derivatives ``d``, nonlinear in the slopes ``p`` only.
    v : ndarray, shape (P, n_v)
    which : sequence of int
        The strain components evaluated here (those whose term uses these points).
    ref : ndarray, shape (P, n_strain)
        Raw strain values of the reference configuration (subtracted).
    Dw : ndarray, shape (P, n_strain)
        Stiffness times quadrature weight (zero where a term does not use a point).
    order : int
        0: energy only; 1: plus gradient; 2: plus Hessian.

    Returns
    -------
    W : (P,), g : (P, n_v) or None, H : (P, n_v, n_v) or None, eps : (P, n_strain)
    """
    P = v.shape[0]
    npv = dim * (dim - 1)
    pj = [jet.variable(v, k * dim, dim, k * dim, npv, order) for k in range(dim - 1)]
    d = [v[:, npv + j * dim: npv + (j + 1) * dim] for j in range(dim)]
    comps = strains(pj, which)
    raw = np.stack([sum(np.einsum("pc,pc->p", c.v, d[j]) for j, c in terms) + (s.v if s is not None else 0.0)
                    for terms, s in comps], axis=1)
    eps = raw - ref
    sig = Dw * eps
    W = 0.5 * np.einsum("pk,pk->p", sig, eps)
    if order == 0:
        return W, None, None, eps
    nv = v.shape[1]
    Jm = np.zeros((P, len(comps), nv))               # d eps / d v
    for k, (terms, s) in enumerate(comps):
        if s is not None:
            Jm[:, k, :npv] += s.g
        for j, c in terms:
            Jm[:, k, :npv] += np.einsum("pck,pc->pk", c.g, d[j])
            Jm[:, k, npv + j * dim: npv + (j + 1) * dim] += c.v
    g = np.einsum("pk,pkv->pv", sig, Jm)
    if order == 1:
        return W, g, None, eps
    H = np.swapaxes(Jm, 1, 2) @ (Dw[:, :, None] * Jm)
    # Second-derivative part sum_k sig_k d2 eps_k: combine the jets per derivative block first.
    for j in range(dim):
        ks = [(k, c) for k, (terms, _) in enumerate(comps) for jj, c in terms if jj == j]
        if not ks:
            continue
        wj = jet.combine([sig[:, k] for k, _ in ks], [c for _, c in ks])
        H[:, :npv, :npv] += np.einsum("pc,pckl->pkl", d[j], wj.h)
        blk = np.swapaxes(wj.g, 1, 2)                 # (P, n_p, dim)
        H[:, :npv, npv + j * dim: npv + (j + 1) * dim] += blk
        H[:, npv + j * dim: npv + (j + 1) * dim, :npv] += np.swapaxes(blk, 1, 2)
    quad = [(k, s) for k, (_, s) in enumerate(comps) if s is not None]
    if quad:
        H[:, :npv, :npv] += jet.combine([sig[:, k] for k, _ in quad], [s for _, s in quad]).h
    return W, g, H, eps
