"""Kernels shared by the SQ2D and SQ3D elements (chapter Sect. 4), vectorised over elements x points.

Both elements interpolate, per node, the axis position ``r`` and the
cross-section slopes ``a_k = x_{,eta_k}`` (``a_2 = x_eta``, 3D also
``a_3 = x_zeta``) with the same scalar Lagrange functions (Eqs. 104-107), so
the position field is ``x(xi, eta, zeta) = r(xi) + eta a_2(xi) + zeta a_3(xi)``.
At an axial point every strain measure depends on the *local variables*

    v = [a_2, (a_3) | r', a_2', (a_3')]          (6 in 2D, 15 in 3D)

ordered as the frame variables ``p = (a_k)`` and the derivative variables
``d = (r', a_k')``; ``v = B q_e`` with a constant matrix ``B`` per point. A
kernel returns the energy density's gradient ``g`` and Hessian ``H`` in ``v``;
the element force and tangent are ``sum_p B^T g`` and ``sum_p B^T H B``.
"""
from __future__ import annotations

import numpy as np

from ..jets import vector as jet
from ..._quadrature import gauss
from ..shapes import linear, quadratic

__all__ = ["rule", "local_map", "assemble", "structural_kernel", "continuum_kernel", "voigt"]


def rule(kind: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Points and weights on [-1, 1]: ``("gauss", n)`` or ``("lobatto", n)`` (n >= 2, end points included)."""
    if kind == "gauss":
        return gauss(n)
    # Gauss-Lobatto: end points and the roots of P'_{n-1}; weights 2 / (n (n-1) P_{n-1}(x)^2).
    P = np.polynomial.legendre.Legendre.basis(n - 1)
    s = np.concatenate([[-1.0], np.sort(P.deriv().roots().real), [1.0]])
    return s, 2.0 / (n * (n - 1) * P(s) ** 2)


def shapes(n_nodes: int, s, lengths):
    """Scalar shape functions and xi-derivatives, (n_el, n_pts, n_nodes), node order (A, B[, C])."""
    return (quadratic if n_nodes == 3 else linear)(s, lengths)


def local_map(N: np.ndarray, dN: np.ndarray, dim: int) -> np.ndarray:
    """The matrix ``B`` with ``v = B q_e`` at every point, shape (n_el, n_pts, n_v, n_edof).

    Node coordinates are ``[r, a_2(, a_3)]`` (``dim`` components each); see the
    module docstring for the order of ``v``.
    """
    n_el, n_pts, nn = N.shape
    nvec = dim                        # vectors per node: r and dim-1 slopes
    blocks = [(k, N) for k in range(1, nvec)] + [(0, dN)] + [(k, dN) for k in range(1, nvec)]
    B = np.zeros((n_el, n_pts, len(blocks) * dim, nn * nvec * dim))
    eye = np.eye(dim)
    for b, (vec, S) in enumerate(blocks):
        for i in range(nn):
            col = (i * nvec + vec) * dim
            B[:, :, b * dim:(b + 1) * dim, col:col + dim] = S[:, :, i, None, None] * eye
    return B


def assemble(B: np.ndarray, g: np.ndarray, H: np.ndarray | None):
    """Element force ``sum_p B^T g`` and tangent ``sum_p B^T H B`` (H may be None)."""
    f = np.einsum("epvi,epv->ei", B, g)
    if H is None:
        return f, None
    Bt = np.swapaxes(B, -1, -2)
    return f, (Bt @ (H @ B)).sum(axis=1)


# -- structural mechanics formulation -------------------------------------------------------------
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


# -- continuum mechanics formulation --------------------------------------------------------------
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
