"""Compiled twin of :class:`~ancfdae.joints.assembled.ConstraintSet`: every quantity of rows (R) in one call.

:class:`CompiledConstraintSet` evaluates the rows from the flat arrays the reference builds once
(:meth:`ConstraintSet._flatten`): linear entries ``(term, row, col, value, slot in G)``, constants
``(term, row, value)`` and quadratic entries ``(i, j, k, a)`` (``g_i += a q_j q_k / 2``), with the term
weights ``w[d, term]`` (``d``-th time derivative of ``phi_term(t)``; term 0 is the scleronomic part) from
one Python pass over the time functions per call. Each method is one compiled loop over these entries
and, for matrices, a CSR on the reference's fixed pattern: no sparse construction, product or
``bincount`` per call. The NumPy methods of the base class stay the reference the tests hold these to.

Why: on B6 (slider-crank, 8 BE2D elements, 48 coordinates, 14 rows) the NumPy reference took 0.13 ms for
``G^T lam``, 0.20 ms for ``g`` and 0.57 ms for ``G`` (body by body, sparse products, one Python call per time
function each), several times the beam's own residual (0.01 ms); a generalized-alpha index-3 run spent
most of its time there (``python -m benchmarks.multibody_vs_exudyn``, profile in the issue's note).
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp
from numba import njit

from ancfdae.joints.assembled import ConstraintSet
from ancfdae._csr import fast_csr

__all__ = ["CompiledConstraintSet"]


@njit(cache=True)
def _g_force(w, lt, lr, lc, lv, ct, cr, cv, qi, qj, qk, qa, q, lam, g, f):
    """``g(t, q)`` into ``g`` and ``G(t, q)^T lam`` into ``f`` (both overwritten); ``w`` the weights' row 0."""
    g[:] = 0.0
    f[:] = 0.0
    for e in range(lt.size):
        c = w[lt[e]] * lv[e]
        g[lr[e]] += c * q[lc[e]]
        f[lc[e]] += c * lam[lr[e]]
    for e in range(ct.size):
        g[cr[e]] += w[ct[e]] * cv[e]
    for e in range(qi.size):
        g[qi[e]] += 0.5 * qa[e] * q[qj[e]] * q[qk[e]]
        f[qj[e]] += qa[e] * lam[qi[e]] * q[qk[e]]


@njit(cache=True)
def _jacobian_data(w, lt, ls, lv, qslot, qk, qa, x, out):
    """Data of ``sum_term w[term] B_term + sum a x_k`` on G's pattern: ``G(t, q)`` for ``(w_0, q)``,
    ``Z(v) + G_t`` for ``(w_1, v)`` (term 0's first derivative is 0)."""
    out[:] = 0.0
    for e in range(lt.size):
        out[ls[e]] += w[lt[e]] * lv[e]
    for e in range(qk.size):
        out[qslot[e]] += qa[e] * x[qk[e]]


@njit(cache=True)
def _h_data(hslot, qi, qa, lam, out):
    """Data of ``H(lam) = sum_i lam_i A_i`` on its pattern."""
    out[:] = 0.0
    for e in range(qi.size):
        out[hslot[e]] += qa[e] * lam[qi[e]]


@njit(cache=True)
def _rates(w1, w2, lt, lr, lc, lv, ct, cr, cv, qi, qj, qk, qa, q, v, gt, gamma):
    """``g_t`` and ``gamma = -(Z(v) v + 2 G_t v + g_tt)`` (both overwritten)."""
    gt[:] = 0.0
    gamma[:] = 0.0
    for e in range(lt.size):
        i, j = lr[e], lc[e]
        gt[i] += w1[lt[e]] * lv[e] * q[j]
        gamma[i] -= lv[e] * (w2[lt[e]] * q[j] + 2.0 * w1[lt[e]] * v[j])
    for e in range(ct.size):
        gt[cr[e]] += w1[ct[e]] * cv[e]
        gamma[cr[e]] -= w2[ct[e]] * cv[e]
    for e in range(qi.size):
        gamma[qi[e]] -= qa[e] * v[qj[e]] * v[qk[e]]


@njit(cache=True)
def _position_terms(w0, w1, lt, lr, lc, ls, lv, ct, cr, cv, qi, qj, qk, qa, qslot, q, g, gt, gdata):
    """``g``, ``g_t`` and ``G``'s data at one state (a GGL stage's rows), overwritten."""
    g[:] = 0.0
    gt[:] = 0.0
    gdata[:] = 0.0
    for e in range(lt.size):
        x = lv[e] * q[lc[e]]
        g[lr[e]] += w0[lt[e]] * x
        gt[lr[e]] += w1[lt[e]] * x
        gdata[ls[e]] += w0[lt[e]] * lv[e]
    for e in range(ct.size):
        g[cr[e]] += w0[ct[e]] * cv[e]
        gt[cr[e]] += w1[ct[e]] * cv[e]
    for e in range(qi.size):
        g[qi[e]] += 0.5 * qa[e] * q[qj[e]] * q[qk[e]]
        gdata[qslot[e]] += qa[e] * q[qk[e]]


class CompiledConstraintSet(ConstraintSet):
    """The rows of :class:`ConstraintSet`, evaluated by the compiled loops of the module docstring.

    Parameters
    ----------
    rows : Rows
        Every row, concatenated (a System's bodies' rows and its joints').
    """

    def __init__(self, rows) -> None:
        super().__init__(rows)
        self._lin = (self.lin_term, self.lin_row, self.lin_col, self.lin_val)
        self._const = (self.const_term, self.const_row, self.const_val)
        self._quad = (self.qi, self.qj, self.qk, self.qa)

    def _csr(self, pattern, data):
        # the pattern is canonical and fixed: skip scipy's format checks (~25 us a matrix)
        return fast_csr(data, pattern.indices, pattern.indptr, pattern.shape)

    def terms_at(self, t: float) -> Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
        """``(q, lam) -> (g(t, q), G(t, q)^T lam)`` with the time functions evaluated once, at ``t`` (the
        residuals of a step's Newton iterations share its time; evaluating them cost 8-15 us a call on B6)."""
        w, args = self.weights(t)[0], (*self._lin, *self._const, *self._quad)
        m, n = self.m, self.n

        def terms(q, lam):
            g, f = np.empty(m), np.empty(n)
            _g_force(w, *args, np.asarray(q, dtype=float), np.asarray(lam, dtype=float), g, f)
            return g, f
        return terms

    def g_and_force(self, t: float, q: np.ndarray, lam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(g(t, q), G(t, q)^T lam)`` in one call."""
        return self.terms_at(t)(q, lam)

    def position_terms_at(self, t: float) -> Callable[[np.ndarray], tuple]:
        """``q -> (g, G, g_t)`` at ``t`` with the time functions evaluated once (a GGL stage's rows)."""
        w = self.weights(t)
        args = (w[0], w[1], self.lin_term, self.lin_row, self.lin_col, self.lin_slot, self.lin_val,
                *self._const, *self._quad, self._q_slot)
        m, nnz, pattern = self.m, self.G_pattern.nnz, self.G_pattern

        def terms(q):
            g, gt, data = np.empty(m), np.empty(m), np.empty(nnz)
            _position_terms(*args, np.asarray(q, dtype=float), g, gt, data)
            return g, self._csr(pattern, data), gt
        return terms

    def position_terms(self, t: float, q: np.ndarray) -> tuple:
        """``(g, G, g_t)`` at ``(t, q)`` in one call."""
        return self.position_terms_at(t)(q)

    def g(self, t: float, q: np.ndarray) -> np.ndarray:
        """``g(t, q)``, shape (m,)."""
        return self.g_and_force(t, q, np.zeros(self.m))[0]

    def force(self, t: float, q: np.ndarray, lam: np.ndarray) -> np.ndarray:
        """``G(t, q)^T lam``, shape (n,)."""
        return self.g_and_force(t, q, lam)[1]

    def _matrix(self, w, x):
        data = np.empty(self.G_pattern.nnz)
        _jacobian_data(w, self.lin_term, self.lin_slot, self.lin_val, self._q_slot, self.qk, self.qa,
                       np.asarray(x, dtype=float), data)
        return self._csr(self.G_pattern, data)

    def G(self, t: float, q: np.ndarray) -> sp.csr_matrix:
        """``G = dg/dq`` on the fixed pattern, shape (m, n)."""
        return self._matrix(self.weights(t)[0], q)

    def velocity_jacobian(self, t: float, q: np.ndarray, v: np.ndarray) -> sp.csr_matrix:
        """``d(G v + g_t)/dq = Z(v) + G_t`` on G's pattern."""
        return self._matrix(self.weights(t)[1], v)

    def H(self, lam: np.ndarray) -> sp.csr_matrix:
        """``d(G^T lam)/dq = sum_i lam_i A_i`` on the fixed pattern, shape (n, n)."""
        data = np.empty(self.H_pattern.nnz)
        _h_data(self._h_slot, self.qi, self.qa, np.asarray(lam, dtype=float), data)
        return self._csr(self.H_pattern, data)

    def rates(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(g_t, gamma)``: ``G v + g_t = 0`` and ``G a = gamma = -(Z(v) v + 2 G_t v + g_tt)``."""
        w = self.weights(t)
        gt, gamma = np.empty(self.m), np.empty(self.m)
        _rates(w[1], w[2], *self._lin, *self._const, *self._quad, np.asarray(q, dtype=float),
               np.asarray(v, dtype=float), gt, gamma)
        return gt, gamma
