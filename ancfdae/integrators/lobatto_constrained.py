"""Lobatto IIIA on constrained models: the stabilised index-2 (GGL) form with a reduced stage system.

A model with the ``"constraints"`` capability (:data:`ancfdae.problem.CAPABILITIES`) has the
equations ``r(t, q, v, a) + G^T lam = 0``, ``g(t, q) = 0``. :class:`~ancfdae.integrators.LobattoIIIA`
integrates them in the form of Gear, Gupta and Leimkuhler (1985), which imposes the position *and*
the velocity constraint through a second multiplier ``mu`` (zero for the exact solution)::

    q' = v + G^T mu,   M v' = -f - G^T lam,   g(t, q) = 0,   G v + g_t = 0.

Why this form (measured on planar point-mass chains, damped, errors at T = 1 s, slopes over
h = T/400 .. T/1600): the index-3 form (``g = 0`` only) keeps order 4 in q and v only for linear
constraints and drops to order 2 on a quadratic one (a distance joint), with multipliers that do not
converge; the Lobatto IIIA-IIIB pair (SPARK) is unstable for ``h omega > 2 sqrt 2``, i.e. at every
step the unresolved axial modes of ANCF beams allow. GGL kept order 4 in q and v on linear,
quadratic and rheonomic constraints; its ``lam`` is order 4 on linear constraints and about 2 on
quadratic ones (``lam`` recomputed from ``(q, v)`` by the KKT system is order 4 everywhere).

Stages ``i = 2..s`` (stage 1 is the known state: ``K_1 = v_n``, ``A_1 = a_n``, ``mu_1 = 0``), with the
stage derivatives of the positions ``K_i`` and ``mu_i = h U_i``::

    Q_i = q_n + h sum_j a_ij K_j,             V_i = v_n + h sum_j a_ij A_j
    (m_s / h)   (K_i - V_i - h G(t_i, Q_i)^T U_i)     = 0      kinematic rows
    r(t_i, Q_i, V_i, A_i) + G(t_i, Q_i)^T Lam_i       = 0      dynamic rows
    (m_s / h^2) g(t_i, Q_i)                           = 0      position constraint
    (m_s / h)   (G(t_i, Q_i) V_i + g_t(t_i, Q_i))     = 0      velocity constraint

``m_s`` (the largest diagonal entry of ``M``) makes every row a force, so that Newton's max-norm test
and the run's absolute tolerance (in newtons) weigh all rows alike. The new state is the last stage
(stiffly accurate); the step's multipliers are ``Lam_s``.

Newton matrix: exact except for ``h H(h U_i)`` in the kinematic rows (``|mu| = O(h^p)``; dropping it
cost no iteration in the measurements). The kinematic rows then read ``dK = rho + h a dA + h G^T dU``
and are eliminated in the solve, which leaves a system in ``[A, Lam, U]`` of size
``(s - 1)(n + 2m)``, factorised once per Jacobian (sparse, banded LAPACK or SuperLU by
:func:`ancfdae.integrators._linsolve.factorize`), on an ordering that keeps each multiplier next
to the last coordinate its constraint row touches. Modified Newton evaluates the blocks at the last
stage for every stage; when that fails a step, the step is retried with per-stage blocks.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ancfdae.integrators._constraint_terms import velocity_constraint_jacobian
from ancfdae.integrators._linsolve import factorize
from ancfdae.integrators.protocol import Quadrature, StepOutcome

__all__ = ["GGLStages", "ReducedMatrix", "ggl_step"]


def rmatvec(G: sp.csr_matrix, u: np.ndarray, n: int) -> np.ndarray:
    """``G^T u`` for a CSR ``G`` of ``n`` columns, without forming the transpose (one bincount)."""
    w = G.data * np.repeat(u, np.diff(G.indptr))
    return np.bincount(G.indices, weights=w, minlength=n)


class GGLStages:
    """The GGL stage system of one Lobatto IIIA stepper (built by its set-up for a constrained model).

    Parameters
    ----------
    stepper : LobattoIIIA
        The stepper (its tableau, model, Newton solver and current state, with ``lam``).
    """

    def __init__(self, stepper) -> None:
        tab = stepper.tableau
        self.stepper = stepper
        self.ns = tab.stages - 1
        self.a_first, self.a = tab.a[1:, 0].copy(), tab.a[1:, 1:].copy()
        self.a2 = (tab.a @ tab.a)[1:, 1:].copy()
        self.c = tab.c[1:].copy()
        model = stepper.model
        self.n, self.m = stepper.n_dof, int(model.n_constraints)
        diag = np.abs(sp.csr_matrix(model.mass(stepper.q)).diagonal())
        self.ms = float(diag.max()) if diag.size and diag.max() > 0 else 1.0
        self.perm = self._ordering(sp.csr_matrix(model.constraint_jacobian(stepper.t, stepper.q)))

    def _ordering(self, G):
        """Permutation of ``[A (n ns), Lam (m ns), U (m ns)]`` (stage copies interleaved): each
        multiplier after the last coordinate its row of ``G`` touches (keeps the matrix banded)."""
        n, m, ns = self.n, self.m, self.ns
        last = np.full(m, float(n))
        for i in range(m):
            cols = G.indices[G.indptr[i]:G.indptr[i + 1]]
            if cols.size:
                last[i] = cols.max() + 0.5
        keys = np.r_[np.repeat(np.arange(n, dtype=float), ns), np.repeat(last, ns), np.repeat(last, ns)]
        return np.argsort(keys, kind="stable")

    # -- unknowns ------------------------------------------------------------------------------
    def split(self, x):
        """``K, A`` (n, ns), ``Lam, U`` (m, ns) of the flat unknown vector."""
        n, m, ns = self.n, self.m, self.ns
        o = 2 * n * ns
        return (x[:n * ns].reshape(n, ns), x[n * ns:o].reshape(n, ns),
                x[o:o + m * ns].reshape(m, ns), x[o + m * ns:].reshape(m, ns))

    def states(self, x, t, h):
        """Stage times, ``Q, V, A, Lam, U`` at the unknowns ``x`` of the step ``(t, h)``."""
        st = self.stepper
        K, A, L, U = self.split(x)
        Q = st.q[:, None] + h * np.outer(st.v, self.a_first) + h * K @ self.a.T
        V = st.v[:, None] + h * np.outer(st.a, self.a_first) + h * A @ self.a.T
        return t + self.c * h, Q, V, A, L, U

    def guess(self, h):
        """``K_i = v_n + c_i h a_n``, ``A_i = a_n``, ``Lam_i = lam_n``, ``U_i = 0``."""
        st = self.stepper
        K = st.v[:, None] + h * self.c * st.a[:, None]
        A = np.repeat(st.a[:, None], self.ns, axis=1)
        L = np.repeat(st.lam[:, None], self.ns, axis=1)
        return np.concatenate([K.ravel(), A.ravel(), L.ravel(), np.zeros(self.m * self.ns)])

    # -- residual ------------------------------------------------------------------------------
    def residual(self, x, t, h):
        """The scaled stage residual (module docstring), flat in the layout of ``x``."""
        model, ms = self.stepper.model, self.ms
        ts, Q, V, A, L, U = self.states(x, t, h)
        K = self.split(x)[0]
        RK, RD = np.empty_like(K), np.empty_like(K)
        Rg, Rv = np.empty_like(L), np.empty_like(L)
        n = self.n
        for i in range(self.ns):
            G = sp.csr_matrix(model.constraint_jacobian(ts[i], Q[:, i]))
            RK[:, i] = (ms / h) * (K[:, i] - V[:, i] - h * rmatvec(G, U[:, i], n))
            RD[:, i] = model.residual(ts[i], Q[:, i], V[:, i], A[:, i]) + rmatvec(G, L[:, i], n)
            Rg[:, i] = (ms / (h * h)) * model.constraints(ts[i], Q[:, i])
            Rv[:, i] = (ms / h) * (G @ V[:, i] + model.constraint_rates(ts[i], Q[:, i], V[:, i])[0])
        return np.concatenate([RK.ravel(), RD.ravel(), Rg.ravel(), Rv.ravel()])

    # -- Newton matrix -------------------------------------------------------------------------
    def blocks(self, x, t, h, stages):
        """Per-stage ``(Kt = K + H(Lam_i), D, M, G, W)`` at the given stages (one set repeated when
        ``stages`` has one entry) and the round-off floor of the largest stiffness."""
        st, model = self.stepper, self.stepper.model
        ts, Q, V, A, L, U = self.states(x, t, h)
        out, floor = [], 0.0
        for i in stages:
            blk = model.jacobian(ts[i], Q[:, i], V[:, i], A[:, i])
            Kt = sp.csr_matrix(blk.K + model.constraint_force_jacobian(ts[i], Q[:, i], L[:, i]))
            G = sp.csr_matrix(model.constraint_jacobian(ts[i], Q[:, i]))
            W = velocity_constraint_jacobian(model, ts[i], Q[:, i], V[:, i])
            out.append((Kt, sp.csr_matrix(blk.D), sp.csr_matrix(blk.M), G, W))
            floor = max(floor, st.floor_of(blk.K, Q[:, i]))
        if len(out) == 1:
            out = out * self.ns
        return ReducedMatrix(self, out, h), floor


def _kron_sum(terms, ns, shape):
    """``sum kron(B_ik, E_ik)`` over ``((i, k), B)``: the stage-interleaved block matrix."""
    out = sp.csr_matrix((shape[0] * ns, shape[1] * ns))
    for (i, k), B in terms:
        if B is None:
            continue
        E = sp.csr_matrix(([1.0], ([i], [k])), shape=(ns, ns))
        out = out + sp.kron(B, E, format="csr")
    return out


class ReducedMatrix:
    """The Newton matrix of the GGL stage system with the kinematic rows eliminated (``factorize``)."""

    def __init__(self, system: GGLStages, blocks, h: float) -> None:
        self.system, self.blocks, self.h = system, blocks, float(h)

    def matrix(self) -> sp.csr_matrix:
        """The reduced matrix in ``[A, Lam, U]`` (natural order, stage copies interleaved)."""
        s, h, ms, blk = self.system, self.h, self.system.ms, self.blocks
        a, a2, ns, n, m = s.a, s.a2, s.ns, s.n, s.m
        pairs = [(i, k) for i in range(ns) for k in range(ns)]
        AA = _kron_sum([((i, k), a2[i, k] * h * h * blk[i][0] + a[i, k] * h * blk[i][1]
                         + (blk[i][2] if i == k else 0 * blk[i][2])) for i, k in pairs], ns, (n, n))
        AL = _kron_sum([((i, i), blk[i][3].T) for i in range(ns)], ns, (n, m))
        AU = _kron_sum([((i, k), (a[i, k] * h * h) * (blk[i][0] @ blk[k][3].T)) for i, k in pairs], ns, (n, m))
        LA = _kron_sum([((i, k), (ms * a2[i, k]) * blk[i][3]) for i, k in pairs], ns, (m, n))
        LU = _kron_sum([((i, k), (ms * a[i, k]) * (blk[i][3] @ blk[k][3].T)) for i, k in pairs], ns, (m, m))
        UA = _kron_sum([((i, k), ms * (a[i, k] * blk[i][3] + (h * a2[i, k]) * blk[i][4])) for i, k in pairs],
                       ns, (m, n))
        UU = _kron_sum([((i, k), (ms * h * a[i, k]) * (blk[i][4] @ blk[k][3].T)) for i, k in pairs], ns, (m, m))
        return sp.bmat([[AA, AL, AU], [LA, None, LU], [UA, None, UU]], format="csr")

    def factorize(self):
        """Factorise on the banded ordering; returns an object with ``solve(r)`` for the full residual."""
        p = self.system.perm
        J = self.matrix()[p][:, p]
        return _ReducedFactor(self, factorize(sp.csr_matrix(J)))


class _ReducedFactor:
    """Solve the full stage system ``J dx = r`` through the reduced factorisation."""

    def __init__(self, rm: ReducedMatrix, lu) -> None:
        self.rm, self.lu = rm, lu

    def solve(self, r):
        s, h, ms, blk = self.rm.system, self.rm.h, self.rm.system.ms, self.rm.blocks
        n, m, ns = s.n, s.m, s.ns
        RK, RD, Rg, Rv = s.split(np.asarray(r, dtype=float))
        rho = RK * (h / ms)
        P = h * rho @ s.a.T
        bD, bg, bv = RD.copy(), Rg.copy(), Rv.copy()
        for i in range(ns):
            Kt, _, _, G, W = blk[i]
            bD[:, i] -= Kt @ P[:, i]
            bg[:, i] -= (ms / (h * h)) * (G @ P[:, i])
            bv[:, i] -= (ms / h) * (W @ P[:, i])
        b = np.concatenate([bD.ravel(), bg.ravel(), bv.ravel()])
        z = np.empty_like(b)
        z[s.perm] = self.lu.solve(b[s.perm])
        dA = z[:n * ns].reshape(n, ns)
        dL = z[n * ns:n * ns + m * ns].reshape(m, ns)
        dU = z[n * ns + m * ns:].reshape(m, ns)
        dK = rho + h * dA @ s.a.T
        for i in range(ns):
            dK[:, i] += h * rmatvec(blk[i][3], dU[:, i], n)
        return np.concatenate([dK.ravel(), dA.ravel(), dL.ravel(), dU.ravel()])


def ggl_step(stepper, system: GGLStages, t: float, h: float) -> StepOutcome:
    """One Lobatto IIIA step of the GGL form from the stepper's state; the state is not changed."""
    last = [system.ns - 1]
    per_stage = [stepper.newton.options.jacobian != "modified"]

    def residual(x):
        return system.residual(x, t, h)

    def jacobian(x):
        return system.blocks(x, t, h, range(system.ns) if per_stage[0] else last)

    guess = system.guess(h)
    out = stepper._solve(residual, jacobian, guess)
    if not out.converged and not per_stage[0]:
        # blocks of the last stage for every stage can be too crude where the stages differ much
        per_stage[0] = True
        stepper.newton.invalidate()
        out = stepper._solve(residual, jacobian, guess)
    if not out.converged:
        return StepOutcome.failure(f"Newton (GGL stage system): {out.message}")
    ts, Q, V, A, L, U = system.states(out.x, t, h)
    quad = None
    if stepper.want_quadrature:
        quad = Quadrature(np.r_[t, ts], np.column_stack([stepper.q, Q]).T, np.column_stack([stepper.v, V]).T,
                          h * stepper.tableau.b)
    return StepOutcome(ok=True, t=t + h, q=Q[:, -1].copy(), v=V[:, -1].copy(), a=A[:, -1].copy(),
                       quadrature=quad, lam=L[:, -1].copy())
