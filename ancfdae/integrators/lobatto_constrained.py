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

from dataclasses import replace

import numpy as np
import scipy.sparse as sp

from ancfdae.integrators._constraint_terms import velocity_constraint_jacobian
from ancfdae.integrators._csr_numba import csr_matvec, csr_rmatvec, ggl_expand, ggl_reduce, ggl_stage_rows
from ancfdae.integrators._linsolve import _factorize_pattern
from ancfdae.integrators.protocol import Quadrature, StepOutcome
from ancfdae.problem import capabilities

__all__ = ["GGLStages", "ReducedMatrix", "ggl_step"]


def as_csr(G) -> sp.csr_matrix:
    """``G`` itself when it is a CSR matrix (no copy, no format check), else converted."""
    return G if getattr(G, "format", None) == "csr" else sp.csr_matrix(G)


def rmatvec(G: sp.csr_matrix, u: np.ndarray, n: int) -> np.ndarray:
    """``G^T u`` for a CSR ``G`` of ``n`` columns, without forming the transpose (compiled)."""
    return csr_rmatvec(G.indptr, G.indices, G.data.astype(float, copy=False), np.ascontiguousarray(u, dtype=float), n)


def matvec(G: sp.csr_matrix, x: np.ndarray) -> np.ndarray:
    """``G x`` for a CSR ``G`` with few rows (compiled; scipy's product costs more to call)."""
    return csr_matvec(G.indptr, G.indices, G.data.astype(float, copy=False), np.ascontiguousarray(x, dtype=float))


def _coo(B):
    """``(rows, cols, values)`` of a CSR matrix or a dense array (its nonzeros), without scipy's checks."""
    if isinstance(B, np.ndarray):
        r, c = np.nonzero(B)
        return r, c, B[r, c]
    return np.repeat(np.arange(B.shape[0]), np.diff(B.indptr)), B.indices, B.data


def _transposed(trip):
    return trip[1], trip[0], trip[2]


def _stage_terms(B, C, ns, r0, c0):
    """COO of ``kron(B, C)`` placed at offsets ``(r0, c0)``: entry ``(p ns + i, q ns + k) = B_pq C_ik``
    (``B`` a CSR matrix, a dense array or a ``(rows, cols, values)`` triple; ``C`` an (ns, ns)
    coefficient array, zeros skipped)."""
    p, q, b = B if isinstance(B, tuple) else _coo(B)
    i, k = np.nonzero(C)
    rows = (r0 + p[:, None] * ns + i[None, :]).ravel()
    cols = (c0 + q[:, None] * ns + k[None, :]).ravel()
    return rows, cols, (b[:, None] * C[i, k][None, :]).ravel()


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
        self.t_step = self.h_step = None
        self._assembly = None
        self.n, self.m = stepper.n_dof, int(model.n_constraints)
        diag = np.abs(sp.csr_matrix(model.mass(stepper.q)).diagonal())
        self.ms = float(diag.max()) if diag.size and diag.max() > 0 else 1.0
        self.perm = self._ordering(sp.csr_matrix(model.constraint_jacobian(stepper.t, stepper.q)))
        self.inv_perm = np.empty_like(self.perm)
        self.inv_perm[self.perm] = np.arange(self.perm.size)
        self.stages = model.residual_stages if "residual_stages" in capabilities(model) else None
        self._stage_terms = None    # per stage: q -> (g, G, g_t) at its time, when the model offers it

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

    def assemble(self, rows, cols, vals, N):
        """CSR from COO triples; the slot map is kept while the triples' pattern repeats (modified Newton
        refreshes the same structure), so the pattern arrays -- and the banded LU's map -- are reused."""
        c = self._assembly
        if c is not None and c[0].size == rows.size and np.array_equal(c[0], rows) and np.array_equal(c[1], cols):
            _, _, slot, indptr, indices = c
        else:
            P = sp.csr_matrix((np.arange(1, rows.size + 1, dtype=float), (rows, cols)), shape=(N, N))
            P.sum_duplicates()
            P.sort_indices()
            key = np.repeat(np.arange(N), np.diff(P.indptr)).astype(np.int64) * N + P.indices
            slot = np.searchsorted(key, rows.astype(np.int64) * N + cols)
            indptr, indices = P.indptr, P.indices
            self._assembly = (rows, cols, slot, indptr, indices)
        return np.bincount(slot, weights=vals, minlength=indices.size), indptr, indices

    # -- unknowns ------------------------------------------------------------------------------
    def split(self, x):
        """``K, A`` (n, ns), ``Lam, U`` (m, ns) of the flat unknown vector."""
        n, m, ns = self.n, self.m, self.ns
        o = 2 * n * ns
        return (x[:n * ns].reshape(n, ns), x[n * ns:o].reshape(n, ns),
                x[o:o + m * ns].reshape(m, ns), x[o + m * ns:].reshape(m, ns))

    def begin(self, t, h):
        """Fix the step ``(t, h)``: stage times and the parts of ``Q, V`` that do not depend on ``x``."""
        st = self.stepper
        self.t_step, self.h_step, self.ts = t, h, t + self.c * h
        self.Q0 = st.q[:, None] + h * np.outer(st.v, self.a_first)
        self.V0 = st.v[:, None] + h * np.outer(st.a, self.a_first)
        self.haT = h * self.a.T
        # (g, G, g_t) of a stage in one pass, time functions evaluated once a step (a compiled System)
        at = getattr(st.model, "constraint_position_terms_at", None)
        self._stage_terms = [at(ti) for ti in self.ts] if callable(at) else None

    def states(self, x, t, h):
        """Stage times, ``Q, V, A, Lam, U`` at the unknowns ``x`` of the step ``(t, h)``."""
        if t != self.t_step or h != self.h_step:
            self.begin(t, h)
        K, A, L, U = self.split(x)
        return self.ts, self.Q0 + K @ self.haT, self.V0 + A @ self.haT, A, L, U

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
        model, ms, n, ns = self.stepper.model, self.ms, self.n, self.ns
        ts, Q, V, A, L, U = self.states(x, t, h)
        K = self.split(x)[0]
        out = np.empty(x.size)
        RD = out[n * ns:2 * n * ns].reshape(n, ns)
        if self.stages is not None:      # every stage's model residual in one call
            RD[:] = self.stages(ts, Q, V, A)
        for i in range(ns):
            q, v = Q[:, i], V[:, i]
            if self.stages is None:
                RD[:, i] = model.residual(ts[i], q, v, A[:, i])
            if self._stage_terms is not None:
                g, G, g_t = self._stage_terms[i](q)
            else:
                G = as_csr(model.constraint_jacobian(ts[i], q))
                g = np.asarray(model.constraints(ts[i], q), dtype=float)
                g_t = np.asarray(model.constraint_rates(ts[i], q, v)[0], dtype=float)
            ggl_stage_rows(out, i, n, self.m, ns, ms, h, G.indptr, G.indices, G.data.astype(float, copy=False),
                           K, V, U, L, g, g_t)
        return out

    # -- Newton matrix -------------------------------------------------------------------------
    def blocks(self, x, t, h, stages):
        """Per-stage ``(Kt = K + H(Lam_i), D, M, G, W)`` at the given stages (one set repeated when
        ``stages`` has one entry) and the residual's round-off floor: that of the largest stiffness, the
        elastic ``K`` or the scaled position rows' ``(m_s / h^2) G``."""
        st, model = self.stepper, self.stepper.model
        ts, Q, V, A, L, U = self.states(x, t, h)
        out, floor = [], 0.0
        for i in stages:
            blk = model.jacobian(ts[i], Q[:, i], V[:, i], A[:, i])
            Kt = sp.csr_matrix(blk.K + model.constraint_force_jacobian(ts[i], Q[:, i], L[:, i]))
            G = sp.csr_matrix(model.constraint_jacobian(ts[i], Q[:, i]))
            W = as_csr(velocity_constraint_jacobian(model, ts[i], Q[:, i], V[:, i]))
            out.append((Kt, sp.csr_matrix(blk.D), sp.csr_matrix(blk.M), G, W))
            # the position rows (m_s / h^2) g are a stiffness (m_s / h^2) G on Q: at small steps their
            # round-off outgrows the elastic forces' (B7, h = 3.125e-4: max|r| stalled at 5.7e-10 N in
            # those rows against a floor of 2.5e-10 N from K, Newton ended "diverging" at t = 0)
            floor = max(floor, st.floor_of(blk.K, Q[:, i]), st.floor_of(G, Q[:, i]) * (self.ms / (h * h)))
        if len(out) == 1:
            out = out * self.ns
        return ReducedMatrix(self, out, h), floor


class ReducedMatrix:
    """The Newton matrix of the GGL stage system with the kinematic rows eliminated (``factorize``)."""

    def __init__(self, system: GGLStages, blocks, h: float) -> None:
        self.system, self.blocks, self.h = system, blocks, float(h)
        self.frozen = all(b is blocks[0] for b in blocks)   # modified Newton: the last stage's blocks

    def matrix(self, permuted: bool = False) -> sp.csr_matrix:
        """The reduced matrix as CSR (see :meth:`triples`)."""
        data, indptr, indices = self.triples(permuted)
        N = indptr.size - 1
        return sp.csr_matrix((data, indices, indptr), shape=(N, N))

    def triples(self, permuted: bool = False):
        """The reduced matrix in ``[A, Lam, U]`` as CSR arrays ``(data, indptr, indices)`` (stage copies
        interleaved; ``permuted``: on the banded ordering ``perm`` of the system, i.e. entry
        ``(perm[i], perm[j])`` moved to ``(i, j)``)."""
        s, h, ms, blk = self.system, self.h, self.system.ms, self.blocks
        a, a2, ns, n, m = s.a, s.a2, s.ns, s.n, s.m
        oA, oL, oU = 0, n * ns, n * ns + m * ns
        parts = []
        eye = np.eye(ns)
        dense = [(b[3].toarray(), b[4].toarray()) for b in (blk[:1] if self.frozen else blk)]   # (G, W), m rows
        for i in range(ns) if not self.frozen else [None]:
            # rows of stage i (all stages at once when the blocks are frozen)
            sel = np.ones((ns, ns)) if i is None else np.outer(eye[i], np.ones(ns))
            Kt, D, M, G, W = blk[0 if i is None else i]
            Gd, Wd = dense[0 if i is None else i]
            g = _coo(G)
            parts += [_stage_terms(M, sel * eye, ns, oA, oA), _stage_terms(D, h * sel * a, ns, oA, oA),
                      _stage_terms(Kt, h * h * sel * a2, ns, oA, oA), _stage_terms(_transposed(g), sel * eye, ns, oA, oL),
                      _stage_terms(g, ms * sel * a2, ns, oL, oA), _stage_terms(g, ms * sel * a, ns, oU, oA),
                      _stage_terms(W, ms * h * sel * a2, ns, oU, oA)]
            for k in range(ns) if not self.frozen else [None]:
                # columns of stage k's mu: G_k^T enters through dQ (products with few columns: dense)
                ck = sel if k is None else sel * np.outer(np.ones(ns), eye[k])
                GcT = (Gd if k is None else dense[k][0]).T
                parts += [_stage_terms(np.asarray(Kt @ GcT), h * h * ck * a, ns, oA, oU),
                          _stage_terms(Gd @ GcT, ms * ck * a, ns, oL, oU),
                          _stage_terms(Wd @ GcT, ms * h * ck * a, ns, oU, oU)]
        rows, cols, vals = (np.concatenate(x) for x in zip(*parts))
        N = (n + 2 * m) * ns
        if permuted:
            rows, cols = s.inv_perm[rows], s.inv_perm[cols]
        return s.assemble(rows, cols, vals, N)   # (data, indptr, indices): CSR arrays

    def factorize(self):
        """Factorise on the banded ordering; returns an object with ``solve(r)`` for the full residual."""
        data, indptr, indices = self.triples(permuted=True)   # the same pattern arrays: band map cached
        return _ReducedFactor(self, _factorize_pattern(data, indptr, indices, indptr.size - 1))


class _ReducedFactor:
    """Solve the full stage system ``J dx = r`` through the reduced factorisation."""

    def __init__(self, rm: ReducedMatrix, lu) -> None:
        self.rm, self.lu = rm, lu
        if rm.frozen:     # the compiled path: arrays of the one set of blocks
            Kt, _, _, G, W = rm.blocks[0]
            s = rm.system
            self._args = (s.n, s.m, s.ns, rm.h, s.ms, s.a) + tuple(
                x for B in (Kt, G, W) for x in (B.indptr, B.indices, B.data.astype(float, copy=False)))
            self._exp = (s.n, s.m, s.ns, rm.h, s.a, G.indptr, G.indices, G.data.astype(float, copy=False), s.perm)

    def solve(self, r):
        if self.rm.frozen:
            bp, rho = ggl_reduce(np.asarray(r, dtype=float), *self._args, self.rm.system.perm)
            return ggl_expand(np.asarray(self.lu.solve(bp), dtype=float), rho, *self._exp)
        s, h, ms, blk = self.rm.system, self.rm.h, self.rm.system.ms, self.rm.blocks
        n, m, ns = s.n, s.m, s.ns
        RK, RD, Rg, Rv = s.split(np.asarray(r, dtype=float))
        rho = RK * (h / ms)
        P = h * rho @ s.a.T
        bD = RD - blk[0][0] @ P if self.rm.frozen else RD.copy()   # frozen: one product for all stages
        bg, bv = Rg.copy(), Rv.copy()
        for i in range(ns):
            Kt, _, _, G, W = blk[i]
            if not self.rm.frozen:
                bD[:, i] -= Kt @ P[:, i]
            bg[:, i] -= (ms / (h * h)) * matvec(G, P[:, i])
            bv[:, i] -= (ms / h) * matvec(W, P[:, i])
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


def _full_newton(stepper, residual, jacobian, guess):
    """The step's last attempt: full Newton (a fresh per-stage matrix every iteration) from the guess.

    Modified Newton can fail a step that Newton solves in 3-4 iterations: on B5 (spin-up, BE2D 8 elements,
    no numerical dissipation) the first residual grows with the unresolved stiff modes the method keeps
    (1e3 N at 5 s, 1e5 N at 7.8 s, h = 0.05) and a matrix kept over iterations no longer contracts there;
    modified Newton stopped at 7.8 s (h = 0.05) and 6.8 s (h = 0.1; 7.4 s with the constraint rows' floor in
    :meth:`GGLStages.blocks`), full Newton at 10.25 and 9.4 s.
    The options are swapped for this one solve only; the matrix it leaves (at the converged stages) is the
    next step's modified-Newton matrix.
    """
    newton = stepper.newton
    options = newton.options
    newton.options = replace(options, jacobian="full")
    newton.invalidate()
    try:
        return stepper._solve(residual, jacobian, guess)
    finally:
        newton.options = options


def ggl_step(stepper, system: GGLStages, t: float, h: float) -> StepOutcome:
    """One Lobatto IIIA step of the GGL form from the stepper's state; the state is not changed."""
    last = [system.ns - 1]
    per_stage = [stepper.newton.options.jacobian != "modified"]

    def residual(x):
        return system.residual(x, t, h)

    def jacobian(x):
        return system.blocks(x, t, h, range(system.ns) if per_stage[0] else last)

    system.begin(t, h)
    guess = system.guess(h)
    out = stepper._solve(residual, jacobian, guess)
    if not out.converged and not per_stage[0]:
        # blocks of the last stage for every stage can be too crude where the stages differ much
        per_stage[0] = True
        stepper.newton.invalidate()
        out = stepper._solve(residual, jacobian, guess)
    if not out.converged and stepper.newton.options.jacobian == "modified":
        out = _full_newton(stepper, residual, jacobian, guess)
    if not out.converged:
        return StepOutcome.failure(f"Newton (GGL stage system): {out.message}")
    ts, Q, V, A, L, U = system.states(out.x, t, h)
    quad = None
    if stepper.want_quadrature:
        quad = Quadrature(np.r_[t, ts], np.column_stack([stepper.q, Q]).T, np.column_stack([stepper.v, V]).T,
                          h * stepper.tableau.b)
    return StepOutcome(ok=True, t=t + h, q=Q[:, -1].copy(), v=V[:, -1].copy(), a=A[:, -1].copy(),
                       quadrature=quad, lam=L[:, -1].copy())
