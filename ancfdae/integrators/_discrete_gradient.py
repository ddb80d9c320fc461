"""Discrete gradients of a model's conservative potential, with their exact Jacobians.

A discrete gradient of ``P`` is a vector ``G(q0, q1)`` with ``G . (q1 - q0) = P(q1) - P(q0)``
exactly (Gonzalez, J. Nonlinear Sci. 6:449, 1996; McLachlan, Quispel, Robidoux, Phil. Trans.
R. Soc. A 357:1021, 1999) and ``G(q, q) = grad P(q)``. Two are implemented, each on the
:class:`ancfdae.problem.PotentialModel` capability:

:class:`AVFGradient`
    the average vector field ``G = int_0^1 grad P(q0 + s (q1 - q0)) ds`` (Quispel and McLaren,
    J. Phys. A 41:045206, 2008; Celledoni et al., J. Comput. Phys. 231:6770, 2012). The identity
    holds by the fundamental theorem of calculus; for a polynomial ``P`` of degree ``p`` the
    integrand is a polynomial of degree ``p - 1`` in ``s`` and an ``ceil(p/2)``-point Gauss rule
    makes it exact. It is equivariant under translations (linear momentum is kept), not under
    rotations.
:class:`GonzalezGradient`
    the midpoint gradient with Gonzalez's correction,
    ``G = grad P(m) + (P(q1) - P(q0) - grad P(m) . d) / (d . n) n``, ``m = (q0 + q1)/2``,
    ``d = q1 - q0``, for any ``P``. Here the correction direction ``n = M p`` is the
    mass-metric projection ``p`` of ``d`` off the rigid-motion directions ``T`` (translations)
    and ``A_k m`` (rotations about the midpoint configuration), so that ``n . T = 0`` and
    ``n . A_k m = 0``: with a translation- and rotation-invariant strain energy the whole
    ``G`` is then orthogonal to them, which keeps linear and angular momentum exactly
    (the plain Euclidean correction ``n = d`` breaks both; with the mass metric the
    correction is also independent of the units of positions and slopes).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae._quadrature import gauss

__all__ = ["AVFGradient", "GonzalezGradient"]

#: Below this ratio ``(d . n) / (d . M d)`` the step is a rigid motion to round-off: the
#: correction is dropped (its 0/0 coefficient is meaningless there).
RIGID_RATIO = 1e-24
#: Below this size the mass matrix is applied as a dense array.
DENSE_MAX = 400


def _sum(mats, weights):
    """``sum w_j A_j`` of sparse matrices, by their data arrays when they share one pattern."""
    first = mats[0]
    same = all(sp.isspmatrix_csr(A) and A.indptr is first.indptr and A.indices is first.indices for A in mats)
    if same:
        data = sum(w * A.data for w, A in zip(weights, mats))
        return sp.csr_matrix((data, first.indices, first.indptr), shape=first.shape)
    return sum(w * A for w, A in zip(weights, mats))


def _pinv_spd(W):
    """Pseudo-inverse of the small Gram matrix ``S^T M S``, symmetrically scaled first.

    Singular when a rotation moves nothing (a straight cable about its own axis through the
    origin): that direction is dropped (relative cutoff 1e-12).
    """
    d = np.sqrt(np.maximum(np.diag(W), 1e-300))
    Ws = W / d[:, None] / d[None, :]
    try:                                   # the usual, well-conditioned case: Cholesky (cheap)
        L = np.linalg.cholesky(Ws)
        if np.min(np.diag(L)) ** 2 > 1e-10:
            Li = np.linalg.inv(L)
            return (Li.T @ Li) / d[:, None] / d[None, :]
    except np.linalg.LinAlgError:
        pass
    lam, V = np.linalg.eigh(Ws)
    keep = lam > 1e-12 * lam.max()
    return ((V[:, keep] / lam[keep]) @ V[:, keep].T) / d[:, None] / d[None, :]


class AVFGradient:
    """Average vector field of ``P``, exact for a polynomial potential of degree ``degree``.

    Parameters
    ----------
    model : PotentialModel
    degree : int
        Polynomial degree of ``P`` in ``q`` (>= 1).
    """

    kind = "avf"

    def __init__(self, model, degree: int):
        self.model = model
        n = max(1, -(-int(degree) // 2))            # ceil(degree / 2) points: exact to degree 2n - 1
        s, w = gauss(n)
        self.s, self.w = (s + 1.0) / 2.0, w / 2.0

    def start(self, t, q0):
        """Fix the step's start ``q0`` and the time at which ``P`` is evaluated."""
        self.t, self.q0 = t, q0

    def gradient(self, x):
        """``G(q0, x)``."""
        d = x - self.q0
        return sum(w * self.model.potential_gradient(self.t, self.q0 + s * d, False)[0]
                   for s, w in zip(self.s, self.w))

    def jacobian(self, x):
        """``dG/dx = int_0^1 s K(q0 + s d) ds`` (same Gauss rule, exact for the same degree)."""
        d = x - self.q0
        Ks = [self.model.potential_gradient(self.t, self.q0 + s * d, True)[1] for s in self.s]
        return _sum(Ks, self.s * self.w)


class GonzalezGradient:
    """Gonzalez's midpoint discrete gradient, corrected along the mass-metric projection of the step.

    Parameters
    ----------
    model : PotentialModel
        With ``symmetry_generators()`` (optional; none means the plain mass-metric correction).
    M : sparse matrix
        The constant mass matrix (the metric).
    rotations : bool
        Project off the rotations too (angular momentum exact). The price: for a step that is
        nearly a rigid rotation, ``d . n`` is small while ``P(q1) - P(q0) - grad P(m) . d`` is
        not yet, so the coefficient and its derivative grow like ``1 / |p|`` and Newton
        converges more slowly. Translations are exact symmetries of ``P`` (the defect then
        vanishes to third order in ``p``) and are always projected off.
    """

    kind = "gonzalez"

    def __init__(self, model, M, rotations=True):
        self.model, self.M = model, sp.csr_matrix(M)
        gens = model.symmetry_generators() if callable(getattr(model, "symmetry_generators", None)) else None
        T, A = (np.zeros((M.shape[0], 0)), []) if gens is None else gens
        A = A if rotations else []
        self.T, self.A = np.asarray(T, dtype=float).reshape(M.shape[0], -1), list(A)
        n = M.shape[0]
        # All rotation directions A_k m in one product; a dense M on small meshes (fewer
        # NumPy/scipy calls per residual, which dominate there).
        self._A_all = sp.csr_matrix(sp.vstack(self.A)) if self.A else None
        self._Mop = self.M.toarray() if n <= DENSE_MAX else self.M
        self._MT = self._Mop @ self.T

    def start(self, t, q0):
        """Fix the step's start ``q0``; evaluates ``P(q0)`` once per step."""
        self.t, self.q0 = t, q0
        self.P0 = self.model.potential(t, q0)

    def _parts(self, x, tangent):
        m = self.model
        d = x - self.q0
        mid = self.q0 + 0.5 * d
        g, K = m.potential_gradient(self.t, mid, tangent)
        N = m.potential(self.t, x) - self.P0 - g @ d
        if self.T.size or self.A:
            if self.A:
                R = (self._A_all @ mid).reshape(len(self.A), -1).T
                S = np.hstack([self.T, R])
                MS = np.hstack([self._MT, self._Mop @ R])
            else:
                S, MS = self.T, self._MT
            Winv = _pinv_spd(S.T @ MS)
            y = Winv @ (MS.T @ d)
            p = d - S @ y
        else:
            p, y, S, MS, Winv = d, None, None, None, None
        n = self._Mop @ p
        D = float(n @ d)
        dMd = float(d @ (self._Mop @ d))
        c = N / D if D > RIGID_RATIO * dMd and D > 0.0 else 0.0
        return dict(d=d, mid=mid, g=g, K=K, N=N, S=S, MS=MS, Winv=Winv, y=y, n=n, D=D, c=c)

    def gradient(self, x):
        """``G(q0, x)``."""
        p = self._parts(x, False)
        return p["g"] + p["c"] * p["n"]

    def jacobian(self, x):
        """Exact ``dG/dx``: sparse ``K(m)/2 + c M (I - B/2)`` plus a dense part of rank ``k + 1``.

        With ``B = sum_k y_k A_k`` (``y``: the rotation part of the projection coefficients),
        ``dD/dx = 2 n + B n``, ``dN/dx = grad P(x) - grad P(m) - K(m) d / 2`` and
        ``dn/dx = M (I - B/2) - M S W^+ (S^T M (I - B/2) + R/2)`` with ``R`` the rows
        ``-(A_k n)^T`` of the rotation directions.
        """
        p = self._parts(x, True)
        d, K, n, c, D = p["d"], p["K"], p["n"], p["c"], p["D"]
        if c == 0.0:
            return 0.5 * K
        gx = self.model.potential_gradient(self.t, x, False)[0]
        dN = gx - p["g"] - 0.5 * (K @ d)
        nt = self.T.shape[1]
        if p["S"] is None:
            dD = 2.0 * n
            sparse = 0.5 * K + c * self.M
            low_u, low_v = n[:, None], ((dN - c * dD) / D)[None, :]
        else:
            yr = p["y"][nt:]
            B = sum((yk * A for yk, A in zip(yr, self.A)), sp.csr_matrix(self.M.shape))
            dD = 2.0 * n + B @ n
            MS, Winv = p["MS"], p["Winv"]
            R = np.zeros((MS.shape[1], n.size))
            for k, A in enumerate(self.A):
                R[nt + k] = -(A @ n)
            # S^T M (I - B/2) = MS^T - (B^T MS)^T / 2
            V = Winv @ (MS.T - 0.5 * (B.T @ MS).T + 0.5 * R)
            sparse = 0.5 * K + c * (self.M - 0.5 * (self.M @ B))
            low_u = np.column_stack([n, -c * MS])
            low_v = np.vstack([((dN - c * dD) / D)[None, :], V])
        return sparse.toarray() + low_u @ low_v
