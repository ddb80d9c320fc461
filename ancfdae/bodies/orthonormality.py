"""The orthonormality constraints of a rigid body's directors, the ``"constraints"`` capability of a body.

The directors ``d_1 .. d_dim`` of a rigid body in natural coordinates (Betsch & Steinmann 2001) stay an
orthonormal frame through ``dim (dim + 1) / 2`` quadratic constraints, in this order::

    g_ii = 1/2 (d_i . d_i - 1)      (i = 1 .. dim)
    g_ij = d_i . d_j                (i < j: (1,2) in 2D; (1,2), (1,3), (2,3) in 3D)

Each row is ``1/2 q^T A q + c`` with a constant symmetric ``A``: the Jacobian ``G`` is linear in ``q``
on a fixed pattern, ``d(G^T lambda)/dq = sum lambda_i A_i`` does not depend on ``q`` (the midpoint ``G`` is
an exact discrete derivative, so energy-momentum schemes keep these constraints to round-off), and the
acceleration constraint ``G a = gamma`` has ``gamma_i = -v^T A_i v``. No constraint depends on time.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["Orthonormality"]


class Orthonormality:
    """The constraints of the module docstring on a body with ``dim`` directors after its reference point.

    Parameters
    ----------
    dim : int
        2 or 3; the coordinates are ``q = (x, d_1, ..., d_dim)``, each a ``dim``-vector.
    """

    def __init__(self, dim: int) -> None:
        self.dim = dim
        self.n_dof = dim * (dim + 1)
        pairs = [(i, i) for i in range(dim)] + [(i, j) for i in range(dim) for j in range(i + 1, dim)]
        self.pairs = tuple(pairs)
        self.n_constraints = len(pairs)
        self.labels = tuple(f"|d{i + 1}| = 1" if i == j else f"d{i + 1} . d{j + 1} = 0" for i, j in pairs)
        self._i = np.array([p[0] for p in pairs])
        self._j = np.array([p[1] for p in pairs])
        self._diag = self._i == self._j
        # G's pattern: row (i, i) holds d_i in block i; row (i, j) holds d_j in block i and d_i in block j.
        cols, src = [], []
        for i, j in pairs:
            blocks = [(i, i)] if i == j else [(i, j), (j, i)]   # (column block, director whose entries go there)
            for block, director in blocks:
                cols.append(self._slots(block))
                src.append(self._slots(director))
        counts = [dim if i == j else 2 * dim for i, j in pairs]
        self._G_indices = np.concatenate(cols)
        self._G_indptr = np.concatenate(([0], np.cumsum(counts)))
        self._G_src = np.concatenate(src)
        # H(lambda) = sum lambda_r A_r: the identity blocks (i, j) and (j, i) scaled by lambda_(ij), 1x on (i, i).
        rows, hcols, which = [], [], []
        for r, (i, j) in enumerate(pairs):
            for a, b in ([(i, i)] if i == j else [(i, j), (j, i)]):
                rows.append(self._slots(a))
                hcols.append(self._slots(b))
                which.append(np.full(dim, r))
        rows, hcols, which = np.concatenate(rows), np.concatenate(hcols), np.concatenate(which)
        # Its CSR pattern once (every (row, column) occurs once): the data are lambda gathered in CSR order.
        order = sp.csr_matrix((np.arange(1.0, rows.size + 1), (rows, hcols)), shape=(self.n_dof, self.n_dof))
        self._H_indices, self._H_indptr = order.indices, order.indptr
        self._H_which = which[order.data.astype(np.int64) - 1]

    def _slots(self, k: int) -> np.ndarray:
        """Coordinate indices of director ``k`` (0-based)."""
        return self.dim * (k + 1) + np.arange(self.dim)

    def _directors(self, q: np.ndarray) -> np.ndarray:
        return q[self.dim:].reshape(self.dim, self.dim)

    def constraints(self, t: float, q: np.ndarray) -> np.ndarray:
        """``g(q)``, shape (n_constraints,)."""
        d = self._directors(q)
        g = np.einsum("rk,rk->r", d[self._i], d[self._j])
        g[self._diag] = 0.5 * (g[self._diag] - 1.0)
        return g

    def constraint_jacobian(self, t: float, q: np.ndarray) -> sp.csr_matrix:
        """``G = dg/dq`` (n_constraints, n_dof) on its fixed pattern."""
        return sp.csr_matrix((q[self._G_src], self._G_indices, self._G_indptr),
                             shape=(self.n_constraints, self.n_dof))

    def constraint_force(self, t: float, q: np.ndarray, lam: np.ndarray) -> np.ndarray:
        """``G^T lambda`` (n_dof,) without forming ``G``: row (i, j) adds ``lambda d_j`` to block i and, if
        ``i != j``, ``lambda d_i`` to block j (a residual is evaluated every Newton iteration; building the
        sparse ``G`` there cost about half of a slider-crank step)."""
        d = self._directors(q)
        f = np.zeros((self.dim + 1, self.dim))
        lam = np.asarray(lam, dtype=float)
        np.add.at(f, self._i + 1, lam[:, None] * d[self._j])
        off = ~self._diag
        np.add.at(f, self._j[off] + 1, lam[off, None] * d[self._i[off]])
        return f.ravel()

    def constraint_force_jacobian(self, t: float, q: np.ndarray, lam: np.ndarray) -> sp.csr_matrix:
        """``d(G^T lambda)/dq = sum lambda_r A_r`` (n_dof, n_dof), independent of ``q``."""
        return sp.csr_matrix((np.asarray(lam, dtype=float)[self._H_which], self._H_indices, self._H_indptr),
                             shape=(self.n_dof, self.n_dof))

    def quadratic_form(self) -> tuple[list, sp.csr_matrix, np.ndarray]:
        """The rows as ``g_r = 1/2 q^T A_r q + b_r . q + c_r``: ``([A_r], b (m, n_dof), c)``, all constant.

        ``A_r`` holds identity blocks: on the director block ``(i, i)`` for ``g_ii`` (``c = -1/2``), on
        ``(i, j)`` and ``(j, i)`` for ``g_ij`` (``c = 0``); ``b = 0``. A :class:`ancfdae.System` evaluates these
        with its joints' rows in one compiled pass (:mod:`ancfdae.joints.assembled_numba`).
        """
        eye, A = np.ones(self.dim), []
        for i, j in self.pairs:
            r = np.concatenate([self._slots(i), self._slots(j)]) if i != j else self._slots(i)
            c = np.concatenate([self._slots(j), self._slots(i)]) if i != j else self._slots(i)
            A.append(sp.csr_matrix((np.concatenate([eye] * (r.size // self.dim)), (r, c)),
                                   shape=(self.n_dof, self.n_dof)))
        c = np.where(self._diag, -0.5, 0.0)
        return A, sp.csr_matrix((self.n_constraints, self.n_dof)), c

    def constraint_rates(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(g_t, gamma)``: zero (no time dependence) and ``gamma_r = -v^T A_r v``."""
        dv = self._directors(v)
        z = np.einsum("rk,rk->r", dv[self._i], dv[self._j])
        z[~self._diag] *= 2.0
        return np.zeros(self.n_constraints), -z
