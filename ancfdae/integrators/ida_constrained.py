"""IDA on constrained models: the stabilised index-2 (GGL) form, ``y = [q, v, lam, mu]``.

For a model with the ``"constraints"`` capability :class:`~ancfdae.integrators.IDA` integrates::

    F(t, y, y') = [q' - v - G^T mu ;  r(t, q, v, v') + G^T lam ;  g(t, q) ;  G v + g_t] = 0

with the multipliers ``lam`` and ``mu`` as algebraic variables (``mu`` is zero for the exact
solution; it makes the position constraint hold with the velocity constraint -- Gear, Gupta and
Leimkuhler 1985). The pure index-3 form (``g`` only) fails in IDA. Exact iteration matrix::

    dF/dy + cj dF/dy' = [[cj I - H(mu), -I,       0,   -G^T],
                         [K + H(lam),    D + cj M, G^T, 0   ],
                         [G,             0,        0,   0   ],
                         [W(v),          G,        0,   0   ]]

with ``H(x) = d(G^T x)/dq`` and ``W(v) = d(G v + g_t)/dq``
(:func:`~ancfdae.integrators._constraint_terms.velocity_constraint_jacobian`).

**The multipliers are out of IDA's error test** (absolute tolerance ``MULTIPLIER_ATOL`` on their
components; scikit-sundae exposes no ``IDASetSuppressAlg``). Why, measured on planar point-mass
chains: ``lam`` and ``mu`` are index-2 variables whose BDF error estimate is one order lower than
that of ``q`` and ``v``, so with them in the test IDA failed on a quadratic (distance) constraint
("error test failed repeatedly" at rtol 1e-4 and 1e-6) or took 25 times the steps (13,714 against
542 at 1e-5); on linear constraints it ran, at 1.4-1.6 times the steps. The price: the same weights
enter IDA's Newton convergence test, which then stops on the ``q, v`` corrections alone, so the
constraints hold only to about the position tolerance (``max |g|`` of the order of ``atol_q``, see
the tests); a tighter position ``atol`` tightens them. ``y0 = [q0, v0, lam0, 0]``,
``y'0 = [v0, a0, 0, 0]`` with ``(a0, lam0)`` from the acceleration-level KKT system (consistent: no
``calc_initcond``).

Ordering of ``y`` inside the solver (band solver): node-interleaved ``q_p, v_p`` and each
multiplier pair after the last coordinate its row of ``G`` touches, which keeps the matrix banded.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.integrators._constraint_terms import velocity_constraint_jacobian
from ancfdae.integrators.lobatto_constrained import rmatvec

__all__ = ["GGLResidual", "MULTIPLIER_ATOL"]

#: absolute tolerance of ``lam`` and ``mu``: large enough to take them out of IDA's error test
MULTIPLIER_ATOL = 1e10


def _ones(x):
    """The structure of a sparse matrix: every stored entry set to one."""
    x = sp.csr_matrix(x, copy=True)
    x.data[:] = 1.0
    return x


class GGLResidual:
    """The GGL residual and iteration matrix of :class:`~ancfdae.integrators.IDA` for a constrained model.

    Parameters
    ----------
    model : Model with the ``"constraints"`` capability (the stepper's counting proxy)
    t0 : float
    q0, v0, a0 : ndarray, shape (n,)
    lam0 : ndarray, shape (m,)
    linsolver : {"band", "dense", "sparse"}

    Attributes
    ----------
    N : int
        ``2 n + 2 m``.
    perm : ndarray
        ``y_solver = y_natural[perm]`` (the natural order is ``[q, v, lam, mu]``).
    bandwidth : int
        Half bandwidth of the iteration matrix in the solver's ordering.
    pattern : scipy.sparse.csc_matrix
        The iteration matrix's pattern in the solver's ordering (for ``linsolver="sparse"``).
    """

    def __init__(self, model, t0, q0, v0, a0, lam0, linsolver: str) -> None:
        self.model = model
        n, m = q0.size, int(model.n_constraints)
        self.n, self.m, self.N, self.linsolver = n, m, 2 * n + 2 * m, linsolver
        G = sp.csr_matrix(model.constraint_jacobian(t0, q0))
        last = np.full(m, float(n))
        for i in range(m):
            cols = G.indices[G.indptr[i]:G.indptr[i + 1]]
            if cols.size:
                last[i] = cols.max() + 0.5
        keys = np.r_[np.arange(n), np.arange(n) + 0.25, last, last + 0.01]
        self.perm = np.argsort(keys, kind="stable")
        self.inv = np.empty(self.N, dtype=np.int64)
        self.inv[self.perm] = np.arange(self.N)
        # pattern: the structure at t0 with every block present (values set to ones)
        J = self._natural(t0, q0, v0, a0, lam0 + 1.0, np.ones(m), 1.0, ones=True).tocoo()
        r, c = self.inv[J.row], self.inv[J.col]
        self.bandwidth = int(np.max(np.abs(r - c))) if r.size else 0
        P = sp.csc_matrix((np.ones(r.size), (r, c)), shape=(self.N, self.N))
        P.sum_duplicates()
        P.sort_indices()
        self.pattern = P
        self._csc_key = (np.repeat(np.arange(self.N), np.diff(P.indptr)).astype(np.int64) * self.N + P.indices)

    # -- layout ------------------------------------------------------------------------------------
    def split(self, y, yp):
        """``q, v, a, lam`` (copies) from the solver's ``y, y'``."""
        n, m = self.n, self.m
        z, zp = np.empty(self.N), np.empty(self.N)
        z[self.perm], zp[self.perm] = y, yp
        return z[:n], z[n:2 * n], zp[n:2 * n], z[2 * n:2 * n + m]

    def join(self, q, v, a, lam):
        """The solver's ``y, y'`` for the state ``(q, v, a, lam)`` with ``mu = 0``."""
        z = np.r_[q, v, lam, np.zeros(self.m)]
        zp = np.r_[v, a, np.zeros(2 * self.m)]
        return z[self.perm], zp[self.perm]

    def atol(self, atol_qv):
        """The solver's atol array: ``atol_qv`` (length 2 n or a scalar) and ``MULTIPLIER_ATOL`` for lam, mu."""
        z = np.r_[np.broadcast_to(np.asarray(atol_qv, float), (2 * self.n,)), np.full(2 * self.m, MULTIPLIER_ATOL)]
        return z[self.perm]

    @property
    def algebraic_idx(self) -> list:
        """Solver indices of ``lam`` and ``mu``."""
        return [int(i) for i in self.inv[2 * self.n:]]

    # -- callbacks ---------------------------------------------------------------------------------
    def resfn(self, t, y, yp, res):
        """``res[:] = F(t, y, y')`` in the solver's ordering."""
        n, m, model = self.n, self.m, self.model
        z, zp = np.empty(self.N), np.empty(self.N)
        z[self.perm], zp[self.perm] = y, yp
        q, v, lam, mu = z[:n], z[n:2 * n], z[2 * n:2 * n + m], z[2 * n + m:]
        G = sp.csr_matrix(model.constraint_jacobian(t, q))
        out = np.empty(self.N)
        out[:n] = zp[:n] - v - rmatvec(G, mu, n)
        out[n:2 * n] = model.residual(t, q, v, zp[n:2 * n]) + rmatvec(G, lam, n)
        out[2 * n:2 * n + m] = model.constraints(t, q)
        out[2 * n + m:] = G @ v + model.constraint_rates(t, q, v)[0]
        res[:] = out[self.perm]

    def _natural(self, t, q, v, a, lam, mu, cj, ones=False):
        """The iteration matrix in the natural order (``ones``: every block's structure, for the pattern)."""
        model, n = self.model, self.n
        blk = model.jacobian(t, q, v, a)
        G = sp.csr_matrix(model.constraint_jacobian(t, q))
        Hl = sp.csr_matrix(model.constraint_force_jacobian(t, q, lam))
        Hm = sp.csr_matrix(model.constraint_force_jacobian(t, q, mu))
        W = velocity_constraint_jacobian(model, t, q, v)
        K, D, M = (sp.csr_matrix(x) for x in (blk.K, blk.D, blk.M))
        eye, neg = sp.identity(n, format="csr"), -1.0
        if ones:
            neg = 1.0   # no cancellation between blocks   # structure only: every stored entry (explicit zeros too) as a one
            K, D, M, G, Hl, Hm, W = (_ones(x) for x in (K, D, M, G, Hl, Hm, W))
            W = _ones(W + G)   # W lives on G's pattern (its values may vanish at t0)
        return sp.bmat([[cj * eye + neg * Hm, neg * eye, None, neg * G.T],
                        [K + Hl, D + cj * M, G.T, None],
                        [G, None, None, None],
                        [W, G, None, None]], format="coo")

    def jacfn(self, t, y, yp, res, cj, JJ):
        """Fill ``JJ`` (full N x N array for "band"/"dense", CSC data for "sparse") with the exact matrix."""
        n, m = self.n, self.m
        z, zp = np.empty(self.N), np.empty(self.N)
        z[self.perm], zp[self.perm] = y, yp
        J = self._natural(t, z[:n], z[n:2 * n], zp[n:2 * n], z[2 * n:2 * n + m], z[2 * n + m:], cj)
        r, c = self.inv[J.row], self.inv[J.col]
        if self.linsolver == "sparse":
            keep = J.data != 0.0          # stored zeros may lie outside the pattern: harmless
            r, c, data = r[keep], c[keep], J.data[keep]
            key = c.astype(np.int64) * self.N + r
            s = np.searchsorted(self._csc_key, key)
            ok = s < self._csc_key.size
            if not (np.all(ok) and np.array_equal(self._csc_key[s], key)):
                raise ValueError("the constrained model's Jacobian has entries outside the pattern seen at t0; "
                                 "IDA's sparse solver needs a fixed pattern (use linsolver='band').")
            JJ[:] = np.bincount(s, weights=data, minlength=self._csc_key.size)
        else:
            JJ[:, :] = 0.0
            np.add.at(JJ, (r, c), J.data)
