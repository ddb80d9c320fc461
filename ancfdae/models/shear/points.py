"""The points of the SQ2D and SQ3D elements (chapter Sect. 4): rules, shape functions and the local variables.

Both elements interpolate, per node, the axis position ``r`` and the
cross-section slopes ``a_k = x_{,eta_k}`` (``a_2 = x_eta``, 3D also
``a_3 = x_zeta``) with the same scalar Lagrange functions (Eqs. 104-107), so
the position field is ``x(xi, eta, zeta) = r(xi) + eta a_2(xi) + zeta a_3(xi)``.
At an axial point every strain measure depends on the *local variables*

    v = [a_2, (a_3) | r', a_2', (a_3')]          (6 in 2D, 15 in 3D)

ordered as the frame variables ``p = (a_k)`` and the derivative variables
``d = (r', a_k')``; ``v = B q_e`` with a constant matrix ``B`` per point. A
density (:mod:`.structural`, :mod:`.continuum`) returns the energy's gradient
``g`` and Hessian ``H`` in ``v``; the element force and tangent are
``sum_p B^T g`` and ``sum_p B^T H B`` (:func:`assemble`).
"""
from __future__ import annotations

import numpy as np

from ..._quadrature import gauss
from ..shapes import linear, quadratic

__all__ = ["rule", "shapes", "local_map", "local_variables", "assemble"]


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


def local_variables(N: np.ndarray, dN: np.ndarray, q: np.ndarray, dim: int, chunk: int = 2048) -> np.ndarray:
    """``v = B q_e`` at every point, shape (n_el, n_pts, n_v), with ``B`` formed for ``chunk`` elements at a time.

    Bit for bit ``einsum("epvi,ei->epv", local_map(N, dN, dim), q)`` (the same sum per element), without
    holding ``B`` for the whole mesh: 405 numbers per SQ3D point, 3.2 GB for 10^5 elements.
    """
    out = [np.einsum("epvi,ei->epv", local_map(N[i:i + chunk], dN[i:i + chunk], dim), q[i:i + chunk])
           for i in range(0, N.shape[0], chunk)]
    return np.concatenate(out) if len(out) != 1 else out[0]


def assemble(B: np.ndarray, g: np.ndarray, H: np.ndarray | None):
    """Element force ``sum_p B^T g`` and tangent ``sum_p B^T H B`` (H may be None)."""
    f = np.einsum("epvi,epv->ei", B, g)
    if H is None:
        return f, None
    Bt = np.swapaxes(B, -1, -2)
    return f, (Bt @ (H @ B)).sum(axis=1)
