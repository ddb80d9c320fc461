"""The rows of every joint of a system, evaluated on fixed sparse patterns without per-row Python work.

:class:`ConstraintSet` turns :class:`~ancfdae.joints.rows.Rows` (form (R) there) into flat arrays once:
the linear part as a CSR matrix, the quadratic parts as entries ``(i, j, k, a)`` meaning
``g_i += a q_j q_k / 2`` (both triangles of the symmetric ``A_i``), and the rheonomic terms. Then

* ``g = B q + c + 1/2 sum a q_j q_k + sum_j phi_j(t) (B_j q + c_j)``,
* ``G = B + sum_j phi_j B_j`` plus ``a q_k`` in entry ``(i, j)``: a ``bincount`` into G's fixed data array,
* ``H(lam) = d(G^T lam)/dq``: ``lam_i a`` in entry ``(j, k)``, constant in ``q``,
* ``Z(v) = d(G v)/dq``: ``a v_k`` in entry ``(i, j)``, on G's pattern,
* ``g_t``, ``G_t``, ``g_tt`` from ``phi'``, ``phi''``; ``gamma = -(Z(v) v + 2 G_t v + g_tt)`` (the
  acceleration constraint ``G a = gamma``).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.joints.rows import Rows

__all__ = ["ConstraintSet"]


def _slots(pattern: sp.csr_matrix, r: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Index into ``pattern.data`` of each entry ``(r, c)`` (all present in the pattern)."""
    lookup = sp.csr_matrix((np.arange(pattern.nnz, dtype=float) + 1, pattern.indices, pattern.indptr),
                           shape=pattern.shape)
    if r.size == 0:
        return np.zeros(0, dtype=np.int64)
    s = np.asarray(lookup[r, c]).ravel().astype(np.int64) - 1
    if np.any(s < 0):
        raise RuntimeError("an entry fell outside the fixed pattern")   # a bug, not user input
    return s


def _pattern(shape, r, c) -> sp.csr_matrix:
    P = sp.csr_matrix((np.ones(r.size), (r, c)), shape=shape)
    P.sum_duplicates()
    P.sort_indices()
    P.data[:] = 0.0
    return P


class ConstraintSet:
    """All joint rows of a system on fixed patterns (see the module docstring).

    Parameters
    ----------
    rows : Rows
        Every joint's rows, concatenated.
    """

    def __init__(self, rows: Rows) -> None:
        n, m = rows.n, rows.m
        self.n, self.m = n, m
        self.labels = tuple(rows.labels)
        B = sp.vstack(rows.b, format="csr") if m else sp.csr_matrix((0, n))
        self.B = sp.csr_matrix(B)
        self.c = np.array(rows.c, dtype=float)
        I, J, K, V = [], [], [], []
        for i, A in enumerate(rows.A):
            if A is not None:
                Ac = A.tocoo()
                I.append(np.full(Ac.nnz, i))
                J.append(Ac.row)
                K.append(Ac.col)
                V.append(Ac.data)
        cat = (lambda x, dt: np.concatenate(x).astype(dt) if x else np.zeros(0, dt))
        self.qi, self.qj, self.qk, self.qa = cat(I, np.int64), cat(J, np.int64), cat(K, np.int64), cat(V, float)
        # rheonomic terms on full rows: (phi, B_j (m, n), c_j (m,))
        self.timed = []
        for idx, term in rows.timed:
            Bt = sp.csr_matrix(term.B).tocoo()
            Bm = sp.csr_matrix((Bt.data, (np.asarray(idx)[Bt.row], Bt.col)), shape=(m, n))
            cm = np.zeros(m)
            cm[idx] = term.c
            self.timed.append((term.phi, Bm, cm))
        self.rheonomic = bool(self.timed)
        # G's pattern: the linear part, every timed B_j (structurally, whatever phi(t) is) and the quadratic rows
        Bc = self.B.tocoo()
        rs = [Bc.row, self.qi] + [Bj.tocoo().row for _, Bj, _ in self.timed]
        cs = [Bc.col, self.qj] + [Bj.tocoo().col for _, Bj, _ in self.timed]
        self.G_pattern = _pattern((m, n), np.concatenate(rs).astype(np.int64), np.concatenate(cs).astype(np.int64))
        nnz = self.G_pattern.nnz
        self._B_data = np.bincount(_slots(self.G_pattern, Bc.row, Bc.col), weights=Bc.data, minlength=nnz)
        self._timed_data = []
        for _, Bj, _ in self.timed:
            bc = Bj.tocoo()
            self._timed_data.append(np.bincount(_slots(self.G_pattern, bc.row, bc.col), weights=bc.data,
                                                minlength=nnz))
        self._q_slot = _slots(self.G_pattern, self.qi, self.qj)
        self._BT = sp.csr_matrix(self.B.T)
        self._timed_T = [sp.csr_matrix(Bj.T) for _, Bj, _ in self.timed]
        self.H_pattern = _pattern((n, n), self.qj, self.qk)
        self._h_slot = _slots(self.H_pattern, self.qj, self.qk)
        self._flatten()

    def _flatten(self) -> None:
        """Every linear entry and constant of (R) as one list with a *term* index: term 0 is the scleronomic
        part (weight 1), term ``j + 1`` the rheonomic ``phi_j(t)`` (weights: :meth:`weights`). The compiled
        twin (:mod:`.assembled_numba`) evaluates every quantity from these arrays in one pass."""
        lin = [(0, self.B.tocoo())] + [(j + 1, sp.coo_matrix(Bj)) for j, (_, Bj, _) in enumerate(self.timed)]
        self.lin_term = np.concatenate([np.full(C.nnz, k, dtype=np.int64) for k, C in lin])
        self.lin_row = np.concatenate([C.row.astype(np.int64) for _, C in lin])
        self.lin_col = np.concatenate([C.col.astype(np.int64) for _, C in lin])
        self.lin_val = np.concatenate([C.data.astype(float) for _, C in lin])
        self.lin_slot = _slots(self.G_pattern, self.lin_row, self.lin_col)
        consts = [(0, self.c)] + [(j + 1, cj) for j, (_, _, cj) in enumerate(self.timed)]
        nz = [(k, np.flatnonzero(c), c) for k, c in consts]
        self.const_term = np.concatenate([np.full(i.size, k, dtype=np.int64) for k, i, _ in nz])
        self.const_row = np.concatenate([i.astype(np.int64) for _, i, _ in nz])
        self.const_val = np.concatenate([c[i] for _, i, c in nz]).astype(float)

    def weights(self, t: float) -> np.ndarray:
        """``w`` (3, 1 + number of timed terms): row ``d`` the ``d``-th time derivative of each term's factor
        (term 0 is 1, so its derivatives are 0)."""
        w = np.zeros((3, 1 + len(self.timed)))
        w[0, 0] = 1.0
        for j, ph in enumerate(self._phis(t)):
            w[:, j + 1] = ph
        return w

    def weight_table(self, times: np.ndarray, derivatives: bool = False) -> np.ndarray:
        """Row 0 of :meth:`weights` at each of ``times``, shape (k, 1 + number of timed terms); with
        ``derivatives`` every row, (k, 3, 1 + number of timed terms).

        A time function that offers ``table(times) -> (k, 3)`` (:class:`~ancfdae.joints.Prescribed`'s: one call of
        the user's function per time, shared by its terms) is evaluated through it; any other at each time."""
        times = np.asarray(times, dtype=float)
        w = np.zeros((times.size, 3, 1 + len(self.timed)))
        w[:, 0, 0] = 1.0
        for j, (phi, _, _) in enumerate(self.timed):
            table = getattr(phi, "table", None)
            w[:, :, j + 1] = (table(times) if table is not None
                              else [np.asarray(phi(t), dtype=float).reshape(3) for t in times])
        return w if derivatives else np.ascontiguousarray(w[:, 0])

    # -- evaluation ----------------------------------------------------------------------------
    def _csr(self, pattern, data):
        return sp.csr_matrix((data, pattern.indices, pattern.indptr), shape=pattern.shape)

    def _phis(self, t):
        return [np.asarray(phi(t), dtype=float) for phi, _, _ in self.timed]

    def g(self, t: float, q: np.ndarray) -> np.ndarray:
        """``g(t, q)``, shape (m,)."""
        g = self.B @ q + self.c
        if self.qa.size:
            g += 0.5 * np.bincount(self.qi, weights=self.qa * q[self.qj] * q[self.qk], minlength=self.m)
        for (_, Bj, cj), ph in zip(self.timed, self._phis(t)):
            g += ph[0] * (Bj @ q + cj)
        return g

    def G(self, t: float, q: np.ndarray) -> sp.csr_matrix:
        """``G = dg/dq`` on the fixed pattern, shape (m, n)."""
        data = self._B_data.copy()
        if self.qa.size:
            data += np.bincount(self._q_slot, weights=self.qa * q[self.qk], minlength=data.size)
        for d, ph in zip(self._timed_data, self._phis(t)):
            data += ph[0] * d
        return self._csr(self.G_pattern, data)

    def force(self, t: float, q: np.ndarray, lam: np.ndarray) -> np.ndarray:
        """``G(t, q)^T lam`` without forming ``G`` (the residuals' term, once per Newton iteration)."""
        f = self._BT @ lam
        if self.qa.size:
            f += np.bincount(self.qj, weights=self.qa * lam[self.qi] * q[self.qk], minlength=self.n)
        for BjT, ph in zip(self._timed_T, self._phis(t)):
            f += ph[0] * (BjT @ lam)
        return f

    def H(self, lam: np.ndarray) -> sp.csr_matrix:
        """``d(G^T lam)/dq = sum_i lam_i A_i`` on the fixed pattern, shape (n, n)."""
        data = np.bincount(self._h_slot, weights=self.qa * lam[self.qi], minlength=self.H_pattern.nnz)
        return self._csr(self.H_pattern, data)

    def Z(self, v: np.ndarray) -> sp.csr_matrix:
        """``Z(v) = d(G v)/dq`` on G's pattern."""
        data = np.bincount(self._q_slot, weights=self.qa * v[self.qk], minlength=self.G_pattern.nnz)
        return self._csr(self.G_pattern, data)

    def time_derivatives(self, t: float, q: np.ndarray):
        """``(g_t (m,), G_t (m, n) on G's pattern, g_tt (m,))``."""
        g_t, g_tt = np.zeros(self.m), np.zeros(self.m)
        Gt = np.zeros(self.G_pattern.nnz)
        for (_, Bj, cj), d, ph in zip(self.timed, self._timed_data, self._phis(t)):
            lin = Bj @ q + cj
            g_t += ph[1] * lin
            g_tt += ph[2] * lin
            Gt += ph[1] * d
        return g_t, self._csr(self.G_pattern, Gt), g_tt

    def rates(self, t: float, q: np.ndarray, v: np.ndarray):
        """``(g_t, gamma)``: ``G v + g_t = 0`` and ``G a = gamma = -(Z(v) v + 2 G_t v + g_tt)``."""
        g_t, Gt, g_tt = self.time_derivatives(t, q)
        gamma = -(self.Z(v) @ v + 2.0 * (Gt @ v) + g_tt)
        return g_t, gamma

    def velocity_jacobian(self, t: float, q: np.ndarray, v: np.ndarray) -> sp.csr_matrix:
        """``d(G v + g_t)/dq = Z(v) + G_t`` on G's pattern."""
        _, Gt, _ = self.time_derivatives(t, q)
        return self._csr(self.G_pattern, self.Z(v).data + Gt.data)
